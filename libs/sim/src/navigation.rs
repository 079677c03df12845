//! Navigation: what the sensors measure, what a navigation estimates from it, and the
//! gate an estimate passes before it becomes knowledge.
//!
//! * [`NavigationGate::measure`] — the simulator's sensors: the true state
//!   measurement age of the truth's bounds old (`uncertainty.truth`, else the declared
//!   `uncertainty.navigation.measurement_age_s`; whole physics steps, at most one control
//!   period, less in a run's first steps) and the true grasping point. The sensors have no noise of their
//!   own: the declared navigation errors are the navigation's.
//! * [`Estimator`] — the navigation (the partition's `navigation` role, which a
//!   partner's estimator may replace): [`PassThrough`] for the `exact` profile,
//!   [`DeclaredNavigation`] the declared error model (bias plus truncated noise on every
//!   navigated quantity).
//! * [`NavigationGate::admit`] — the simulator's side: an estimate is admitted when it is
//!   there, current (the tick, its time and its measurement's), finite, its quaternions
//!   unit, its orbit the measured one and every navigated quantity within its declared
//!   bound of the measurement. Otherwise the simulator's own [`DeclaredNavigation`] is
//!   substituted (its errors are the declared ones, so the filters' margins cover it)
//!   and the rejection reported. The admitted estimate becomes knowledge: the declared
//!   model's observation of it (declared mass properties, the estimated grasping point).
//!
//! The mission in one process and the partition run the same three steps with the same
//! code (`sc_mission::Mission::compute`, the simulator and navigation roles).

use crate::state::{SimState, Simulator};
use crate::uncertainty::{
    AGE_ROUNDING, NAVIGATION_ERROR_NAMES, NAVIGATION_ERROR_ROUNDING, NavigationBias,
    NavigationError, SUBSTITUTE_STREAM, rotation, truncated, truncated1,
};
use nalgebra::{Matrix3, Vector3};
use rand_chacha::ChaCha8Rng;
use sc_core::Observation;
use sc_models::quat;
use sc_multibody::{NJ, Robot, Vector7};
use sc_scenario::Scenario;
use sc_scenario::uncertainty::{BiasNoise, NavigationBounds};
use std::sync::Arc;

/// How far a quaternion's norm may be from 1 before an estimate is refused [-]: the
/// propagated and the error-rotated quaternions stay within a few ulps of it.
pub const UNIT_QUATERNION_TOLERANCE: f64 = 1e-9;

/// A navigation state: a measurement or an estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavSample {
    /// The tick it answers.
    pub tick: u64,
    /// Time of the measurement the values rest on [s] (≤ `state.t`).
    pub measured_t: f64,
    /// The values, inertial; `state.t` is the tick's time (an estimate is of it).
    pub state: SimState,
    /// Grasping point relative to the target CoM, F_T [m].
    pub grasp_t: Vector3<f64>,
}

/// A navigation: the estimate of the tick's state from its newest measurement.
pub trait Estimator {
    fn estimate(&mut self, measurement: &NavSample) -> NavSample;
}

/// The navigation of the `exact` profile: the measurement is the estimate.
#[derive(Debug, Clone, Copy, Default)]
pub struct PassThrough;

impl Estimator for PassThrough {
    fn estimate(&mut self, m: &NavSample) -> NavSample {
        *m
    }
}

/// The default navigation of a declared `[uncertainty]`: the measurement with the
/// declared errors (a per-run bias plus per-step noise truncated at its bound; position
/// and velocity errors in F_R, attitude errors as small rotations in the body frames).
#[derive(Debug, Clone)]
pub struct DeclaredNavigation {
    bounds: NavigationBounds,
    pub bias: NavigationBias,
    /// F_R → F_I (the declared reference frame).
    r_ir: Matrix3<f64>,
    rng: ChaCha8Rng,
}

/// `v` scaled into the ball of `radius` (unchanged, bit for bit, when inside it).
fn clamp3(v: &mut [f64; 3], radius: f64) {
    let n = Vector3::from(*v).norm();
    if n > radius {
        let k = radius / n;
        v.iter_mut().for_each(|x| *x *= k);
    }
}

/// Adds a bias plus a truncated noise draw to a 3-vector.
fn err3(rng: &mut ChaCha8Rng, bias: &[f64; 3], b: BiasNoise) -> Vector3<f64> {
    Vector3::from(*bias) + truncated(rng, b.noise)
}

