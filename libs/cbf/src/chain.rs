//! The typed causal chain of the safety layer (paper Sec. "Method" and Fig.
//! "control_safety_framework"): translational → attitude → robotic, each downstream filter
//! taking the commands that act upstream as its known coupling ξ.
//!
//! One chain, used by everything that runs the layer: the mission in one process
//! ([`SafetyLayer::step`]), each filter process of the partition ([`SafetyLayer::stage`]
//! with the upstream safe commands it received), and the partition's backups — what the
//! simulator applies and the recorder records when a safe command is missing or refused
//! ([`SafetyLayer::backup_translational`] and its siblings, flagged
//! [`faults::UPSTREAM_MISSING`]).

use crate::common::{FilterOutput, faults};
use crate::filter::{Coupling, SafetyFilter};
use crate::safe_mode::EnvelopeWatch;
use crate::translational::TranslationalParams;
use crate::{
    AttitudeFilter, AttitudeOutput, RoboticFilter, RoboticOutput, TranslationalFilter,
    TranslationalOutput,
};
use nalgebra::{SVector, Vector3};
use sc_core::{Command, Observation, PerSubsystem, Subsystem};
use sc_models::quat;
use sc_multibody::{Robot, Vector7};
use std::sync::Arc;

/// The nominal commands of one step (`None`: missing — the filter then runs on its
/// substitute nominal).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Nominals {
    /// `f_H,nom` [N, F_H].
    pub translational: Option<Vector3<f64>>,
    /// `τ_B,nom` [N m, F_B].
    pub attitude: Option<Vector3<f64>>,
    /// `τ_M,nom` [N m].
    pub robotic: Option<Vector7>,
}

/// What acts on the spacecraft from each stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Actuation {
    /// The safe commands (the safety layer in the loop).
    Safe,
    /// The nominal commands alone, saturated by the actuators (`run --no-filter`): the
    /// filters still run on them so that every barrier is reported.
    NominalSaturated(ActuatorLimits),
}

/// The actuators' bounds `‖f_B‖∞ ≤ force`, `‖τ_B‖∞ ≤ torque`, `‖τ_M‖∞ ≤ joint_torque`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorLimits {
    /// [N]
    pub force: f64,
    /// [N m]
    pub torque: f64,
    /// [N m]
    pub joint_torque: f64,
}

impl ActuatorLimits {
    /// From `[limits]`.
    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        Self {
            force: s.limits.force_max_n,
            torque: s.limits.torque_max_nm,
            joint_torque: s.limits.joint_torque_max_nm,
        }
    }
}

/// The three filters' outputs of one step and what was applied.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainOutput {
    pub translational: TranslationalOutput,
    pub attitude: AttitudeOutput,
    pub robotic: RoboticOutput,
    /// What acts on the spacecraft over the step.
    pub applied: Command,
}

/// The three filters of the modular safety layer with the servicer model they evaluate,
/// and the watch on the certified envelope that puts every stage in safe mode
/// ([`crate::safe_mode`]).
pub struct SafetyLayer {
    pub translational: TranslationalFilter,
    pub attitude: AttitudeFilter,
    pub robotic: RoboticFilter,
    pub watch: EnvelopeWatch,
    model: Arc<Robot>,
}

impl SafetyLayer {
    /// All three filters from the scenario and the servicer model.
    pub fn from_scenario(s: &sc_scenario::Scenario, robot: Arc<Robot>) -> Self {
        let mass = robot.total_mass();
        Self {
            translational: TranslationalFilter::new(TranslationalParams::from_model(s, &robot)),
            attitude: AttitudeFilter::from_scenario(s, mass),
            robotic: RoboticFilter::from_scenario(s, robot.clone()),
            watch: EnvelopeWatch::from_scenario(s),
            model: robot,
        }
    }

