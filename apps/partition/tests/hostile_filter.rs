//! The simulator re-validates every safe command (`sc_flight::admission`): a lying
//! process in the translational safety filter's role (`scripts/python/hostile_filter.py`)
//! publishes, for the right tick, 1000 × the force bound, NaN or +inf in turn. Every one
//! must be rejected and logged, the filter's backup applied instead, and the run stay
//! safe and within bounds. Needs a Python with iceoryx2 (`SC_PYTHON`, set by
//! scripts/test.sh; without one the test is skipped with the reason printed).

mod common;
use common::*;

#[test]
fn lying_safe_commands_are_rejected_and_the_backup_applied() {
    let Some(py) = python() else {
        return;
    };
    let dir = tmp("liar");
    let out = dir.join("out");
    let config = write_config(&dir, Some(30.0), None, 20.0);
    let mut opts = options(&config, &out, "liar");
    opts.role_override.push((
        "safety_translational".into(),
        py.display().to_string(),
        vec![
            repo()
                .join("scripts/python/hostile_filter.py")
                .display()
                .to_string(),
        ],
    ));
    let rep = sc_ground::launch(&opts).unwrap();
    assert_clean(&rep, &out);
    let log = |role: &str| std::fs::read_to_string(out.join(format!("logs/{role}.log"))).unwrap();
    let liar = log("safety_translational");
    assert!(liar.contains("hostile_filter.py: sent"), "{liar}");
    let sent: usize = liar
        .split("sent ")
        .nth(1)
        .and_then(|x| x.split_whitespace().next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("{liar}"));
    let steps = contiguous_steps(&out);
    assert!(
        sent + 1 >= steps && steps >= 290,
        "{sent} lies, {steps} steps"
    );
    // the simulator names every rejection and counts them at the end
    let sim = log("simulator");
    assert!(
        sim.contains("translational safe command rejected (not finite or beyond the input bounds), backup applied"),
        "{sim}"
    );
    let counts = sim
        .split("safe commands rejected (translational, attitude, robotic) [")
        .nth(1)
        .and_then(|x| x.split(']').next())
        .unwrap_or_else(|| panic!("{sim}"));
    let counts: Vec<usize> = counts.split(", ").map(|x| x.parse().unwrap()).collect();
    assert_eq!(counts[1..], [0, 0], "{sim}");
    assert!(counts[0] + 1 >= steps, "{counts:?} of {steps} steps");
    // what was applied: finite and within the force box at every step; safe
    let tel = std::fs::read_to_string(out.join("telemetry.csv")).unwrap();
    let mut lines = tel.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let f = [
        col("f_b_applied_x_n"),
        col("f_b_applied_y_n"),
        col("f_b_applied_z_n"),
    ];
    let fmax = sc_scenario::Scenario::load(&dir.join("scenario.toml"))
        .unwrap()
        .limits
        .force_max_n;
    for line in lines {
        let v: Vec<&str> = line.split(',').collect();
        for &i in &f {
            let x: f64 = v[i].parse().unwrap();
            assert!(x.is_finite() && x.abs() <= fmax, "applied {x} in {line}");
        }
    }
    let s = summary(&out);
    assert!(
        s["violated_constraints"].as_array().unwrap().is_empty(),
        "{s}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
