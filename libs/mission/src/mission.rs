//! The whole mission in one process.

use crate::nominal_source::{NominalCommands, NominalOverride};
use crate::record::StepRecord;
use crate::setup::{Setup, SetupError};
use crate::stages;
use sc_cbf::monitor::{Barriers, Monitor, min_into};
use sc_cbf::{Actuation, ActuatorLimits, Nominals, QpDump, SafetyLayer};
use sc_nominal::NominalControllers;
use sc_sim::navigation::{default_navigation, substitute_navigation};
use sc_sim::{Estimator, NavigationGate, Plant, Realisation, Simulator};
use std::sync::Arc;

/// Options of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RunOptions {
    /// Apply the nominal commands (saturated to the actuator bounds) instead of the safe
    /// ones. The filters still run, so that every barrier value is reported.
    pub no_filter: bool,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum MissionEnd {
    /// The end-effector reached the grasping point within tolerance at `t` [s].
    Captured { t: f64 },
    /// The configured duration elapsed without capture.
    Timeout { t: f64 },
    /// The simulator failed (non-finite state).
    SimulatorFailed { t: f64, message: String },
    /// The run was stopped before the mission ended: by `--max-ticks`, or by the
    /// partition's scheduler (a process the run cannot go on without died).
    Stopped { t: f64 },
    /// The run was interrupted (SIGINT/SIGTERM) before the mission ended.
    Interrupted { t: f64 },
}

impl MissionEnd {
    /// The name in `summary.json`: "captured", "timeout", "simulator_failed" (the
    /// mission's own ends), "stopped" or "interrupted" (the run ended before the
    /// mission did).
    pub fn name(&self) -> &'static str {
        match self {
            MissionEnd::Captured { .. } => "captured",
            MissionEnd::Timeout { .. } => "timeout",
            MissionEnd::SimulatorFailed { .. } => "simulator_failed",
            MissionEnd::Stopped { .. } => "stopped",
            MissionEnd::Interrupted { .. } => "interrupted",
        }
    }

    /// The mission time of the last step [s].
    pub fn t(&self) -> f64 {
        match self {
            MissionEnd::Captured { t }
            | MissionEnd::Timeout { t }
            | MissionEnd::SimulatorFailed { t, .. }
            | MissionEnd::Stopped { t }
            | MissionEnd::Interrupted { t } => *t,
        }
    }

    /// The end named `name` (see [`Self::name`]) at `t`; `None` for an unknown name.
    /// A simulator failure rebuilt this way carries no message of its own.
    pub fn from_name(name: &str, t: f64) -> Option<Self> {
        match name {
            "captured" => Some(MissionEnd::Captured { t }),
            "timeout" => Some(MissionEnd::Timeout { t }),
            "simulator_failed" => Some(MissionEnd::SimulatorFailed {
                t,
                message: "simulator failed".into(),
            }),
            "stopped" => Some(MissionEnd::Stopped { t }),
            "interrupted" => Some(MissionEnd::Interrupted { t }),
            _ => None,
        }
    }
}

/// The three QPs of one step, for `--dump-qp`.
pub struct StepQps {
    pub translational: QpDump,
    pub attitude: QpDump,
    pub robotic: QpDump,
}

/// Simulator + nominal controllers + safety layer, stepped at the control period.
pub struct Mission {
    pub setup: Setup,
    pub sim: Simulator,
    pub nominal: NominalControllers,
    pub safety: SafetyLayer,
    pub options: RunOptions,
    /// Every barrier from the true state, at control and physics steps.
    pub monitor: Monitor,
    /// Barrier minima over the physics steps since the last control step.
    between: Option<Barriers>,
    /// Replaces nominal commands (a partner's controller or a red-team adversary).
    pub nominal_override: Option<Box<dyn NominalOverride>>,
    /// Propagates the true state instead of the simulator's own RK4 ([`Self::set_plant`]).
    plant: Option<Box<dyn Plant + Send>>,
    /// The run's realisation of the declared uncertainty: the plant the simulator
    /// propagates, the actuators and the navigation the controllers and filters see
    /// through. `None` for the `exact` profile (truth and knowledge are one).
    pub realisation: Option<Realisation>,
    /// The barriers on knowledge (the declared model), with a realisation only.
    knowledge_monitor: Option<Monitor>,
    /// The navigation the controllers and filters see through (the partition's
    /// navigation role runs the same), replaceable ([`Self::set_navigation`]).
    navigation: Box<dyn Estimator + Send>,
    /// The simulator's sensors and the gate every estimate passes.
    gate: NavigationGate,
    end: Option<MissionEnd>,
}

