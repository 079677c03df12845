//! The navigation: the estimate of each tick's state from the simulator's measurement
//! (`sc_sim::navigation`: the declared error model, or the measurement itself for the
//! `exact` profile); a partner replaces it with its own estimator process
//! (docs/PARTNER.md). The simulator admits every estimate before anything uses it.
//!
//! Wakes on the measurements only (a newest-wins service: a slow navigation never holds
//! the simulator up, which substitutes its own navigation at the navigation deadline);
//! answers every measurement with the estimate for its tick; reads the control service
//! at every wake-up for the stop (the simulator wakes it once when it stops).

use super::LOST_STOP_WAKEUP;
use crate::component::{Component, Env, Finish, Message, Next, Outbox, WakeSet, Wakeup, Woke};
use crate::convert;
use crate::error::FlightError;
use crate::process::Proc;
use sc_icd::services::{self, ServiceName};
use sc_icd::{NavState, Role, RoleKind, tick_command};
use sc_sim::Estimator;
use sc_sim::navigation::default_navigation;

/// The navigation role.
pub struct NavigationRole {
    name: &'static str,
    estimator: Box<dyn Estimator + Send>,
    last: Option<NavState>,
    handled: u64,
    stop: bool,
}

const WAKE: &[WakeSet] = &[WakeSet {
    on: &[services::MEASUREMENT, services::PREPARE],
    lazy: false,
}];

impl NavigationRole {
    /// The role estimating with `estimator`.
    pub fn new(estimator: Box<dyn Estimator + Send>) -> Self {
        Self {
            name: Role::of(RoleKind::Navigation).name,
            estimator,
            last: None,
            handled: 0,
            stop: false,
        }
    }

    /// From the process's config: the default navigation of the scenario's declared
    /// uncertainty, drawn from its seed as the simulator and the mission in one process
    /// draw it.
    pub fn from_process(p: &Proc) -> Result<Self, FlightError> {
        let scenario = p.scenario_with_period(p.schedule.base_period_s);
        let realisation = sc_sim::Realisation::declared(&scenario, &p.setup.robot)
            .map_err(|e| FlightError::Simulator(format!("uncertainty: {e}")))?;
        Ok(Self::new(default_navigation(realisation.as_ref())))
    }

    /// The estimate message answering measurement `m`.
    fn estimate(&mut self, m: &NavState) -> NavState {
        convert::nav_state(&self.estimator.estimate(&convert::nav_sample(m)))
    }
}

impl Component for NavigationRole {
    fn wake_sets(&self) -> &'static [WakeSet] {
        WAKE
    }

    fn inputs(&self) -> &'static [ServiceName] {
        &[services::PREPARE, services::MEASUREMENT, services::CONTROL]
    }

    fn warm(&self) -> &'static [ServiceName] {
        &[services::ESTIMATE]
    }

    fn next(&mut self, _: u64) -> Next {
        if self.stop {
            return Next::Exit;
        }
        Next::Wait {
            set: 0,
            until_ns: None,
        }
    }

    fn handle(&mut self, w: &Wakeup, inputs: &[Message], _: &mut dyn Env, out: &mut Outbox) {
        out.rehearse = w.prepare > 0 && self.last.is_some();
        for m in inputs {
            match m {
                Message::Measurement(m) => {
                    self.last = Some(*m);
                    let e = self.estimate(m);
                    out.send(Message::Estimate(e));
                    self.handled += 1;
                }
                Message::Control(t) if t.command == tick_command::STOP => self.stop = true,
                _ => {}
            }
        }
        if self.stop && w.why == Woke::Timeout {
            out.log(format!("{}: {LOST_STOP_WAKEUP}", self.name));
        }
    }

    /// The conversions of the last measurement (the estimator is not run: it may draw
    /// noise, and a rehearsal must not change the run).
    fn rehearse(&mut self) {
        if let Some(m) = self.last {
            std::hint::black_box(convert::nav_state(&convert::nav_sample(&m)));
        }
    }

    fn finish(&mut self, _: Finish, _: &[(ServiceName, u64)], out: &mut Outbox) -> i32 {
        out.log(format!(
            "{}: handled {} measurements",
            self.name, self.handled
        ));
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::component::NoPeers;
    use crate::roles::testing::{setup, wakeup};
    use sc_sim::navigation::PassThrough;
    use sc_sim::{NavigationGate, Simulator};

    /// The measurement of the default mission's first tick.
    fn measurement(tick: u64) -> NavState {
        let su = setup();
        let sim = Simulator::new(&su.scenario, su.robot.clone()).unwrap();
        let gate = NavigationGate::new(&su.scenario, su.robot, Box::new(PassThrough)).unwrap();
        convert::nav_state(&gate.measure(&sim, tick))
    }

    #[test]
    fn answers_each_measurement_with_the_estimate_for_its_tick() {
        let mut r = NavigationRole::new(Box::new(PassThrough));
        let (a, b) = (measurement(4), measurement(5));
        let mut out = Outbox::default();
        r.handle(
            &wakeup(100, Woke::Event),
            &[Message::Measurement(a), Message::Measurement(b)],
            &mut NoPeers,
            &mut out,
        );
        let [Message::Estimate(ea), Message::Estimate(eb)] = out.send[..] else {
            panic!("{:?}", out.send)
        };
        // the exact profile's navigation: the measurement, bit for bit
        assert_eq!(
            sc_icd::Message::as_bytes(&ea),
            sc_icd::Message::as_bytes(&a)
        );
        assert_eq!(eb.tick, 5);
        assert_eq!(
            r.next(0),
            Next::Wait {
                set: 0,
                until_ns: None
            }
        );
    }

    #[test]
    fn the_stop_ends_the_role() {
        let mut r = NavigationRole::new(Box::new(PassThrough));
        let stop = sc_icd::Tick {
            command: tick_command::STOP,
            ..Default::default()
        };
        let mut out = Outbox::default();
        r.handle(
            &wakeup(1, Woke::Timeout),
            &[Message::Control(stop)],
            &mut NoPeers,
            &mut out,
        );
        assert!(out.log[0].contains(LOST_STOP_WAKEUP), "{:?}", out.log);
        assert_eq!(r.next(0), Next::Exit);
        let mut fin = Outbox::default();
        assert_eq!(r.finish(Finish::Done, &[], &mut fin), 0);
        assert_eq!(fin.log, vec!["navigation: handled 0 measurements"]);
    }
}