    /// The three filters, each certifying its command (and its backup) for the hold it
    /// gets in a multi-rate partition: `hold_s[s]` [s], its rate group's period, in place
    /// of the scenario's control period. A backup recomputed at a shorter period keeps its
    /// barriers over the shorter hold too: condition C1 of the sampled-data rows bounds
    /// the barrier at every instant of the hold (`sampled`, docs/SAFETY.md).
    pub fn with_holds(
        s: &sc_scenario::Scenario,
        robot: Arc<Robot>,
        hold_s: &PerSubsystem<f64>,
    ) -> Self {
        let held = |sub: Subsystem| {
            let mut x = s.clone();
            x.mission.control_period_s = hold_s[sub];
            x
        };
        let (t, a, r) = (
            held(Subsystem::Translational),
            held(Subsystem::Attitude),
            held(Subsystem::Robotic),
        );
        let mass = robot.total_mass();
        Self {
            translational: TranslationalFilter::new(TranslationalParams::from_model(&t, &robot)),
            attitude: AttitudeFilter::from_scenario(&a, mass),
            robotic: RoboticFilter::from_scenario(&r, robot.clone()),
            // the envelope's margins grow with the attitude filter's hold
            watch: EnvelopeWatch::from_scenario(&a),
            model: robot,
        }
    }

    /// The servicer model the filters evaluate.
    pub fn model(&self) -> &Robot {
        &self.model
    }

    /// The whole chain of one step at the known state `o`: each filter on its nominal,
    /// with the commands that act upstream (by `actuation`) as its coupling.
    pub fn step(
        &mut self,
        o: &Observation,
        nominal: &Nominals,
        actuation: Actuation,
    ) -> ChainOutput {
        let tr = self.translational_stage(o, nominal.translational.as_ref());
        let force_b = match actuation {
            Actuation::Safe => tr.actuated,
            Actuation::NominalSaturated(l) => saturate(
                &hill_to_body(o, &nominal.translational.unwrap_or_default()),
                l.force,
            ),
        };
        let at = self.attitude_stage(o, &force_b, nominal.attitude.as_ref());
        let torque_b = match actuation {
            Actuation::Safe => at.u,
            Actuation::NominalSaturated(l) => {
                saturate(&nominal.attitude.unwrap_or_default(), l.torque)
            }
        };
        let rb = self.robotic_stage(o, &force_b, &torque_b, nominal.robotic.as_ref());
        let tau = match actuation {
            Actuation::Safe => rb.u,
            Actuation::NominalSaturated(l) => {
                saturate(&nominal.robotic.unwrap_or_default(), l.joint_torque)
            }
        };
        ChainOutput {
            translational: tr,
            attitude: at,
            robotic: rb,
            applied: Command {
                force_b,
                torque_b,
                tau,
            },
        }
    }

    /// The translational stage (first in the causal order: ξ_tr = 0); in safe mode on the
    /// retreat instead of `nominal`.
    pub fn translational_stage(
        &mut self,
        o: &Observation,
        nominal: Option<&Vector3<f64>>,
    ) -> TranslationalOutput {
        let safe = self.watch.check(o).is_some();
        let f = &mut self.translational;
        let Some(x) = f.input(&self.model, o, &Coupling::default()) else {
            return flag_safe_mode(f.invalid_state(), safe);
        };
        if !safe {
            return f.filter_with(&x, nominal);
        }
        let retreat = f.toward_velocity(&x, &self.watch.retreat_velocity(&x.r_h, &x.omega_h));
        let out = f.filter_with(&x, Some(&retreat));
        in_safe_mode(out, nominal, f.input_bound())
    }

    /// The attitude stage with the actuated safe force `force_b` [N, F_B] as ξ_att (its
    /// nominal kept in safe mode).
    pub fn attitude_stage(
        &mut self,
        o: &Observation,
        force_b: &Vector3<f64>,
        nominal: Option<&Vector3<f64>>,
    ) -> AttitudeOutput {
        let safe = self.watch.check(o).is_some();
        let xi = Coupling {
            force_b: *force_b,
            torque_b: Vector3::zeros(),
        };
        flag_safe_mode(self.attitude.stage(&self.model, o, &xi, nominal), safe)
    }

