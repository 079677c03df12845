//! The partition applies only what was certified: a command acts only with exactly the
//! upstream commands it was certified against (its ξ, carried in the safe messages).
//! A late attitude safety filter (`scripts/python/late_attitude_filter.py`) answers every
//! tick 85 ms after it started — after the robotic filter gave up on it (80 ms) and
//! certified against the attitude backup, before the simulator's own deadline (90 ms).
//! Read back from the run's recording: in every step where the robotic command acts, the
//! force and torque applied are the ones it was certified against; the window was hit;
//! no barrier went below zero. Needs a Python with iceoryx2 (`SC_PYTHON`, set by
//! scripts/test.sh; without one the test is skipped with the reason printed).

mod common;
use common::*;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// The messages of `topic` in the recording of `out`, by tick.
fn by_tick(out: &Path, topic: &str) -> BTreeMap<u64, Value> {
    let bytes = std::fs::read(out.join("recording.mcap")).unwrap();
    let mut m = BTreeMap::new();
    for msg in mcap::MessageStream::new(&bytes).unwrap() {
        let msg = msg.unwrap();
        if msg.channel.topic == topic {
            let v: Value = serde_json::from_slice(&msg.data).unwrap();
            m.insert(v["tick"].as_u64().unwrap(), v);
        }
    }
    m
}

fn vec3(v: &Value) -> [f64; 3] {
    let a = v.as_array().unwrap();
    [0, 1, 2].map(|i| a[i].as_f64().unwrap())
}

/// `sc_core::Subsystem::Robotic.bit()` (docs/ICD.md, `due`).
const ROBOTIC: u64 = 4;
/// `sc_icd::fault::COUPLING_MISMATCH`.
const COUPLING_MISMATCH: u64 = 1 << 10;

#[test]
fn a_command_late_for_its_downstream_filter_never_acts() {
    let Some(py) = python() else {
        return;
    };
    let dir = tmp("late");
    let out = dir.join("out");
    let config = write_config(&dir, Some(20.0), None, 20.0);
    let text = std::fs::read_to_string(&config).unwrap();
    let real_time = text.replace("clock = \"lock_step\"", "clock = \"real_time\"");
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
        ],
    ));
    let rep = sc_ground::launch(&opts).unwrap();
    assert_clean(&rep, &out);
    let robotic = by_tick(&out, "safe_capture/safe/robotic");
    let results = by_tick(&out, "safe_capture/sim/step_result");
    assert!(results.len() >= 150, "{} steps", results.len());
    let (mut acted, mut mismatched) = (0, 0);
    for (k, r) in &results {
        let flags = r["fault_flags"].as_u64().unwrap();
        mismatched += usize::from(flags & COUPLING_MISMATCH != 0);
        if r["fallback_mask"].as_u64().unwrap() & ROBOTIC != 0 {
            continue;
        }
        let cmd = &robotic[k];
        let applied = (vec3(&r["force_b"]), vec3(&r["torque_b"]));
        let xi = (vec3(&cmd["xi_f_b"]), vec3(&cmd["xi_tau_b"]));
        assert_eq!(
            applied, xi,
            "tick {k}: the robotic command acted with other upstream commands than it was certified against"
        );
        acted += 1;
    }
    eprintln!(
        "{acted} steps with the robotic command acting, {mismatched} with a command refused for its coupling"
    );
    // the late commands reached the simulator inside its deadline and were refused there
    assert!(
        acted > 0 && mismatched > 0,
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
