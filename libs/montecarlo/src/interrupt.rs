//! Graceful stop of a campaign on SIGINT or SIGTERM (Ctrl-C).
//!
//! [`install`] sets a handler that only records the request (and, on the first signal,
//! says on stderr what happens next). A campaign whose executor is wrapped in
//! [`StopOnSignal`] then starts no further run, lets the runs in flight finish, and
//! aggregates the runs that completed; the campaign says it was interrupted and
//! `--resume` completes it. A second signal ends the process at once with
//! [`EXIT_FORCED`]: the runs in flight are abandoned, and since a run's directory only
//! gets its final name once the run is saved, nothing half-written looks complete.

use sc_mission::{ExecError, Executed, Execution, Executor, Job};
use std::sync::atomic::{AtomicBool, Ordering};

/// Exit code of a process ended by a second SIGINT/SIGTERM: 128 + SIGINT, what a shell
/// reports for a process killed by Ctrl-C.
pub const EXIT_FORCED: i32 = 128 + libc::SIGINT;

/// What the first signal prints (from the handler: one `write`, async-signal-safe).
const FIRST_SIGNAL_NOTE: &[u8] = b"\nmontecarlo: interrupted: no further run starts; the runs in flight finish, then the completed runs are aggregated (signal again to quit at once)\n";

static REQUESTED: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    if REQUESTED.swap(true, Ordering::SeqCst) {
        // SAFETY: _exit is async-signal-safe.
        unsafe { libc::_exit(EXIT_FORCED) }
    }
    // SAFETY: write(2) on stderr is async-signal-safe; the buffer is static. A failed
    // write only loses the note.
    unsafe {
        libc::write(
            libc::STDERR_FILENO,
            FIRST_SIGNAL_NOTE.as_ptr().cast(),
            FIRST_SIGNAL_NOTE.len(),
        );
    }
}

/// A signal handler the system refused.
#[derive(Debug, thiserror::Error)]
#[error("cannot install the {signal} handler: {error}")]
pub struct InstallError {
    pub signal: &'static str,
    pub error: std::io::Error,
}

/// Installs the SIGINT and SIGTERM handlers of a graceful stop.
pub fn install() -> Result<(), InstallError> {
    for (sig, name) in [(libc::SIGINT, "SIGINT"), (libc::SIGTERM, "SIGTERM")] {
        // SAFETY: the handler only touches an atomic and calls async-signal-safe functions.
        let previous = unsafe { libc::signal(sig, on_signal as *const () as libc::sighandler_t) };
        if previous == libc::SIG_ERR {
            return Err(InstallError {
                signal: name,
                error: std::io::Error::last_os_error(),
            });
        }
    }
    Ok(())
}

/// True once SIGINT or SIGTERM arrived after [`install`].
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

/// An executor that stops (no further run starts) once [`requested`].
pub struct StopOnSignal<E>(pub E);

impl<E: Executor> Executor for StopOnSignal<E> {
    fn execute(&self, job: Job<'_>) -> Result<Executed, ExecError> {
        self.0.execute(job)
    }

    fn stopped(&self) -> bool {
        requested() || self.0.stopped()
    }

    fn execution(&self) -> Execution {
        self.0.execution()
    }
}
