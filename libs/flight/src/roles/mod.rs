//! The roles of the partition as components (`crate::component::Component`): each
//! file one role's decisions, driven by the one runner (`crate::runner`).
//!
//! * [`scheduler`] — rate groups, lock-step or real time, the end of the run, liveness;
//! * [`simulator`] — the plant: measures, admits the estimate, publishes the knowledge,
//!   applies the (re-validated) safe commands;
//! * [`navigation`] — the estimate from the measurements, replaceable by a partner's process;
//! * [`nominal`] — a nominal controller, replaceable by a partner's process;
//! * [`filter`] — a safety filter.
//!
//! The recorder is a ground tool: `sc_ground::recorder`.

pub mod filter;
pub mod navigation;
pub mod nominal;
pub mod scheduler;
pub mod simulator;

pub use filter::FilterRole;
pub use navigation::NavigationRole;
pub use nominal::NominalRole;
pub use scheduler::{SchedulerReport, SchedulerRole};
pub use simulator::SimulatorRole;

/// The log line of a process that saw the stop only when a 1 s wait ran out: the
/// wake-up that should have brought it was lost (the lock-step tests look for it).
pub const LOST_STOP_WAKEUP: &str =
    "the stop was seen only at a 1 s wait timeout (its wake-up was lost)";

/// The deadline [monotonic ns] `after_ns` from a time stamp of another process (the
/// same clock); a missing stamp (0) counts from `now_ns`.
pub fn deadline_from(stamp_ns: u64, now_ns: u64, after_ns: u64) -> u64 {
    let from = if stamp_ns == 0 { now_ns } else { stamp_ns };
    from.saturating_add(after_ns)
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
pub fn keep_for_tick<T>(
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

#[cfg(test)]
mod tests {
    use super::keep_for_tick;
    use super::testing::{controllers, setup};
    use super::*;
    use crate::component::Component;
    use sc_icd::services::{HANDSHAKE, ServiceName};
    use sc_icd::{ROLES, Role, RoleKind, Subsystem};

    /// The component of every flight role (the recorder's test is sc-ground's).
    fn components() -> Vec<(RoleKind, Box<dyn Component>)> {
        let su = setup();
        let layer = || sc_cbf::SafetyLayer::from_scenario(&su.scenario, su.robot.clone());
        let sim = sc_sim::Simulator::new(&su.scenario, su.robot.clone()).unwrap();
        let schedule = crate::config::Schedule {
            base_period_s: 0.1,
            period_s: sc_core::PerSubsystem([0.1; 3]),
            ratio: sc_core::PerSubsystem([1; 3]),
        };
        let timing = scheduler::Timing {
            schedule,
            real_time: false,
            period_ns: 1,
            warmup_lead_ns: None,
            stage_deadline_ns: [1; 3],
            step_timeout_ns: 1,
            recorder_window: 1,
            max_ticks: 0,
        };
        let mut v: Vec<(RoleKind, Box<dyn Component>)> = vec![
            (
                RoleKind::Scheduler,
                Box::new(SchedulerRole::new(timing, "LockStep")),
            ),
            (
                RoleKind::Simulator,
                Box::new(
                    SimulatorRole::new(sim, None, su.scenario.clone(), su.robot.clone(), 1, false)
                        .unwrap(),
                ),
            ),
            (
                RoleKind::Navigation,
                Box::new(NavigationRole::new(Box::new(
                    sc_sim::navigation::PassThrough,
                ))),
            ),
        ];
        for s in Subsystem::ALL {
            v.push((
                RoleKind::Nominal(s),
                Box::new(NominalRole::new(s, controllers())),
            ));
            v.push((
                RoleKind::Filter(s),
                Box::new(FilterRole::new(s, layer(), su.scenario.clone(), 1)),
            ));
        }
        v
    }

    fn sorted(v: impl IntoIterator<Item = ServiceName>) -> Vec<&'static str> {
        let mut v: Vec<&str> = v.into_iter().map(|s| s.as_str()).collect();
        v.sort();
        v
    }

    /// What a component reads and wakes on is what the role table says it subscribes
    /// to: the table is the one list, and a component cannot drift from it.
    #[test]
    fn every_flight_role_reads_exactly_its_table_row() {
        let comps = components();
        let flight: Vec<&Role> = ROLES.iter().filter(|r| r.flight).collect();
        assert_eq!(
            comps.len(),
            flight.len(),
            "a flight role without a component"
        );
        for (kind, c) in &comps {
            let role = Role::of(*kind);
            let table = role.subscribes.iter().copied().filter(|s| *s != HANDSHAKE);
            assert_eq!(
                sorted(c.inputs().iter().copied()),
                sorted(table),
                "{}",
                role.name
            );
            for set in c.wake_sets() {
                for s in set.on {
                    assert!(
                        c.inputs().contains(s),
                        "{}: wakes on {s} it does not read",
                        role.name
                    );
                }
            }
            for s in c.warm() {
                assert!(
                    role.publishes.contains(s),
                    "{}: warms {s} it does not publish",
                    role.name
                );
            }
        }
    }

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

/// Made-up inputs for the roles' unit tests.
#[cfg(test)]
pub(crate) mod testing {
    use crate::component::{Wakeup, Woke};
    use sc_icd::SimState;
    use std::path::Path;
    use std::sync::Arc;

    fn repo() -> &'static Path {
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
    }

    /// The default scenario and servicer model.
    pub fn setup() -> sc_mission::Setup {
        sc_mission::Setup::load(&repo().join("config/scenario.toml")).unwrap()
    }

    /// The reference nominal controllers of the default scenario.
    pub fn controllers() -> sc_nominal::NominalControllers {
        let s = setup();
        sc_nominal::NominalControllers::new(&s.scenario, (*s.robot).clone()).unwrap()
    }

    /// The simulator's first state of the default mission, as tick `tick` with `due`.
    pub fn state(tick: u64, due: u32) -> SimState {
        let s = setup();
        let sim = sc_sim::Simulator::new(&s.scenario, Arc::clone(&s.robot)).unwrap();
        let mut m = crate::convert::sim_state(&sim.observe());
        m.tick = tick;
        m.due_mask = due;
        m
    }

    /// A wake-up at `now_ns` without signals.
    pub fn wakeup(now_ns: u64, why: Woke) -> Wakeup {
        Wakeup {
            now_ns,
            why,
            stage_deadline: 0,
            prepare: 0,
        }
    }
}
