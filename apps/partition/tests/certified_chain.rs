//! The partition applies only what was certified: a command acts only with exactly the
//! upstream commands it was certified against (its ξ, carried in the safe messages).
//! A late attitude safety filter (`scripts/python/late_attitude_filter.py`) answers every
//! tick 65 ms after it started — after the robotic filter gave up on it (its deadline cut
//! to 45 ms here, for 20 ms of room on both sides on a loaded machine) and certified
//! against the attitude backup, before the simulator's own deadline (90 ms).
//! Read back from the run's recording: in every step where the robotic command acts, the
//! force and torque applied are the ones it was certified against; the window was hit;
//! no barrier went below zero. Needs a Python with iceoryx2 (`SC_PYTHON`, set by
//! scripts/test.sh; without one the test is skipped with the reason printed).

mod common;
use common::*;

#[test]
fn a_command_late_for_its_downstream_filter_never_acts() {
    let Some(py) = python() else {
        return;
    };
    let dir = tmp("late");
    let out = dir.join("out");
    let config = write_config(&dir, Some(20.0), None, 20.0);
    let text = std::fs::read_to_string(&config).unwrap();
    let mut real_time = text.replace("clock = \"lock_step\"", "clock = \"real_time\"");
    for (stage, ms) in [
        ("translational", "20.0"),
        ("attitude", "30.0"),
        ("robotic", "45.0"),
    ] {
        let key = format!("safety_{stage}_ms = ");
        let at = real_time.find(&key).unwrap() + key.len();
        let end = at + real_time[at..].find('\n').unwrap();
        real_time.replace_range(at..end, ms);
    }
    assert_ne!(text, real_time, "the config names its clock");
    std::fs::write(&config, real_time).unwrap();
    let mut opts = options(&config, &out, "late");
    opts.role_override.push((
        "safety_attitude".into(),
        py.display().to_string(),
        vec![
            repo()
                .join("scripts/python/late_attitude_filter.py")
                .display()
                .to_string(),
            "--delay-ms".into(),
            "65".into(),
        ],
    ));
    let rep = sc_ground::launch(&opts).unwrap();
    assert_clean(&rep, &out);
    let (steps, acted, mismatched) = assert_applied_as_certified(&out);
    eprintln!(
        "{steps} steps: the robotic command acted in {acted}, a command was refused for its coupling in {mismatched}"
    );
    assert!(steps >= 150, "{steps} steps");
    // the late commands reached the simulator inside its deadline and were refused there
    // (in most steps: with 20 ms of room on both sides)
    assert!(
        acted > 0 && 2 * mismatched >= steps,
        "acted {acted}, mismatched {mismatched}"
    );
    let sim = std::fs::read_to_string(out.join("logs/simulator.log")).unwrap();
    assert!(
        sim.contains(
            "attitude safe command came after the downstream filters certified against its backup"
        ),
        "{sim}"
    );
    let s = summary(&out);
    assert!(
        s["violated_constraints"].as_array().unwrap().is_empty(),
        "{s}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
