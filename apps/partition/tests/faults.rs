//! Faults: SIGKILL of each kind of process mid-mission, and hung (SIGSTOPped) ones. The partition reacts with
//! the defined fallback and a recorded fault; telemetry up to that point is complete;
//! no process is left behind and nothing is left in /dev/shm.

mod common;
use common::*;
use std::path::Path;

/// Steps in which `filter` reported upstream_missing (telemetry.csv `<filter>_faults`).
fn flagged_steps(out: &Path, filter: &str, mask: u32) -> Vec<u64> {
    let text = std::fs::read_to_string(out.join("telemetry.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|c| *c == format!("{filter}_faults"))
        .unwrap();
    lines
        .filter_map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            let flags: u32 = v[col].parse().unwrap();
            (flags & mask != 0).then(|| v[0].parse().unwrap())
        })
        .collect()
}

/// `sc_cbf::faults::UPSTREAM_MISSING` (bit 5, documented in docs/ICD.md): the filter's
/// command is the backup the simulator applied, or its upstream command was.
const UPSTREAM_MISSING: u32 = 1 << 5;
/// `sc_cbf::faults::NOMINAL_MISSING` (bit 7): the filter ran its QP on the substitute nominal.
const NOMINAL_MISSING: u32 = 1 << 7;

/// Runs a shortened mission (60 s, lock-step) and SIGKILLs `exec` after 100 steps.
fn kill_run(
    tag: &str,
    exec: &str,
) -> (
    sc_ground::LaunchReport,
    std::path::PathBuf,
    std::path::PathBuf,
) {
    let dir = tmp(tag);
    let out = dir.join("out");
    let config = write_config(&dir, Some(60.0), None, 5.0);
    let opts = options(&config, &out, tag);
    let h = std::thread::spawn(move || sc_ground::launch(&opts).unwrap());
    kill_when(&out, exec, 100);
    let rep = h.join().unwrap();
    assert_clean(&rep, &out);
    assert_eq!(rep.code, 3, "a killed process is a failed run: {rep:?}");
    let killed = rep
        .exits
        .iter()
        .filter(|e| e.signal == Some(9) && !e.killed_by_launcher)
        .count();
    assert_eq!(killed, 1, "{:?}", rep.exits);
    (rep, dir, out)
}

