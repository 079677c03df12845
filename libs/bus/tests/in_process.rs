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

/// A subscriber that stays full (hung) is dropped at once after its first timeout,
/// but only it: another subscriber that is merely full at that moment still gets the
/// lossless wait.
#[test]
fn a_stuck_subscriber_is_dropped_alone() {
    let run = RunScope::unique("stuck").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step();
        let tx = Publisher::<Tick>::with_name(&node, "st", &qos).unwrap();
        let hung = Subscriber::<Tick>::with_name(&node, "st", &qos).unwrap();
        let busy = Subscriber::<Tick>::with_name(&node, "st", &qos).unwrap();
        let tick = |i: u64| Tick {
            tick: i,
            ..Default::default()
        };
        for i in 0..qos.subscriber_buffer as u64 {
            assert_eq!(tx.send(&tick(i)).unwrap(), 2);
        }
        let mut got = Vec::new();
        busy.receive_all(&mut got).unwrap();
        // `hung` is full: the first send waits the timeout, then drops it for `hung`
        let t0 = Instant::now();
        assert!(tx.send(&tick(100)).is_err());
        assert!(t0.elapsed() >= qos.backpressure_timeout);
        // from now on `hung` costs nothing, and `busy` still gets every sample
        let t0 = Instant::now();
        for i in 101..101 + qos.subscriber_buffer as u64 - 1 {
            assert!(tx.send(&tick(i)).is_err());
        }
        assert!(
            t0.elapsed() < qos.backpressure_timeout,
            "{:?}",
            t0.elapsed()
        );
        // `busy` is full now too: it is not taken for hung, the send waits for it
        let t0 = Instant::now();
        assert!(tx.send(&tick(200)).is_err());
        assert!(
            t0.elapsed() >= qos.backpressure_timeout,
            "{:?}",
            t0.elapsed()
        );
        got.clear();
        busy.receive_all(&mut got).unwrap();
        assert_eq!(
            got.iter().map(|t| t.tick).collect::<Vec<_>>(),
            vec![100, 101, 102, 103],
            "nothing was dropped for the subscriber that only was busy"
        );
        let mut none = Vec::new();
        hung.receive_all(&mut none).unwrap();
        assert_eq!(
            none.len(),
            qos.subscriber_buffer,
            "the hung one kept its old queue"
        );
    }
    run.teardown().unwrap();
    assert!(run.leftovers().is_empty(), "{:?}", run.leftovers());
}

/// A polled subscriber has no listener (publishers do not wake it) until it is
/// attached to a waiter; then a send wakes the waiter.
#[test]
fn polled_subscriber_gets_its_listener_when_attached() {
    let run = RunScope::unique("polled").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step();
        let tx = Publisher::<Tick>::with_name(&node, "pl", &qos).unwrap();
        let rx = Subscriber::<Tick>::polled_with_name(&node, "pl", &qos).unwrap();
        assert!(!rx.has_listener());
        tx.send(&Tick::default()).unwrap();
        assert!(
            rx.drain_events().unwrap().is_empty(),
            "no listener, no events"
        );
        assert_eq!(rx.receive_latest().unwrap().map(|t| t.tick), Some(0));
        let waiter = Waiter::new().unwrap();
        let _a = waiter.attach(&rx).unwrap();
        assert!(rx.has_listener());
        tx.send(&Tick {
            tick: 7,
            ..Default::default()
        })
        .unwrap();
        let outcome = waiter.wait_once(Duration::from_secs(5), |_| {}).unwrap();
        assert_eq!(outcome, WaitOutcome::Handled);
        assert!(rx.drain_events().unwrap().notifications >= 1);
        assert_eq!(rx.receive_latest().unwrap().map(|t| t.tick), Some(7));
    }
    run.teardown().unwrap();
    assert!(run.leftovers().is_empty(), "{:?}", run.leftovers());
}

