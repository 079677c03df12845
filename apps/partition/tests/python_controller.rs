//! The third-party Python nominal translational controller (iceoryx2 PyPI package)
//! replaces the Rust role from config and the mission runs through it to capture.
//! Skipped, with the reason printed, when scripts/.venv is missing (CI creates it:
//! `python3 -m venv scripts/.venv && scripts/.venv/bin/pip install -r scripts/requirements.txt`).

mod common;
use common::*;

#[test]
fn python_nominal_controller_runs_the_mission() {
    let py = repo().join("scripts/.venv/bin/python");
    if !py.exists() {
        eprintln!(
            "SKIPPED: {} missing (create the venv from scripts/requirements.txt)",
            py.display()
        );
        return;
    }
    let ok = std::process::Command::new(&py)
        .args(["-c", "import iceoryx2"])
        .status()
        .map(|s| s.success());
    if ok.ok() != Some(true) {
        eprintln!("SKIPPED: iceoryx2 is not installed in {}", py.display());
        return;
    }
    let dir = tmp("python");
    let out = dir.join("out");
    let config = repo().join("config/partition_python.toml");
    let rep = sc_partition::launch(&options(&config, &out, "py")).unwrap();
    assert_clean(&rep, &out);
    assert_eq!(rep.code, 0, "{rep:?}");
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
