//! A nominal controller (the reference controllers of `sc_nominal`); a partner replaces
//! it with its own process (docs/PARTNER.md).
//!
//! Wakes on the states only (the nominal controllers' newest-wins copy, so a slow
//! controller never holds the simulator up); answers every state of its rate group with
//! its command for that tick; reads the control service at every wake-up for the stop
//! (the simulator wakes its consumers once when it stops).

use super::LOST_STOP_WAKEUP;
use crate::component::{Component, Env, Finish, Message, Next, Outbox, WakeSet, Wakeup, Woke};
use crate::convert;
use crate::error::FlightError;
use crate::process::Proc;
use sc_core::{Subsystem, SubsystemSet};
use sc_icd::services::{self, ServiceName};
use sc_icd::{
    NominalAttitude, NominalRobotic, NominalTranslational, Role, RoleKind, SimState, tick_command,
};
use sc_mission::stages;
use sc_nominal::{NominalControllers, NominalOutput, SubsystemStatus};

/// One nominal controller.
pub struct NominalRole {
    subsystem: Subsystem,
    name: &'static str,
    controllers: NominalControllers,
    last_state: Option<SimState>,
    handled: u64,
    stop: bool,
}

const WAKE: &[WakeSet] = &[WakeSet {
    on: &[services::PARTNER_STATE, services::PREPARE],
    lazy: false,
}];

impl NominalRole {
    /// The controller of `subsystem` with the reference controllers of `controllers`.
    pub fn new(subsystem: Subsystem, controllers: NominalControllers) -> Self {
        Self {
            subsystem,
            name: Role::of(RoleKind::Nominal(subsystem)).name,
            controllers,
            last_state: None,
            handled: 0,
            stop: false,
        }
    }

    /// From the process's config: the controllers step at the subsystem's rate group's
    /// period (their MPC's step).
    pub fn from_process(subsystem: Subsystem, p: &Proc) -> Result<Self, FlightError> {
        let scenario = p.scenario_with_period(p.schedule.period_s[subsystem]);
        let controllers = NominalControllers::new(&scenario, (*p.setup.robot).clone())?;
        Ok(Self::new(subsystem, controllers))
    }

    /// This controller's command for state `s`.
    fn command(&self, s: &SimState) -> NominalOutput {
        let o = convert::observation(s);
        self.controllers.command_subsystems(
            &stages::nominal_input(&o),
            SubsystemSet::only(self.subsystem),
        )
    }

    /// The command message for state `s` received at `recv_ns`.
    fn message(&self, s: &SimState, recv_ns: u64) -> Message {
        let out = self.command(s);
        let status = match self.subsystem {
            Subsystem::Translational => out.translational,
            Subsystem::Attitude => out.attitude,
            Subsystem::Robotic => out.robotic,
        };
        let (tick, t, phase) = (s.tick, s.t, out.phase as u32);
        let valid = u32::from(status != SubsystemStatus::InvalidInput);
        match self.subsystem {
            Subsystem::Translational => Message::NominalTranslational(NominalTranslational {
                tick,
                t,
                valid,
                phase,
                recv_ns,
                publish_ns: 0,
                f_h: convert::arr3(&out.f_h),
            }),
            Subsystem::Attitude => Message::NominalAttitude(NominalAttitude {
                tick,
                t,
                valid,
                phase,
                recv_ns,
                publish_ns: 0,
                tau_b: convert::arr3(&out.tau_b),
            }),
            Subsystem::Robotic => Message::NominalRobotic(NominalRobotic {
                tick,
                t,
                valid,
                phase,
                recv_ns,
                publish_ns: 0,
                tau_m: convert::arr7(&out.tau_m),
            }),
        }
    }

    /// The service it publishes on.
    fn output(&self) -> &'static [ServiceName] {
        match self.subsystem {
            Subsystem::Translational => &[services::NOMINAL_TRANSLATIONAL],
            Subsystem::Attitude => &[services::NOMINAL_ATTITUDE],
            Subsystem::Robotic => &[services::NOMINAL_ROBOTIC],
        }
    }
}

