//! [`Waiter`]: one thread sleeps on several sources at once (iceoryx2 `WaitSet`):
//! subscribers' events, deadlines ("this input must arrive every X") and intervals
//! (periodic ticks). No busy polling.
//!
//! ```no_run
//! use sc_bus::{RunScope, ServiceSettings, Subscriber, Waiter, WaitOutcome};
//! use sc_icd::{services, SimState};
//! use std::time::Duration;
//! let run = RunScope::unique("doc")?;
//! let node = run.node("filter")?;
//! let state = Subscriber::<SimState>::new(&node, services::SIM_STATE, &ServiceSettings::lock_step())?;
//! let waiter = Waiter::new()?;
//! let on_state = waiter.attach_deadline(&state, Duration::from_millis(200))?;
//! let heartbeat = waiter.attach_interval(Duration::from_secs(1))?;
//! let outcome = waiter.wait_once(Duration::from_secs(5), |wake| {
//!     if on_state.woke(&wake) {
//!         let _ev = state.drain_events();          // always drain, or the waiter spins
//!         let _s = state.receive_latest();
//!     } else if on_state.missed_deadline(&wake) {
//!         // input late: degrade
//!     } else if heartbeat.woke(&wake) {
//!         // publish health
//!     }
//! })?;
//! assert!(matches!(outcome, WaitOutcome::Handled | WaitOutcome::Timeout));
//! # Ok::<(), sc_bus::BusError>(())
//! ```

use crate::error::{BusError, Result, reason};
use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use iceoryx2::waitset::WaitSetRunResult;
use std::time::Duration;

/// Something whose event listener can be attached to a [`Waiter`].
pub trait Waitable {
    /// The listener to sleep on (created here if the source creates it lazily).
    fn listener(&self) -> Result<&Listener<ipc::Service>>;
}

impl<T: core::fmt::Debug + ZeroCopySend + Copy + 'static> Waitable for crate::Subscriber<T> {
    fn listener(&self) -> Result<&Listener<ipc::Service>> {
        self.ensure_listener()
    }
}

impl Waitable for Listener<ipc::Service> {
    fn listener(&self) -> Result<&Listener<ipc::Service>> {
        Ok(self)
    }
}

/// Event multiplexer of one thread.
pub struct Waiter {
    ws: WaitSet<ipc::Service>,
}

/// Handle of one attachment; dropping it detaches.
pub struct Attachment<'w, 'a> {
    guard: WaitSetGuard<'w, 'a, ipc::Service>,
}

/// Identifies what woke the waiter; test it with [`Attachment::woke`] /
/// [`Attachment::missed_deadline`].
#[derive(Debug)]
pub struct Wake(WaitSetAttachmentId<ipc::Service>);

/// Why [`Waiter::wait_once`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WaitOutcome {
    /// At least one attachment fired and the callback ran for each.
    Handled,
    /// Nothing fired before the timeout.
    Timeout,
    /// SIGTERM or SIGINT received (iceoryx2 signal handling).
    TerminationRequest,
}

impl Attachment<'_, '_> {
    /// True if this attachment's listener has events (or its interval elapsed).
    pub fn woke(&self, wake: &Wake) -> bool {
        wake.0.has_event_from(&self.guard)
    }

    /// True if this attachment's deadline passed without an event.
    pub fn missed_deadline(&self, wake: &Wake) -> bool {
        wake.0.has_missed_deadline(&self.guard)
    }
}

fn attach_err(op: &'static str) -> impl Fn(WaitSetAttachmentError) -> BusError {
    move |e| BusError::WaitSet {
        op,
        reason: reason(e),
    }
}

use iceoryx2::waitset::WaitSetAttachmentError;

impl Waiter {
    /// New, empty waiter.
    pub fn new() -> Result<Self> {
        let ws = WaitSetBuilder::new()
            .create::<ipc::Service>()
            .map_err(|e| BusError::WaitSet {
                op: "create",
                reason: reason(e),
            })?;
        Ok(Self { ws })
    }

    /// Wake when `src` has events.
    pub fn attach<'w, 'a, W: Waitable + ?Sized>(
        &'w self,
        src: &'a W,
    ) -> Result<Attachment<'w, 'a>> {
        let guard = self
            .ws
            .attach_notification(src.listener()?)
            .map_err(attach_err("attach notification"))?;
        Ok(Attachment { guard })
    }

    /// Wake when `src` has events, and also when no event came for `deadline`
    /// (reported by [`Attachment::missed_deadline`]); each event resets the deadline.
    pub fn attach_deadline<'w, 'a, W: Waitable + ?Sized>(
        &'w self,
        src: &'a W,
        deadline: Duration,
    ) -> Result<Attachment<'w, 'a>> {
        let guard = self
            .ws
            .attach_deadline(src.listener()?, deadline)
            .map_err(attach_err("attach deadline"))?;
        Ok(Attachment { guard })
    }

    /// Wake every `period`.
    pub fn attach_interval(&self, period: Duration) -> Result<Attachment<'_, 'static>> {
        let guard = self
            .ws
            .attach_interval(period)
            .map_err(attach_err("attach interval"))?;
        Ok(Attachment { guard })
    }

    /// Sleeps until something fires (or `timeout`), then calls `on_wake` once per
    /// fired attachment. The callback must drain the listeners it is told about.
    ///
    /// A wait interrupted by a signal (EINTR) is not a termination request by
    /// itself: iceoryx2 reports every EINTR as `Interrupt`, including the SIGCONT
    /// that resumes a stopped process or a debugger attaching. The waiter then
    /// looks once more without blocking, which reports a pending SIGTERM/SIGINT as
    /// [`WaitOutcome::TerminationRequest`]; after any other signal it goes on
    /// waiting for the rest of `timeout`.
    pub fn wait_once<F: FnMut(Wake)>(
        &self,
        timeout: Duration,
        mut on_wake: F,
    ) -> Result<WaitOutcome> {
        let fired = std::cell::Cell::new(false);
        let mut once = |timeout: Duration| {
            self.ws
                .wait_and_process_once_with_timeout(
                    |id| {
                        fired.set(true);
                        on_wake(Wake(id));
                        CallbackProgression::Continue
                    },
                    timeout,
                )
                .map_err(|e| BusError::WaitSet {
                    op: "wait",
                    reason: reason(e),
                })
        };
        // None: a timeout too long to add to now, i.e. no end
        let until = std::time::Instant::now().checked_add(timeout);
        let left = || match until {
            Some(u) => u.saturating_duration_since(std::time::Instant::now()),
            None => timeout,
        };
        let r = loop {
            let r = once(left())?;
            if r != WaitSetRunResult::Interrupt {
                break r;
            }
            // EINTR: a pending SIGTERM/SIGINT shows now; any other signal goes on waiting
            let r = once(Duration::ZERO)?;
            if r == WaitSetRunResult::TerminationRequest || fired.get() || left().is_zero() {
                break r;
            }
        };
        Ok(match r {
            WaitSetRunResult::TerminationRequest => WaitOutcome::TerminationRequest,
            _ if fired.get() => WaitOutcome::Handled,
            _ => WaitOutcome::Timeout,
        })
    }
}
