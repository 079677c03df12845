//! Two processes over iceoryx2: handshake, ping/pong with event wake-ups both ways,
//! SIGKILL of the peer and its detection, then no leftovers for the run's prefix.

use sc_bus::{Coordinator, PeerMonitor, Publisher, RunScope, ServiceSettings, Subscriber};
use sc_icd::{Tick, services};
use std::process::{Child, Command};
use std::time::{Duration, Instant};

struct KillOnDrop(Child);
impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn spawn_peer(run: &RunScope, base: &str) -> KillOnDrop {
    let child = Command::new(env!("CARGO_BIN_EXE_sc-bus-peer"))
        .arg(run.run_id())
        .arg(base)
        .spawn()
        .expect("spawn sc-bus-peer");
    KillOnDrop(child)
}

#[test]
fn ping_pong_kill_detect_and_clean() {
    let run = RunScope::unique("twoproc").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step();
        let ping = Publisher::<Tick>::with_name(&node, "test/ping", &qos).unwrap();
        let pong = Subscriber::<Tick>::with_name(&node, "test/pong", &qos).unwrap();
        let coord = Coordinator::new(&node, services::HANDSHAKE, &[1]).unwrap();
        let mut peer = spawn_peer(&run, "test");
        coord.wait_all(Duration::from_secs(20)).unwrap();

        // Lock-step exchange: every ping is answered, nothing lost, order kept.
        let t0 = Instant::now();
        for i in 0..200u64 {
            let delivered = ping
                .send(&Tick {
                    tick: i,
                    t: i as f64 * 0.1,
                    ..Default::default()
                })
                .unwrap();
            assert_eq!(delivered, 1, "ping {i} must reach the peer");
            let reply = pong
                .receive_timeout(Duration::from_secs(5))
                .unwrap()
                .unwrap_or_else(|| panic!("no pong for ping {i}"));
            assert_eq!(reply.tick, i + 1000);
            assert_eq!(reply.t, i as f64 * 0.1);
        }
        eprintln!("200 round trips in {:?}", t0.elapsed());

        let mut monitor = PeerMonitor::new(&["peer"]);
        assert!(monitor.poll(&run).unwrap().is_empty());
        assert_eq!(monitor.alive(), vec!["peer"]);
        let pid = peer.0.id() as i32;

        // SIGKILL: the peer gets no chance to clean up.
        peer.0.kill().unwrap();
        peer.0.wait().unwrap();
        let lost = monitor.poll(&run).unwrap();
        assert_eq!(lost.len(), 1, "the dead peer must be reported");
        assert_eq!(lost[0].name, "peer");
        assert_eq!(lost[0].pid, pid);
        assert!(monitor.poll(&run).unwrap().is_empty(), "reported once");

        // The reaping told the pong subscriber that its publisher died.
        let ev = pong.wait(Duration::from_secs(1)).unwrap();
        assert!(
            ev.publisher_died,
            "notifier-dead event expected, got {ev:?}"
        );

        // Sending to the reaped peer neither blocks nor fails.
        assert_eq!(ping.send(&Tick::default()).unwrap(), 0);
    }
    run.teardown().unwrap();
    assert_eq!(run.leftovers(), Vec::<std::path::PathBuf>::new());
}

#[test]
fn peer_exits_cleanly_on_stop_tick() {
    let run = RunScope::unique("stop").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step();
        let ping = Publisher::<Tick>::with_name(&node, "test/ping", &qos).unwrap();
        let coord = Coordinator::new(&node, services::HANDSHAKE, &[1]).unwrap();
        let mut peer = spawn_peer(&run, "test");
        coord.wait_all(Duration::from_secs(20)).unwrap();
        ping.send(&Tick {
            tick: u64::MAX,
            ..Default::default()
        })
        .unwrap();
        let status = peer.0.wait().unwrap();
        assert!(status.success());
    }
    run.teardown().unwrap();
    assert!(run.leftovers().is_empty(), "{:?}", run.leftovers());
}

/// A signal that interrupts the peer's wait (EINTR, which iceoryx2 reports as an
/// interrupt) — here SIGUSR1, for which the peer has a handler like a profiler would —
/// and a stop/continue (SIGSTOP, SIGCONT) leave it running and answering; only
/// SIGTERM stops it.
#[test]
fn interrupting_signals_are_not_a_termination_request() {
    let run = RunScope::unique("sigcont").unwrap();
    {
        let node = run.node("main").unwrap();
        let qos = ServiceSettings::lock_step();
        let ping = Publisher::<Tick>::with_name(&node, "test/ping", &qos).unwrap();
        let pong = Subscriber::<Tick>::with_name(&node, "test/pong", &qos).unwrap();
        let coord = Coordinator::new(&node, services::HANDSHAKE, &[1]).unwrap();
        let mut peer = spawn_peer(&run, "test");
        coord.wait_all(Duration::from_secs(20)).unwrap();
        let pid = peer.0.id() as i32;
        for round in 0..3u64 {
            // SAFETY: kill(2) on our own child's pid.
            unsafe { libc::kill(pid, libc::SIGSTOP) };
            std::thread::sleep(Duration::from_millis(50));
            // SAFETY: as above.
            unsafe { libc::kill(pid, libc::SIGCONT) };
            std::thread::sleep(Duration::from_millis(50));
            // SAFETY: as above; the peer handles SIGUSR1.
            unsafe { libc::kill(pid, libc::SIGUSR1) };
            std::thread::sleep(Duration::from_millis(50));
            assert!(
                peer.0.try_wait().unwrap().is_none(),
                "the peer exited after the signals of round {round}"
            );
            ping.send(&Tick {
                tick: round,
                ..Default::default()
            })
            .unwrap();
            let reply = pong
                .receive_timeout(Duration::from_secs(5))
                .unwrap()
                .unwrap_or_else(|| panic!("no pong after the signals of round {round}"));
            assert_eq!(reply.tick, round + 1000);
        }
        // SAFETY: as above.
        unsafe { libc::kill(pid, libc::SIGTERM) };
        let status = peer.0.wait().unwrap();
        assert!(status.success(), "SIGTERM is a clean stop: {status:?}");
    }
    run.teardown().unwrap();
    assert!(run.leftovers().is_empty(), "{:?}", run.leftovers());
}
