//! Truth and knowledge: one run's realisation of the declared uncertainty
//! ([`sc_scenario::Uncertainty`]).
//!
//! * [`PlantErrors`] make the simulated plant differ from the model the filters and
//!   nominals use (mass properties of the servicer, its arm and the target).
//! * [`ActuatorErrors`] make what the actuators deliver differ from the applied command.
//! * [`DeclaredNavigation`] turns the measurement into the estimate the controllers and
//!   filters act on: bias and noise on every navigated quantity
//!   ([`crate::navigation`]: the measurement's age, the gate, the declared model).
//!
//! Every draw stays inside its bound (uniform inside the bound, noise truncated at it):
//! the bounds are what the filters' margins may rest on. A realisation is a function of
//! the bounds and the seed only.

use crate::navigation::DeclaredNavigation;
use crate::state::Simulator;
use nalgebra::{Matrix3, Vector3};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};
use sc_models::quat;
use sc_multibody::{NJ, Robot, Vector7};
use sc_scenario::uncertainty::{ActuatorBounds, BiasNoise, ModelBounds, NavigationBounds};
use sc_scenario::{Scenario, Uncertainty};
use serde::Serialize;

/// The random stream of the per-step draws (noise, ripple), separate from the draws made
/// once per run so that adding a per-step source does not change a run's plant.
const STEP_STREAM: u64 = 1;

/// The random stream of the simulator's own navigation, substituted for a rejected
/// estimate (apart from the navigation's so that the two never share their noise).
pub(crate) const SUBSTITUTE_STREAM: u64 = STEP_STREAM + 2;

/// A uniform draw in `[0, 1)` (53 bits).
fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Uniform in `[-b, b]`.
fn symmetric(rng: &mut ChaCha8Rng, b: f64) -> f64 {
    b * (2.0 * unit(rng) - 1.0)
}

/// A standard normal draw (Box–Muller).
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - unit(rng); // in (0, 1]
    let u2 = unit(rng);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Uniform in the ball of radius `b`.
fn in_ball(rng: &mut ChaCha8Rng, b: f64) -> Vector3<f64> {
    let d = Vector3::new(normal(rng), normal(rng), normal(rng));
    let n = d.norm();
    if b == 0.0 || n == 0.0 {
        return Vector3::zeros();
    }
    d * (b * unit(rng).cbrt() / n)
}

/// Normal with σ = `bound`/3 per component, its norm truncated at `bound` (redrawn,
/// then scaled onto the bound if the redraws run out).
pub(crate) fn truncated(rng: &mut ChaCha8Rng, bound: f64) -> Vector3<f64> {
    const REDRAWS: usize = 8;
    if bound == 0.0 {
        return Vector3::zeros();
    }
    let sigma = bound / 3.0;
    let mut v = Vector3::zeros();
    for _ in 0..REDRAWS {
        v = Vector3::new(normal(rng), normal(rng), normal(rng)) * sigma;
        if v.norm() <= bound {
            return v;
        }
    }
    v * (bound / v.norm())
}

/// The scalar version of [`truncated`]: redrawn outside the bound (a clamp would put
/// 0.27 % of the draws exactly on it), projected only after the last redraw.
pub(crate) fn truncated1(rng: &mut ChaCha8Rng, bound: f64) -> f64 {
    const REDRAWS: usize = 8;
    if bound == 0.0 {
        return 0.0;
    }
    let mut x = 0.0;
    for _ in 0..REDRAWS {
        x = normal(rng) * bound / 3.0;
        if x.abs() <= bound {
            return x;
        }
    }
    x.clamp(-bound, bound)
}

/// The rotation by the small rotation vector `v` [rad] as a quaternion.
pub(crate) fn rotation(v: &Vector3<f64>) -> quat::Quat {
    let a = v.norm();
    if a == 0.0 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let s = (0.5 * a).sin() / a;
    [(0.5 * a).cos(), v.x * s, v.y * s, v.z * s]
}

