//! The launcher/supervisor: starts every process of the partition from the config,
//! supervises them, tears everything down on success, Ctrl-C or failure, and
//! leaves nothing in /dev/shm.

use anyhow::Context;
use sc_bus::RunScope;
use sc_flight::config::{ClockMode, PartitionConfig};
use sc_icd::{ROLES, Role};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// `eprintln!` that cannot panic: with stderr a closed pipe (`launch 2>&1 | head`) the
/// launcher must still tear the run down and leave nothing in /dev/shm.
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr().lock(), $($arg)*);
    }};
}

/// Environment variable: directory of the partition's executables.
pub const BIN_DIR_ENV: &str = "SC_PARTITION_BIN_DIR";

/// What to launch.
#[derive(Debug, Clone, Default)]
pub struct LaunchOptions {
    pub config: PathBuf,
    pub out: PathBuf,
    /// Where bare executable names are looked up (default: `SC_PARTITION_BIN_DIR`,
    /// else the launcher's own directory).
    pub bin_dir: Option<PathBuf>,
    /// Run id (iceoryx2 prefix); default a fresh unique one.
    pub run_id: Option<String>,
    /// Overrides of the config.
    pub clock: Option<ClockMode>,
    pub max_ticks: Option<u64>,
    /// Lock-step deadlines as a multiple of the real-time ones (`[lock_step] deadline_scale`).
    pub deadline_scale: Option<f64>,
    /// Kill everything after this long (default 15 min).
    pub timeout: Option<Duration>,
    /// Replace role executables: (role, exec, args).
    pub role_override: Vec<(String, String, Vec<String>)>,
    /// Run this scenario instead of the config's (relative to the working directory).
    pub scenario: Option<PathBuf>,
    /// Print nothing on stderr (how each process ended is in the report and launch.json).
    pub quiet: bool,
}

/// How one process ended.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ProcessExit {
    pub role: String,
    pub pid: u32,
    /// Exit code, if it exited.
    pub code: Option<i32>,
    /// Signal that ended it, if any.
    pub signal: Option<i32>,
    /// Killed by the launcher during teardown.
    pub killed_by_launcher: bool,
}

impl ProcessExit {
    /// The process did its job: exit 0 (the recorder's too when the mission did not
    /// capture: that is the mission's result, in summary.json, not the recorder's).
    pub fn ended_well(&self) -> bool {
        self.code == Some(0)
    }
}

/// Result of a launch.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LaunchReport {
    pub run_id: String,
    pub exits: Vec<ProcessExit>,
    /// 0 all fine and captured safely; 1 the mission did not capture safely; 3 a process
    /// failed; 4 every process ended well but flight-side samples were lost in transport
    /// (an infrastructure failure, named in `error`).
    pub code: i32,
    pub interrupted: bool,
    /// Files of the run left in /dev/shm or /tmp/iceoryx2 after teardown (should be empty).
    pub leftovers: Vec<PathBuf>,
    /// Stale files of earlier dead runs removed at start-up.
    pub stale_removed: usize,
    /// The CPU wake-up latency during the run (config `cpu_wakeup_latency_us`,
    /// real-time mode only).
    pub cpu_wakeup_latency: String,
    pub wall_s: f64,
    /// Why a role could not be started, or what the infrastructure lost (code 4).
    pub error: Option<String>,
}

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// True when SIGINT or SIGTERM arrived since the last [`launch`] started (the launcher
/// handles both once it ran; a caller running launches in a row checks this between
/// them, since the next launch starts with a cleared flag).
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

extern "C" fn on_signal(_: libc::c_int) {
    INTERRUPTED.store(true, Ordering::SeqCst);
}

fn install_signal_handlers() {
    // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
    unsafe {
        libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
    }
}

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
const REAP_TIMEOUT: Duration = Duration::from_secs(5);

