//! A subscriber that never reads, on every flight service, cannot change what the
//! partition does: flight publishers never wait for a reader (`sc_flight::process::qos`,
//! backpressure timeout 0), so the full queue loses its samples alone, reported in the
//! publishers' logs, and the run's telemetry is the same bytes as without it.

mod common;
use common::*;
use sc_icd::spec::Qos;
use std::time::{Duration, Instant};

#[test]
fn a_subscriber_that_never_reads_changes_nothing() {
    let dir = tmp("stuck");
    let config = write_config(&dir, None, None, 20.0);
    let plain = dir.join("plain");
    let rep = sc_ground::launch(&options(&config, &plain, "plain")).unwrap();
    assert_clean(&rep, &plain);
    assert_eq!(rep.code, 0, "the default mission is captured: {rep:?}");

    let out = dir.join("out");
    let opts = options(&config, &out, "stuck");
    let run_id = opts.run_id.clone().unwrap();
    let h = std::thread::spawn(move || sc_ground::launch(&opts).unwrap());
    let t0 = Instant::now();
    while rows(&out) < 1 {
        assert!(
            t0.elapsed() < Duration::from_secs(120),
            "the run never started"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    let run = sc_bus::RunScope::new(&run_id).unwrap();
    let node = run.node("never_reads").unwrap();
    let flight: Vec<_> = sc_icd::services::SERVICES
        .iter()
        .filter(|s| s.qos == Qos::Flight && s.message.is_some())
        .map(|s| {
            let qos = sc_flight::process::Qos::one_host();
            sc_flight::runner::ports::open_input(&node, s.name, &qos).unwrap()
        })
        .collect();
    assert!(flight.len() >= 8, "{} flight services", flight.len());
    // left before the run ends (the teardown then removes every port of the run)
    while rows(&out) < 600 && !h.is_finished() {
        std::thread::sleep(Duration::from_millis(1));
    }
    drop(flight);
    drop(node);
    let rep = h.join().unwrap();
    assert_clean(&rep, &out);
    assert_eq!(rep.code, 0, "{rep:?}");
    let same = std::fs::read(out.join("telemetry.csv")).unwrap()
        == std::fs::read(plain.join("telemetry.csv")).unwrap();
    assert!(
        same,
        "telemetry.csv differs from the run without the stuck subscriber"
    );
    // the simulator's state publishes lost their samples for it, and said so
    let sim = std::fs::read_to_string(out.join("logs/simulator.log")).unwrap();
    assert!(sim.contains("safe_capture/sim/state"), "{sim}");
    let _ = std::fs::remove_dir_all(&dir);
}