impl Mission {
    /// Builds a mission from a setup.
    pub fn new(setup: Setup, options: RunOptions) -> Result<Self, SetupError> {
        let realisation = draw_realisation(&setup)?;
        // the simulator and the monitor see the truth; controllers and filters the model
        let (truth, robot) = match &realisation {
            Some(r) => (&r.true_scenario, Arc::new(r.true_robot.clone())),
            None => (&setup.scenario, setup.robot.clone()),
        };
        let sim =
            Simulator::new(truth, robot.clone()).map_err(|e| SetupError::Other(e.to_string()))?;
        let monitor = Monitor::from_scenario(truth, robot);
        let nominal = NominalControllers::new(&setup.scenario, (*setup.robot).clone())
            .map_err(|e| SetupError::Other(e.to_string()))?;
        let safety = SafetyLayer::from_scenario(&setup.scenario, setup.robot.clone());
        let knowledge_monitor = realisation
            .is_some()
            .then(|| Monitor::from_scenario(&setup.scenario, setup.robot.clone()));
        let navigation = default_navigation(realisation.as_ref());
        let declared_navigation = setup.scenario.uncertainty_bounds().navigation;
        let substitute = substitute_navigation(realisation.as_ref(), &declared_navigation);
        let gate = NavigationGate::new(&setup.scenario, setup.robot.clone(), substitute)
            .map_err(|e| SetupError::Other(e.to_string()))?;
        Ok(Self {
            setup,
            sim,
            nominal,
            safety,
            options,
            monitor,
            between: None,
            nominal_override: None,
            plant: None,
            realisation,
            knowledge_monitor,
            navigation,
            gate,
            end: None,
        })
    }

    /// Estimates with `navigation` from now on (a partner's estimator, a hostile one).
    pub fn set_navigation(&mut self, navigation: Box<dyn Estimator + Send>) {
        self.navigation = navigation;
    }

    /// Propagates with `plant` from now on (another simulator in the loop, e.g. Basilisk),
    /// started at the current state.
    pub fn set_plant(
        &mut self,
        mut plant: Box<dyn Plant + Send>,
    ) -> Result<(), sc_sim::PlantError> {
        if self.sim.world_event_pending() {
            return Err(sc_sim::PlantError(
                "the scenario's [world] event needs the simulator's own propagation: an external plant cannot apply it".into(),
            ));
        }
        plant.start(self.sim.state())?;
        self.plant = Some(plant);
        Ok(())
    }

    /// How the run ended, once it has.
    pub fn end(&self) -> Option<&MissionEnd> {
        self.end.as_ref()
    }

    /// Computes the commands of the current step (nominal → translational → attitude →
    /// robotic filter), without advancing the simulator.
    pub fn compute(&mut self) -> StepRecord {
        let truth = self.sim.observe();
        let barriers = self.monitor.evaluate(&truth.barrier_state());
        // what the controllers and filters know: the navigation's estimate, admitted
        let m = self.gate.measure(&self.sim, self.sim.step_count());
        let estimate = self.navigation.estimate(&m);
        let (known, rejected) = self.gate.admit(Some(&estimate), &m, &self.sim, &truth);
        let o = known.observation;
        let navigation_error = self.realisation.is_some().then_some(known.error);
        let knowledge_barriers = self
            .knowledge_monitor
            .as_ref()
            .map(|m| m.evaluate(&o.barrier_state()));
        let barriers_between = self.between.unwrap_or(barriers);
        let nom = self.nominal.command(&stages::nominal_input(&o));
        let cmds = match self.nominal_override.as_mut() {
            Some(src) => src.commands(&o, &nom),
            None => NominalCommands::REFERENCE,
        };
        let nominals = Nominals {
            translational: cmds.translational.resolve(nom.f_h),
            attitude: cmds.attitude.resolve(nom.tau_b),
            robotic: cmds.robotic.resolve(nom.tau_m),
        };
        let actuation = if self.options.no_filter {
            Actuation::NominalSaturated(ActuatorLimits::from_scenario(&self.setup.scenario))
        } else {
            Actuation::Safe
        };
        let out = self.safety.step(&o, &nominals, actuation);
        let nan3 = nalgebra::Vector3::from_element(f64::NAN);
        StepRecord {
            step: o.step,
            t: o.t,
            // the phase comes from the mission's own schedule, never from a controller
            phase: self.setup.scenario.phase_index(o.t),
            obs: truth,
            navigation_error,
            knowledge_barriers,
            navigation_rejected: rejected.is_some(),
            // a missing nominal is recorded as NaN
            f_h_nom: nominals.translational.unwrap_or(nan3),
            tau_b_nom: nominals.attitude.unwrap_or(nan3),
            tau_m_nom: nominals
                .robotic
                .unwrap_or(sc_multibody::Vector7::from_element(f64::NAN)),
            translational: out.translational,
            attitude: out.attitude,
            robotic: out.robotic,
            applied: out.applied,
            barriers,
            barriers_between,
        }
    }

