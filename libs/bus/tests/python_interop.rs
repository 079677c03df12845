//! Rust <-> Python over iceoryx2: the Python process (scripts/python/interop_check.py)
//! plays the nominal translational controller. Runs only if the venv
//! `scripts/.venv` with the `iceoryx2` wheel exists (otherwise prints why and passes).

use sc_bus::{Coordinator, Publisher, RunScope, ServiceSettings, Subscriber};
use sc_icd::{NominalTranslational, Role, RoleKind, SimState, Subsystem, services};
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

fn venv_python() -> Option<PathBuf> {
    // Canonical directory (not file: the venv's python is a symlink whose own path
    // must be kept so that it finds its pyvenv.cfg).
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let root = std::fs::canonicalize(&root).unwrap_or(root);
    let py = std::env::var_os("SC_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("scripts/.venv/bin/python"));
    let ok = Command::new(&py)
        .args(["-c", "import iceoryx2"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    ok.then_some(py)
}

#[test]
fn python_controller_answers_rust_states() {
    let Some(py) = venv_python() else {
        eprintln!(
            "SKIPPED python_controller_answers_rust_states: no python with iceoryx2 \
             (create scripts/.venv and pip install -r scripts/requirements.txt, or set SC_PYTHON)"
        );
        return;
    };
    let script =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scripts/python/interop_check.py");
    let run = RunScope::unique("pyinterop").unwrap();
    {
        let node = run.node("rust_sim").unwrap();
        let qos = ServiceSettings::lock_step();
        let state_tx = Publisher::<SimState>::new(&node, services::SIM_STATE, &qos).unwrap();
        let cmd_rx =
            Subscriber::<NominalTranslational>::new(&node, services::NOMINAL_TRANSLATIONAL, &qos)
                .unwrap();
        let coord = Coordinator::new(
            &node,
            services::HANDSHAKE,
            &[Role::of(RoleKind::Nominal(Subsystem::Translational)).id()],
        )
        .unwrap();
        let mut child = Command::new(&py)
            .arg(&script)
            .env("SC_RUN_ID", run.run_id())
            .spawn()
            .expect("spawn python");
        coord.wait_all(Duration::from_secs(30)).unwrap();

        for i in 0..50u64 {
            let mut s = SimState {
                tick: i,
                step: i,
                t: i as f64 * 0.1,
                due_mask: sc_icd::due::ALL,
                ..Default::default()
            };
            s.r_h = [10.0 + i as f64, -2.0, 0.5];
            assert_eq!(state_tx.send(&s).unwrap(), 1, "state {i} must reach python");
            let cmd = cmd_rx
                .receive_timeout(Duration::from_secs(5))
                .unwrap()
                .unwrap_or_else(|| panic!("no command for state {i}"));
            assert_eq!(cmd.tick, i);
            assert_eq!(cmd.valid, 1);
            assert_eq!(cmd.f_h, [-0.5 * (10.0 + i as f64), 1.0, -0.25]);
        }
        // due_mask 0 = stop.
        state_tx.send(&SimState::default()).unwrap();
        let status = child.wait().unwrap();
        assert!(status.success(), "python exited with {status}");
    }
    run.teardown().unwrap();
    assert!(run.leftovers().is_empty(), "{:?}", run.leftovers());
}
