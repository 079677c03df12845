//! The simulator: the plant in the loop. At each tick it publishes the measurement,
//! waits up to the navigation deadline for the navigation's estimate, admits it
//! (`sc_sim::navigation`: its own navigation substituted, flagged, for one missing or
//! refused) and publishes the knowledge derived from it as the state, waits up to its
//! deadline for the safe commands of the subsystems due, applies them after re-validating them (`crate::admission`) — the filter's backup
//! when one is missing or refused, the held command of a slower rate group — advances
//! the physics and publishes the step result.
//!
//! Wake-ups (docs/PARTITION.md, "Who wakes whom"): between ticks on the tick only;
//! within a tick first on the estimate, then on the robotic safe command, the last of the causal chain (the earlier
//! ones were sent before it). While a filter is absent (dead or late: its command may
//! never come), when the robotic group is not due, or when the robotic command of the
//! tick is here without an earlier one, on every safe command — their listeners are
//! created then, so that in a healthy run the translational and attitude filters wake
//! only their downstream filter.

use crate::admission;
use crate::component::{Component, Env, Finish, Message, Next, Outbox, WakeSet, Wakeup};
use crate::convert::{self, Coupling};
use crate::error::FlightError;
use crate::process::Proc;
use sc_cbf::SafetyLayer;
use sc_cbf::monitor::{Barriers, Monitor, N_ALL, min_into};
use sc_core::{Command, Observation, PerSubsystem, Subsystem, SubsystemSet};
use sc_icd::services::{self, ServiceName};
use sc_icd::{SimState, StepResult, Tick, end, fault, tick_command};
use sc_scenario::Scenario;
use sc_sim::navigation::{PassThrough, substitute_navigation};
use sc_sim::{NavSample, NavigationGate, Plant, Realisation, Rejection, Simulator};
use std::collections::VecDeque;

/// A safe command as the simulator judges it, whatever its subsystem.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Received {
    tick: u64,
    /// It passed the re-validation (finite, within the input bounds).
    admitted: bool,
    /// What it applies: `f_B`, `τ_B` or `τ_M` (the first 3 or 7 components).
    command: [f64; 7],
    /// The upstream commands it was certified against.
    xi: Coupling,
}

impl Received {
    /// The safe command carried by `m` with its subsystem, judged against `limits`.
    fn of(m: &Message, limits: &sc_scenario::Limits) -> Option<(Subsystem, Self)> {
        let pad3 = |a: &[f64; 3]| [a[0], a[1], a[2], 0.0, 0.0, 0.0, 0.0];
        let (s, tick, admitted, command, xi) = match m {
            Message::SafeTranslational(x) => (
                Subsystem::Translational,
                x.tick,
                admission::translational(x, limits),
                pad3(&x.actuated),
                Coupling::of(x),
            ),
            Message::SafeAttitude(x) => (
                Subsystem::Attitude,
                x.tick,
                admission::attitude(x, limits),
                pad3(&x.u),
                Coupling::of(x),
            ),
            Message::SafeRobotic(x) => (
                Subsystem::Robotic,
                x.tick,
                admission::robotic(x, limits),
                x.u,
                Coupling::of(x),
            ),
            _ => return None,
        };
        Some((
            s,
            Self {
                tick,
                admitted,
                command,
                xi,
            },
        ))
    }
}

/// The tick in progress: its state and deadline.
struct InTick {
    tick: Tick,
    /// When the tick was received [monotonic ns].
    recv_ns: u64,
    /// The true state (capture, monitor).
    o: Observation,
    /// What the sensors measured.
    measurement: NavSample,
    /// What the controllers and filters know: the admitted estimate through the declared
    /// model (the truth for the `exact` profile); the backups are computed on it, as the
    /// filters would. `None` while the estimate is awaited.
    known: Option<Observation>,
    /// The estimate was missing or refused and the simulator's own navigation used.
    navigation_rejected: bool,
    barriers: Barriers,
    barriers_between: Barriers,
    /// The navigation deadline while the estimate is awaited, then the safe commands'.
    until_ns: u64,
    /// When the robotic safe command (the tick's last) was delivered [monotonic ns].
    safe_recv_ns: u64,
}

/// The wake sets: between ticks, within a tick, within a tick on every safe command,
/// within a tick awaiting the estimate.
const IDLE: usize = 0;
const ROBOTIC: usize = 1;
const ANY: usize = 2;
const NAVIGATION: usize = 3;
const WAKE: &[WakeSet] = &[
    WakeSet {
        on: &[services::TICK, services::PREPARE],
        lazy: false,
    },
    WakeSet {
        on: &[services::TICK, services::SAFE_ROBOTIC],
        lazy: false,
    },
    WakeSet {
        on: &[
            services::TICK,
            services::SAFE_TRANSLATIONAL,
            services::SAFE_ATTITUDE,
            services::SAFE_ROBOTIC,
        ],
        lazy: true,
    },
    WakeSet {
        on: &[services::TICK, services::ESTIMATE],
        lazy: false,
    },
];

/// The simulator role.
pub struct SimulatorRole {
    /// Propagates the truth (the realisation's plant with a declared uncertainty).
    sim: Simulator,
    plant: Option<Box<dyn Plant + Send>>,
    /// The layer on the declared model (the backups).
    layer: SafetyLayer,
    /// Every barrier on the truth.
    monitor: Monitor,
    /// With a declared `[uncertainty]`: the realisation (plant, actuators, navigation)
    /// and the barriers on knowledge (the declared model on the estimate).
    realisation: Option<(Realisation, Monitor)>,
    /// The sensors and the gate of the navigation's estimates.
    gate: NavigationGate,
    /// The newest estimate received (the awaited tick's, once it came).
    estimate: Option<sc_icd::NavState>,
    /// The navigation missed its deadline and has not answered since: not waited for.
    navigation_absent: bool,
    /// The tick of the last measurement published.
    measured_tick: Option<u64>,
    navigation_rejected: u64,
    navigation_deadline_ns: u64,
    scenario: Scenario,
    deadline_ns: u64,
    /// With `max_ticks` (benchmarks, soak runs) the physics goes on after the mission's
    /// end and the scheduler stops after exactly `max_ticks`.
    keep_going: bool,
    ticks: VecDeque<Tick>,
    got: PerSubsystem<Option<Received>>,
    absent: PerSubsystem<bool>,
    rejected: PerSubsystem<u64>,
    held: Command,
    /// The coupling each held command was certified against (a backup: the upstream
    /// commands it was computed with).
    held_xi: PerSubsystem<Coupling>,
    between: Option<Barriers>,
    pending: Option<InTick>,
    ended: bool,
    stop: bool,
    rehearse: bool,
    misses: u64,
}