/// The drawn mass-property errors of the plant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlantErrors {
    pub servicer_mass_scale: f64,
    pub servicer_inertia_scale: f64,
    pub servicer_com_offset_m: [f64; 3],
    pub link_mass_scale: [f64; NJ],
    pub link_inertia_scale: [f64; NJ],
    /// Scale of each diagonal entry of the target inertia (`D I D`, `D = diag(√s)`).
    pub target_inertia_scale: [f64; 3],
}

impl PlantErrors {
    fn draw(b: &ModelBounds, rng: &mut ChaCha8Rng) -> Self {
        let mut scale = |bound: f64| 1.0 + symmetric(rng, bound);
        let servicer_mass_scale = scale(b.servicer_mass_rel);
        let servicer_inertia_scale = scale(b.servicer_inertia_rel);
        let link_mass_scale = std::array::from_fn(|_| scale(b.link_mass_rel));
        let link_inertia_scale = std::array::from_fn(|_| scale(b.link_inertia_rel));
        let target_inertia_scale = std::array::from_fn(|_| scale(b.target_inertia_rel));
        let com = in_ball(rng, b.servicer_com_m);
        Self {
            servicer_mass_scale,
            servicer_inertia_scale,
            servicer_com_offset_m: com.into(),
            link_mass_scale,
            link_inertia_scale,
            target_inertia_scale,
        }
    }

    /// The plant: the declared robot and scenario with these errors; `None` if a scaled
    /// body is not physical (cannot happen for validated bounds).
    pub fn apply(&self, scenario: &Scenario, robot: &Robot) -> Option<(Scenario, Robot)> {
        let com = Vector3::from(self.servicer_com_offset_m);
        let mut plant = robot.with_body_mass_properties(
            0,
            self.servicer_mass_scale,
            self.servicer_inertia_scale,
            com,
        )?;
        for k in 0..NJ {
            plant = plant.with_body_mass_properties(
                k + 1,
                self.link_mass_scale[k],
                self.link_inertia_scale[k],
                Vector3::zeros(),
            )?;
        }
        let mut truth = scenario.clone();
        let d = self.target_inertia_scale.map(f64::sqrt);
        for (i, row) in truth.target.inertia_kg_m2.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x *= d[i] * d[j];
            }
        }
        let t = truth.target.inertia_kg_m2;
        is_inertia(&Matrix3::from_fn(|i, j| t[i][j])).then_some((truth, plant))
    }
}

/// The keys whose largest relative deviation `|scale − 1|` in `scales` exceeds `bound`.
fn scale_outside(key: &'static str, scales: &[f64], bound: f64) -> Option<&'static str> {
    let worst = scales.iter().map(|s| (s - 1.0).abs()).fold(0.0, f64::max);
    (worst > bound || scales.iter().any(|s| !s.is_finite())).then_some(key)
}

impl PlantErrors {
    /// The `[model]` keys whose realised error exceeds the declared bound `b`.
    pub fn outside(&self, b: &ModelBounds) -> Vec<&'static str> {
        let com = Vector3::from(self.servicer_com_offset_m).norm();
        [
            scale_outside(
                "model.servicer_mass_rel",
                &[self.servicer_mass_scale],
                b.servicer_mass_rel,
            ),
            scale_outside(
                "model.servicer_inertia_rel",
                &[self.servicer_inertia_scale],
                b.servicer_inertia_rel,
            ),
            (com > b.servicer_com_m).then_some("model.servicer_com_m"),
            scale_outside(
                "model.link_mass_rel",
                &self.link_mass_scale,
                b.link_mass_rel,
            ),
            scale_outside(
                "model.link_inertia_rel",
                &self.link_inertia_scale,
                b.link_inertia_rel,
            ),
            scale_outside(
                "model.target_inertia_rel",
                &self.target_inertia_scale,
                b.target_inertia_rel,
            ),
        ]
        .into_iter()
        .flatten()
        .collect()
    }
}