    /// The robotic stage with the safe base force and torque [F_B] as ξ_rob; in safe mode
    /// on the arm's brake instead of `nominal`.
    pub fn robotic_stage(
        &mut self,
        o: &Observation,
        force_b: &Vector3<f64>,
        torque_b: &Vector3<f64>,
        nominal: Option<&Vector7>,
    ) -> RoboticOutput {
        let safe = self.watch.check(o).is_some();
        let xi = Coupling {
            force_b: *force_b,
            torque_b: *torque_b,
        };
        let f = &mut self.robotic;
        let Some(x) = f.input(&self.model, o, &xi) else {
            return flag_safe_mode(f.invalid_state(), safe);
        };
        if !safe {
            return f.filter_with(&x, nominal);
        }
        let out = f.filter_with(&x, Some(&f.brake(&x)));
        in_safe_mode(out, nominal, f.input_bound())
    }

    /// The translational backup, as the partition applies it when the safe command is
    /// missing or refused: the filter's QP on its substitute nominal, flagged
    /// [`faults::UPSTREAM_MISSING`].
    pub fn backup_translational(&mut self, o: &Observation) -> TranslationalOutput {
        flag_missing(self.translational_stage(o, None))
    }

    /// The attitude backup with the force `force_b` acting [N, F_B].
    pub fn backup_attitude(&mut self, o: &Observation, force_b: &Vector3<f64>) -> AttitudeOutput {
        flag_missing(self.attitude_stage(o, force_b, None))
    }

    /// The robotic backup with the base force and torque acting [F_B].
    pub fn backup_robotic(
        &mut self,
        o: &Observation,
        force_b: &Vector3<f64>,
        torque_b: &Vector3<f64>,
    ) -> RoboticOutput {
        flag_missing(self.robotic_stage(o, force_b, torque_b, None))
    }
}

/// Marks an output of a stage in safe mode, with the flag the partner's nominal `given`
/// would have raised ([`faults::NOMINAL_MISSING`], [`faults::INVALID_NOMINAL`]): the
/// partner is still accounted for, and the partition's recorder still knows that no
/// nominal came (`bound`: the filter's input bound).
fn in_safe_mode<const M: usize, const N: usize>(
    mut out: FilterOutput<M, N>,
    given: Option<&SVector<f64, M>>,
    bound: f64,
) -> FilterOutput<M, N> {
    let (_, partner) = crate::common::resolve_nominal(given, bound, SVector::zeros);
    out.report.faults |= faults::SAFE_MODE | partner;
    out
}

/// Marks an output of a stage in safe mode (when `safe`).
fn flag_safe_mode<const M: usize, const N: usize>(
    mut out: FilterOutput<M, N>,
    safe: bool,
) -> FilterOutput<M, N> {
    if safe {
        out.report.faults |= faults::SAFE_MODE;
    }
    out
}

/// Marks an output computed with an input missing.
pub fn flag_missing<const M: usize, const N: usize>(
    mut out: FilterOutput<M, N>,
) -> FilterOutput<M, N> {
    out.report.faults |= faults::UPSTREAM_MISSING;
    out
}

/// Saturates a command to `±limit` componentwise (what the actuators do when no filter is
/// in the loop); non-finite components become zero.
pub fn saturate<const M: usize>(u: &SVector<f64, M>, limit: f64) -> SVector<f64, M> {
    u.map(|x| {
        if x.is_finite() {
            x.clamp(-limit, limit)
        } else {
            0.0
        }
    })
}

/// `f_B = R_BH f_H` for a force given in the Hill frame, at the known attitude.
pub fn hill_to_body(o: &Observation, f_h: &Vector3<f64>) -> Vector3<f64> {
    let r_hb = quat::to_matrix(&quat::mul(&o.q_hr, &o.q_rb));
    r_hb.transpose() * f_h
}