impl SimulatorRole {
    /// The role with its simulator (and, optionally, another propagator behind it) on
    /// `scenario` (whose control period is the base period); it waits `deadline_ns` for
    /// the safe commands after it published the state, and as long for the estimate
    /// unless [`Self::with_navigation_deadline`] says otherwise.
    pub fn new(
        sim: Simulator,
        plant: Option<Box<dyn Plant + Send>>,
        scenario: Scenario,
        robot: std::sync::Arc<sc_multibody::Robot>,
        deadline_ns: u64,
        keep_going: bool,
    ) -> Result<Self, FlightError> {
        let gate = NavigationGate::new(&scenario, robot.clone(), Box::new(PassThrough))
            .map_err(|e| FlightError::Simulator(e.to_string()))?;
        Ok(Self {
            sim,
            plant,
            layer: SafetyLayer::from_scenario(&scenario, robot.clone()),
            monitor: Monitor::from_scenario(&scenario, robot),
            realisation: None,
            gate,
            estimate: None,
            navigation_absent: false,
            measured_tick: None,
            navigation_rejected: 0,
            navigation_deadline_ns: deadline_ns,
            scenario,
            deadline_ns,
            keep_going,
            ticks: VecDeque::new(),
            got: PerSubsystem::default(),
            absent: PerSubsystem::default(),
            rejected: PerSubsystem::default(),
            held: Command::zero(),
            held_xi: PerSubsystem::default(),
            between: None,
            pending: None,
            ended: false,
            stop: false,
            rehearse: false,
            misses: 0,
        })
    }

    /// Waits `ns` for the navigation's estimate after the measurement.
    pub fn with_navigation_deadline(mut self, ns: u64) -> Self {
        self.navigation_deadline_ns = ns;
        self
    }

    /// The role propagating the truth of `realisation` (drawn for `scenario`, the
    /// declared one): the simulator and its monitor on the realised plant, the actuators'
    /// errors on every applied command, the navigation's estimate published as the state.
    pub fn with_realisation(mut self, realisation: Realisation) -> Result<Self, FlightError> {
        let robot = std::sync::Arc::new(realisation.true_robot.clone());
        let truth = &realisation.true_scenario;
        self.sim = Simulator::new(truth, robot.clone())
            .map_err(|e| FlightError::Simulator(e.to_string()))?;
        let known = std::mem::replace(&mut self.monitor, Monitor::from_scenario(truth, robot));
        let declared = *self.gate.declared();
        self.gate
            .set_substitute(substitute_navigation(Some(&realisation), &declared));
        self.realisation = Some((realisation, known));
        Ok(self)
    }

    /// From the process's config: the simulator at the base period (on the realised plant
    /// of a declared `[uncertainty]`), the plant process of `[simulator] plant` (started
    /// now, before the handshake), the simulator's deadline.
    pub fn from_process(p: &Proc) -> Result<Self, FlightError> {
        let scenario = p.scenario_with_period(p.schedule.base_period_s);
        let robot = p.setup.robot.clone();
        let realisation = Realisation::declared(&scenario, &robot)
            .map_err(|e| FlightError::Simulator(format!("uncertainty: {e}")))?;
        let sim = Simulator::new(&scenario, robot.clone())
            .map_err(|e| FlightError::Simulator(e.to_string()))?;
        let ns = |ms| p.deadline(ms).as_nanos().min(u128::from(u64::MAX)) as u64;
        let keep_going = p.cfg.max_ticks > 0;
        let deadline = ns(p.cfg.deadlines.simulator_ms);
        let mut role = Self::new(sim, None, scenario, robot.clone(), deadline, keep_going)?
            .with_navigation_deadline(ns(p.cfg.deadlines.navigation_ms));
        // the backups act for their group's hold, as the filters certify them
        role.layer = SafetyLayer::with_holds(&p.setup.scenario, robot, &p.schedule.period_s);
        if let Some(r) = realisation {
            if !p.cfg.simulator.plant.is_empty() {
                // as the preflight: the plant process would propagate the model
                return Err(FlightError::Usage(
                    "a declared [uncertainty] needs the built-in simulator: `[simulator] plant` propagates the declared model only".into(),
                ));
            }
            role = role.with_realisation(r)?;
        }
        role.plant = start_plant(p, &role.sim)?;
        Ok(role)
    }

    /// Takes the inputs of one wake-up (in the role's read order).
    fn absorb(&mut self, w: &Wakeup, inputs: &[Message]) {
        self.rehearse |= w.prepare > 0;
        let in_tick = self.pending.as_ref().map(|p| p.tick.tick);
        for m in inputs {
            if let Message::Tick(t) = m {
                self.ticks.push_back(*t);
            } else if let Message::Estimate(e) = m {
                // an estimate of the last measured tick or the one before brings an absent
                // navigation back, also when that tick is already done
                let known = self.measured_tick;
                let want = in_tick.or(known);
                let came =
                    super::keep_for_tick(vec![*e], &mut self.estimate, want, known, |e| e.tick);
                self.navigation_absent &= !came;
            } else if let Some((s, r)) = Received::of(m, &self.scenario.limits) {
                if in_tick.is_some() || Some(r.tick) == self.measured_tick {
                    // within a tick, or for the tick just finished (a filter that answers
                    // after the simulator stopped waiting for it), a command brings an
                    // absent filter back
                    self.absent[s] = false;
                }
                if s == Subsystem::Robotic && Some(r.tick) == in_tick {
                    // delivered: the simulator holds the tick's last safe command
                    if let Some(p) = self.pending.as_mut() {
                        p.safe_recv_ns = w.now_ns;
                    }
                }
                self.got[s] = Some(r);
            }
        }
    }

    /// The subsystems of tick `t` whose safe command is here, not due, or absent.
    fn complete(&self, t: &Tick) -> bool {
        let due = SubsystemSet::from_bits(t.due_mask);
        Subsystem::ALL.into_iter().all(|s| {
            !due.contains(s) || self.absent[s] || self.got[s].is_some_and(|m| m.tick == t.tick)
        })
    }