/// The drawn actuator errors, and the stream of the per-step ripple.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ActuatorErrors {
    pub force_scale: f64,
    /// Rotation vector of the thrusters' misalignment [rad].
    pub force_misalignment_rad: [f64; 3],
    pub torque_scale: f64,
    pub joint_torque_scale: [f64; NJ],
    pub joint_torque_bias_nm: [f64; NJ],
    pub joint_torque_ripple_rel: f64,
    #[serde(skip)]
    rng: ChaCha8Rng,
}

impl ActuatorErrors {
    fn draw(b: &ActuatorBounds, rng: &mut ChaCha8Rng, step_rng: ChaCha8Rng) -> Self {
        let force_scale = 1.0 + symmetric(rng, b.thruster_force_scale_rel);
        let mis = in_ball(rng, b.thruster_misalignment_rad);
        let torque_scale = 1.0 + symmetric(rng, b.body_torque_scale_rel);
        let joint_torque_scale =
            std::array::from_fn(|_| 1.0 + symmetric(rng, b.joint_torque_scale_rel));
        let joint_torque_bias_nm = std::array::from_fn(|_| symmetric(rng, b.joint_torque_bias_nm));
        Self {
            force_scale,
            force_misalignment_rad: mis.into(),
            torque_scale,
            joint_torque_scale,
            joint_torque_bias_nm,
            joint_torque_ripple_rel: b.joint_torque_ripple_rel,
            rng: step_rng,
        }
    }

    /// The `[actuators]` keys whose realised error exceeds the declared bound `b`.
    pub fn outside(&self, b: &ActuatorBounds) -> Vec<&'static str> {
        let mis = Vector3::from(self.force_misalignment_rad).norm();
        let bias = self.joint_torque_bias_nm.iter().map(|x| x.abs());
        [
            scale_outside(
                "actuators.thruster_force_scale_rel",
                &[self.force_scale],
                b.thruster_force_scale_rel,
            ),
            (mis > b.thruster_misalignment_rad).then_some("actuators.thruster_misalignment_rad"),
            scale_outside(
                "actuators.body_torque_scale_rel",
                &[self.torque_scale],
                b.body_torque_scale_rel,
            ),
            scale_outside(
                "actuators.joint_torque_scale_rel",
                &self.joint_torque_scale,
                b.joint_torque_scale_rel,
            ),
            (bias.fold(0.0, f64::max) > b.joint_torque_bias_nm)
                .then_some("actuators.joint_torque_bias_nm"),
            (self.joint_torque_ripple_rel > b.joint_torque_ripple_rel)
                .then_some("actuators.joint_torque_ripple_rel"),
        ]
        .into_iter()
        .flatten()
        .collect()
    }

    /// What the actuators deliver over the next period for the applied command `u`.
    pub fn deliver(&mut self, u: &sc_core::Command) -> sc_core::Command {
        let mis = quat::to_matrix(&rotation(&Vector3::from(self.force_misalignment_rad)));
        let tau = Vector7::from_fn(|k, _| {
            let ripple = 1.0 + symmetric(&mut self.rng, self.joint_torque_ripple_rel);
            u.tau[k] * self.joint_torque_scale[k] * ripple + self.joint_torque_bias_nm[k]
        });
        sc_core::Command {
            force_b: mis * u.force_b * self.force_scale,
            torque_b: u.torque_b * self.torque_scale,
            tau,
        }
    }
}

/// One step's realised navigation errors (norms; joints: the largest of the seven).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct NavigationError {
    pub relative_position_m: f64,
    pub relative_velocity_m_s: f64,
    pub servicer_attitude_rad: f64,
    pub servicer_rate_rad_s: f64,
    pub target_attitude_rad: f64,
    pub target_rate_rad_s: f64,
    pub grasp_point_m: f64,
    pub joint_angle_rad: f64,
    pub joint_rate_rad_s: f64,
    /// Age of the measurement the estimate rests on [s].
    pub measurement_age_s: f64,
}