    /// The QPs of the last [`Self::compute`].
    pub fn last_qps(&self) -> StepQps {
        StepQps {
            translational: self.safety.translational.dump_qp(),
            attitude: self.safety.attitude.dump_qp(),
            robotic: self.safety.robotic.dump_qp(),
        }
    }

    /// True if the record shows a capture: grasping phase, end-effector on the grasping
    /// point within the configured distance and relative-speed tolerances, and every
    /// barrier ≥ 0 at this step and since the previous one (true state).
    pub fn is_capture(&self, r: &StepRecord) -> bool {
        capture_check(&self.setup.scenario, r.phase, &r.obs)
            && all_hold(&r.barriers)
            && all_hold(&r.barriers_between)
    }

    /// One control step: compute, then advance the simulator under the applied command.
    /// Returns the record, or `None` once the mission has ended.
    pub fn step(&mut self) -> Option<StepRecord> {
        if self.end.is_some() {
            return None;
        }
        let r = self.compute();
        self.advance(&r);
        Some(r)
    }

    /// Ends the mission on capture or timeout, or advances the simulator by one period.
    pub fn advance(&mut self, r: &StepRecord) {
        if self.is_capture(r) {
            self.end = Some(MissionEnd::Captured { t: r.t });
            return;
        }
        if timeout_check(&self.setup.scenario, r.t) {
            self.end = Some(MissionEnd::Timeout { t: r.t });
            return;
        }
        let monitor = &self.monitor;
        let mut between: Barriers = [f64::INFINITY; sc_cbf::monitor::N_ALL];
        let at_physics_step =
            |b: &sc_sim::BarrierState| min_into(&mut between, &monitor.evaluate(b));
        // what the actuators deliver of the applied command
        let delivered = match self.realisation.as_mut() {
            Some(real) => real.actuators.deliver(&r.applied),
            None => r.applied,
        };
        let stepped = match self.plant.as_mut() {
            Some(p) => self
                .sim
                .step_with_plant(p.as_mut(), &delivered, at_physics_step),
            None => self.sim.step_with(&delivered, at_physics_step),
        };
        self.between = Some(between);
        if let Err(e) = stepped {
            self.end = Some(MissionEnd::SimulatorFailed {
                t: r.t,
                message: e.to_string(),
            });
        }
    }

    /// Runs to the end, handing every record to `sink`.
    pub fn run(&mut self, mut sink: impl FnMut(&Mission, &StepRecord)) -> MissionEnd {
        while self.end.is_none() {
            let r = self.compute();
            sink(self, &r);
            self.advance(&r);
        }
        self.end.clone().unwrap_or(MissionEnd::Timeout { t: 0.0 })
    }
}

/// The realisation of the scenario's declared uncertainty (`None` when it declares
/// none), drawn from its seed.
fn draw_realisation(setup: &Setup) -> Result<Option<Realisation>, SetupError> {
    Realisation::declared(&setup.scenario, &setup.robot)
        .map_err(|e| SetupError::Other(format!("uncertainty: {e}")))
}

/// True if phase `phase` grasps and the observation shows the end-effector on the
/// grasping point within the scenario's distance and relative-speed tolerances.
/// Shared by [`Mission`] and the partition's simulator process.
pub fn capture_check(
    scenario: &sc_scenario::Scenario,
    phase: usize,
    o: &sc_sim::Observation,
) -> bool {
    let m = &scenario.mission;
    let grasping = m.phases.get(phase).map(|p| p.robotic) == Some(sc_scenario::RoboticMode::Grasp);
    grasping
        && o.grasp_distance() <= m.capture_tolerance_m
        && o.grasp_speed() <= m.capture_speed_tolerance_m_s
}

/// True if every barrier value is ≥ 0 (a NaN fails).
pub fn all_hold(h: &Barriers) -> bool {
    h.iter().all(|v| *v >= 0.0)
}

/// True if the step starting at `t` is the last one of the configured duration.
pub fn timeout_check(scenario: &sc_scenario::Scenario, t: f64) -> bool {
    let m = &scenario.mission;
    t + 0.5 * m.control_period_s >= m.duration_s
}

#[cfg(test)]
mod tests {
    use super::MissionEnd;

    /// Every end reads back from its name in summary.json, the run's ends as well as the
    /// mission's; the scheduler's words for a stop are not ends.
    #[test]
    fn every_end_reads_back_from_its_name() {
        const T: f64 = 4.9;
        for end in [
            MissionEnd::Captured { t: T },
            MissionEnd::Timeout { t: T },
            MissionEnd::SimulatorFailed {
                t: T,
                message: "simulator failed".into(),
            },
            MissionEnd::Stopped { t: T },
            MissionEnd::Interrupted { t: T },
        ] {
            assert_eq!(MissionEnd::from_name(end.name(), T), Some(end.clone()));
            assert_eq!(end.t(), T);
        }
        assert_eq!(MissionEnd::from_name("max_ticks", T), None);
    }
}