    /// Starts tick `t` received at `now_ns`: observes, publishes the truth (with a
    /// declared uncertainty, for the recorder) and the measurement, awaits the estimate
    /// (not while the navigation is absent).
    fn start_tick(&mut self, t: Tick, now_ns: u64, out: &mut Outbox) {
        let o = self.sim.observe();
        let barriers = self.monitor.evaluate(&o.barrier_state());
        let barriers_between = self.between.unwrap_or(barriers);
        if self.realisation.is_some() {
            let mut truth = stamp(convert::sim_state(&o), &t, now_ns);
            truth.held_f_b = convert::arr3(&self.held.force_b);
            truth.held_tau_b = convert::arr3(&self.held.torque_b);
            out.send(Message::Truth(with_barriers(
                truth,
                barriers,
                barriers_between,
            )));
        }
        let measurement = self.gate.measure(&self.sim, t.tick);
        out.send(Message::Measurement(convert::nav_state(&measurement)));
        // nothing received before this measurement answers it (a late estimate of an
        // earlier tick would otherwise be refused as not current at this one's deadline)
        self.estimate = None;
        self.measured_tick = Some(t.tick);
        let wait = if self.navigation_absent {
            0
        } else {
            self.navigation_deadline_ns
        };
        self.pending = Some(InTick {
            tick: t,
            recv_ns: now_ns,
            o,
            measurement,
            known: None,
            navigation_rejected: false,
            barriers,
            barriers_between,
            until_ns: now_ns.saturating_add(wait),
            safe_recv_ns: 0,
        });
    }

    /// Admits the tick's estimate (or substitutes the simulator's own navigation) and
    /// publishes the knowledge: the realised errors (with a declared uncertainty), then
    /// the state, flight side first (a nominal command can then never reach a filter
    /// before the state it answers); the safe commands are awaited until `simulator_ms`
    /// after the tick.
    fn publish_knowledge(&mut self, p: &mut InTick, now_ns: u64, out: &mut Outbox) {
        let k = p.tick.tick;
        let estimate = self.estimate.take().map(|e| convert::nav_sample(&e));
        let came = estimate.is_some_and(|e| e.tick == k);
        let (known, rejected) = self
            .gate
            .admit(estimate.as_ref(), &p.measurement, &self.sim, &p.o);
        if let Some(why) = rejected {
            self.refuse_estimate(k, &why, out);
            p.navigation_rejected = true;
        }
        self.navigation_absent = !came;
        let (b, between) = if known.truth {
            (p.barriers, p.barriers_between)
        } else {
            let m = self.realisation.as_ref().map_or(&self.monitor, |(_, m)| m);
            let kb = m.evaluate(&known.observation.barrier_state());
            (kb, kb)
        };
        if self.realisation.is_some() {
            out.send(Message::NavigationError(convert::navigation_error(
                k,
                p.o.t,
                &known.error,
            )));
        }
        let mut msg = with_barriers(
            stamp(convert::sim_state(&known.observation), &p.tick, p.recv_ns),
            b,
            between,
        );
        // what acts while a group is not due: the downstream filters certify against it
        msg.held_f_b = convert::arr3(&self.held.force_b);
        msg.held_tau_b = convert::arr3(&self.held.torque_b);
        out.send(Message::State(msg));
        out.send(Message::PartnerState(msg));
        // the backups are computed on exactly what the filters read (the published state)
        p.known = Some(convert::observation(&msg));
        // the safe commands' deadline counts from the tick, as before the navigation had a
        // stage of its own: waiting for the estimate does not lengthen the tick
        p.until_ns = p.recv_ns.saturating_add(self.deadline_ns).max(now_ns);
    }

    /// Logs and counts a refused or missing estimate (a missing one once per absence).
    fn refuse_estimate(&mut self, k: u64, why: &Rejection, out: &mut Outbox) {
        self.navigation_rejected += 1;
        if *why != Rejection::Missing || !self.navigation_absent {
            out.log(format!("simulator: FAULT tick {k}: navigation estimate {why}; the simulator's own navigation substituted"));
        }
    }

    /// What acts for subsystem `s` over tick `k` (decided in causal order): the fresh
    /// safe command if it passed the re-validation and was certified against exactly the
    /// upstream commands now acting, and unless the downstream filters certified against
    /// its backup instead (they gave up on it at their earlier deadline); the held one of
    /// a slower group; else the filter's backup, which is flagged, counted and logged.
    fn apply(
        &mut self,
        s: Subsystem,
        o: &Observation,
        k: u64,
        due: SubsystemSet,
        res: &mut StepResult,
        out: &mut Outbox,
    ) {
        if !due.contains(s) {
            if self.certified_against_acting(s, &self.held_xi[s]) {
                res.held_mask |= s.bit();
                return;
            }
            // held, but something else acts upstream: cannot happen with nested rate
            // groups (`config::nested`: an upstream group is due only with its downstream
            // one); should it, the held command does not act uncertified — its backup on
            // what acts now does, said and flagged
            out.log(format!("simulator: FAULT tick {k}: held {s} command certified against other upstream commands than those acting; backup applied"));
            let backup = self.backup(s, o);
            self.hold(s, &backup, self.acting());
            res.fallback_mask |= s.bit();
            res.fault_flags |= fault::COUPLING_MISMATCH;
            return;
        }
        let fresh = self.got[s].filter(|m| m.tick == k);
        let admitted = fresh.filter(|m| m.admitted);
        let certified = admitted.filter(|m| self.certified_against_acting(s, &m.xi));
        let applied = certified.filter(|m| !self.downstream_took_backup(s, o, k, &m.command));
        if let Some(m) = applied {
            self.hold(s, &m.command, m.xi);
            return;
        }
        let backup = self.backup(s, o);
        self.hold(s, &backup, self.acting());
        res.fallback_mask |= s.bit();
        if certified.is_some() {
            out.log(format!("simulator: FAULT tick {k}: {s} safe command came after the downstream filters certified against its backup; backup applied"));
            res.fault_flags |= fault::COUPLING_MISMATCH;
        } else if admitted.is_some() {
            out.log(format!("simulator: FAULT tick {k}: {s} safe command certified against other upstream commands than those applied; backup applied"));
            res.fault_flags |= fault::COUPLING_MISMATCH;
        } else if fresh.is_some() {
            self.rejected[s] += 1;
            out.log(format!("simulator: FAULT tick {k}: {s} safe command rejected (not finite or beyond the input bounds), backup applied"));
            res.fault_flags |= fault::REJECTED_COMMAND;
        } else {
            if !self.absent[s] {
                out.log(format!(
                    "simulator: FAULT tick {k}: {s} safe command missing, fallback applied"
                ));
            }
            self.absent[s] = true;
            res.fault_flags |= fault::DEADLINE_MISS;
        }
    }