/// Relative rounding allowed when a measurement age is turned into physics steps.
pub(crate) const AGE_ROUNDING: f64 = 1e-9;

/// How far a realised navigation error may exceed its bound before it counts as
/// outside it, in the quantity's own unit: the error is recomputed as the difference of
/// the estimate and the truth, whose rounding (a few ulps of the state, ≲ 1e-14 here) a
/// bound at the edge would otherwise cross; and the age is whole physics steps, equal
/// to the declared age up to [`AGE_ROUNDING`].
pub const NAVIGATION_ERROR_ROUNDING: f64 = 1e-12;

/// Names of [`NavigationError`]'s fields, in order (telemetry columns, summaries).
pub const NAVIGATION_ERROR_NAMES: [&str; 10] = [
    "relative_position_m",
    "relative_velocity_m_s",
    "servicer_attitude_rad",
    "servicer_rate_rad_s",
    "target_attitude_rad",
    "target_rate_rad_s",
    "grasp_point_m",
    "joint_angle_rad",
    "joint_rate_rad_s",
    "measurement_age_s",
];

impl NavigationError {
    /// The values in [`NAVIGATION_ERROR_NAMES`]' order.
    pub fn values(&self) -> [f64; 10] {
        [
            self.relative_position_m,
            self.relative_velocity_m_s,
            self.servicer_attitude_rad,
            self.servicer_rate_rad_s,
            self.target_attitude_rad,
            self.target_rate_rad_s,
            self.grasp_point_m,
            self.joint_angle_rad,
            self.joint_rate_rad_s,
            self.measurement_age_s,
        ]
    }

    /// From values in [`NAVIGATION_ERROR_NAMES`]' order ([`Self::values`]' inverse).
    pub fn from_values(v: &[f64; 10]) -> Self {
        Self {
            relative_position_m: v[0],
            relative_velocity_m_s: v[1],
            servicer_attitude_rad: v[2],
            servicer_rate_rad_s: v[3],
            target_attitude_rad: v[4],
            target_rate_rad_s: v[5],
            grasp_point_m: v[6],
            joint_angle_rad: v[7],
            joint_rate_rad_s: v[8],
            measurement_age_s: v[9],
        }
    }

    /// The declared bounds in the same order.
    pub fn bounds(b: &NavigationBounds) -> [f64; 10] {
        let e = b.errors().map(|(_, x): (&str, BiasNoise)| x.bound());
        [
            e[0],
            e[1],
            e[2],
            e[3],
            e[4],
            e[5],
            e[6],
            e[7],
            e[8],
            b.measurement_age_s,
        ]
    }
}

/// The per-run biases of the navigation errors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NavigationBias {
    pub relative_position_m: [f64; 3],
    pub relative_velocity_m_s: [f64; 3],
    pub servicer_attitude_rad: [f64; 3],
    pub servicer_rate_rad_s: [f64; 3],
    pub target_attitude_rad: [f64; 3],
    pub target_rate_rad_s: [f64; 3],
    pub grasp_point_m: [f64; 3],
    pub joint_angle_rad: [f64; NJ],
    pub joint_rate_rad_s: [f64; NJ],
}

impl NavigationBias {
    fn draw(b: &NavigationBounds, rng: &mut ChaCha8Rng) -> Self {
        let mut ball = |x: BiasNoise| in_ball(rng, x.bias).into();
        let relative_position_m = ball(b.relative_position_m);
        let relative_velocity_m_s = ball(b.relative_velocity_m_s);
        let servicer_attitude_rad = ball(b.servicer_attitude_rad);
        let servicer_rate_rad_s = ball(b.servicer_rate_rad_s);
        let target_attitude_rad = ball(b.target_attitude_rad);
        let target_rate_rad_s = ball(b.target_rate_rad_s);
        let grasp_point_m = ball(b.grasp_point_m);
        Self {
            relative_position_m,
            relative_velocity_m_s,
            servicer_attitude_rad,
            servicer_rate_rad_s,
            target_attitude_rad,
            target_rate_rad_s,
            grasp_point_m,
            joint_angle_rad: std::array::from_fn(|_| symmetric(rng, b.joint_angle_rad.bias)),
            joint_rate_rad_s: std::array::from_fn(|_| symmetric(rng, b.joint_rate_rad_s.bias)),
        }
    }
}

