//! The loop of every process, one file per role kind. Each wakes on iceoryx2 events
//! only (WaitSet), no busy polling; deadlines are timed waits.
//!
//! * [`scheduler`] — rate groups, lock-step or real time, the end of the run, liveness;
//! * [`simulator`] — the plant: applies the (re-validated) safe commands, publishes states;
//! * [`nominal`] — a nominal controller ([`Subsystem`]), replaceable by a partner's process;
//! * [`filter`] — a safety filter ([`Subsystem`]).
//!
//! The recorder's loop is [`crate::recorder`].

mod filter;
mod nominal;
mod scheduler;
mod simulator;

pub use filter::filter;
pub use nominal::nominal;
pub use scheduler::{SchedulerReport, scheduler};
pub use simulator::simulator;

use sc_bus::Subscriber;
use sc_icd::{Tick, monotonic_ns, tick_command};
use std::time::{Duration, Instant};

pub use sc_core::Subsystem;

pub(crate) fn now() -> u64 {
    monotonic_ns()
}

/// Drains a subscriber's events and returns its queued samples.
pub(crate) fn drain<T: core::fmt::Debug + sc_bus::ZeroCopySend + Copy + 'static>(
    s: &Subscriber<T>,
) -> anyhow::Result<Vec<T>> {
    s.drain_events()?;
    let mut v = Vec::new();
    s.receive_all(&mut v)?;
    Ok(v)
}

/// Drains an optional subscriber (a role's input that this process may not have)
/// and returns its newest sample, if any came.
pub(crate) fn newest<T: core::fmt::Debug + sc_bus::ZeroCopySend + Copy + 'static>(
    s: Option<&Subscriber<T>>,
) -> anyhow::Result<Option<T>> {
    Ok(match s {
        Some(s) => drain(s)?.pop(),
        None => None,
    })
}

/// Drains an optional subscriber (a role's input that this process may not have).
pub(crate) fn drain_opt<T: core::fmt::Debug + sc_bus::ZeroCopySend + Copy + 'static>(
    s: Option<&Subscriber<T>>,
) -> anyhow::Result<Vec<T>> {
    s.map_or_else(|| Ok(Vec::new()), drain)
}

/// Keeps, of a partner's nominal commands `got` (drained before the states, so every
/// state a command was computed from is known: `known` is the newest state's tick),
/// the one to use in `held`:
/// * a command labelled for a tick whose state did not exist yet is a lie and dropped
///   (a partner answering "the next tick" early would otherwise have its stale command
///   used for that tick);
/// * a command for the awaited tick `want` is never replaced by one for another tick (a
///   partner bursting commands with other ticks cannot hide the one the filter waits
///   for); among several for the same tick the newest wins.
///
/// Returns whether a command for the awaited tick or the one before it came: only that
/// brings an absent partner back (a late partner answers the tick before; one that
/// answers for older ticks would otherwise cost every tick a full deadline).
pub(crate) fn keep_for_tick<T>(
    got: Vec<T>,
    held: &mut Option<T>,
    want: Option<u64>,
    known: Option<u64>,
    tick: impl Fn(&T) -> u64,
) -> bool {
    let mut came = false;
    // a partner's tick is any u64: compared, never computed with
    for m in got.into_iter().filter(|m| Some(tick(m)) <= known) {
        let holds_wanted = held.as_ref().is_some_and(|h| Some(tick(h)) == want);
        let wanted = Some(tick(&m)) == want;
        came |= wanted || Some(tick(&m)) == want.and_then(|w| w.checked_sub(1));
        if wanted || !holds_wanted {
            *held = Some(m);
        }
    }
    came
}

/// The `Instant` of a monotonic time stamp `ns` of another process (same clock).
pub(crate) fn instant_of(ns: u64) -> Instant {
    let t = Instant::now();
    if ns == 0 {
        return t; // no stamp: count from now
    }
    let ago = Duration::from_nanos(now().saturating_sub(ns));
    t.checked_sub(ago).unwrap_or(t)
}

pub(crate) fn stop_seen(ticks: &[Tick]) -> bool {
    ticks.iter().any(|t| t.command == tick_command::STOP)
}

#[cfg(test)]
mod tests {
    use super::keep_for_tick;

    #[test]
    fn the_awaited_command_is_kept_and_lies_about_ticks_are_dropped() {
        let id = |t: &u64| *t;
        // a burst around the awaited tick 10: the one for 10 is kept
        let mut held = None;
        assert!(keep_for_tick(
            vec![9, 10, 7, 8],
            &mut held,
            Some(10),
            Some(10),
            id
        ));
        assert_eq!(held, Some(10));
        // labelled for a state that does not exist yet (11, u64::MAX): dropped
        let mut held = None;
        assert!(!keep_for_tick(
            vec![11, u64::MAX],
            &mut held,
            Some(10),
            Some(10),
            id
        ));
        assert_eq!(held, None);
        // old ticks are held (the newest) but do not bring an absent partner back...
        let mut held = None;
        assert!(!keep_for_tick(
            vec![3, 0],
            &mut held,
            Some(10),
            Some(10),
            id
        ));
        assert_eq!(held, Some(0));
        // ...a late answer for the tick before does
        assert!(keep_for_tick(vec![9], &mut held, Some(10), Some(10), id));
        // no state yet: nothing is plausible
        let mut held = None;
        assert!(!keep_for_tick(vec![0], &mut held, Some(0), None, id));
        assert_eq!(held, None);
    }
}