impl DeclaredNavigation {
    pub(crate) fn new(
        bounds: NavigationBounds,
        bias: NavigationBias,
        r_ir: Matrix3<f64>,
        rng: ChaCha8Rng,
    ) -> Self {
        Self {
            bounds,
            bias,
            r_ir,
            rng,
        }
    }

    /// The simulator's substitute: the same errors with noise of its own, held to the
    /// `declared` bounds (a truth drawn from wider ones, `[uncertainty.truth]`, must not
    /// reach the filters through the substitute): every bias within the declared bias,
    /// the noise truncated at the declared noise.
    pub fn substitute(&self, declared: &NavigationBounds) -> Self {
        let mut s = self.clone();
        s.rng.set_stream(SUBSTITUTE_STREAM);
        s.bounds = *declared;
        let b = &mut s.bias;
        let d = declared;
        clamp3(&mut b.relative_position_m, d.relative_position_m.bias);
        clamp3(&mut b.relative_velocity_m_s, d.relative_velocity_m_s.bias);
        clamp3(&mut b.servicer_attitude_rad, d.servicer_attitude_rad.bias);
        clamp3(&mut b.servicer_rate_rad_s, d.servicer_rate_rad_s.bias);
        clamp3(&mut b.target_attitude_rad, d.target_attitude_rad.bias);
        clamp3(&mut b.target_rate_rad_s, d.target_rate_rad_s.bias);
        clamp3(&mut b.grasp_point_m, d.grasp_point_m.bias);
        for x in b.joint_angle_rad.iter_mut() {
            *x = x.clamp(-d.joint_angle_rad.bias, d.joint_angle_rad.bias);
        }
        for x in b.joint_rate_rad_s.iter_mut() {
            *x = x.clamp(-d.joint_rate_rad_s.bias, d.joint_rate_rad_s.bias);
        }
        s
    }
}

impl Estimator for DeclaredNavigation {
    fn estimate(&mut self, m: &NavSample) -> NavSample {
        let (b, n, r_ir) = (self.bias, self.bounds, self.r_ir);
        let rng = &mut self.rng;
        let mut est = *m;
        let s = &mut est.state;
        s.dr += r_ir * err3(rng, &b.relative_position_m, n.relative_position_m);
        s.dv += r_ir * err3(rng, &b.relative_velocity_m_s, n.relative_velocity_m_s);
        let att_b = err3(rng, &b.servicer_attitude_rad, n.servicer_attitude_rad);
        s.q_ib = rotated(&m.state.q_ib, &att_b);
        s.w_b += err3(rng, &b.servicer_rate_rad_s, n.servicer_rate_rad_s);
        let att_t = err3(rng, &b.target_attitude_rad, n.target_attitude_rad);
        s.q_it = rotated(&m.state.q_it, &att_t);
        s.w_t += err3(rng, &b.target_rate_rad_s, n.target_rate_rad_s);
        est.grasp_t += err3(rng, &b.grasp_point_m, n.grasp_point_m);
        for k in 0..NJ {
            s.theta[k] += b.joint_angle_rad[k] + truncated1(rng, n.joint_angle_rad.noise);
            s.theta_dot[k] += b.joint_rate_rad_s[k] + truncated1(rng, n.joint_rate_rad_s.noise);
        }
        est
    }
}

/// `q` turned by the small rotation `v` (unchanged, not re-rounded, when `v` is zero).
fn rotated(q: &quat::Quat, v: &Vector3<f64>) -> quat::Quat {
    if *v == Vector3::zeros() {
        *q
    } else {
        quat::mul(q, &rotation(v))
    }
}

/// Why an estimate was not admitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Rejection {
    #[error("missing at the navigation deadline")]
    Missing,
    #[error(
        "not current: it answers tick {tick} at t = {t} s from a measurement at {measured_t} s"
    )]
    NotCurrent { tick: u64, t: f64, measured_t: f64 },
    #[error("not finite")]
    NonFinite,
    #[error("a quaternion off the unit sphere (norm {norm})")]
    NotUnit { norm: f64 },
    #[error("the target's orbit is not the measured one")]
    Orbit,
    #[error("{name} {value:e} farther from the measurement than its declared bound {bound:e}")]
    Outside {
        name: &'static str,
        value: f64,
        bound: f64,
    },
}

/// What an admitted (or substituted) estimate gives the controllers and filters.
#[derive(Debug, Clone, Copy)]
pub struct Knowledge {
    /// The declared model's observation of the estimate.
    pub observation: Observation,
    /// The realised errors of the estimate used against the measured truth.
    pub error: NavigationError,
    /// The observation is the truth's own (the `exact` profile, an estimate equal to
    /// the measurement).
    pub truth: bool,
}

