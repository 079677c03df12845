//! The watch over a run's processes until every one has ended: a process that fails
//! before every process is ready stops the start at once (naming it and the last line
//! of its log); the scheduler's end starts the teardown; the death of an essential role
//! (scheduler, simulator, recorder) too; a signal or the run's timeout too. The teardown
//! is the stop tick (already sent by the scheduler), then SIGTERM, then SIGKILL for a
//! process that ignores both (a hung process: a failure).

use super::start::Started;
use super::{ALL_READY, ProcessExit, QUOTED_LOG_CHARS, last_log_line, note};
use sc_icd::{Role, RoleKind};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// After the scheduler ended normally, the others have this long to finish their
/// outputs (they got the stop tick) before SIGTERM.
const AFTER_SCHEDULER: Duration = Duration::from_secs(8);
/// After the simulator or the recorder died, the scheduler notices and stops the run;
/// the launcher waits this long for that.
const AFTER_ESSENTIAL_DEATH: Duration = Duration::from_secs(20);
/// SIGTERM to SIGKILL.
const TERM_TO_KILL: Duration = Duration::from_secs(3);
/// How often the launcher looks at its processes.
const POLL: Duration = Duration::from_millis(20);
/// How often a running mission's progress is said (wall time) [s]; the environment
/// variable [`PROGRESS_ENV`] overrides it (tests).
const PROGRESS_EVERY_S: f64 = 10.0;
/// Environment variable with the progress interval [s].
pub const PROGRESS_ENV: &str = "SC_LAUNCH_PROGRESS_S";
/// Across hosts: after this host's last role ended, its link keeps moving samples this
/// long before SIGTERM (the scheduler's stop tick, sent just before it ended, must reach
/// the other hosts; the link passes every few hundred µs).
const LINK_DRAIN: Duration = Duration::from_millis(500);

/// The progress interval: [`PROGRESS_ENV`] if it is a positive number, else the default.
fn progress_every() -> Duration {
    std::env::var(PROGRESS_ENV)
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|s| *s > 0.0)
        .and_then(|s| Duration::try_from_secs_f64(s).ok())
        .unwrap_or(Duration::from_secs_f64(PROGRESS_EVERY_S))
}

/// What the watch found.
pub(super) struct Supervised {
    pub exits: Vec<ProcessExit>,
    /// How this host's end of the link ended (a run across hosts).
    pub link: Option<ProcessExit>,
    pub interrupted: bool,
    pub failed: bool,
    /// A process that failed by itself before every process was ready.
    pub early_err: Option<String>,
}

struct Watched {
    role: &'static str,
    child: std::process::Child,
    exit: Option<ProcessExit>,
}

/// The watch over one run.
pub(super) struct Supervisor<'a> {
    procs: Vec<Watched>,
    /// This host's end of the link (a run across hosts): stopped after the roles.
    link: Option<Watched>,
    /// This host is not the home host: no scheduler and no telemetry here (no progress
    /// to say); each role ends on the stop tick that comes through the link.
    away: bool,
    /// When the last role of this host ended.
    roles_done_at: Option<Instant>,
    /// The link got its SIGTERM.
    link_termed: bool,
    quiet: bool,
    out: &'a Path,
    teardown_at: Option<Instant>,
    interrupted: bool,
    failed: bool,
    termed: bool,
    killed: bool,
    early_err: Option<String>,
    /// The scheduler ended well: every process got the stop tick, and one still running
    /// at the teardown is hung.
    normal_end: bool,
    /// When the progress was last said, and how often it is.
    progress_at: Instant,
    progress_every: Duration,
    /// telemetry.csv's rows counted so far and the bytes they were counted in.
    progress_rows: usize,
    progress_bytes: u64,
}

/// How a process ended, in words.
fn how(code: Option<i32>, signal: Option<i32>, exit_word: &str) -> String {
    match (code, signal) {
        (Some(c), _) => format!("{exit_word} {c}"),
        (_, Some(s)) => format!("signal {s}"),
        _ => "unknown end".into(),
    }
}

impl<'a> Supervisor<'a> {
    /// The watch over `procs`; `start_failed`: a role could not be started (tear down).
    pub fn new(procs: Vec<Started>, start_failed: bool, quiet: bool, out: &'a Path) -> Self {
        Self {
            procs: procs
                .into_iter()
                .map(|p| Watched {
                    role: p.role,
                    child: p.child,
                    exit: None,
                })
                .collect(),
            link: None,
            away: false,
            roles_done_at: None,
            link_termed: false,
            quiet,
            out,
            teardown_at: start_failed.then(Instant::now),
            interrupted: false,
            failed: start_failed,
            termed: false,
            killed: false,
            early_err: None,
            normal_end: false,
            progress_at: Instant::now(),
            progress_every: progress_every(),
            progress_rows: 0,
            progress_bytes: 0,
        }
    }

    /// A run across hosts: this host's link process, and whether this is not the home host.
    pub fn with_link(mut self, link: Option<std::process::Child>, away: bool) -> Self {
        self.link = link.map(|child| Watched {
            role: "link",
            child,
            exit: None,
        });
        self.away = away;
        self
    }

