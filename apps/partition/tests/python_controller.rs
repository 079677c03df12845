//! The third-party Python nominal translational controller (iceoryx2 PyPI package)
//! replaces the Rust role from config and the mission runs through it to capture.
//! The interpreter is `SC_PYTHON` (set by scripts/test.sh, which creates the venv; then
//! a missing or broken interpreter fails the test), else scripts/.venv/bin/python;
//! without either the test is skipped, with the reason printed.

mod common;
use common::*;

#[test]
fn python_nominal_controller_runs_the_mission() {
    let Some(py) = python() else {
        return;
    };
    let dir = tmp("python");
    let out = dir.join("out");
    let config = repo().join("config/partition_python.toml");
    let mut opts = options(&config, &out, "py");
    opts.role_override.push((
        "nominal_translational".into(),
        py.display().to_string(),
        vec![
            repo()
                .join("scripts/python/nominal_translational.py")
                .display()
                .to_string(),
        ],
    ));
    let rep = sc_ground::launch(&opts).unwrap();
    assert_clean(&rep, &out);
    assert_eq!(rep.code, 0, "{rep:?}");
    // the Python process is woken and wakes the filter like the Rust one: nothing
    // waited for the stage-deadline watchdog or a wait timeout
    assert_no_lost_wakeups(&out);
    let s = summary(&out);
    assert_eq!(s["end"], "captured", "{s}");
    assert!(
        s["violated_constraints"].as_array().unwrap().is_empty(),
        "{s}"
    );
    let log = std::fs::read_to_string(out.join("logs/nominal_translational.log")).unwrap();
    assert!(log.contains("nominal_translational.py: handled"), "{log}");
    // the Python law is not the Rust MPC: the nominal forces differ from the in-process run
    let eff = std::fs::read_to_string(out.join("partition.effective.toml")).unwrap();
    assert!(eff.contains("nominal_translational.py"), "{eff}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("recorder.json")).unwrap()).unwrap();
    assert_eq!(r["missing"]["safe_capture/nominal/translational"], 0, "{r}");
    std::fs::remove_dir_all(&dir).ok();
}