    /// Whether a command of `s` certified against `xi` may act with the upstream
    /// commands already decided for this tick (bit for bit: what the filter's certificate
    /// assumed is what acts).
    fn certified_against_acting(&self, s: Subsystem, xi: &Coupling) -> bool {
        let force = || xi.force_b == self.held.force_b;
        match s {
            Subsystem::Translational => true,
            Subsystem::Attitude => force(),
            Subsystem::Robotic => force() && xi.torque_b == self.held.torque_b,
        }
    }

    /// Whether the downstream commands of tick `k` that would act were certified against
    /// the backup of `s` and none against its command `command`: the downstream filters
    /// gave up on `command` at their deadline, so its backup is what they certified.
    fn downstream_took_backup(
        &mut self,
        s: Subsystem,
        o: &Observation,
        k: u64,
        command: &[f64; 7],
    ) -> bool {
        let claims: Vec<nalgebra::Vector3<f64>> = Subsystem::ALL
            .into_iter()
            .filter(|d| *d > s)
            .filter_map(|d| self.got[d].filter(|m| m.tick == k && m.admitted))
            .filter_map(|m| match s {
                Subsystem::Translational => Some(m.xi.force_b),
                Subsystem::Attitude => Some(m.xi.torque_b),
                Subsystem::Robotic => None,
            })
            .collect();
        let v3 = |c: &[f64; 7]| nalgebra::Vector3::new(c[0], c[1], c[2]);
        if claims.is_empty() || claims.contains(&v3(command)) {
            return false;
        }
        let backup = v3(&self.backup(s, o));
        claims.contains(&backup)
    }

    /// The backup of subsystem `s` with what acts upstream (the causal chain's backups).
    fn backup(&mut self, s: Subsystem, o: &Observation) -> [f64; 7] {
        let pad3 = |v: nalgebra::Vector3<f64>| [v.x, v.y, v.z, 0.0, 0.0, 0.0, 0.0];
        match s {
            Subsystem::Translational => pad3(self.layer.backup_translational(o).actuated),
            Subsystem::Attitude => pad3(self.layer.backup_attitude(o, &self.held.force_b).u),
            Subsystem::Robotic => convert::arr7(
                &self
                    .layer
                    .backup_robotic(o, &self.held.force_b, &self.held.torque_b)
                    .u,
            ),
        }
    }

    /// The upstream commands acting now (for a backup computed on them).
    fn acting(&self) -> Coupling {
        Coupling {
            force_b: self.held.force_b,
            torque_b: self.held.torque_b,
        }
    }

    /// Holds `command`, certified against `xi`, for subsystem `s` until it is due again.
    fn hold(&mut self, s: Subsystem, command: &[f64; 7], xi: Coupling) {
        self.held_xi[s] = xi;
        let v3 = nalgebra::Vector3::new(command[0], command[1], command[2]);
        match s {
            Subsystem::Translational => self.held.force_b = v3,
            Subsystem::Attitude => self.held.torque_b = v3,
            Subsystem::Robotic => self.held.tau = convert::vec7(command),
        }
    }

    /// Ends the tick in progress: applies the commands, decides the mission's end,
    /// advances the physics (the barriers monitored at every physics step) and
    /// publishes the step result.
    fn finish_tick(&mut self, p: InTick, known: Observation, out: &mut Outbox) {
        let (k, o) = (p.tick.tick, p.o);
        let due = SubsystemSet::from_bits(p.tick.due_mask);
        let mut res = StepResult {
            tick: k,
            t: o.t,
            safe_recv_ns: p.safe_recv_ns,
            ..Default::default()
        };
        if p.navigation_rejected {
            res.fault_flags |= fault::NAVIGATION_REJECTED;
        }
        for s in Subsystem::ALL {
            self.apply(s, &known, k, due, &mut res, out);
        }
        convert::set_applied(&mut res, &self.held);
        // the phase is the mission's own schedule, never a partner's report
        let phase = self.scenario.phase_index(o.t);
        let captured = sc_mission::capture_check(&self.scenario, phase, &o)
            && sc_mission::all_hold(&p.barriers)
            && sc_mission::all_hold(&p.barriers_between);
        res.end = if captured {
            end::CAPTURED
        } else if sc_mission::timeout_check(&self.scenario, o.t) {
            end::TIMEOUT
        } else {
            end::RUNNING
        };
        if res.end == end::RUNNING || self.keep_going {
            self.advance(&mut res, out);
        }
        self.ended =
            res.end == end::SIMULATOR_FAILED || (res.end != end::RUNNING && !self.keep_going);
        out.send(Message::StepResult(res));
    }

    /// One control period of physics under the held command, with the barrier minima
    /// over its physics steps.
    fn advance(&mut self, res: &mut StepResult, out: &mut Outbox) {
        let mut min: Barriers = [f64::INFINITY; N_ALL];
        let monitor = &self.monitor;
        let at_physics_step = |b: &sc_sim::BarrierState| min_into(&mut min, &monitor.evaluate(b));
        // what the actuators deliver of the applied command
        let delivered = match self.realisation.as_mut() {
            Some((r, _)) => r.actuators.deliver(&self.held),
            None => self.held,
        };
        let stepped = match self.plant.as_mut() {
            Some(pl) => self
                .sim
                .step_with_plant(pl.as_mut(), &delivered, at_physics_step),
            None => self.sim.step_with(&delivered, at_physics_step),
        };
        self.between = Some(min);
        if let Err(e) = stepped {
            out.log(format!("simulator: {e}"));
            res.end = end::SIMULATOR_FAILED;
        }
    }