/// The simulator's side of navigation: the sensors, the gate, the declared model.
pub struct NavigationGate {
    /// The sensors' measurement age [s] (the truth's).
    age_s: f64,
    /// The declared navigation bounds.
    declared: NavigationBounds,
    /// The declared bounds, in [`NAVIGATION_ERROR_NAMES`]' order.
    bounds: [f64; 10],
    /// A simulator of the declared scenario and robot: knowledge is its observation.
    knower: Simulator,
    /// No declared uncertainty: an estimate equal to the measurement is the truth.
    exact: bool,
    substitute: Box<dyn Estimator + Send>,
}

impl NavigationGate {
    /// The gate of the `declared` scenario and `robot` (the model the filters use), with
    /// `substitute` for a rejected estimate.
    pub fn new(
        declared: &Scenario,
        robot: Arc<Robot>,
        substitute: Box<dyn Estimator + Send>,
    ) -> Result<Self, crate::SimError> {
        let nav = declared.uncertainty_bounds().navigation;
        Ok(Self {
            // the sensors' age is the truth's ([uncertainty.truth] may declare it longer
            // than the filters were told: then the realised errors say so)
            age_s: declared
                .uncertainty_truth_bounds()
                .navigation
                .measurement_age_s,
            declared: nav,
            bounds: NavigationError::bounds(&nav),
            knower: Simulator::new(declared, robot)?,
            exact: declared.uncertainty.is_none(),
            substitute,
        })
    }

    /// The measurement's age in whole physics steps of `truth` (at most one period).
    /// (`0.03 / 0.01` is 2.9999999999999996 in floating point: the quotient is rounded
    /// up by [`AGE_ROUNDING`] before it is floored.)
    fn age_steps(&self, truth: &Simulator) -> usize {
        let q = self.age_s / truth.p.physics_step;
        let steps = (q * (1.0 + AGE_ROUNDING)).floor();
        (steps as usize).min(truth.p.substeps)
    }

    /// The declared navigation bounds the gate checks against.
    pub fn declared(&self) -> &NavigationBounds {
        &self.declared
    }

    /// Substitutes `substitute` for a refused estimate from now on.
    pub fn set_substitute(&mut self, substitute: Box<dyn Estimator + Send>) {
        self.substitute = substitute;
    }

    /// The measurement's age [s] on `truth`'s physics steps (whole steps: a difference of
    /// two times would add its rounding).
    pub fn measurement_age(&self, truth: &Simulator) -> f64 {
        self.age_steps(truth) as f64 * truth.p.physics_step
    }

    /// What the sensors measure at tick `tick` of `truth`.
    pub fn measure(&self, truth: &Simulator, tick: u64) -> NavSample {
        let mut state = truth.state_ago(self.age_steps(truth));
        let measured_t = state.t;
        state.t = truth.state.t;
        NavSample {
            tick,
            measured_t,
            state,
            grasp_t: truth.p.grasp_point_t,
        }
    }

    /// The knowledge of `estimate` (`None`: missing) against the measurement `m` of
    /// `truth`, whose own observation is `truth_obs`; the reason when the estimate was
    /// refused and the substitute used.
    pub fn admit(
        &mut self,
        estimate: Option<&NavSample>,
        m: &NavSample,
        truth: &Simulator,
        truth_obs: &Observation,
    ) -> (Knowledge, Option<Rejection>) {
        let age_s = realised_age(m, truth);
        let checked = estimate
            .ok_or(Rejection::Missing)
            .and_then(|e| self.check(e, m, age_s).map(|err| (*e, err)));
        let (est, error, rejected) = match checked {
            Ok((e, err)) => (e, err, None),
            Err(why) => {
                let e = self.substitute.estimate(m);
                (e, error_of(&e, m, age_s), Some(why))
            }
        };
        let is_truth = self.exact && est == *m;
        let observation = if is_truth {
            *truth_obs
        } else {
            self.knower.p.grasp_point_t = est.grasp_t;
            self.knower.state = est.state;
            self.knower.step = truth.step;
            self.knower.observe()
        };
        (
            Knowledge {
                observation,
                error,
                truth: is_truth,
            },
            rejected,
        )
    }