fn degraded(exec: &str, filter: &str, mask: u32) {
    let (_, dir, out) = kill_run(exec, exec);
    // the mission went on to its end, every step recorded
    let n = contiguous_steps(&out);
    assert_eq!(n, 601, "all steps 0..=600 of the 60 s mission recorded");
    let s = summary(&out);
    assert_eq!(s["end"], "timeout");
    // from the kill on, the subsystem runs on its substitute nominal (a dead nominal) or
    // on the backup the simulator applies (a dead filter), flagged
    let f = flagged_steps(&out, filter, mask);
    let first = *f
        .first()
        .unwrap_or_else(|| panic!("{filter}: no step flagged {mask:#x}"));
    assert!(
        first >= 100,
        "{filter}: flagged before the kill (step {first})"
    );
    let expect: Vec<u64> = (first..=600).collect();
    assert_eq!(
        f, expect,
        "{filter}: every step from the kill on is on the flagged fallback"
    );
    // latency.csv marks the same steps, and the latency report counts them as
    // deadline misses (a filter's fallback as much as the simulator's)
    let bit = match filter {
        "translational" => 1,
        "attitude" => 2,
        _ => 4,
    };
    let lat = std::fs::read_to_string(out.join("latency.csv")).unwrap();
    let mut lines = lat.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let c = header
        .iter()
        .position(|h| *h == "upstream_missing_mask")
        .unwrap();
    let marked: Vec<u64> = lines
        .filter_map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            (v[c].parse::<u32>().unwrap() & bit != 0).then(|| v[0].parse().unwrap())
        })
        .collect();
    assert_eq!(
        marked, expect,
        "{filter}: latency.csv upstream_missing_mask"
    );
    let r = sc_ground::latency::analyse(&out, 0).unwrap();
    assert!(
        r.deadline_misses >= expect.len() as u64,
        "{}",
        r.deadline_misses
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn killed_nominal_translational_gives_the_qp_on_the_substitute_nominal() {
    degraded("sc-nominal-translational", "translational", NOMINAL_MISSING);
}

#[test]
fn killed_nominal_robotic_gives_the_qp_on_the_substitute_nominal() {
    degraded("sc-nominal-robotic", "robotic", NOMINAL_MISSING);
}

#[test]
fn killed_translational_filter_gives_backup_applied_by_simulator() {
    degraded("sc-safety-translational", "translational", UPSTREAM_MISSING);
    // (the attitude and robotic filters use the translational backup as coupling)
}

#[test]
fn killed_attitude_filter_gives_backup_applied_by_simulator() {
    degraded("sc-safety-attitude", "attitude", UPSTREAM_MISSING);
}

#[test]
fn killed_robotic_filter_gives_backup_applied_by_simulator() {
    degraded("sc-safety-robotic", "robotic", UPSTREAM_MISSING);
}

fn aborted(exec: &str, peer: &str) {
    let (_, dir, out) = kill_run(exec, exec);
    let n = contiguous_steps(&out);
    assert!((100..600).contains(&n), "{n} steps recorded up to the kill");
    let sched: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("scheduler.json")).unwrap())
            .unwrap();
    if peer != "scheduler" {
        assert_eq!(sched["aborted"], true, "{sched}");
        assert!(
            sched["lost_peers"]
                .as_array()
                .unwrap()
                .iter()
                .any(|p| p == peer),
            "{sched}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn killed_simulator_aborts_the_run_with_complete_telemetry() {
    aborted("sc-simulator", "simulator");
}

#[test]
fn killed_scheduler_tears_the_run_down_with_complete_telemetry() {
    let (_, dir, out) = kill_run("sc-scheduler", "sc-scheduler");
    let n = contiguous_steps(&out);
    assert!((100..600).contains(&n), "{n} steps");
    assert!(
        out.join("summary.json").exists(),
        "recorder finished its outputs on SIGTERM"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn killed_recorder_aborts_the_run() {
    let (_, dir, out) = kill_run("sc-recorder", "sc-recorder");
    let sched: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("scheduler.json")).unwrap())
            .unwrap();
    assert_eq!(sched["aborted"], true, "{sched}");
    assert!(
        sched["lost_peers"]
            .as_array()
            .unwrap()
            .iter()
            .any(|p| p == "recorder"),
        "{sched}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A hung (SIGSTOPped) robotic filter: its missed deadlines put the robotic
/// subsystem on the fallback applied by the simulator; the launcher kills it at
/// teardown; nothing is left behind; the telemetry is gap-free and the recorder lost
/// nothing that was sent: the stopped filter's full queues make its publishers drop
/// samples for *it* after the backpressure timeout, never for the recorder.
#[test]
fn hung_robotic_filter_is_detected_by_deadlines() {
    let dir = tmp("hung");
    let out = dir.join("out");
    let config = write_config(&dir, Some(60.0), None, 5.0);
    let opts = options(&config, &out, "hung");
    let h = std::thread::spawn(move || sc_ground::launch(&opts).unwrap());
    let t0 = std::time::Instant::now();
    while rows(&out) < 100 {
        assert!(t0.elapsed() < std::time::Duration::from_secs(120));
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let pids = pids_of("sc-safety-robotic", &out);
    assert_eq!(pids.len(), 1);
    // SAFETY: kill(2) on the pid found above.
    unsafe { libc::kill(pids[0], libc::SIGSTOP) };
    let rep = h.join().unwrap();
    assert_clean(&rep, &out);
    assert_eq!(rep.code, 3, "{rep:?}");
    assert_eq!(contiguous_steps(&out), 601);
    let f = flagged_steps(&out, "robotic", UPSTREAM_MISSING);
    let first = *f.first().expect("robotic steps flagged");
    assert_eq!(f, (first..=600).collect::<Vec<u64>>());
    let rec: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("recorder.json")).unwrap()).unwrap();
    for (service, n) in rec["missing"].as_object().unwrap() {
        if service != "safe_capture/safe/robotic" {
            assert_eq!(n, 0, "recorder missed samples of {service}: {rec}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A hung (SIGSTOPped) nominal translational controller: the translational filter,
/// which wakes only on its inputs, is woken by the scheduler's stage-deadline
/// watchdog, applies its own fallback (flagged) and publishes it on every later tick,
/// so the simulator never has to substitute the translational command.
#[test]
fn hung_nominal_is_caught_by_the_stage_deadline_watchdog() {
    let dir = tmp("hungnom");
    let out = dir.join("out");
    let config = write_config(&dir, Some(60.0), None, 5.0);
    let opts = options(&config, &out, "hungnom");
    let h = std::thread::spawn(move || sc_ground::launch(&opts).unwrap());
    let t0 = std::time::Instant::now();
    while rows(&out) < 100 {
        assert!(t0.elapsed() < std::time::Duration::from_secs(120));
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let pids = pids_of("sc-nominal-translational", &out);
    assert_eq!(pids.len(), 1);
    // SAFETY: kill(2) on the pid found above.
    unsafe { libc::kill(pids[0], libc::SIGSTOP) };
    let rep = h.join().unwrap();
    assert_clean(&rep, &out);
    assert_eq!(contiguous_steps(&out), 601);
    let f = flagged_steps(&out, "translational", NOMINAL_MISSING);
    let first = *f.first().expect("translational steps flagged");
    assert!(first >= 100, "flagged before the stop (step {first})");
    assert_eq!(f, (first..=600).collect::<Vec<u64>>());
    let sched: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("scheduler.json")).unwrap())
            .unwrap();
    assert!(
        sched["watchdog_wakeups"].as_u64().unwrap() >= 1,
        "the watchdog never fired: {sched}"
    );
    let rec: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("recorder.json")).unwrap()).unwrap();
    assert_eq!(
        rec["missing"]["safe_capture/safe/translational"], 0,
        "the filter published on every tick: {rec}"
    );
    assert_eq!(rec["fallback_steps"], 0, "no simulator fallback: {rec}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A role whose process never joins the handshake (here: a process that only sleeps)
/// fails the launch, and the scheduler names the role, not its number.
#[test]
fn a_role_that_never_joins_is_named() {
    let dir = tmp("nojoin");
    let out = dir.join("out");
    let config = write_config(&dir, Some(5.0), None, 20.0);
    let text = std::fs::read_to_string(&config)
        .unwrap()
        .replace("handshake_timeout_s = 30.0", "handshake_timeout_s = 2.0");
    assert!(text.contains("handshake_timeout_s = 2.0"));
    std::fs::write(&config, text).unwrap();
    let mut opts = options(&config, &out, "nojoin");
    // (a process that fails at once instead is named by the launcher at once)
    opts.role_override.push((
        "safety_robotic".into(),
        "/bin/sh".into(),
        vec!["-c".into(), "exec sleep 60".into()],
    ));
    let t0 = std::time::Instant::now();
    let rep = sc_ground::launch(&opts).unwrap();
    assert_ne!(rep.code, 0, "{rep:?}");
    assert!(t0.elapsed() < std::time::Duration::from_secs(60), "{rep:?}");
    let log = std::fs::read_to_string(out.join("logs/scheduler.log")).unwrap();
    assert!(log.contains("never joined: safety_robotic"), "{log}");
    // and the launch's error (on the terminal, in launch.json) says so at once
    assert!(
        rep.error.as_deref().is_some_and(|e| e.starts_with(
            "role `scheduler` ended (exit code 2) before every process was ready: error: handshake timed out"
        ) && e.contains("never joined: safety_robotic")),
        "{rep:?}"
    );
    assert!(rep.leftovers.is_empty(), "{rep:?}");
    // a start that failed leaves no (empty) recording behind
    assert!(!out.join("recording.mcap").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
