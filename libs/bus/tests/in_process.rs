//! Single-process behaviour of the building blocks (each test has its own prefix).

use sc_bus::{
    BusError, Coordinator, Publisher, RunScope, ServiceSettings, Subscriber, WaitOutcome, Waiter,
};
use sc_icd::{Health, Tick, services};
use std::time::{Duration, Instant};

#[test]
fn lock_step_never_drops_and_stuck_subscriber_cannot_block_forever() {
    let run = RunScope::unique("backpressure").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step();
        let tx = Publisher::<Tick>::with_name(&node, "bp", &qos).unwrap();
        let rx = Subscriber::<Tick>::with_name(&node, "bp", &qos).unwrap();
        // Fill the subscriber buffer: all delivered, none overwritten.
        for i in 0..qos.subscriber_buffer as u64 {
            assert_eq!(
                tx.send(&Tick {
                    tick: i,
                    ..Default::default()
                })
                .unwrap(),
                1
            );
        }
        // The next send waits for space, then gives up with a typed error.
        let t0 = Instant::now();
        let err = tx
            .send(&Tick {
                tick: 99,
                ..Default::default()
            })
            .unwrap_err();
        let waited = t0.elapsed();
        assert!(matches!(err, BusError::Backpressure { .. }), "{err}");
        assert!(waited >= qos.backpressure_timeout, "{waited:?}");
        assert!(waited < Duration::from_secs(2), "{waited:?}");
        // Nothing was lost or reordered; the rejected sample is not there.
        let mut got = Vec::new();
        rx.receive_all(&mut got).unwrap();
        assert_eq!(
            got.iter().map(|t| t.tick).collect::<Vec<_>>(),
            vec![0, 1, 2, 3]
        );
        let ev = rx.drain_events().unwrap();
        assert!(ev.notifications >= 1);
    }
    run.teardown().unwrap();
    assert!(run.leftovers().is_empty(), "{:?}", run.leftovers());
}

#[test]
fn wrong_payload_type_is_a_typed_error() {
    let run = RunScope::unique("types").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step();
        let _tx = Publisher::<Tick>::new(&node, services::TICK, &qos).unwrap();
        let err = Subscriber::<Health>::new(&node, services::TICK, &qos)
            .err()
            .expect("must fail");
        match err {
            BusError::IncompatibleType { service, type_name } => {
                assert_eq!(service, services::TICK.as_str());
                assert_eq!(type_name, "safe_capture::v1::Health");
            }
            e => panic!("unexpected {e}"),
        }
    }
    run.teardown().unwrap();
}

#[test]
fn waiter_reports_events_deadlines_and_intervals() {
    let run = RunScope::unique("waiter").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step();
        let tx = Publisher::<Tick>::with_name(&node, "w", &qos).unwrap();
        let rx = Subscriber::<Tick>::with_name(&node, "w", &qos).unwrap();
        let waiter = Waiter::new().unwrap();
        let data = waiter
            .attach_deadline(&rx, Duration::from_millis(30))
            .unwrap();
        let tick = waiter.attach_interval(Duration::from_millis(500)).unwrap();

        // Nothing sent: the deadline is missed first.
        let (mut missed, mut woke, mut ticked) = (false, false, false);
        let out = waiter
            .wait_once(Duration::from_secs(2), |w| {
                missed |= data.missed_deadline(&w);
                woke |= data.woke(&w);
                ticked |= tick.woke(&w);
            })
            .unwrap();
        assert_eq!(out, WaitOutcome::Handled);
        assert!(missed && !woke && !ticked);

        // A sample wakes the waiter through the event.
        tx.send(&Tick {
            tick: 7,
            ..Default::default()
        })
        .unwrap();
        let mut got = None;
        waiter
            .wait_once(Duration::from_secs(2), |w| {
                if data.woke(&w) {
                    rx.drain_events().unwrap();
                    got = rx.receive_latest().unwrap();
                }
            })
            .unwrap();
        assert_eq!(got.map(|t| t.tick), Some(7));

        // Timeout when nothing is due.
        drop(data);
        drop(tick);
        let quiet = waiter.attach(&rx).unwrap();
        let out = waiter.wait_once(Duration::from_millis(20), |_| {}).unwrap();
        assert_eq!(out, WaitOutcome::Timeout);
        drop(quiet);
    }
    run.teardown().unwrap();
}

#[test]
fn handshake_timeout_names_the_missing_participants() {
    let run = RunScope::unique("hs").unwrap();
    {
        let node = run.node("main").unwrap();
        let coord = Coordinator::new(&node, services::HANDSHAKE, &[1, 2, 3]).unwrap();
        let p2 = sc_bus::Participant::new(&node, services::HANDSHAKE, 2).unwrap();
        // One announcement from participant 2 only.
        let _ = p2.announce_and_wait(Duration::from_millis(1));
        match coord.wait_all(Duration::from_millis(100)) {
            Err(BusError::HandshakeTimeout { missing, .. }) => assert_eq!(missing, vec![1, 3]),
            other => panic!("unexpected {other:?}"),
        }
        assert!(matches!(
            sc_bus::Participant::new(&node, services::HANDSHAKE, 64),
            Err(BusError::ParticipantOutOfRange { id: 64, .. })
        ));
    }
    run.teardown().unwrap();
}

#[test]
fn teardown_refuses_while_a_node_is_alive() {
    let run = RunScope::unique("alive").unwrap();
    let node = run.node("main").unwrap();
    let _tx = Publisher::<Tick>::with_name(&node, "x", &ServiceSettings::lock_step()).unwrap();
    assert!(
        !run.leftovers().is_empty(),
        "the run must have created files"
    );
    assert!(matches!(
        run.teardown(),
        Err(BusError::NodesStillAlive { alive: 1, .. })
    ));
    drop(_tx);
    drop(node);
    run.teardown().unwrap();
    assert!(run.leftovers().is_empty(), "{:?}", run.leftovers());
}