    /// The realised errors of `e` when it is admissible against `m`.
    fn check(
        &self,
        e: &NavSample,
        m: &NavSample,
        age_s: f64,
    ) -> Result<NavigationError, Rejection> {
        let (s, ms) = (&e.state, &m.state);
        if e.tick != m.tick || s.t != ms.t || e.measured_t != m.measured_t {
            return Err(Rejection::NotCurrent {
                tick: e.tick,
                t: s.t,
                measured_t: e.measured_t,
            });
        }
        if !finite(e) {
            return Err(Rejection::NonFinite);
        }
        for q in [&s.q_ib, &s.q_it] {
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            if (norm - 1.0).abs() > UNIT_QUATERNION_TOLERANCE {
                return Err(Rejection::NotUnit { norm });
            }
        }
        let near = |a: &Vector3<f64>, b: &Vector3<f64>| {
            (a - b).norm() <= NAVIGATION_ERROR_ROUNDING * (1.0 + b.norm())
        };
        if !near(&s.r_t, &ms.r_t) || !near(&s.v_t, &ms.v_t) {
            return Err(Rejection::Orbit);
        }
        let error = error_of(e, m, age_s);
        let values = error.values();
        // the age is the sensors' (checked above as the measurement's time)
        for k in 0..values.len() - 1 {
            if values[k] > self.bounds[k] + NAVIGATION_ERROR_ROUNDING {
                return Err(Rejection::Outside {
                    name: NAVIGATION_ERROR_NAMES[k],
                    value: values[k],
                    bound: self.bounds[k],
                });
            }
        }
        Ok(error)
    }
}

/// The age of measurement `m` of `truth` [s]: its whole physics steps (the first ticks of a
/// run have less history than the declared age; a difference of two times would add its
/// rounding).
fn realised_age(m: &NavSample, truth: &Simulator) -> f64 {
    let h = truth.p.physics_step;
    ((m.state.t - m.measured_t) / h).round() * h
}

/// Every number of `e` is finite.
fn finite(e: &NavSample) -> bool {
    let s = &e.state;
    let v3 = [s.r_t, s.v_t, s.w_t, s.dr, s.dv, s.w_b, e.grasp_t];
    s.t.is_finite()
        && e.measured_t.is_finite()
        && v3.iter().all(|v| v.iter().all(|x| x.is_finite()))
        && s.q_it.iter().chain(&s.q_ib).all(|x| x.is_finite())
        && s.theta
            .iter()
            .chain(s.theta_dot.iter())
            .all(|x| x.is_finite())
}

/// The realised errors of the estimate `e` against the measured truth `m`, `age_s` old.
pub fn error_of(e: &NavSample, m: &NavSample, age_s: f64) -> NavigationError {
    let (est, truth) = (&e.state, &m.state);
    let angle = |a: &quat::Quat, b: &quat::Quat| {
        // 2 atan2(‖v‖, |w|): exact near zero, where acos(|w|) is not
        if a == b {
            return 0.0;
        }
        let d = quat::mul(&quat::conj(a), b);
        2.0 * Vector3::new(d[1], d[2], d[3]).norm().atan2(d[0].abs())
    };
    let max_abs = |a: &Vector7, b: &Vector7| (a - b).amax();
    NavigationError {
        relative_position_m: (est.dr - truth.dr).norm(),
        relative_velocity_m_s: (est.dv - truth.dv).norm(),
        servicer_attitude_rad: angle(&est.q_ib, &truth.q_ib),
        servicer_rate_rad_s: (est.w_b - truth.w_b).norm(),
        target_attitude_rad: angle(&est.q_it, &truth.q_it),
        target_rate_rad_s: (est.w_t - truth.w_t).norm(),
        grasp_point_m: (e.grasp_t - m.grasp_t).norm(),
        joint_angle_rad: max_abs(&est.theta, &truth.theta),
        joint_rate_rad_s: max_abs(&est.theta_dot, &truth.theta_dot),
        measurement_age_s: age_s,
    }
}

/// The default navigation of `realisation` (the `exact` profile's without one).
pub fn default_navigation(realisation: Option<&crate::Realisation>) -> Box<dyn Estimator + Send> {
    match realisation {
        Some(r) => Box::new(r.navigation.clone()),
        None => Box::new(PassThrough),
    }
}

/// The simulator's substitute for a rejected estimate of `realisation`'s navigation.
pub fn substitute_navigation(
    realisation: Option<&crate::Realisation>,
    declared: &NavigationBounds,
) -> Box<dyn Estimator + Send> {
    match realisation {
        Some(r) => Box::new(r.navigation.substitute(declared)),
        None => Box::new(PassThrough),
    }
}