    /// Works through the queued ticks until one awaits its commands.
    fn process(&mut self, now_ns: u64, out: &mut Outbox) {
        loop {
            if let Some(mut p) = self.pending.take() {
                let known = match p.known {
                    Some(known) => known,
                    None => {
                        let here = self.estimate.is_some_and(|e| e.tick == p.tick.tick);
                        if !here && now_ns < p.until_ns {
                            self.pending = Some(p);
                            return;
                        }
                        self.publish_knowledge(&mut p, now_ns, out);
                        self.pending = Some(p);
                        continue;
                    }
                };
                let complete = self.complete(&p.tick);
                if !complete && now_ns < p.until_ns {
                    self.pending = Some(p);
                    return;
                }
                if !complete {
                    self.misses += 1;
                }
                self.finish_tick(p, known, out);
                continue;
            }
            let Some(t) = self.ticks.pop_front() else {
                return;
            };
            if t.command == tick_command::STOP {
                // wake the consumers once so that they see the stop too
                out.notify.extend_from_slice(&[
                    services::MEASUREMENT,
                    services::PARTNER_STATE,
                    services::SIM_STATE,
                    services::STEP_RESULT,
                ]);
                self.stop = true;
                return;
            }
            if !self.ended {
                self.start_tick(t, now_ns, out);
            }
        }
    }
}

/// `msg` stamped as the state of tick `t` received at `recv_ns`.
fn stamp(mut msg: SimState, t: &Tick, recv_ns: u64) -> SimState {
    msg.tick = t.tick;
    msg.due_mask = t.due_mask;
    msg.tick_send_ns = t.send_ns;
    msg.recv_ns = recv_ns;
    msg
}

/// `msg` with the barriers `b` and their minima since the last state `between`.
fn with_barriers(mut msg: SimState, b: Barriers, between: Barriers) -> SimState {
    msg.barriers = b;
    msg.barriers_between = between;
    msg
}

/// Starts the plant process of `[simulator] plant`, if any, at the simulator's state.
fn start_plant(p: &Proc, sim: &Simulator) -> Result<Option<Box<dyn Plant + Send>>, FlightError> {
    let Some((program, args)) = p.cfg.simulator.plant.split_first() else {
        return Ok(None);
    };
    if sim.world_event_pending() {
        return Err(FlightError::Simulator(
            "the scenario's [world] event needs the simulator's own propagation: an external plant ([simulator] plant) cannot apply it".into(),
        ));
    }
    let mut args = args.to_vec();
    args.push("--scenario".into());
    args.push(p.cfg.scenario_path().display().to_string());
    let fail = |e: sc_sim::PlantError| FlightError::Simulator(e.0);
    let mut child =
        sc_sim::ProcessPlant::spawn(std::path::Path::new(program), &args).map_err(fail)?;
    child.start(sim.state()).map_err(fail)?;
    eprintln!(
        "simulator: the plant `{}` propagates",
        p.cfg.simulator.plant.join(" ")
    );
    Ok(Some(Box::new(child)))
}

