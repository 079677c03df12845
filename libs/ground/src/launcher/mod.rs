//! The launcher/supervisor: starts every process of the partition from the config,
//! supervises them, tears everything down on success, Ctrl-C or failure, and leaves
//! nothing in /dev/shm.
//!
//! * [`start`]: the effective config (absolute paths) and one process per role of the
//!   role table, each with its log;
//! * [`supervise`]: the watch until every process ended — early failures, essential
//!   roles, signals, the run's timeout, the teardown (stop tick, SIGTERM, SIGKILL);
//! * [`verdict`]: the exit code from the mission's summary and the recorder's counts;
//! * [`clean`]: what earlier runs left behind.

mod clean;
mod start;
mod supervise;
mod verdict;

pub use clean::{RUN_OUTPUTS, clean_stale_runs};
pub use start::{LINK_EXEC, configured, resolve_exec};
pub use verdict::{infrastructure_losses, mission_verdict};

use sc_bus::RunScope;
use sc_flight::config::{ClockMode, ConfigError, PartitionConfig};
use std::path::{Path, PathBuf};
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
pub(crate) use note;

/// Written by the scheduler into the output directory once every process joined the
/// start-up handshake. A process that fails by itself before then can never join: the
/// launcher tears the run down at once instead of waiting for the handshake timeout.
pub use sc_flight::ALL_READY;

/// Why a run could not be launched (one line).
#[derive(Debug, thiserror::Error)]
pub enum LaunchError {
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error(transparent)]
    Bus(#[from] sc_bus::BusError),
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    /// An override names a role the role table does not have.
    #[error("unknown role `{role}` (known: {known})")]
    UnknownRole { role: String, known: String },
    /// A file of the run is not what the launcher expects.
    #[error("{0}")]
    Output(String),
}

impl LaunchError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> Self {
        LaunchError::Io {
            path: path.display().to_string(),
            source,
        }
    }
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
    /// A run across hosts (`[hosts]`): the host whose roles this launch starts (default:
    /// the home host). Every host's launch needs the same `run_id`.
    pub host: Option<String>,
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
    /// A run across hosts: the host this launch ran, and how its end of the link ended.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub host: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link: Option<ProcessExit>,
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

/// The run's output folder, absolute.
fn abs(p: &Path) -> PathBuf {
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        std::env::current_dir()
            .map(|d| d.join(p))
            .unwrap_or_else(|_| p.to_path_buf())
    }
}

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

/// A run killed after this long unless [`LaunchOptions::timeout`] says otherwise.
const DEFAULT_RUN_TIMEOUT: Duration = Duration::from_secs(900);

/// Starts, supervises and tears down one run of the partition.
pub fn launch(opts: &LaunchOptions) -> Result<LaunchReport, LaunchError> {
    install_signal_handlers();
    INTERRUPTED.store(false, Ordering::SeqCst);
    let started = Instant::now();
    let out = abs(&opts.out);
    let (cfg, eff) = start::prepare(opts, &out)?;
    let run = match &opts.run_id {
        Some(id) => RunScope::new(id)?,
        None => RunScope::unique("run")?,
    };
    // held until the launcher returns (after teardown); in both clock modes, since
    // every hop of a lock-step tick waits for a wake-up as well
    let wakeup_request = cfg.cpu_wakeup_latency_us;
    let wakeup_held = wakeup_request.map(crate::pm_qos::CpuWakeupLatency::request);
    if let Some(Err(e)) = &wakeup_held {
        let device = crate::pm_qos::DEVICE;
        note!("launch: warning: CPU wake-up latency not set ({device}: {e})");
    }
    let stale_removed = clean_stale_runs(run.run_id());
    let _ = clean::reap_bounded(&run);
    let host = this_host(&cfg, opts)?;
    // the link first: it bridges each service as the roles create it
    let (link, link_err) = match start::spawn_link(&cfg, &host, &opts.bin_dir, &out, &run) {
        Ok(l) => (l, None),
        Err(e) => (None, Some(e)),
    };
    let link_pid = link.as_ref().map(|l| l.id());
    let (procs, spawn_err) = match link_err {
        None => start::spawn_roles(&cfg, &host, link_pid, &eff, &out, &run),
        e => (Vec::new(), e),
    };
    let timeout = opts.timeout.unwrap_or(DEFAULT_RUN_TIMEOUT);
    let away = cfg.hosts.as_ref().is_some_and(|h| h.home != host);
    let watch = supervise::Supervisor::new(procs, spawn_err.is_some(), opts.quiet, &out)
        .with_link(link, away);
    let s = watch.run(started, timeout, &INTERRUPTED);
    let mut rep = report(&run, &out, s, spawn_err, opts.quiet, away);
    rep.host = cfg.across_hosts().then_some(host);
    rep.stale_removed = stale_removed;
    rep.cpu_wakeup_latency = crate::pm_qos::describe(wakeup_request, &wakeup_held);
    rep.wall_s = started.elapsed().as_secs_f64();
    let path = out.join("launch.json");
    let text = serde_json::to_string_pretty(&rep).unwrap_or_default() + "\n";
    std::fs::write(&path, text).map_err(|e| LaunchError::io(&path, e))?;
    Ok(rep)
}

/// The host this launch runs (`""` on one host): `--host`, else the home host.
fn this_host(cfg: &PartitionConfig, opts: &LaunchOptions) -> Result<String, LaunchError> {
    match (&cfg.hosts, &opts.host) {
        (None, None) => Ok(String::new()),
        (None, Some(h)) => Err(LaunchError::Output(format!(
            "--host {h}: the config has no [hosts] (a run on one host)"
        ))),
        (Some(hosts), None) => Ok(hosts.home.clone()),
        (Some(hosts), Some(h)) if hosts.link.contains_key(h) => Ok(h.clone()),
        (Some(hosts), Some(h)) => Err(LaunchError::Output(format!(
            "--host {h}: not a host of the config's hosts.link ({})",
            hosts.names().join(", ")
        ))),
    }
}

/// Every process of the run is gone: removes what the run left behind, names an
/// interrupted run, and judges it (`away` from the home host there is no mission
/// result: 0 when every process of this host ended well, else 3).
fn report(
    run: &RunScope,
    out: &Path,
    s: supervise::Supervised,
    spawn_err: Option<start::SpawnError>,
    quiet: bool,
    away: bool,
) -> LaunchReport {
    if clean::reap_bounded(run).is_none() && !quiet {
        note!(
            "launch: warning: iceoryx2's cleanup of the run's dead nodes did not finish within {:?} (a process was stopped while creating a service); the run's files are removed by name",
            clean::REAP_TIMEOUT
        );
    }
    let _ = run.force_remove_files();
    if s.interrupted
        && let Err(e) = verdict::mark_interrupted(out)
        && !quiet
    {
        note!("launch: warning: {e}");
    }
    let leftovers = run.leftovers();
    let broken = s.failed || s.interrupted || spawn_err.is_some() || !leftovers.is_empty();
    let error = spawn_err.map(|e| e.to_string()).or(s.early_err);
    let (code, error) = if away {
        (if broken { 3 } else { 0 }, error)
    } else {
        verdict::judge(out, broken, error)
    };
    if let Some(e) = error.as_ref().filter(|_| !quiet) {
        note!("launch: {e}");
    }
    LaunchReport {
        run_id: run.run_id().to_string(),
        exits: s.exits,
        host: None,
        link: s.link,
        code,
        interrupted: s.interrupted,
        leftovers,
        stale_removed: 0,
        cpu_wakeup_latency: String::new(),
        wall_s: 0.0,
        error,
    }
}