    /// Watches until every process ended.
    pub fn run(mut self, started: Instant, timeout: Duration, signal: &AtomicBool) -> Supervised {
        loop {
            self.reap();
            self.watch_link();
            let roles_done = self.procs.iter().all(|p| p.exit.is_some());
            if roles_done && self.link.as_ref().is_none_or(|l| l.exit.is_some()) {
                break;
            }
            self.watch_signal_and_timeout(started, timeout, signal);
            self.say_progress(started);
            self.tear_down();
            std::thread::sleep(POLL);
        }
        Supervised {
            link: self.link.and_then(|l| l.exit),
            exits: self.procs.into_iter().filter_map(|p| p.exit).collect(),
            interrupted: self.interrupted,
            failed: self.failed,
            early_err: self.early_err,
        }
    }

    /// Notes every process that ended since the last look.
    fn reap(&mut self) {
        for i in 0..self.procs.len() {
            let p = &mut self.procs[i];
            if p.exit.is_some() {
                continue;
            }
            let Ok(Some(st)) = p.child.try_wait() else {
                continue;
            };
            use std::os::unix::process::ExitStatusExt;
            let ex = ProcessExit {
                role: p.role.to_string(),
                pid: p.child.id(),
                code: st.code(),
                signal: st.signal(),
                killed_by_launcher: self.termed,
            };
            self.on_exit(self.procs[i].role, &ex);
            self.procs[i].exit = Some(ex);
        }
    }

    /// The link: a failure when it ends by itself while roles still need it (the run
    /// cannot go on across hosts: tear down); stopped [`LINK_DRAIN`] after the last role
    /// ended, killed if it ignores SIGTERM.
    fn watch_link(&mut self) {
        if self.roles_done_at.is_none() && self.procs.iter().all(|p| p.exit.is_some()) {
            self.roles_done_at = Some(Instant::now());
        }
        let Some(link) = self.link.as_mut() else {
            return;
        };
        if link.exit.is_none()
            && let Ok(Some(st)) = link.child.try_wait()
        {
            use std::os::unix::process::ExitStatusExt;
            // after the mission's normal end (the scheduler here, or every role of this
            // host) the other host leaving is no failure: it ended too
            let stopped = self.roles_done_at.is_some() || self.normal_end;
            let ex = ProcessExit {
                role: link.role.to_string(),
                pid: link.child.id(),
                code: st.code(),
                signal: st.signal(),
                killed_by_launcher: stopped || self.termed,
            };
            if !stopped && !self.termed {
                self.failed = true;
                if !self.quiet {
                    note!(
                        "launch: the link (pid {}) exited: {}; the run cannot go on across hosts",
                        ex.pid,
                        how(ex.code, ex.signal, "code")
                    );
                }
                self.teardown_at = Some(Instant::now());
            } else if !ex.ended_well() && ex.signal != Some(libc::SIGTERM) && !self.normal_end {
                self.failed = true;
            }
            link.exit = Some(ex);
            return;
        }
        let Some(done) = self.roles_done_at else {
            return;
        };
        if link.exit.is_none() && done.elapsed() >= LINK_DRAIN && !self.link_termed {
            self.link_termed = true;
            signal_pid(link.child.id(), libc::SIGTERM);
        }
        if link.exit.is_none() && done.elapsed() >= LINK_DRAIN + TERM_TO_KILL {
            // a link that ignores SIGTERM is hung
            self.failed = true;
            let _ = link.child.kill();
        }
    }

    /// What the end of `role`'s process means for the run.
    fn on_exit(&mut self, role: &'static str, ex: &ProcessExit) {
        let ok = ex.ended_well();
        let kind = Role::named(role).map(|r| r.kind);
        // a process that ended well is counted in the verdict line, and so is one the
        // teardown stopped; one that failed by itself is named here as it happens
        if !self.quiet && !ok && !self.termed {
            note!(
                "launch: {role} (pid {}) exited: {}",
                ex.pid,
                how(ex.code, ex.signal, "code")
            );
        }
        // before every process was ready even an exit 0 is a failure: the role can
        // never join (e.g. a partner script that never calls its controller's main)
        if !self.termed && !self.out.join(ALL_READY).exists() {
            self.failed = true;
            self.early_failure(role, ex);
        }
        if !ok && !self.termed {
            self.failed = true;
            // the scheduler, simulator and recorder are essential: without them the run
            // cannot go on; nominal/filter deaths are degraded modes the partition
            // handles (fallbacks)
            match kind {
                Some(RoleKind::Scheduler) => self.tear_down_in(Duration::ZERO),
                Some(RoleKind::Simulator | RoleKind::Recorder) => {
                    self.tear_down_in(AFTER_ESSENTIAL_DEATH)
                }
                _ => {}
            }
        }
        if kind == Some(RoleKind::Scheduler) {
            // normal end: the others got the stop tick and finish their outputs (away
            // from home no scheduler runs: each role ends on the stop tick that came
            // through the link, and the link ends the run when the home host has left)
            self.normal_end = ok && !self.termed;
            self.tear_down_in(AFTER_SCHEDULER);
        }
    }