impl Component for SimulatorRole {
    fn wake_sets(&self) -> &'static [WakeSet] {
        WAKE
    }

    fn inputs(&self) -> &'static [ServiceName] {
        // reverse causal order: a command published while the queues are read is never
        // seen without the earlier commands of its tick, which do not wake the simulator
        &[
            services::PREPARE,
            services::TICK,
            services::ESTIMATE,
            services::SAFE_ROBOTIC,
            services::SAFE_ATTITUDE,
            services::SAFE_TRANSLATIONAL,
        ]
    }

    fn warm(&self) -> &'static [ServiceName] {
        &[
            services::MEASUREMENT,
            services::PARTNER_STATE,
            services::SIM_STATE,
            services::TRUTH,
            services::NAVIGATION_ERROR,
        ]
    }

    fn next(&mut self, _: u64) -> Next {
        if self.stop {
            return Next::Exit;
        }
        let Some(p) = &self.pending else {
            return Next::Wait {
                set: IDLE,
                until_ns: None,
            };
        };
        if p.known.is_none() {
            return Next::Wait {
                set: NAVIGATION,
                until_ns: Some(p.until_ns),
            };
        }
        let due = SubsystemSet::from_bits(p.tick.due_mask);
        let robotic_here = self.got[Subsystem::Robotic].is_some_and(|m| m.tick == p.tick.tick);
        let any =
            self.absent.0.iter().any(|a| *a) || !due.contains(Subsystem::Robotic) || robotic_here;
        Next::Wait {
            set: if any { ANY } else { ROBOTIC },
            until_ns: Some(p.until_ns),
        }
    }

    fn handle(&mut self, w: &Wakeup, inputs: &[Message], _: &mut dyn Env, out: &mut Outbox) {
        let idle = self.pending.is_none();
        self.absorb(w, inputs);
        if idle {
            // the pre-tick warm-up: only between ticks
            out.rehearse = std::mem::take(&mut self.rehearse);
        }
        self.process(w.now_ns, out);
    }

    /// The start of a tick on the current state; nothing is sent.
    fn rehearse(&mut self) {
        std::hint::black_box(convert::sim_state(&self.sim.observe()));
    }

    fn finish(&mut self, why: Finish, impostors: &[(ServiceName, u64)], out: &mut Outbox) -> i32 {
        if why == Finish::Terminated && self.pending.is_some() {
            return 0;
        }
        let dropped = |svc| {
            impostors
                .iter()
                .find(|(s, _)| *s == svc)
                .map_or(0, |(_, n)| *n)
        };
        let impostors = [
            dropped(services::SAFE_TRANSLATIONAL),
            dropped(services::SAFE_ATTITUDE),
            dropped(services::SAFE_ROBOTIC),
        ];
        out.log(format!(
            "simulator: done at step {}, {} deadline misses, safe commands rejected (translational, attitude, robotic) {:?}, navigation estimates missing or rejected {}, samples from a second publisher dropped {impostors:?}",
            self.sim.step_count(),
            self.misses,
            self.rejected.0,
            self.navigation_rejected
        ));
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::component::{NoPeers, Woke};
    use crate::roles::testing::{setup, wakeup};
    use sc_icd::{SafeAttitude, SafeRobotic, SafeTranslational};

    const DEADLINE_NS: u64 = 90_000_000;
    /// The navigation's deadline of the realistic role (the configs' 10 ms).
    const NAV_NS: u64 = 10_000_000;

    fn role() -> SimulatorRole {
        let su = setup();
        let sim = Simulator::new(&su.scenario, su.robot.clone()).unwrap();
        SimulatorRole::new(sim, None, su.scenario, su.robot, DEADLINE_NS, false).unwrap()
    }

    fn tick(k: u64, due: SubsystemSet) -> Message {
        Message::Tick(Tick {
            tick: k,
            due_mask: due.bits(),
            ..Default::default()
        })
    }

    fn safe(k: u64) -> [Message; 3] {
        [
            Message::SafeRobotic(SafeRobotic {
                tick: k,
                ..Default::default()
            }),
            Message::SafeAttitude(SafeAttitude {
                tick: k,
                ..Default::default()
            }),
            Message::SafeTranslational(SafeTranslational {
                tick: k,
                ..Default::default()
            }),
        ]
    }

    fn handle(r: &mut SimulatorRole, now: u64, why: Woke, inputs: &[Message]) -> Outbox {
        let mut out = Outbox::default();
        r.handle(&wakeup(now, why), inputs, &mut NoPeers, &mut out);
        out
    }

    /// The tick's measurement in `out`, answered as the `exact` navigation would.
    fn estimate_of(out: &Outbox) -> Message {
        match out.send.iter().find_map(|m| match m {
            Message::Measurement(x) => Some(*x),
            _ => None,
        }) {
            Some(m) => Message::Estimate(m),
            None => panic!("no measurement in {:?}", out.send),
        }
    }

    /// Tick `k` started and its estimate answered: the outbox of the estimate's wake-up.
    fn start(r: &mut SimulatorRole, now: u64, k: u64, due: SubsystemSet) -> Outbox {
        let out = handle(r, now, Woke::Event, &[tick(k, due)]);
        handle(r, now, Woke::Event, &[estimate_of(&out)])
    }

    fn result(out: &Outbox) -> StepResult {
        match out.send.iter().find_map(|m| match m {
            Message::StepResult(r) => Some(*r),
            _ => None,
        }) {
            Some(r) => r,
            None => panic!("no step result in {:?}", out.send),
        }
    }

    /// The role on a realisation of the `realistic` profile (seed 3).
    fn realistic_role() -> (SimulatorRole, Realisation) {
        let mut su = setup();
        let spec = sc_scenario::UncertaintySpec {
            profile: "realistic".into(),
            seed: 3,
            model: None,
            actuators: None,
            navigation: None,
            truth: None,
        };
        su.scenario.set_uncertainty(spec).unwrap();
        let real = Realisation::declared(&su.scenario, &su.robot)
            .unwrap()
            .expect("a declared profile");
        let sim = Simulator::new(&su.scenario, su.robot.clone()).unwrap();
        let role = SimulatorRole::new(sim, None, su.scenario, su.robot, DEADLINE_NS, false)
            .unwrap()
            .with_navigation_deadline(NAV_NS)
            .with_realisation(real.clone())
            .unwrap();
        (role, real)
    }

    /// The estimate of the measurement in `out` by the declared navigation `nav`.
    fn declared_estimate(nav: &mut dyn sc_sim::Estimator, out: &Outbox) -> Message {
        let Message::Estimate(m) = estimate_of(out) else {
            unreachable!()
        };
        let e = nav.estimate(&convert::nav_sample(&m));
        Message::Estimate(convert::nav_state(&e))
    }

    /// An estimate that is not finite, not current or beyond its declared bound of the
    /// measurement is refused: the simulator's own navigation is substituted, the step
    /// flagged, the fault logged and counted; a missing one likewise at the deadline.
    #[test]
    fn a_refused_or_missing_estimate_is_replaced_and_flagged() {
        let (mut r, real) = realistic_role();
        let mut nav = real.navigation.clone();
        type Spoil = fn(&mut sc_icd::NavState);
        let bad: [(&str, Spoil); 4] = [
            ("not finite", |e| e.r_i[0] = f64::NAN),
            ("relative_position_m", |e| e.r_i[0] += 1.0),
            ("off the unit sphere", |e| e.q_ib[0] *= 2.0),
            // for another tick: still awaited, refused at the deadline
            ("not current", |e| e.tick = e.tick.wrapping_sub(1)),
        ];
        for (k, (why, spoil)) in bad.into_iter().enumerate() {
            let k = k as u64;
            let out = handle(&mut r, 0, Woke::Event, &[tick(k, SubsystemSet::ALL)]);
            let Message::Estimate(mut e) = declared_estimate(&mut nav, &out) else {
                unreachable!()
            };
            spoil(&mut e);
            let mut out = handle(&mut r, 1, Woke::Event, &[Message::Estimate(e)]);
            if why == "not current" {
                assert!(out.send.is_empty(), "the tick's estimate is still awaited");
                out = handle(&mut r, NAV_NS, Woke::Timeout, &[]);
            }
            assert!(
                out.log.iter().any(
                    |l| l.contains(&format!("FAULT tick {k}: navigation estimate"))
                        && l.contains(why)
                ),
                "{why}: {:?}",
                out.log
            );
            let Some(Message::State(known)) =
                out.send.iter().find(|m| matches!(m, Message::State(_)))
            else {
                panic!("{why}: no state in {:?}", out.send)
            };
            assert!(
                known.r_r.iter().all(|x| x.is_finite()),
                "{why}: the substitute's"
            );
            let Some(Message::NavigationError(err)) = out
                .send
                .iter()
                .find(|m| matches!(m, Message::NavigationError(_)))
            else {
                panic!("{why}: no errors")
            };
            assert!(
                err.relative_position_m <= 0.02,
                "{why}: within the declared bound"
            );
            let res = result(&handle(&mut r, 2, Woke::Event, &safe(k)));
            assert_eq!(res.fault_flags, fault::NAVIGATION_REJECTED, "{why}");
        }
        // no estimate of the tick by the deadline: absent, the next tick is not waited for
        let out = handle(
            &mut r,
            2 * DEADLINE_NS,
            Woke::Event,
            &[tick(4, SubsystemSet::ALL)],
        );
        assert!(
            out.send.iter().any(|m| matches!(m, Message::State(_))),
            "absent: no wait"
        );
        let mut fin = Outbox::default();
        r.finish(Finish::Done, &[], &mut fin);
        assert!(
            fin.log[0].contains("navigation estimates missing or rejected 5"),
            "{:?}",
            fin.log
        );
        // a missing estimate is logged once, at the deadline
        let (mut r, _) = realistic_role();
        handle(&mut r, 10, Woke::Event, &[tick(0, SubsystemSet::ALL)]);
        let out = handle(&mut r, 10 + NAV_NS, Woke::Timeout, &[]);
        assert!(
            out.log.iter().any(|l| l
                .contains("FAULT tick 0: navigation estimate missing at the navigation deadline")),
            "{:?}",
            out.log
        );
        let res = result(&handle(&mut r, 11 + NAV_NS, Woke::Event, &safe(0)));
        assert_eq!(res.fault_flags, fault::NAVIGATION_REJECTED);
    }

    /// A late estimate (of a tick whose knowledge was already published) brings an
    /// absent navigation back but never answers the next tick: that tick's deadline finds
    /// it missing, not "not current".
    #[test]
    fn a_late_estimate_is_not_the_next_ticks() {
        let (mut r, real) = realistic_role();
        let mut nav = real.navigation.clone();
        let out = handle(&mut r, 0, Woke::Event, &[tick(0, SubsystemSet::ALL)]);
        let late = declared_estimate(&mut nav, &out);
        handle(&mut r, NAV_NS, Woke::Timeout, &[]);
        assert!(r.navigation_absent, "missing at its deadline");
        handle(&mut r, NAV_NS + 1, Woke::Event, &[late]);
        assert!(!r.navigation_absent, "a late answer brings it back");
        result(&handle(&mut r, NAV_NS + 2, Woke::Event, &safe(0)));
        let t1 = 100_000_000;
        handle(&mut r, t1, Woke::Event, &[tick(1, SubsystemSet::ALL)]);
        assert_eq!(
            r.pending.as_ref().map(|p| p.until_ns),
            Some(t1 + NAV_NS),
            "awaited"
        );
        let out = handle(&mut r, t1 + NAV_NS, Woke::Timeout, &[]);
        assert!(
            out.log
                .iter()
                .any(|l| l.contains("FAULT tick 1: navigation estimate missing")),
            "{:?}",
            out.log
        );
    }

    /// With a declared uncertainty the truth (with the monitor's barriers) and the
    /// realised errors go first, then the estimate on both state services with the
    /// barriers on knowledge; the backups are computed on the estimate, the capture and
    /// the monitor on the truth.
    #[test]
    fn a_realisation_publishes_the_truth_apart_from_the_estimate() {
        let (mut r, real) = realistic_role();
        let out = handle(&mut r, 100, Woke::Event, &[tick(0, SubsystemSet::ALL)]);
        let [Message::Truth(truth), Message::Measurement(_)] = out.send[..] else {
            panic!("the truth, then the measurement: {:?}", out.send);
        };
        let mut navigation = real.navigation.clone();
        let estimate = declared_estimate(&mut navigation, &out);
        let out = handle(&mut r, 100, Woke::Event, &[estimate]);
        assert!(out.log.is_empty(), "admitted: {:?}", out.log);
        let [
            Message::NavigationError(nav),
            Message::State(known),
            Message::PartnerState(partner),
        ] = out.send[..]
        else {
            panic!("truth, errors, then the estimate: {:?}", out.send);
        };
        assert_eq!(
            sc_icd::Message::as_bytes(&known),
            sc_icd::Message::as_bytes(&partner)
        );
        assert_ne!(truth.r_r, known.r_r, "the estimate is not the truth");
        assert_eq!((truth.tick, nav.tick, known.tick), (0, 0, 0));
        assert!(nav.relative_position_m > 0.0 && nav.relative_position_m <= 0.02);
        let p = r.pending.as_ref().unwrap();
        assert_eq!(p.barriers, truth.barriers, "the monitor on the truth");
        assert_eq!(convert::sim_state(&p.known.unwrap()).r_r, known.r_r);
        assert_ne!(known.barriers, truth.barriers, "barriers on knowledge");
        // no safe command by the deadline: the backups, on what the filters knew
        let out = handle(&mut r, 100 + DEADLINE_NS, Woke::Timeout, &[]);
        let res = result(&out);
        assert_eq!(res.fallback_mask, SubsystemSet::ALL.bits());
        let mut layer = SafetyLayer::from_scenario(&r.scenario, setup().robot);
        let o = convert::observation(&known);
        assert_eq!(
            convert::arr3(&layer.backup_translational(&o).actuated),
            res.force_b,
            "the translational backup on the estimate"
        );
    }

    #[test]
    fn a_tick_publishes_the_state_then_applies_the_safe_commands() {
        let mut r = role();
        let out = handle(&mut r, 100, Woke::Event, &[tick(0, SubsystemSet::ALL)]);
        assert!(
            matches!(out.send[..], [Message::Measurement(_)]),
            "the measurement, then the estimate is awaited"
        );
        assert_eq!(
            r.next(100),
            Next::Wait {
                set: NAVIGATION,
                until_ns: Some(100 + DEADLINE_NS)
            }
        );
        let out = handle(&mut r, 100, Woke::Event, &[estimate_of(&out)]);
        assert!(
            matches!(out.send[..], [Message::State(_), Message::PartnerState(_)]),
            "flight side first"
        );
        assert_eq!(
            r.next(100),
            Next::Wait {
                set: ROBOTIC,
                until_ns: Some(100 + DEADLINE_NS)
            }
        );
        let out = handle(&mut r, 200, Woke::Event, &safe(0));
        let res = result(&out);
        assert_eq!(
            (res.tick, res.fallback_mask, res.fault_flags, res.end),
            (0, 0, 0, end::RUNNING)
        );
        assert_eq!(res.safe_recv_ns, 200);
        assert_eq!(r.sim.step_count(), 1, "the physics advanced");
    }

    #[test]
    fn at_the_deadline_the_missing_commands_are_the_filters_backups() {
        let mut r = role();
        start(&mut r, 0, 0, SubsystemSet::ALL);
        // a command for another tick is not this tick's
        let late = Message::SafeTranslational(SafeTranslational {
            tick: 7,
            ..Default::default()
        });
        assert!(handle(&mut r, 10, Woke::Event, &[late]).send.is_empty());
        let out = handle(&mut r, DEADLINE_NS, Woke::Timeout, &[]);
        let res = result(&out);
        assert_eq!(res.fallback_mask, SubsystemSet::ALL.bits());
        assert_eq!(res.fault_flags, fault::DEADLINE_MISS);
        assert!(out.log.iter().any(|l| {
            l.contains("FAULT tick 0: translational safe command missing, fallback applied")
        }));
        assert_eq!(r.misses, 1);
        assert!(r.absent.0.iter().all(|a| *a), "not waited for again");
        assert_eq!(
            r.next(0),
            Next::Wait {
                set: IDLE,
                until_ns: None
            }
        );
    }

    /// The observation the filters read in tick `k` (the state in `out`).
    fn published(out: &Outbox) -> Observation {
        match out.send.iter().find_map(|m| match m {
            Message::State(x) => Some(*x),
            _ => None,
        }) {
            Some(s) => convert::observation(&s),
            None => panic!("no state in {:?}", out.send),
        }
    }

    /// Tick 0's three commands: the translational force `f`, the attitude command
    /// certified against `xi_a`, the robotic one against `xi_r`.
    fn chain(
        f: [f64; 3],
        xi_a: [f64; 3],
        xi_r: (nalgebra::Vector3<f64>, [f64; 3]),
    ) -> [Message; 3] {
        [
            Message::SafeRobotic(SafeRobotic {
                xi_f_b: xi_r.0.into(),
                xi_tau_b: xi_r.1,
                ..Default::default()
            }),
            Message::SafeAttitude(SafeAttitude {
                u: [0.0, 0.01, 0.0],
                xi_f_b: xi_a,
                ..Default::default()
            }),
            Message::SafeTranslational(SafeTranslational {
                actuated: f,
                ..Default::default()
            }),
        ]
    }

    /// The translational command came after the attitude and robotic filters had given
    /// up on it and certified against its backup (the 60–90 ms window): its backup acts,
    /// with the attitude and robotic commands certified against it; flagged and logged.
    #[test]
    fn a_command_the_downstream_filters_gave_up_on_is_not_applied() {
        let mut r = role();
        let o = published(&start(&mut r, 0, 0, SubsystemSet::ALL));
        let backup = r.layer.backup_translational(&o).actuated;
        let out = handle(
            &mut r,
            10,
            Woke::Event,
            &chain([0.05, 0.0, 0.0], backup.into(), (backup, [0.0, 0.01, 0.0])),
        );
        let res = result(&out);
        assert_eq!(res.force_b, <[f64; 3]>::from(backup));
        assert_eq!(res.torque_b, [0.0, 0.01, 0.0], "the attitude command acts");
        assert_eq!(res.fallback_mask, Subsystem::Translational.bit());
        assert_eq!(res.fault_flags, fault::COUPLING_MISMATCH);
        assert!(out.log.iter().any(|l| l.contains(
            "FAULT tick 0: translational safe command came after the downstream filters certified against its backup"
        )));
    }

    /// A command certified against other upstream commands than those acting never acts:
    /// its backup does (on what acts upstream), and so do the commands downstream of it.
    #[test]
    fn a_command_certified_against_other_upstream_commands_is_replaced() {
        let mut r = role();
        let o = published(&start(&mut r, 0, 0, SubsystemSet::ALL));
        let f = nalgebra::Vector3::new(0.05, 0.0, 0.0);
        let other = [0.05 + 1e-9, 0.0, 0.0];
        let out = handle(
            &mut r,
            10,
            Woke::Event,
            &chain(f.into(), other, (f, [0.0, 0.01, 0.0])),
        );
        let res = result(&out);
        assert_eq!(res.force_b, <[f64; 3]>::from(f));
        let tau = r.layer.backup_attitude(&o, &f).u;
        assert_eq!(res.torque_b, <[f64; 3]>::from(tau), "the attitude backup");
        let tau_m = r.layer.backup_robotic(&o, &f, &tau).u;
        assert_eq!(res.tau, convert::arr7(&tau_m), "the robotic backup on it");
        let both = Subsystem::Attitude.bit() | Subsystem::Robotic.bit();
        assert_eq!(res.fallback_mask, both);
        assert_eq!(res.fault_flags, fault::COUPLING_MISMATCH);
    }

    #[test]
    fn a_command_beyond_its_bounds_is_refused_and_counted() {
        let mut r = role();
        start(&mut r, 0, 0, SubsystemSet::ALL);
        let mut cmds = safe(0);
        if let Message::SafeRobotic(m) = &mut cmds[0] {
            m.u[6] = f64::NAN;
        }
        let res = result(&handle(&mut r, 10, Woke::Event, &cmds));
        assert_eq!(res.fallback_mask, Subsystem::Robotic.bit());
        assert_eq!(res.fault_flags, fault::REJECTED_COMMAND);
        assert!(res.tau.iter().all(|x| x.is_finite()));
        let mut fin = Outbox::default();
        r.finish(Finish::Done, &[], &mut fin);
        assert!(
            fin.log[0]
                .contains("safe commands rejected (translational, attitude, robotic) [0, 0, 1]")
        );
    }

    #[test]
    fn a_slower_group_holds_its_command() {
        let mut r = role();
        let only_robotic = SubsystemSet::only(Subsystem::Robotic);
        start(&mut r, 0, 0, only_robotic);
        let Next::Wait { set, .. } = r.next(0) else {
            panic!()
        };
        assert_eq!(set, ROBOTIC);
        let cmd = [Message::SafeRobotic(SafeRobotic {
            tick: 0,
            ..Default::default()
        })];
        let res = result(&handle(&mut r, 10, Woke::Event, &cmd));
        let others = Subsystem::Translational.bit() | Subsystem::Attitude.bit();
        assert_eq!((res.held_mask, res.fallback_mask), (others, 0));
    }

    #[test]
    fn the_stop_wakes_every_consumer_and_ends_the_role() {
        let mut r = role();
        let stop = Message::Tick(Tick {
            command: tick_command::STOP,
            ..Default::default()
        });
        let out = handle(&mut r, 0, Woke::Event, &[stop]);
        assert_eq!(
            out.notify,
            vec![
                services::MEASUREMENT,
                services::PARTNER_STATE,
                services::SIM_STATE,
                services::STEP_RESULT
            ]
        );
        assert_eq!(r.next(0), Next::Exit);
    }
}
