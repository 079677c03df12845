//! What earlier runs left behind: their files in /dev/shm (crashed launchers) and their
//! outputs in the output folder.

use super::ALL_READY;
use sc_bus::RunScope;
use std::path::Path;
use std::time::Duration;

/// Removes the files of earlier runs whose every node is dead (crashed launchers)
/// and that were last touched more than a minute ago. Returns how many files.
pub fn clean_stale_runs(except: &str) -> usize {
    let mut prefixes = std::collections::BTreeSet::new();
    let Ok(rd) = std::fs::read_dir("/dev/shm") else {
        return 0;
    };
    for e in rd.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        let Some(rest) = name.strip_prefix("sc_") else {
            continue;
        };
        let Some(end) = rest.find('_') else { continue };
        let id = &rest[..end];
        if id != except {
            let old = e
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|d| d > Duration::from_secs(60));
            if old {
                prefixes.insert(id.to_string());
            }
        }
    }
    let mut removed = 0;
    for id in prefixes {
        let Ok(run) = RunScope::new(&id) else {
            continue;
        };
        match reap_bounded(&run) {
            Some(Ok(r)) if r.alive.is_empty() => {
                let n = run.leftovers().len();
                if run.force_remove_files().is_ok() {
                    removed += n;
                }
            }
            _ => {}
        }
    }
    removed
}

/// How long the launcher waits for iceoryx2's cleanup of a run's dead nodes.
pub(super) const REAP_TIMEOUT: Duration = Duration::from_secs(5);

/// [`sc_bus::reap_dead_nodes`] with a bounded wait. iceoryx2 waits without limit to open
/// a service whose creator was stopped while creating it (its dynamic config is never
/// marked initialised): a process torn down in its first milliseconds — the early stop
/// of a launch whose partner fails at start — hung the launcher there (measured: a test
/// stuck for minutes in `AdaptiveWait`). `None` when the cleanup did not finish in time;
/// its thread is left behind, sleeping, and the caller removes the run's files by name.
pub(super) fn reap_bounded(run: &RunScope) -> Option<sc_bus::Result<sc_bus::NodeReport>> {
    let (tx, rx) = std::sync::mpsc::channel();
    let scope = run.clone();
    std::thread::Builder::new()
        .name("reap-dead-nodes".into())
        .spawn(move || {
            let _ = tx.send(sc_bus::reap_dead_nodes(&scope));
        })
        .ok()?;
    rx.recv_timeout(REAP_TIMEOUT).ok()
}

/// What a partition run writes into its output directory (besides `logs/`).
pub const RUN_OUTPUTS: [&str; 19] = [
    ALL_READY,
    "summary.json",
    "telemetry.csv",
    "navigation.csv",
    "timing.csv",
    "recording.mcap",
    "launch.json",
    "recorder.json",
    "scheduler.json",
    "partition.effective.toml",
    "latency.csv",
    "latency.svg",
    "latency_report.json",
    "latency_report.md",
    "latency_timeline.svg",
    "latency_whole_tick.hgrm",
    "steal.csv",
    "compare",
    "figures",
];

/// Removes what an earlier run left in `out` (only the files a run writes, never anything
/// else), so that a run that fails early cannot be reported with an old run's results.
pub(super) fn clear_previous_run(out: &Path) {
    for name in RUN_OUTPUTS {
        let p = out.join(name);
        let _ = if p.is_dir() {
            std::fs::remove_dir_all(&p)
        } else {
            std::fs::remove_file(&p)
        };
    }
    if let Ok(logs) = std::fs::read_dir(out.join("logs")) {
        for e in logs.flatten() {
            if e.path().extension().is_some_and(|x| x == "log") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}