    /// The handshake can never complete (a participant that cannot join, or the
    /// scheduler itself, e.g. at its handshake timeout naming who never joined): stop
    /// now, naming it, instead of waiting for the scheduler's handshake timeout.
    fn early_failure(&mut self, role: &str, ex: &ProcessExit) {
        let log = self.out.join("logs").join(format!("{role}.log"));
        self.early_err.get_or_insert_with(|| {
            let last = last_log_line(&log, QUOTED_LOG_CHARS);
            // a script that ends at once with exit 0 and says nothing never ran its loop
            let hint = if ex.ended_well() && last.is_none() {
                " (a partner script must run its controller: `sys.exit(MyController.main())`, docs/PARTNER.md)"
            } else {
                ""
            };
            format!(
                "role `{role}` ended ({}) before every process was ready{}{hint}; see {}",
                how(ex.code, ex.signal, "exit code"),
                last.map(|l| format!(": {l}")).unwrap_or_default(),
                log.display()
            )
        });
        self.teardown_at = Some(Instant::now());
    }

    /// Every [`PROGRESS_EVERY_S`] while the mission runs, one line on stderr: the steps the
    /// recorder has written so far (telemetry.csv's rows) — a real-time run of 240 s, or
    /// a latency bench of minutes, otherwise says nothing until it ends.
    fn say_progress(&mut self, started: Instant) {
        if self.quiet
            || self.away
            || self.teardown_at.is_some()
            || self.progress_at.elapsed() < self.progress_every
            || !self.out.join(ALL_READY).exists()
        {
            return;
        }
        self.progress_at = Instant::now();
        self.count_new_rows();
        note!(
            "launch: {} steps recorded after {:.0} s",
            self.progress_rows.saturating_sub(1),
            started.elapsed().as_secs_f64()
        );
    }

    /// Counts the rows appended to telemetry.csv since the last look (only the new bytes
    /// are read: the latency bench measures while this runs).
    fn count_new_rows(&mut self) {
        use std::io::{Read, Seek, SeekFrom};
        let Ok(mut f) = std::fs::File::open(self.out.join("telemetry.csv")) else {
            return;
        };
        if f.seek(SeekFrom::Start(self.progress_bytes)).is_err() {
            return;
        }
        let mut new = Vec::new();
        if f.read_to_end(&mut new).is_ok() {
            self.progress_bytes += new.len() as u64;
            self.progress_rows += new.iter().filter(|c| **c == b'\n').count();
        }
    }

    /// Sets the teardown `after` from now, unless one is set already.
    fn tear_down_in(&mut self, after: Duration) {
        if self.teardown_at.is_none() {
            self.teardown_at = Some(Instant::now() + after);
        }
    }

    fn watch_signal_and_timeout(
        &mut self,
        started: Instant,
        timeout: Duration,
        signal: &AtomicBool,
    ) {
        if signal.load(Ordering::SeqCst) && !self.interrupted {
            self.interrupted = true;
            // the scheduler may have ended on the same signal: not the mission's end
            self.normal_end = false;
            if !self.quiet {
                note!("launch: interrupted, tearing down");
            }
            self.teardown_at = Some(Instant::now());
        }
        if started.elapsed() > timeout && self.teardown_at.is_none() {
            if !self.quiet {
                note!("launch: run timed out after {timeout:?}, tearing down");
            }
            self.failed = true;
            self.normal_end = false;
            self.teardown_at = Some(Instant::now());
        }
    }

    /// SIGTERM at the teardown time, SIGKILL [`TERM_TO_KILL`] later.
    fn tear_down(&mut self) {
        let Some(t) = self.teardown_at else { return };
        let now = Instant::now();
        if now >= t && !self.termed {
            self.termed = true;
            for p in self.procs.iter().filter(|p| p.exit.is_none()) {
                if self.normal_end {
                    // it got the stop tick AFTER_SCHEDULER ago and still runs: hung
                    self.failed = true;
                    if !self.quiet {
                        note!(
                            "launch: {} (pid {}) did not end on the stop tick within {AFTER_SCHEDULER:?}: hung, stopping it",
                            p.role,
                            p.child.id()
                        );
                    }
                }
                signal_pid(p.child.id(), libc::SIGTERM);
            }
        }
        if now >= t + TERM_TO_KILL && !self.killed {
            self.killed = true;
            for p in self.procs.iter_mut().filter(|p| p.exit.is_none()) {
                // a process that ignores the stop tick and SIGTERM is hung: a failure
                self.failed = true;
                if !self.quiet {
                    note!("launch: killing {} (pid {})", p.role, p.child.id());
                }
                let _ = p.child.kill();
            }
        }
    }
}

fn signal_pid(pid: u32, sig: libc::c_int) {
    // SAFETY: kill(2) on a child pid we started and have not reaped yet.
    unsafe {
        libc::kill(pid as libc::pid_t, sig);
    }
}