/// One run's realisation: the plant, the actuators and the navigation.
#[derive(Debug, Clone)]
pub struct Realisation {
    pub plant: PlantErrors,
    pub actuators: ActuatorErrors,
    /// The navigation's errors (the default navigation's estimator).
    pub navigation: DeclaredNavigation,
    /// The plant's scenario and robot (the truth the simulator propagates).
    pub true_scenario: Scenario,
    pub true_robot: Robot,
}

/// Why a realisation could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UncertaintyError {
    #[error(
        "the drawn plant is not physical (a mass or inertia scale ≤ 0, or a target inertia that breaks the triangle inequality: lower `uncertainty.model.target_inertia_rel`)"
    )]
    NotPhysical,
    #[error("{0}")]
    Simulator(String),
}

/// Draws of a plant before its bounds are refused as admitting no physical body.
const MAX_PLANT_DRAWS: usize = 100;

impl Realisation {
    /// The realisation of `scenario`'s declared uncertainty, drawn from its seed and its
    /// truth bounds (`uncertainty.truth`, else the declared ones); `None` when it declares
    /// none (truth and knowledge are one). The mission in one process and the partition's
    /// simulator draw the same realisation from the same scenario.
    pub fn declared(scenario: &Scenario, robot: &Robot) -> Result<Option<Self>, UncertaintyError> {
        let Some(spec) = scenario.uncertainty.as_ref() else {
            return Ok(None);
        };
        Self::draw(
            &scenario.uncertainty_truth_bounds(),
            spec.seed,
            scenario,
            robot,
        )
        .map(Some)
    }

    /// Draws the realisation of `bounds` with `seed` for the declared `scenario` and
    /// `robot`.
    pub fn draw(
        bounds: &Uncertainty,
        seed: u64,
        scenario: &Scenario,
        robot: &Robot,
    ) -> Result<Self, UncertaintyError> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut step_rng = ChaCha8Rng::seed_from_u64(seed);
        step_rng.set_stream(STEP_STREAM);
        // independent scales of the target's principal moments can break its triangle
        // inequality (a flat target): such a plant is drawn again from the same stream,
        // so the draw stays inside the bounds, physical and a function of the seed
        let (plant, (true_scenario, true_robot)) = (0..MAX_PLANT_DRAWS)
            .find_map(|_| {
                let plant = PlantErrors::draw(&bounds.model, &mut rng);
                plant.apply(scenario, robot).map(|truth| (plant, truth))
            })
            .ok_or(UncertaintyError::NotPhysical)?;
        let actuators = ActuatorErrors::draw(&bounds.actuators, &mut rng, step_rng.clone());
        let bias = NavigationBias::draw(&bounds.navigation, &mut rng);
        let knower = Simulator::new(scenario, std::sync::Arc::new(robot.clone()))
            .map_err(|e| UncertaintyError::Simulator(e.to_string()))?;
        step_rng.set_stream(STEP_STREAM + 1);
        let r_ir = quat::to_matrix(&knower.p.q_ir);
        let navigation = DeclaredNavigation::new(bounds.navigation, bias, r_ir, step_rng);
        Ok(Self {
            plant,
            actuators,
            navigation,
            true_scenario,
            true_robot,
        })
    }
}

/// True if `i` is the inertia of a rigid body: positive principal moments that meet the
/// triangle inequalities.
pub fn is_inertia(i: &Matrix3<f64>) -> bool {
    let e = i.symmetric_eigen().eigenvalues;
    let (a, b, c) = (e[0], e[1], e[2]);
    a > 0.0 && b > 0.0 && c > 0.0 && a + b >= c && a + c >= b && b + c >= a
}