impl Component for NominalRole {
    fn wake_sets(&self) -> &'static [WakeSet] {
        WAKE
    }

    fn inputs(&self) -> &'static [ServiceName] {
        &[
            services::PREPARE,
            services::PARTNER_STATE,
            services::CONTROL,
        ]
    }

    fn warm(&self) -> &'static [ServiceName] {
        self.output()
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
        out.rehearse = w.prepare > 0 && self.last_state.is_some();
        for m in inputs {
            match m {
                Message::PartnerState(s) if s.due_mask & self.subsystem.bit() != 0 => {
                    self.last_state = Some(*s);
                    out.send(self.message(s, w.now_ns));
                    self.handled += 1;
                }
                Message::Control(t) if t.command == tick_command::STOP => self.stop = true,
                _ => {}
            }
        }
        if self.stop {
            if w.why == Woke::Timeout {
                out.log(format!("{}: {LOST_STOP_WAKEUP}", self.name));
            }
            // wake the filter once so that it sees the stop too
            out.notify.extend_from_slice(self.output());
        }
    }

    fn rehearse(&mut self) {
        if let Some(s) = self.last_state {
            std::hint::black_box(self.command(&s));
        }
    }

    fn finish(&mut self, _: Finish, _: &[(ServiceName, u64)], out: &mut Outbox) -> i32 {
        out.log(format!("{}: handled {} states", self.name, self.handled));
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::component::NoPeers;
    use crate::roles::testing::{controllers, state, wakeup};

    fn role(s: Subsystem) -> NominalRole {
        NominalRole::new(s, controllers())
    }

    #[test]
    fn answers_each_state_of_its_rate_group_for_its_tick() {
        let mut r = role(Subsystem::Attitude);
        let mut out = Outbox::default();
        let due = state(7, Subsystem::Attitude.bit());
        let not_due = state(8, Subsystem::Robotic.bit());
        r.handle(
            &wakeup(100, Woke::Event),
            &[Message::PartnerState(due), Message::PartnerState(not_due)],
            &mut NoPeers,
            &mut out,
        );
        assert_eq!(out.send.len(), 1, "only the state of its rate group");
        let Message::NominalAttitude(m) = out.send[0] else {
            panic!("{:?}", out.send[0])
        };
        assert_eq!((m.tick, m.recv_ns, m.valid), (7, 100, 1));
        assert_eq!(
            r.next(0),
            Next::Wait {
                set: 0,
                until_ns: None
            }
        );
    }

    #[test]
    fn a_state_it_cannot_use_gives_an_invalid_command() {
        let mut r = role(Subsystem::Translational);
        let mut bad = state(3, SubsystemSet::ALL.bits());
        bad.q_hr = [f64::NAN; 4];
        let mut out = Outbox::default();
        r.handle(
            &wakeup(1, Woke::Event),
            &[Message::PartnerState(bad)],
            &mut NoPeers,
            &mut out,
        );
        let Message::NominalTranslational(m) = out.send[0] else {
            panic!()
        };
        assert_eq!(m.valid, 0, "flagged invalid, never a silent command");
    }

    #[test]
    fn the_stop_wakes_its_filter_and_ends_the_role() {
        let mut r = role(Subsystem::Robotic);
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
        assert_eq!(out.notify, vec![services::NOMINAL_ROBOTIC]);
        assert!(out.log[0].contains(LOST_STOP_WAKEUP), "{:?}", out.log);
        assert_eq!(r.next(0), Next::Exit);
        let mut fin = Outbox::default();
        assert_eq!(r.finish(Finish::Done, &[], &mut fin), 0);
        assert_eq!(fin.log, vec!["nominal_robotic: handled 0 states"]);
    }
}