/// [`sc_bus::reap_dead_nodes`] with a bounded wait. iceoryx2 waits without limit to open
/// a service whose creator was stopped while creating it (its dynamic config is never
/// marked initialised): a process torn down in its first milliseconds — the early stop
/// of a launch whose partner fails at start — hung the launcher there (measured: a test
/// stuck for minutes in `AdaptiveWait`). `None` when the cleanup did not finish in time;
/// its thread is left behind, sleeping, and the caller removes the run's files by name.
fn reap_bounded(run: &RunScope) -> Option<sc_bus::Result<sc_bus::NodeReport>> {
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

/// Written by the scheduler into the output directory once every process joined the
/// start-up handshake. A process that fails by itself before then can never join: the
/// launcher tears the run down at once instead of waiting for the handshake timeout.
pub use sc_flight::ALL_READY;

/// What a partition run writes into its output directory (besides `logs/`).
pub const RUN_OUTPUTS: [&str; 18] = [
    ALL_READY,
    "summary.json",
    "telemetry.csv",
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

/// The last non-empty line of a log, shortened to `max_chars`.
pub fn last_log_line(log: &Path, max_chars: usize) -> Option<String> {
    let text = std::fs::read_to_string(log).ok()?;
    let line = text.lines().rev().find(|l| !l.trim().is_empty())?.trim();
    let mut s: String = line.chars().take(max_chars).collect();
    if s.len() < line.len() {
        s.push('…');
    }
    Some(s)
}

/// How much of a log's last line an error quotes.
const QUOTED_LOG_CHARS: usize = 200;

/// Removes what an earlier run left in `out` (only the files a run writes, never anything
/// else), so that a run that fails early cannot be reported with an old run's results.
fn clear_previous_run(out: &Path) {
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

/// The executable a role's `exec` names: a path relative to the config directory
/// `base_dir`, or a bare name looked up in `bin_dir`, `SC_PARTITION_BIN_DIR` and the
/// launcher's own directory; a bare name found in none of them is returned as is
/// (then `PATH` decides).
pub fn resolve_exec(exec: &str, base_dir: &Path, bin_dir: &Option<PathBuf>) -> PathBuf {
    if exec.contains('/') {
        let p = PathBuf::from(exec);
        return if p.is_absolute() { p } else { base_dir.join(p) };
    }
    let mut dirs: Vec<PathBuf> = Vec::new();
    if let Some(d) = bin_dir {
        dirs.push(d.clone());
    }
    if let Some(d) = std::env::var_os(BIN_DIR_ENV) {
        dirs.push(PathBuf::from(d));
    }
    if let Ok(me) = std::env::current_exe()
        && let Some(d) = me.parent()
    {
        dirs.push(d.to_path_buf());
        if d.file_name().is_some_and(|n| n == "deps")
            && let Some(pd) = d.parent()
        {
            dirs.push(pd.to_path_buf());
        }
    }
    for d in dirs {
        let c = d.join(exec);
        if c.is_file() {
            return c;
        }
    }
    PathBuf::from(exec)
}

fn abs(p: &Path) -> PathBuf {
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        std::env::current_dir()
            .map(|d| d.join(p))
            .unwrap_or_else(|_| p.to_path_buf())
    }
}

fn signal_pid(pid: u32, sig: libc::c_int) {
    // SAFETY: kill(2) on a child pid we started and have not reaped yet.
    unsafe {
        libc::kill(pid as libc::pid_t, sig);
    }
}

struct Proc {
    role: String,
    child: Child,
    exit: Option<ProcessExit>,
}

/// The config `opts` names, with the options' overrides applied (scenario, clock,
/// ticks, deadline scale, role executables); paths still relative to its directory.
pub fn configured(opts: &LaunchOptions) -> anyhow::Result<PartitionConfig> {
    let mut cfg = PartitionConfig::load(&opts.config)?;
    if let Some(sc) = &opts.scenario {
        cfg.scenario = abs(sc);
    }
    if let Some(c) = opts.clock {
        cfg.clock = c;
    }
    if let Some(n) = opts.max_ticks {
        cfg.max_ticks = n;
    }
    if let Some(d) = opts.deadline_scale {
        cfg.lock_step.deadline_scale = d;
    }
    for (role, exec, args) in &opts.role_override {
        if Role::named(role).is_none() {
            let known: Vec<&str> = sc_icd::roles::names().collect();
            anyhow::bail!("unknown role `{role}` (known: {})", known.join(", "));
        }
        let e = cfg.roles.get_mut(role).context("role")?;
        e.exec = exec.clone();
        e.args = args.clone();
    }
    Ok(cfg)
}

/// Starts, supervises and tears down one run of the partition.
pub fn launch(opts: &LaunchOptions) -> anyhow::Result<LaunchReport> {
    install_signal_handlers();
    INTERRUPTED.store(false, Ordering::SeqCst);
    let started = Instant::now();
    let mut cfg = configured(opts)?;
    let out = abs(&opts.out);
    clear_previous_run(&out);
    std::fs::create_dir_all(out.join("logs"))
        .with_context(|| format!("cannot create {}", out.display()))?;
    // the effective config, with absolute paths, is what every process reads
    let base = abs(&cfg.base_dir);
    cfg.scenario = base.join(&cfg.scenario);
    for e in cfg.roles.values_mut() {
        e.exec = resolve_exec(&e.exec, &base, &opts.bin_dir)
            .display()
            .to_string();
        // arguments that name files relative to the config directory
        for a in e.args.iter_mut() {
            if !a.starts_with('-')
                && a.contains('/')
                && !Path::new(a).is_absolute()
                && base.join(&*a).exists()
            {
                *a = base.join(&*a).display().to_string();
            }
        }
    }
    // the plant's program and files, relative to the config directory like a role's
    for (i, a) in cfg.simulator.plant.iter_mut().enumerate() {
        if !a.starts_with('-')
            && (i == 0 || a.contains('/'))
            && !Path::new(a).is_absolute()
            && base.join(&*a).exists()
        {
            *a = base.join(&*a).display().to_string();
        }
    }
    cfg.validate()?;
    let eff = out.join("partition.effective.toml");
    std::fs::write(
        &eff,
        toml::to_string(&cfg).context("serialising the effective config")?,
    )
    .with_context(|| format!("cannot write {}", eff.display()))?;
    let run = match &opts.run_id {
        Some(id) => RunScope::new(id)?,
        None => RunScope::unique("run")?,
    };
    // held until the launcher returns (after teardown); in both clock modes, since
    // every hop of a lock-step tick waits for a wake-up as well
    let wakeup_request = cfg.cpu_wakeup_latency_us;
    let wakeup_held = match wakeup_request {
        Some(us) => crate::pm_qos::CpuWakeupLatency::request(us)
            .map_err(|e| format!("{}: {e}", crate::pm_qos::DEVICE)),
        None => Err(String::new()),
    };
    if let (Some(_), Err(e)) = (wakeup_request, &wakeup_held) {
        note!("launch: warning: CPU wake-up latency not set ({e})");
    }
    let stale_removed = clean_stale_runs(run.run_id());
    let _ = reap_bounded(&run);
    let mut procs: Vec<Proc> = Vec::new();
    let mut spawn_err = None;
    for role in ROLES.iter().map(|r| r.name) {
        let e = &cfg.roles[role];
        // a log that cannot be opened stops the start like a process that cannot start:
        // the processes already running are torn down below, not left behind
        let path = out.join("logs").join(format!("{role}.log"));
        let log = match std::fs::File::create(&path).and_then(|l| Ok((l.try_clone()?, l))) {
            Ok(l) => l,
            Err(err) => {
                spawn_err = Some(format!(
                    "cannot open the log of role `{role}` ({}): {err}",
                    path.display()
                ));
                break;
            }
        };
        let mut cmd = Command::new(&e.exec);
        cmd.args(&e.args);
        if !e.no_standard_args {
            cmd.arg("--config").arg(&eff).arg("--out").arg(&out);
        }
        cmd.env(sc_bus::RUN_ID_ENV, run.run_id())
            .env(sc_flight::process::CONFIG_ENV, &eff)
            .env(sc_flight::process::OUT_ENV, &out)
            .stdin(Stdio::null())
            .stdout(log.0)
            .stderr(log.1);
        match cmd.spawn() {
            Ok(child) => procs.push(Proc {
                role: role.to_string(),
                child,
                exit: None,
            }),
            Err(err) => {
                spawn_err = Some(format!("cannot start role `{role}` ({}): {err}", e.exec));
                break;
            }
        }
    }
    let timeout = opts.timeout.unwrap_or(Duration::from_secs(900));
    let mut teardown_at: Option<Instant> = None;
    let mut interrupted = false;
    let mut failed = spawn_err.is_some();
    if spawn_err.is_some() {
        teardown_at = Some(Instant::now());
    }
    let mut termed = false;
    let mut killed = false;
    // a process that failed by itself before every process was ready
    let mut early_err: Option<String> = None;
    loop {
        for p in procs.iter_mut() {
            if p.exit.is_none()
                && let Ok(Some(st)) = p.child.try_wait()
            {
                use std::os::unix::process::ExitStatusExt;
                let ex = ProcessExit {
                    role: p.role.clone(),
                    pid: p.child.id(),
                    code: st.code(),
                    signal: st.signal(),
                    killed_by_launcher: termed,
                };
                // a process that ended well is counted in the verdict line, and so is one
                // the teardown stopped; one that failed by itself is named here as it
                // happens
                if !opts.quiet && !ex.ended_well() && !termed {
                    note!(
                        "launch: {} (pid {}) exited: {}",
                        p.role,
                        ex.pid,
                        match (ex.code, ex.signal) {
                            (Some(c), _) => format!("code {c}"),
                            (_, Some(s)) => format!("signal {s}"),
                            _ => "?".into(),
                        }
                    );
                }
                let ok = ex.ended_well();
                if !ok && !termed && !out.join(ALL_READY).exists() {
                    // the handshake can never complete (a participant that cannot join,
                    // or the scheduler itself, e.g. at its handshake timeout naming who
                    // never joined): stop now, naming it, instead of waiting for the
                    // scheduler's handshake timeout
                    let log = out.join("logs").join(format!("{}.log", p.role));
                    early_err.get_or_insert_with(|| {
                        format!(
                            "role `{}` ended ({}) before every process was ready{}; see {}",
                            p.role,
                            match (ex.code, ex.signal) {
                                (Some(c), _) => format!("exit code {c}"),
                                (_, Some(s)) => format!("signal {s}"),
                                _ => "unknown end".into(),
                            },
                            last_log_line(&log, QUOTED_LOG_CHARS)
                                .map(|l| format!(": {l}"))
                                .unwrap_or_default(),
                            log.display()
                        )
                    });
                    teardown_at = Some(Instant::now());
                }
                if !ok && !termed {
                    failed = true;
                    // the scheduler, simulator and recorder are essential: without
                    // them the run cannot go on; nominal/filter deaths are degraded
                    // modes the partition handles (fallbacks)
                    if matches!(p.role.as_str(), "scheduler") && teardown_at.is_none() {
                        teardown_at = Some(Instant::now());
                    }
                    if matches!(p.role.as_str(), "simulator" | "recorder") && teardown_at.is_none()
                    {
                        // the scheduler notices and stops; the launcher waits a little for that
                        teardown_at = Some(Instant::now() + Duration::from_secs(20));
                    }
                }
                if p.role == "scheduler" && teardown_at.is_none() {
                    // normal end: the others got the stop tick and finish their outputs
                    teardown_at = Some(Instant::now() + Duration::from_secs(8));
                }
                p.exit = Some(ex);
            }
        }
        if procs.iter().all(|p| p.exit.is_some()) {
            break;
        }
        if INTERRUPTED.load(Ordering::SeqCst) && !interrupted {
            interrupted = true;
            if !opts.quiet {
                note!("launch: interrupted, tearing down");
            }
            teardown_at = Some(Instant::now());
        }
        if started.elapsed() > timeout && teardown_at.is_none() {
            if !opts.quiet {
                note!("launch: run timed out after {timeout:?}, tearing down");
            }
            failed = true;
            teardown_at = Some(Instant::now());
        }
        if let Some(t) = teardown_at {
            let now = Instant::now();
            if now >= t && !termed {
                termed = true;
                for p in procs.iter().filter(|p| p.exit.is_none()) {
                    signal_pid(p.child.id(), libc::SIGTERM);
                }
            }
            if now >= t + Duration::from_secs(3) && !killed {
                killed = true;
                for p in procs.iter_mut().filter(|p| p.exit.is_none()) {
                    // a process that ignores the stop tick and SIGTERM is hung: a failure
                    failed = true;
                    if !opts.quiet {
                        note!("launch: killing {} (pid {})", p.role, p.child.id());
                    }
                    let _ = p.child.kill();
                }
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    // every process of the run is gone: remove what the run left behind
    if reap_bounded(&run).is_none() && !opts.quiet {
        note!(
            "launch: warning: iceoryx2's cleanup of the run's dead nodes did not finish within {REAP_TIMEOUT:?} (a process was stopped while creating a service); the run's files are removed by name"
        );
    }
    let _ = run.force_remove_files();
    if interrupted
        && let Err(e) = mark_interrupted(&out)
        && !opts.quiet
    {
        note!("launch: warning: {e:#}");
    }
    let leftovers = run.leftovers();
    let exits: Vec<ProcessExit> = procs.into_iter().filter_map(|p| p.exit).collect();
    let mut code = if failed || interrupted || spawn_err.is_some() || !leftovers.is_empty() {
        3
    } else {
        match mission_verdict(&out.join("summary.json")) {
            Some(true) => 0,
            Some(false) => 1,
            // every process ended well and yet the recorder left no result
            None => 3,
        }
    };
    let mut error = spawn_err.or(early_err);
    // every process ended well, yet the flight side lost samples: the transport failed
    // (e.g. a publisher gave up on a full queue under load), not the mission
    let lost = std::fs::read_to_string(out.join("recorder.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .map(|v| infrastructure_losses(&v))
        .unwrap_or_default();
    if code <= 1 && !lost.is_empty() {
        code = 4;
        error = Some(format!(
            "infrastructure: flight-side samples lost in transport ({}); the run's result is not the mission's",
            lost.join(", ")
        ));
    }
    if let Some(e) = error.as_ref().filter(|_| !opts.quiet) {
        note!("launch: {e}");
    }
    let rep = LaunchReport {
        run_id: run.run_id().to_string(),
        exits,
        code,
        interrupted,
        leftovers,
        stale_removed,
        cpu_wakeup_latency: crate::pm_qos::describe(wakeup_request, &wakeup_held),
        wall_s: started.elapsed().as_secs_f64(),
        error,
    };
    std::fs::write(
        out.join("launch.json"),
        serde_json::to_string_pretty(&rep)? + "\n",
    )?;
    Ok(rep)
}

/// The files of a run that name its end ([`sc_mission::MissionEnd::name`]).
const END_FILES: [&str; 2] = ["summary.json", "recorder.json"];

/// Names the end of an interrupted run: the recorder saw the run stop before the
/// mission ended ("stopped") but cannot tell a signal from the scheduler's stop; the
/// launcher, that caught SIGINT/SIGTERM, rewrites it as "interrupted" in summary.json and
/// recorder.json. A mission that had ended before the signal keeps its end; a file the
/// recorder did not write is left absent.
fn mark_interrupted(out: &Path) -> anyhow::Result<()> {
    use sc_mission::MissionEnd;
    for name in END_FILES {
        let path = out.join(name);
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let mut v: serde_json::Value =
            serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
        let Some(fields) = v.as_object_mut() else {
            anyhow::bail!("{}: not a JSON object", path.display());
        };
        let t = fields
            .get("final_time_s")
            .and_then(|t| t.as_f64())
            .unwrap_or(f64::NAN);
        let end = fields.get("end").and_then(|e| e.as_str());
        if let Some(MissionEnd::Stopped { t }) = end.and_then(|e| MissionEnd::from_name(e, t)) {
            fields.insert("end".into(), MissionEnd::Interrupted { t }.name().into());
            std::fs::write(&path, serde_json::to_string_pretty(&v)? + "\n")
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
    }
    Ok(())
}

/// The mission's verdict from a run's summary.json: captured with every barrier
/// satisfied and no fault; `None` without a readable summary.
pub fn mission_verdict(summary: &Path) -> Option<bool> {
    let s: sc_mission::Summary =
        serde_json::from_str(&std::fs::read_to_string(summary).ok()?).ok()?;
    Some(s.captured && s.violated_constraints.is_empty() && s.fault_count == 0)
}

/// The flight-side services (everything but the partners' `safe_capture/nominal/*`) of
/// which the recorder missed samples, from its `recorder.json`, as `service: count`.
pub fn infrastructure_losses(recorder: &serde_json::Value) -> Vec<String> {
    recorder["missing"]
        .as_object()
        .map(|m| {
            m.iter()
                .filter(|(svc, _)| !svc.starts_with("safe_capture/nominal/"))
                .filter_map(|(svc, n)| n.as_u64().filter(|n| *n > 0).map(|n| format!("{svc}: {n}")))
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod infrastructure_tests {
    use super::infrastructure_losses;

    #[test]
    fn only_flight_side_losses_count() {
        let r = serde_json::json!({"missing": {
            "safe_capture/nominal/attitude": 550,
            "safe_capture/sim/state": 0,
            "safe_capture/safe/robotic": 3,
        }});
        assert_eq!(
            infrastructure_losses(&r),
            vec!["safe_capture/safe/robotic: 3"]
        );
        let healthy = serde_json::json!({"missing": {"safe_capture/nominal/robotic": 9}});
        assert!(infrastructure_losses(&healthy).is_empty());
        assert!(infrastructure_losses(&serde_json::json!({})).is_empty());
    }
}

#[cfg(test)]
mod end_tests {
    use super::{END_FILES, mark_interrupted};
    use serde_json::json;

    fn end_of(dir: &std::path::Path, name: &str) -> serde_json::Value {
        let text = std::fs::read_to_string(dir.join(name)).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).unwrap()["end"].clone()
    }

    /// An interrupted run that the recorder saw stopped is named interrupted; a mission
    /// that had ended keeps its end; absent files stay absent.
    #[test]
    fn an_interrupted_run_is_named_so_unless_the_mission_had_ended() {
        let dir = std::env::temp_dir().join(format!("sc-mark-interrupted-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (end, want) in [
            ("stopped", "interrupted"),
            ("captured", "captured"),
            ("timeout", "timeout"),
        ] {
            for name in END_FILES {
                let v = json!({"end": end, "final_time_s": 4.9, "steps": 50});
                std::fs::write(dir.join(name), v.to_string()).unwrap();
            }
            mark_interrupted(&dir).unwrap();
            for name in END_FILES {
                assert_eq!(end_of(&dir, name), want, "{name} of a run that ended {end}");
            }
        }
        for name in END_FILES {
            std::fs::remove_file(dir.join(name)).unwrap();
        }
        mark_interrupted(&dir).unwrap();
        assert!(END_FILES.iter().all(|n| !dir.join(n).exists()));
        // a file that is not a JSON object is named, not overwritten
        std::fs::write(dir.join(END_FILES[0]), "[]").unwrap();
        let err = mark_interrupted(&dir).unwrap_err().to_string();
        assert!(err.contains("not a JSON object"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