/// `warm` (the pre-tick warm-up) loans and returns a sample: subscribers get
/// nothing and no wake-up, the sample goes back to the pool (warming more often
/// than the pool is deep does not exhaust it), and the next send is delivered once.
#[test]
fn warming_a_publisher_sends_nothing() {
    let run = RunScope::unique("warm").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step();
        let tx = Publisher::<Tick>::with_name(&node, "wm", &qos).unwrap();
        let rx = Subscriber::<Tick>::with_name(&node, "wm", &qos).unwrap();
        for _ in 0..4 * qos.subscriber_buffer {
            tx.warm().unwrap();
        }
        assert!(rx.drain_events().unwrap().is_empty(), "no wake-up");
        assert_eq!(rx.try_receive().unwrap().map(|t| t.tick), None);
        tx.send(&Tick {
            tick: 3,
            ..Default::default()
        })
        .unwrap();
        assert_eq!(rx.drain_events().unwrap().notifications, 1);
        let mut got = Vec::new();
        rx.receive_all(&mut got).unwrap();
        assert_eq!(got.iter().map(|t| t.tick).collect::<Vec<_>>(), [3]);
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

/// Across hosts a subscriber is told whom to accept (the owner's node, or the link's):
/// an intruder that publishes first is not pinned, and its samples are dropped and
/// counted; the expected publisher's are taken.
#[test]
fn a_subscriber_told_its_publisher_does_not_pin_an_intruder_heard_first() {
    let run = RunScope::unique("expected").unwrap();
    {
        let owner_node = run.node("simulator").unwrap();
        let intruder_node = run.node("nominal_attitude").unwrap();
        let reader = run.node("safety_attitude").unwrap();
        let qos = ServiceSettings::lock_step(); // two publishers allowed
        let tick = |tick| Tick {
            tick,
            ..Default::default()
        };
        let mut rx = Subscriber::<Tick>::with_name(&reader, "state", &qos).unwrap();
        rx.expect_publisher(
            &reader,
            sc_bus::ExpectedPublisher {
                node_name: "simulator".into(),
                pid: Some(std::process::id() as i32),
            },
        );
        let intruder = Publisher::<Tick>::with_name(&intruder_node, "state", &qos).unwrap();
        let owner = Publisher::<Tick>::with_name(&owner_node, "state", &qos).unwrap();
        intruder.send(&tick(666)).unwrap();
        owner.send(&tick(1)).unwrap();
        intruder.send(&tick(667)).unwrap();
        let mut got = Vec::new();
        rx.receive_all(&mut got).unwrap();
        assert_eq!(got.iter().map(|t| t.tick).collect::<Vec<_>>(), vec![1]);
        assert_eq!(rx.rejected(), 2);
        // the right name in another process is no match either
        let mut rx = Subscriber::<Tick>::with_name(&reader, "state", &qos).unwrap();
        rx.expect_publisher(
            &reader,
            sc_bus::ExpectedPublisher {
                node_name: "simulator".into(),
                pid: Some(1),
            },
        );
        owner.send(&tick(2)).unwrap();
        assert_eq!(rx.try_receive().unwrap(), None);
        assert_eq!(rx.rejected(), 1);
    }
    run.teardown().unwrap();
}

/// The link re-opens a bridge with a new publisher port of its node: a subscriber told
/// whom to accept takes the new port in the old one's place (pinned by arrival alone, it
/// would refuse it).
#[test]
fn a_new_port_of_the_expected_publisher_is_pinned_again() {
    let run = RunScope::unique("repin").unwrap();
    {
        let link = run.node("link").unwrap();
        let reader = run.node("simulator").unwrap();
        let qos = ServiceSettings::lock_step();
        let tick = |tick| Tick {
            tick,
            ..Default::default()
        };
        let mut rx = Subscriber::<Tick>::with_name(&reader, "safe", &qos).unwrap();
        rx.expect_publisher(
            &reader,
            sc_bus::ExpectedPublisher {
                node_name: "link".into(),
                pid: Some(std::process::id() as i32),
            },
        );
        let first = Publisher::<Tick>::with_name(&link, "safe", &qos).unwrap();
        first.send(&tick(1)).unwrap();
        assert_eq!(rx.try_receive().unwrap().map(|t| t.tick), Some(1));
        drop(first);
        let reopened = Publisher::<Tick>::with_name(&link, "safe", &qos).unwrap();
        reopened.send(&tick(2)).unwrap();
        assert_eq!(rx.try_receive().unwrap().map(|t| t.tick), Some(2));
        assert_eq!(rx.rejected(), 0);
    }
    run.teardown().unwrap();
}

/// Who may publish: a subscriber accepts samples only from the first publisher it heard
/// (a second one's are dropped and counted), and a service created with room for more
/// publishers than the settings say is refused at open (impersonation, issue #12).
#[test]
fn subscribers_are_pinned_to_their_first_publisher() {
    let run = RunScope::unique("pinned").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step(); // two publishers allowed
        let owner = Publisher::<Tick>::with_name(&node, "cmd", &qos).unwrap();
        let rx = Subscriber::<Tick>::with_name(&node, "cmd", &qos).unwrap();
        let tick = |tick| Tick {
            tick,
            ..Default::default()
        };
        owner.send(&tick(1)).unwrap();
        assert_eq!(rx.try_receive().unwrap().map(|t| t.tick), Some(1));
        let intruder = Publisher::<Tick>::with_name(&node, "cmd", &qos).unwrap();
        intruder.send(&tick(666)).unwrap();
        owner.send(&tick(2)).unwrap();
        intruder.send(&tick(667)).unwrap();
        let mut got = Vec::new();
        rx.receive_all(&mut got).unwrap();
        assert_eq!(got.iter().map(|t| t.tick).collect::<Vec<_>>(), vec![2]);
        assert_eq!(rx.rejected(), 2);
        // the service allows 2 publishers; opening it as a 1-publisher service is refused
        let one = ServiceSettings {
            max_publishers: 1,
            ..qos
        };
        let err = Subscriber::<Tick>::with_name(&node, "cmd", &one)
            .err()
            .expect("a service with room for more publishers must be refused");
        assert!(err.to_string().contains("allows 2 publishers"), "{err}");
    }
    run.teardown().unwrap();
    assert!(run.leftovers().is_empty(), "{:?}", run.leftovers());
}
