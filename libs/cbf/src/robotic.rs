//! Robotic safety filter (paper Sec. "CBFs for the Robotic Subsystem", QP eq.
//! "robotic_qp").
//!
//! State `x_rob = [θ; θ̇]` (rad, rad/s); input the joint torques `τ_M` [N m]. The rows take
//! the *precomputed* reduced free-floating arm dynamics in control-affine form
//!
//! ```text
//! θ̈ = A τ_M + b + ξ_rob,    A = M_eff⁻¹,  b = −M_eff⁻¹ c_free,  ξ_rob = −M_eff⁻¹ K [f_B; τ_B]
//! ```
//!
//! where `ξ_rob` [rad/s²] is the effect on the arm of the base acceleration produced by the
//! upstream safe force and torque (`K` the wrench map of the Schur-reduced dynamics), and per
//! collision sphere its centre `p_i`, Jacobian `J_i` and `J̇_i θ̇` in the base frame F_B.
//! [`robotic_input_from_model`] computes all of these from `sc_multibody`.
//!
//! **Sampled data at 10 Hz.** The arm's light distal links make its joint accelerations
//! change by tens of rad/s² inside one 0.1 s sample (docs/SAFETY.md, "The arm at 10 Hz"),
//! so the analytic bounds of [`crate::sampled`] — with the joint jerk bounded over the
//! envelope (`joint_jerk_bound_rad_s3`) — give a cheap candidate away from the limits.
//! Every command is then **verified**: with the servicer model the filter integrates the
//! sample exactly as the simulator does (RK4 at the physics step, the upstream force and
//! torque held) and checks every barrier at every physics step and the braking barrier at
//! the next sample, so the certificate does not rest on the jerk bounds (sampled maxima,
//! not proven ones). Where the cheap candidate fails or does not verify, a row whose
//! prediction fell short gets the shortfall as a margin and the QP is solved again.
//!
//! **Contract with the attitude filter.** The command keeps the reaction on the base
//! angular acceleration of what the arm does beyond holding its joint rates within the
//! budget the attitude filter assumes, `|(Q (τ_M − τ_hold))_i| ≤ β_i` (six hard rows).

use crate::arm_target::TargetBody;
use crate::barrier::{RelDegOne, RelDegTwo, Row};
use crate::common::{self, BOX_MARGIN, FilterOutput, FilterReport, clamp_box};
use crate::engine::{Engine, Kind, LastProblem, Outcome, SolverTally};
use crate::filter::{Coupling, SafetyFilter};
use crate::link_target::{self, Sampled, Surroundings, TargetMotion};
use crate::sampled::{
    Decay, RateBounds, RateDecay, SampleBounds, braking_barrier, hdot_required_of, phi_required_of,
};
use crate::step::{self, Actuated, FilterStep, Invalid, Solved};
use crate::{Formulation, qp::SolverParams};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3, Vector6};
use sc_core::{Observation, Subsystem};
use sc_multibody::{CollisionSphere, ComTerms, Robot, Vector13};
use std::sync::Arc;

/// Joint-space vector and matrix.
pub type Vector7 = SVector<f64, 7>;
pub type Matrix7 = SMatrix<f64, 7, 7>;
/// Point Jacobian (3×7).
pub type Matrix3x7 = SMatrix<f64, 3, 7>;

/// Number of joints, link collision spheres, constraints (the joints' angles and rates,
/// every sphere against the base, every sphere against the target).
pub const NJ: usize = 7;
pub const NS: usize = 21;
pub const N: usize = 3 * NJ + 2 * NS;

/// Constraint names in report order: `theta_1..7`, `theta_dot_max_1..7`,
/// `theta_dot_min_1..7`, `link_base_<link>_<k>` (link 1..7, sphere k 1..3 along the link),
/// `link_target_<link>_<k>` (the same spheres against the target, [`crate::link_target`]).
pub const NAMES: [&str; N] = [
    "theta_1",
    "theta_2",
    "theta_3",
    "theta_4",
    "theta_5",
    "theta_6",
    "theta_7",
    "theta_dot_max_1",
    "theta_dot_max_2",
    "theta_dot_max_3",
    "theta_dot_max_4",
    "theta_dot_max_5",
    "theta_dot_max_6",
    "theta_dot_max_7",
    "theta_dot_min_1",
    "theta_dot_min_2",
    "theta_dot_min_3",
    "theta_dot_min_4",
    "theta_dot_min_5",
    "theta_dot_min_6",
    "theta_dot_min_7",
    "link_base_1_1",
    "link_base_1_2",
    "link_base_1_3",
    "link_base_2_1",
    "link_base_2_2",
    "link_base_2_3",
    "link_base_3_1",
    "link_base_3_2",
    "link_base_3_3",
    "link_base_4_1",
    "link_base_4_2",
    "link_base_4_3",
    "link_base_5_1",
    "link_base_5_2",
    "link_base_5_3",
    "link_base_6_1",
    "link_base_6_2",
    "link_base_6_3",
    "link_base_7_1",
    "link_base_7_2",
    "link_base_7_3",
    "link_target_1_1",
    "link_target_1_2",
    "link_target_1_3",
    "link_target_2_1",
    "link_target_2_2",
    "link_target_2_3",
    "link_target_3_1",
    "link_target_3_2",
    "link_target_3_3",
    "link_target_4_1",
    "link_target_4_2",
    "link_target_4_3",
    "link_target_5_1",
    "link_target_5_2",
    "link_target_5_3",
    "link_target_6_1",
    "link_target_6_2",
    "link_target_6_3",
    "link_target_7_1",
    "link_target_7_2",
    "link_target_7_3",
];

/// Index of the first link–target row.
pub const LINK_TARGET: usize = 3 * NJ + NS;

/// Accepted ranges of the model terms (any finite joint angle and rate is accepted: the
/// filter never switches itself off): drift and coupling accelerations `≤ MAX_ACCEL`, `A`
/// entries `≤ MAX_GAIN`, sphere centres `≤ MAX_REACH_M`. Beyond them the braking law applies.
pub const MAX_ACCEL: f64 = 1e6;
/// Accepted range of the upstream state the verification integrates with: base rate
/// `≤ MAX_BASE_RATE_RAD_S`, base force and torque components `≤ MAX_WRENCH` (N, N m).
pub const MAX_BASE_RATE_RAD_S: f64 = 10.0;
pub const MAX_WRENCH: f64 = 1e4;
pub const MAX_GAIN: f64 = 1e6;
pub const MAX_REACH_M: f64 = 100.0;

/// One link collision sphere, base frame F_B.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SphereTerms {
    /// Centre `p_i(θ)` [m].
    pub center: Vector3<f64>,
    /// `J_i = ∂p_i/∂θ` [m/rad].
    pub jacobian: Matrix3x7,
    /// `J̇_i θ̇` [m/s²].
    pub jdot_qdot: Vector3<f64>,
    /// `ρ_i` [m].
    pub radius: f64,
}

/// Everything the robotic filter needs at one control step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoboticInput {
    pub theta: Vector7,
    pub theta_dot: Vector7,
    /// `A = M_eff⁻¹` (the reduced free-floating joint-space inverse inertia) [1/(kg m²)].
    pub a: Matrix7,
    /// `M_eff` [kg m²] (the braking law `τ_M = sat(−M θ̇/T)`).
    pub m_eff: Matrix7,
    /// `b = −M_eff⁻¹ c_free` [rad/s²]: velocity-product drift.
    pub drift: Vector7,
    /// `ξ_rob = −M_eff⁻¹ K [f_B,SF; τ_B,SF]` [rad/s²]: coupling of the upstream safe wrench.
    pub xi: Vector7,
    /// The 21 link spheres (link-major: link 1 spheres 1..3, link 2, …).
    pub spheres: [SphereTerms; NS],
    /// Base collision zone `c_base` [m] (F_B) and `R_base` [m].
    pub base_center: Vector3<f64>,
    pub base_radius: f64,
    /// `Q = ∂ω̇_B/∂τ_M` [1/(kg m²)]: the arm's reaction on the base (the contract rows).
    pub reaction: Matrix3x7,
    /// Base body rate [rad/s, F_B] and the upstream safe force [N] and torque [N m] (F_B)
    /// held over the sample: what the verification integrates with.
    pub omega_b: Vector3<f64>,
    pub force_b: Vector3<f64>,
    pub torque_b: Vector3<f64>,
    /// The system CoM relative to the base, F_B (the link–target rows).
    pub com: ComTerms,
    /// `ω̇_B` at `τ_M = 0` under the upstream safe force and torque [rad/s², F_B].
    pub omega_dot_b0: Vector3<f64>,
    /// The servicer's mass [kg].
    pub total_mass: f64,
    /// Where the servicer and the target are, from the observation; `None` for an input
    /// built from the model alone (no target known: the link–target rows read
    /// [`link_target::FAR_M`]² and hold for any command — tests and the envelope's samples).
    pub around: Option<Surroundings>,
}

/// Parameters of the robotic filter.
#[derive(Debug, Clone, PartialEq)]
pub struct RoboticParams {
    pub theta_min: Vector7,
    pub theta_max: Vector7,
    /// Symmetric `|θ̇_i| ≤ θ̇_max,i` [rad/s].
    pub theta_dot_max: Vector7,
    /// γ_h [1/s], ε_θ [rad²/s], μ of H_θ [rad²/s²].
    pub gamma: f64,
    pub eps_theta: f64,
    pub u_max_theta: f64,
    /// γ_θ̇ [1/s], ε_θ̇ [rad/s²].
    pub gamma_theta_dot: f64,
    pub eps_theta_dot: f64,
    /// ε_LB [m²/s], μ of H_LB [m²/s²].
    pub eps_lb: f64,
    pub u_max_lb: f64,
    /// `‖τ_M‖∞ ≤ T_M` [N m].
    pub torque_max: f64,
    /// T of the braking law `τ_M = sat(−M θ̇ / T)` [s]: the substitute nominal.
    pub brake_time: f64,
    pub solver: SolverParams,
    /// Sample length `T` [s] and the simulator's physics step [s] (the verification's).
    pub period: f64,
    pub physics_step: f64,
    pub formulation: Formulation,
    /// Bound on `|θ⃛_i|` over the certified envelope [rad/s³].
    pub joint_jerk_bound: Vector7,
    /// Bound on the jerk of the centres of each link's spheres [m/s³] (link 1..7).
    pub sphere_jerk_bound: Vector7,
    /// The contract with the attitude filter, `|(Q τ_M)_i| ≤ β_i` [rad/s²].
    pub arm_reaction_budget: Vector3<f64>,
    /// The declared bound on what the joint motors deliver beyond the command
    /// ([`TorqueError`]); zero for the `exact` profile, where the rows are the nominal
    /// ones bit for bit.
    pub joint_torque_error: TorqueError,
    /// The target's keep-out spheres, its declared inertia [kg m²] and the inverse (the
    /// verification propagates its tumble; the scenario's validation makes the inertia
    /// positive definite).
    pub target: TargetBody,
    pub target_inertia: Matrix3<f64>,
    pub target_inertia_inv: Matrix3<f64>,
}

/// The declared bound on the joint motors' torque error, from the scenario's
/// `[uncertainty.actuators]`: a motor delivers `τ (1 + s)(1 + r) + b` with `|s|`, `|r|`,
/// `|b|` within their bounds, so `|Δτ_k| ≤ rel |τ_k| + bias_k` with `rel = s + r + s r`
/// (docs/SAFETY.md, "Margins for the declared errors").
///
/// Built only from bounds that are finite and non-negative (anything else is refused as
/// no bound at all would be: [`TorqueError::new`] returns `None`), so the rows never see
/// a NaN or a negative margin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorqueError {
    /// `rel` [-].
    rel: f64,
    /// `bias_k` [N m].
    bias: Vector7,
}

impl TorqueError {
    /// `rel` [-] and `bias` [N m], each finite and ≥ 0; `None` otherwise.
    pub fn new(rel: f64, bias: Vector7) -> Option<Self> {
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        (ok(rel) && bias.iter().all(|b| ok(*b))).then_some(Self { rel, bias })
    }

    /// No error.
    pub fn none() -> Self {
        Self {
            rel: 0.0,
            bias: Vector7::zeros(),
        }
    }

    /// From the scenario's declared bounds (validated by the scenario: finite, ≥ 0).
    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        Self::from_actuators(&s.uncertainty_bounds().actuators)
    }

    /// From the declared actuator bounds; [`TorqueError::none`] if they are not finite
    /// and non-negative (the scenario's validation refuses such bounds before).
    pub fn from_actuators(a: &sc_scenario::uncertainty::ActuatorBounds) -> Self {
        let (sc, r) = (a.joint_torque_scale_rel, a.joint_torque_ripple_rel);
        Self::new(sc + r + sc * r, Vector7::repeat(a.joint_torque_bias_nm))
            .unwrap_or_else(Self::none)
    }

    /// No error declared.
    pub fn is_zero(&self) -> bool {
        self.rel == 0.0 && self.bias.iter().all(|b| *b == 0.0)
    }

    /// `e_k = rel τ̄_k + bias_k` [N m] for torques `|τ_k| ≤ τ̄_k`.
    pub fn at(&self, torque_cap: &Vector7) -> Vector7 {
        torque_cap.abs() * self.rel + self.bias
    }
}

impl RoboticParams {
    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        let r = &s.safety.robotic;
        let inertia = Matrix3::from_row_slice(&s.target.inertia_kg_m2.concat());
        Self {
            theta_min: Vector7::from(r.theta_min_rad),
            theta_max: Vector7::from(r.theta_max_rad),
            theta_dot_max: Vector7::from(r.theta_dot_max_rad_s),
            gamma: s.safety.gamma_per_s,
            eps_theta: r.eps_theta,
            u_max_theta: r.u_max_theta_rad2_s2,
            gamma_theta_dot: r.gamma_theta_dot_per_s,
            eps_theta_dot: r.eps_theta_dot,
            eps_lb: r.eps_lb,
            u_max_lb: r.u_max_lb_m2_s2,
            torque_max: s.limits.joint_torque_max_nm,
            brake_time: s.safety.fallback.robotic_brake_time_s,
            solver: SolverParams::from_scenario(s),
            period: s.mission.control_period_s,
            physics_step: s.mission.physics_step_s,
            formulation: s.safety.formulation,
            joint_jerk_bound: Vector7::from(r.joint_jerk_bound_rad_s3),
            sphere_jerk_bound: Vector7::from(r.link_sphere_jerk_bound_m_s3),
            arm_reaction_budget: Vector3::from(s.safety.attitude.arm_reaction_budget_rad_s2),
            joint_torque_error: TorqueError::from_scenario(s),
            target: TargetBody::from_scenario(s),
            target_inertia: inertia,
            // validated positive definite; a singular one would predict no tumble
            target_inertia_inv: inertia.try_inverse().unwrap_or_else(Matrix3::zeros),
        }
    }
}

/// Joint-angle limit, paper eq. "CBF-joint-angle": `h = (θ−θ_min)(θ_max−θ)` [rad²],
/// `ḣ = θ̇ (θ_max + θ_min − 2θ)`, `ḧ = θ̈ (θ_max + θ_min − 2θ) − 2θ̇²`, `θ̈_i = A_i τ + b_i + ξ_i`.
pub fn joint_angle(i: usize, x: &RoboticInput, theta_min: f64, theta_max: f64) -> RelDegTwo<NJ> {
    let th = x.theta[i];
    let thd = x.theta_dot[i];
    let k = theta_max + theta_min - 2.0 * th;
    RelDegTwo {
        h: (th - theta_min) * (theta_max - th),
        hdot: thd * k,
        hddot_drift: k * (x.drift[i] + x.xi[i]) - 2.0 * thd * thd,
        hddot_u: x.a.row(i).transpose() * k,
    }
}

/// Joint-velocity limits, paper eq. "CBF-joint-velocity": `h⁺ = θ̇_max − θ̇_i`,
/// `h⁻ = θ̇_i − θ̇_min` with `θ̇_min = −θ̇_max` [rad/s]; relative degree one.
pub fn joint_velocity(i: usize, x: &RoboticInput, theta_dot_max: f64) -> [RelDegOne<NJ>; 2] {
    let acc0 = x.drift[i] + x.xi[i];
    let a: Vector7 = x.a.row(i).transpose();
    [
        RelDegOne {
            h: theta_dot_max - x.theta_dot[i],
            hdot_drift: -acc0,
            hdot_u: -a,
        },
        RelDegOne {
            h: x.theta_dot[i] + theta_dot_max,
            hdot_drift: acc0,
            hdot_u: a,
        },
    ]
}

/// Link–base collision sphere, paper eq. "CBF-link-base":
/// `h = ‖p_i − c_base‖² − (ρ_i + R_base)²` [m²], `ḣ = 2 dᵀ J θ̇` (`d = p_i − c_base`),
/// `ḧ = 2‖Jθ̇‖² + 2 dᵀ(J θ̈ + J̇θ̇)`, so `∂ḧ/∂τ = 2 Aᵀ Jᵀ d`.
pub fn link_base(s: &SphereTerms, x: &RoboticInput) -> RelDegTwo<NJ> {
    let d = s.center - x.base_center;
    let v = s.jacobian * x.theta_dot;
    let jtd = tr_mul(&s.jacobian, &d);
    let rr = s.radius + x.base_radius;
    RelDegTwo {
        h: d.dot(&d) - rr * rr,
        hdot: 2.0 * d.dot(&v),
        hddot_drift: 2.0 * v.dot(&v) + 2.0 * jtd.dot(&(x.drift + x.xi)) + 2.0 * d.dot(&s.jdot_qdot),
        hddot_u: tr_mul(&x.a, &jtd) * 2.0,
    }
}

/// `rows` with their offsets replaced by `c` (the same normals).
fn with_offsets(rows: &[Row<NJ>; N], c: &[f64; N]) -> [Row<NJ>; N] {
    std::array::from_fn(|j| Row {
        a: rows[j].a,
        c: c[j],
    })
}

/// `mᵀ v` without forming `mᵀ` (21 of these per step), summed in the order of
/// `m.transpose() * v`, so the bits are the same.
fn tr_mul<const R: usize, const C: usize>(
    m: &SMatrix<f64, R, C>,
    v: &SVector<f64, R>,
) -> SVector<f64, C> {
    // the sums of all columns advance together (independent chains, each in the order
    // `k = 0, 1, …` of the dot product)
    let mut s: SVector<f64, C> = SVector::from_fn(|i, _| m[(0, i)] * v[0]);
    for k in 1..R {
        for i in 0..C {
            s[i] += m[(k, i)] * v[k];
        }
    }
    s
}

/// All barrier terms of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoboticTerms {
    pub theta: [RelDegTwo<NJ>; NJ],
    pub theta_dot_max: [RelDegOne<NJ>; NJ],
    pub theta_dot_min: [RelDegOne<NJ>; NJ],
    pub link_base: [RelDegTwo<NJ>; NS],
    pub link_target: [RelDegTwo<NJ>; NS],
}

impl RoboticTerms {
    /// The normal `a_j` of sampled-data row `j` ([`NAMES`] order) at every level:
    /// `∂ḧ/∂τ_M` or `∂ḣ/∂τ_M`.
    fn normal(&self, j: usize) -> Vector7 {
        if j < NJ {
            self.theta[j].hddot_u
        } else if j < 2 * NJ {
            self.theta_dot_max[j - NJ].hdot_u
        } else if j < 3 * NJ {
            self.theta_dot_min[j - 2 * NJ].hdot_u
        } else if j < LINK_TARGET {
            self.link_base[j - 3 * NJ].hddot_u
        } else {
            self.link_target[j - LINK_TARGET].hddot_u
        }
    }

    /// The relative-degree-two terms of sphere row `j` (link–base or link–target).
    fn sphere(&self, j: usize) -> &RelDegTwo<NJ> {
        if j < LINK_TARGET {
            &self.link_base[j - 3 * NJ]
        } else {
            &self.link_target[j - LINK_TARGET]
        }
    }

    /// `h` of every constraint in [`NAMES`] order.
    pub fn h(&self) -> [f64; N] {
        let mut h = [0.0; N];
        for i in 0..NJ {
            h[i] = self.theta[i].h;
            h[NJ + i] = self.theta_dot_max[i].h;
            h[2 * NJ + i] = self.theta_dot_min[i].h;
        }
        for k in 0..NS {
            h[3 * NJ + k] = self.link_base[k].h;
            h[LINK_TARGET + k] = self.link_target[k].h;
        }
        h
    }
}

/// Validated input: the barrier terms, the rows' weights and the hard rows (input bounds,
/// then the contract with the attitude filter).
pub(crate) struct Prepared {
    terms: RoboticTerms,
    weights: [f64; N],
    hard: [Row<NJ>; 2 * NJ + 6],
}

/// The rows behind a robotic command besides the local ones, written where
/// [`FilterStep::solve_qp`] keeps them (they are large).
struct RowsBehind {
    /// The rows the command was solved with (`None`: the local rows).
    solved: Option<[Row<NJ>; N]>,
    /// The rows that certify it (`None`: the local rows).
    certifying: Option<[Row<NJ>; N]>,
}

/// What the a-posteriori certificate ([`RoboticFilter::certify`]) found besides the rows
/// (which it writes into the [`RowsBehind`]).
struct Certificate {
    /// The last hard solve taken.
    res: Outcome<NJ>,
    /// Solver iterations of all its solves.
    iterations: u32,
}

/// A command of the verification path ([`RoboticFilter::verified`]).
struct Verified {
    u: Vector7,
    /// The (tightened) rows it was solved with.
    rows: [Row<NJ>; N],
    /// Its violation when it came from the relaxed problem or did not verify (0 otherwise).
    violation: f64,
    /// It is Clarabel's second opinion.
    second_opinion: bool,
    /// The multipliers of its solve.
    row_duals: [f64; 64],
    bound_duals: [f64; crate::engine::MAX_HARD_ROWS],
}

/// A command the envelope bounds certified that did not verify on the model's sample:
/// where the verification path starts ([`RoboticFilter::verified`]).
struct Refuted {
    verdict: Verdict,
    candidate: Verified,
}

/// Rows of relative degree two: the joint angles and the link spheres (not the rates).
fn is_rel_deg_two(j: usize) -> bool {
    !(NJ..3 * NJ).contains(&j)
}

/// Rounds of the a-posteriori certificate before the verification path.
pub const CERTIFY_ROUNDS: usize = 2;
/// Rows of the verification path: at most this many QP + verification rounds (8: with the
/// link–target rows a step at the grasp under a 0.1 rad/s tumble needed more than 4,
/// docs/SAFETY.md "The arm and the target").
pub const MAX_VERIFY_ROUNDS: usize = 8;
/// A row whose verified shortfall is `s` gets the margin `VERIFY_GAIN · s` on the next round.
pub const VERIFY_GAIN: f64 = 1.5;
/// On the verification path, the factor on the first-order effect of the declared torque
/// error on the joint state and the sphere centres (the sum over the joints of each
/// error's own effect, [`RoboticFilter::verify`]) that covers its higher orders [-]: the
/// remainder measured over the envelope is below 2 %, kept with a factor ≥ 1.5 (test
/// `the_verification_margin_bounds_the_torque_errors_effect`).
pub const VERIFY_SECOND_ORDER: f64 = 1.1;
/// Upper bound on the distance of any sphere centre from any joint axis [m] (the arm's
/// reach plus its sphere offsets): the lever of the joints' motion in the link-base bounds.
pub const LEVER_BOUND_M: f64 = 2.0;

/// Which bounds the rows carry.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Level {
    /// Bounds valid for every command whose joint accelerations at the sample are at most
    /// the given ones and whose torques are at most the given ones (the a-posteriori
    /// certificate; the torques bound the declared torque error).
    Certified(Caps),
    /// No in-sample bounds (the sample's own prediction), the declared torque error taken
    /// for torques up to the given ones; the verification adds margins.
    Local(Vector7),
}

/// What a certified row's bounds hold for: joint accelerations at the sample
/// `|θ̈_i| ≤ accel_i` [rad/s²] and torques `|τ_k| ≤ torque_k` [N m].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Caps {
    accel: Vector7,
    torque: Vector7,
}

impl Caps {
    /// The caps of a command with joint accelerations `qdd` and torques `tau`.
    fn of(qdd: &Vector7, tau: &Vector7) -> Self {
        Self {
            accel: qdd.abs(),
            torque: tau.abs(),
        }
    }

    /// Both caps, the larger of each.
    fn sup(&self, o: &Self) -> Self {
        Self {
            accel: self.accel.sup(&o.accel),
            torque: self.torque.sup(&o.torque),
        }
    }

    /// Twice as large (the next candidate's guess).
    fn grown(&self) -> Self {
        Self {
            accel: self.accel * 2.0,
            torque: self.torque * 2.0,
        }
    }

    /// `o` is within these caps (its torques only if they `matter`).
    fn covers(&self, o: &Self, torque_matters: bool) -> bool {
        let within = |a: &Vector7, g: &Vector7| a.iter().zip(g.iter()).all(|(a, g)| a <= g);
        within(&o.accel, &self.accel) && (!torque_matters || within(&o.torque, &self.torque))
    }
}

/// The outcome of verifying one command over one sample.
#[derive(Debug, Clone, Copy)]
struct Verdict {
    /// Every barrier ≥ 0 at every physics step and every next-sample condition held.
    ok: bool,
    /// Per row, how much larger its `ḧ` (or `ḣ`) needed to be [row units].
    shortfall: [f64; N],
    /// The smallest barrier value over the sample, each divided by its weight.
    worst: f64,
}

impl Verdict {
    /// Row `j` fell short by `short`.
    fn fail(&mut self, j: usize, short: f64) {
        self.ok = false;
        self.shortfall[j] = self.shortfall[j].max(short);
    }
}

/// What the declared joint-torque error `|Δτ_k| ≤ e_k` ([`RoboticParams::joint_torque_error`])
/// can do at the sample: the plant moves like the model under the held torque `τ + Δτ`, so
/// each row's `ḧ` (or `ḣ`), affine in the torque with normal `a_j`, is off by at most
/// `Σ_k |a_jk| e_k` — the exact worst case over the box (docs/SAFETY.md, "Margins for the
/// declared errors").
#[derive(Debug, Clone, Copy)]
struct Disturbance {
    /// `δ_i = Σ_k |A_ik| e_k` [rad/s²]: the joint accelerations' share.
    joint: Vector7,
    /// Per row [row units / s² or / s], [`NAMES`] order.
    rows: [f64; N],
}

impl Disturbance {
    /// The `exact` profile: no error.
    fn none() -> Self {
        Self {
            joint: Vector7::zeros(),
            rows: [0.0; N],
        }
    }
}

/// The arm at one physics step of the verification: joint state and the link spheres'
/// centres and velocities (F_B).
#[derive(Debug, Clone, Copy)]
struct ArmSnapshot {
    theta: Vector7,
    theta_dot: Vector7,
    centers: [Vector3<f64>; NS],
    velocities: [Vector3<f64>; NS],
    /// The spheres' radii [m]; `None` where the sphere's state could not be evaluated.
    radii: [Option<f64>; NS],
    /// The centres and velocities in F_R, relative to the target's CoM.
    world: [Vector3<f64>; NS],
    world_v: [Vector3<f64>; NS],
    /// Each sphere's link–target barrier and rate (the nearest keep-out sphere).
    target_h: [f64; NS],
    target_hdot: [f64; NS],
}

/// The robotic CBF-QP safety filter (paper eq. "robotic_qp").
pub struct RoboticFilter {
    pub params: RoboticParams,
    engine: Engine<NJ, { N + 6 + 2 * NJ }>,
    /// The servicer model for the verification path (without it, the envelope rows only).
    robot: Option<Arc<Robot>>,
    last: LastProblem<NJ>,
    /// Commands the envelope bounds certified that did not verify on the model's sample
    /// ([`Self::bounds_refuted`]).
    bounds_refuted: u64,
}

/// Every entry finite and `|m_ij| ≤ max`. Compares the magnitudes' bit patterns (for
/// non-negative floats their order is the numbers' order, and infinity and NaN lie above
/// every finite value), without early exit, so that it vectorises: the filter checks ~900
/// numbers of its input every step.
fn finite_in<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>, max: f64) -> bool {
    if max.is_nan() || max < 0.0 {
        return false;
    }
    // `abs`: −0.0 would keep its sign bit and let every magnitude through
    let limit = max.abs().min(f64::MAX).to_bits();
    m.as_slice()
        .iter()
        .fold(true, |ok, v| ok & (v.to_bits() & !SIGN_BIT <= limit))
}

/// The sign bit of an `f64`.
const SIGN_BIT: u64 = 1 << 63;

impl RoboticFilter {
    pub fn new(params: RoboticParams) -> Self {
        Self {
            params,
            engine: Engine::new(),
            robot: None,
            last: LastProblem::with_capacity(N, 2 * NJ + 6),
            bounds_refuted: 0,
        }
    }

    /// The filter with the servicer model, so that it can verify its commands.
    pub fn with_model(params: RoboticParams, robot: Arc<Robot>) -> Self {
        Self {
            params,
            engine: Engine::new(),
            robot: Some(robot),
            last: LastProblem::with_capacity(N, 2 * NJ + 6),
            bounds_refuted: 0,
        }
    }

    pub fn from_scenario(s: &sc_scenario::Scenario, robot: Arc<Robot>) -> Self {
        Self::with_model(RoboticParams::from_scenario(s), robot)
    }

    /// A state the filter can work with: everything finite and the dynamics
    /// non-degenerate. Large angles and rates are not refused (the filter keeps filtering).
    fn state_valid(x: &RoboticInput) -> bool {
        common::finite(&x.theta)
            && common::finite(&x.theta_dot)
            && finite_in(&x.a, MAX_GAIN)
            && finite_in(&x.m_eff, MAX_GAIN)
            && finite_in(&x.drift, MAX_ACCEL)
            && common::finite(&x.reaction)
            && common::finite(&x.omega_b)
            && common::finite(&x.force_b)
            && common::finite(&x.torque_b)
            && (0..NJ).all(|i| x.a[(i, i)] > 0.0 && x.m_eff[(i, i)] > 0.0)
            && finite_in(&x.base_center, MAX_REACH_M)
            && x.base_radius.is_finite()
            && (0.0..=MAX_REACH_M).contains(&x.base_radius)
            && x.spheres.iter().all(|s| {
                finite_in(&s.center, MAX_REACH_M)
                    && finite_in(&s.jacobian, MAX_REACH_M)
                    && finite_in(&s.jdot_qdot, MAX_ACCEL)
                    && (0.0..=MAX_REACH_M).contains(&s.radius)
            })
            && finite_in(&x.com.position, MAX_REACH_M)
            && finite_in(&x.com.jacobian, MAX_REACH_M)
            && finite_in(&x.com.jdot_qdot, MAX_ACCEL)
            && finite_in(&x.omega_dot_b0, MAX_ACCEL)
            && x.total_mass.is_finite()
            && x.total_mass > 0.0
            && x.around
                .is_none_or(|a| a.valid(MAX_BASE_RATE_RAD_S, MAX_ACCEL))
    }

    /// Barrier terms for a valid input (`None` otherwise).
    pub fn constraints(&self, x: &RoboticInput) -> Option<RoboticTerms> {
        self.terms(x).ok()
    }

    fn terms(&self, x: &RoboticInput) -> Result<RoboticTerms, Invalid> {
        Self::checked(x)?;
        Ok(self.terms_of(x))
    }

    /// The input's checks: the state valid ([`Self::state_valid`]), then the coupling and
    /// the upstream state the verification integrates with in range.
    fn checked(x: &RoboticInput) -> Result<(), Invalid> {
        if !Self::state_valid(x) {
            return Err(Invalid::State);
        }
        if !finite_in(&x.xi, MAX_ACCEL)
            || !finite_in(&x.omega_b, MAX_BASE_RATE_RAD_S)
            || !finite_in(&x.force_b, MAX_WRENCH)
            || !finite_in(&x.torque_b, MAX_WRENCH)
        {
            return Err(Invalid::Coupling);
        }
        Ok(())
    }

    /// The barrier terms of a checked input (paper eqs. "CBF-joint-angle",
    /// "CBF-joint-velocity", "CBF-link-base"; the link–target rows beyond the paper).
    fn terms_of(&self, x: &RoboticInput) -> RoboticTerms {
        let p = &self.params;
        let rates: [_; NJ] = std::array::from_fn(|i| joint_velocity(i, x, p.theta_dot_max[i]));
        RoboticTerms {
            theta: std::array::from_fn(|i| joint_angle(i, x, p.theta_min[i], p.theta_max[i])),
            theta_dot_max: std::array::from_fn(|i| rates[i][0]),
            theta_dot_min: std::array::from_fn(|i| rates[i][1]),
            link_base: std::array::from_fn(|k| link_base(&x.spheres[k], x)),
            link_target: std::array::from_fn(|k| {
                link_target::link_target(&x.spheres[k], x, &p.target)
            }),
        }
    }

    /// Weights of the rows in the relaxed problem — the deceleration the formulation budgets
    /// for each row: `μ_θ` [rad²/s²], the paper's `ε_θ̇` for the rates [rad/s²], `μ_LB`
    /// [m²/s²].
    fn weights(&self) -> [f64; N] {
        let p = &self.params;
        std::array::from_fn(|j| {
            if j < NJ {
                p.u_max_theta
            } else if j < 3 * NJ {
                p.eps_theta_dot
            } else {
                p.u_max_lb
            }
        })
    }

    /// The in-sample bounds of every row for a command whose joint accelerations at the
    /// sample are `qdd` (docs/SAFETY.md, "The arm at 10 Hz"): with the configured jerk
    /// bounds `J_i` (joints) and `J_k` (sphere centres), the accelerations inside the sample
    /// stay within `ā_i = |θ̈_i| + δ_i + J_i T` (`δ_i` the declared torque error's share,
    /// [`Disturbance`]), the rates within `v̄_i = |θ̇_i| + ā_i T`; then
    /// * joint angle (`ḧ = kθ̈ − 2θ̇²`): `M₃ = |k|_max J_i + 6 v̄_i ā_i`;
    /// * joint rate: `J = J_i`;
    /// * link sphere against the base (`ḧ = 2‖ṗ‖² + 2dᵀp̈`): `M₃ = 6 V A + 2 D J_k` with
    ///   the centre's acceleration `A = ‖p̈‖ + ‖J‖_F ‖δ‖ + J_k T`, speed `V = ‖ṗ‖ + A T`,
    ///   distance `D = ‖d‖ + V T`;
    /// * link sphere against the target: `M₃ = 0` (left to the verification);
    ///
    /// and every row's `M₂` (or `D`) is its share of the torque error at the sample.
    fn certified_bounds(
        &self,
        x: &RoboticInput,
        qdd: &Vector7,
        dist: &Disturbance,
    ) -> ([SampleBounds; NJ], [RateBounds; NJ], [SampleBounds; 2 * NS]) {
        let p = &self.params;
        let t = p.period;
        let acc = Vector7::from_fn(|i, _| qdd[i].abs() + dist.joint[i] + p.joint_jerk_bound[i] * t);
        let vel = Vector7::from_fn(|i, _| x.theta_dot[i].abs() + acc[i] * t);
        let theta = std::array::from_fn(|i| {
            let k = (p.theta_max[i] + p.theta_min[i] - 2.0 * x.theta[i]).abs() + 2.0 * vel[i] * t;
            SampleBounds {
                period: t,
                m2: dist.rows[i],
                m3: k * p.joint_jerk_bound[i] + 6.0 * vel[i] * acc[i],
            }
        });
        let rate = std::array::from_fn(|i| RateBounds {
            period: t,
            d: dist.rows[NJ + i].max(dist.rows[2 * NJ + i]),
            j: p.joint_jerk_bound[i],
        });
        let joint_norm = dist.joint.norm();
        let lb = std::array::from_fn(|j| {
            if j >= NS {
                // the link–target rows: no in-sample bound — the base's and the target's
                // motion are not in the arm's jerk bounds, and the verification every
                // command passes integrates all of it (a bound here only made the cheap
                // candidate needlessly conservative at the target's range)
                return SampleBounds {
                    period: t,
                    m2: dist.rows[3 * NJ + j],
                    m3: 0.0,
                };
            }
            let s = &x.spheres[j];
            let jk = p.sphere_jerk_bound[j / 3];
            let a =
                (s.jacobian * qdd + s.jdot_qdot).norm() + s.jacobian.norm() * joint_norm + jk * t;
            let v = (s.jacobian * x.theta_dot).norm() + a * t;
            let d = (s.center - x.base_center).norm() + v * t;
            SampleBounds {
                period: t,
                m2: dist.rows[3 * NJ + j],
                m3: 6.0 * v * a + 2.0 * d * jk,
            }
        });
        (theta, rate, lb)
    }

    /// What the declared joint-torque error can do at the sample ([`Disturbance`]) for
    /// torques `|τ_k| ≤ torque_cap_k`; zero without one.
    fn disturbance(&self, x: &RoboticInput, t: &RoboticTerms, torque_cap: &Vector7) -> Disturbance {
        let te = &self.params.joint_torque_error;
        if te.is_zero() {
            return Disturbance::none();
        }
        let e = te.at(torque_cap);
        Disturbance {
            joint: x.a.abs() * e,
            rows: std::array::from_fn(|j| t.normal(j).abs().dot(&e)),
        }
    }

    /// The 63 barrier rows at `level`, each tightened by `margin[j]` [row units].
    fn barrier_rows(
        &self,
        x: &RoboticInput,
        t: &RoboticTerms,
        level: Level,
        margin: &[f64; N],
    ) -> [Row<NJ>; N] {
        let p = &self.params;
        let mut rows: [Row<NJ>; N] = match p.formulation {
            Formulation::Paper => std::array::from_fn(|j| {
                if j < NJ {
                    t.theta[j].row(p.gamma, p.eps_theta, p.u_max_theta)
                } else if j < 2 * NJ {
                    t.theta_dot_max[j - NJ].row(p.gamma_theta_dot, p.eps_theta_dot)
                } else if j < 3 * NJ {
                    t.theta_dot_min[j - 2 * NJ].row(p.gamma_theta_dot, p.eps_theta_dot)
                } else {
                    t.sphere(j).row(p.gamma, p.eps_lb, p.u_max_lb)
                }
            }),
            Formulation::SampledData => {
                let c = self.sampled_offsets(x, t, level);
                std::array::from_fn(|j| Row {
                    a: t.normal(j),
                    c: c[j],
                })
            }
        };
        for (r, m) in rows.iter_mut().zip(margin) {
            r.c -= m;
        }
        rows
    }

    /// The offsets `c` of the 63 barrier rows at `level` (untightened). Only the offsets
    /// depend on the level — the normals are the terms' `∂ḧ/∂τ` and `∂ḣ/∂τ` — so the
    /// a-posteriori certificate checks a command against the rows of another level
    /// without building them: `c_j + a_j·τ` with the normals of any level.
    fn barrier_offsets(&self, x: &RoboticInput, t: &RoboticTerms, level: Level) -> [f64; N] {
        match self.params.formulation {
            Formulation::Paper => self.barrier_rows(x, t, level, &[0.0; N]).map(|r| r.c),
            Formulation::SampledData => self.sampled_offsets(x, t, level),
        }
    }

    /// The sampled-data rows' offsets `ḧ_drift − φ_req` and `ḣ_drift − ḣ_req` at `level`.
    fn sampled_offsets(&self, x: &RoboticInput, t: &RoboticTerms, level: Level) -> [f64; N] {
        let p = &self.params;
        let dist = match level {
            Level::Certified(caps) => self.disturbance(x, t, &caps.torque),
            Level::Local(torque) => self.disturbance(x, t, &torque),
        };
        let (bt, br, blb) = match level {
            Level::Certified(caps) => self.certified_bounds(x, &caps.accel, &dist),
            Level::Local(_) => {
                let z = |m2| SampleBounds {
                    period: p.period,
                    m2,
                    m3: 0.0,
                };
                let zr = |i: usize| RateBounds {
                    period: p.period,
                    d: dist.rows[NJ + i].max(dist.rows[2 * NJ + i]),
                    j: 0.0,
                };
                (
                    std::array::from_fn(|i| z(dist.rows[i])),
                    std::array::from_fn(zr),
                    std::array::from_fn(|j| z(dist.rows[3 * NJ + j])),
                )
            }
        };
        // the decays of (C2) and of the rate rows, evaluated once for all rows
        let decay = Decay::linear(p.gamma).at(p.period);
        let rate = RateDecay::new(p.gamma_theta_dot, p.eps_theta_dot, p.period);
        let rel2 = |r: &RelDegTwo<NJ>, b: &SampleBounds, mu: f64| {
            r.hddot_drift - phi_required_of(r.h, r.hdot, b, mu, &decay)
        };
        let rel1 =
            |r: &RelDegOne<NJ>, b: &RateBounds| r.hdot_drift - hdot_required_of(r.h, b, &rate);
        std::array::from_fn(|j| {
            if j < NJ {
                rel2(&t.theta[j], &bt[j], p.u_max_theta)
            } else if j < 2 * NJ {
                rel1(&t.theta_dot_max[j - NJ], &br[j - NJ])
            } else if j < 3 * NJ {
                rel1(&t.theta_dot_min[j - 2 * NJ], &br[j - 2 * NJ])
            } else {
                rel2(t.sphere(j), &blb[j - 3 * NJ], p.u_max_lb)
            }
        })
    }

    /// The commanded torque's bound per joint [N m]: `T_M (1 − BOX_MARGIN)`, or with a
    /// declared torque error the command whose delivered torque `τ(1 + rel) + bias` stays
    /// within that — the plant's torques stay in the box the envelope's bounds hold for.
    fn command_limit(&self) -> Vector7 {
        let p = &self.params;
        let lim = p.torque_max * (1.0 - BOX_MARGIN);
        let te = &p.joint_torque_error;
        if te.is_zero() {
            return Vector7::repeat(lim);
        }
        te.bias.map(|b| ((lim - b) / (1.0 + te.rel)).max(0.0))
    }

    /// Input bounds and the contract rows `β_i ∓ (Q (τ_M − τ_hold))_i − (|Q| e)_i ≥ 0`,
    /// with `τ_hold = c_eff = −M_eff (b + ξ)` the torque that holds the joint rates and
    /// `e` the declared torque error for any command in the box ([`Self::command_limit`]).
    fn hard_rows(&self, x: &RoboticInput) -> [Row<NJ>; 2 * NJ + 6] {
        let p = &self.params;
        let lim = self.command_limit();
        let hold = hold_torque(x);
        let q_hold = x.reaction * hold;
        // the motors' declared error (for any torque in the box) moves the reaction by up
        // to `|Q| e`: kept inside β
        let te = &p.joint_torque_error;
        let q_err = if te.is_zero() {
            Vector3::zeros()
        } else {
            x.reaction.abs() * te.at(&lim)
        };
        std::array::from_fn(|k| {
            if k < 2 * NJ {
                let mut a = Vector7::zeros();
                a[k / 2] = if k % 2 == 0 { -1.0 } else { 1.0 };
                Row { a, c: lim[k / 2] }
            } else {
                let i = (k - 2 * NJ) / 2;
                let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
                Row {
                    a: x.reaction.row(i).transpose() * sign,
                    c: p.arm_reaction_budget[i] - sign * q_hold[i] - q_err[i],
                }
            }
        })
    }

    /// The braking law `τ_M = sat(−M_eff θ̇ / T)` (direction kept) — the substitute nominal,
    /// and the backup when the solver fails; zero when the state is invalid.
    pub fn brake(&self, x: &RoboticInput) -> Vector7 {
        if !(common::finite(&x.theta_dot) && finite_in(&x.m_eff, MAX_GAIN)) {
            return Vector7::zeros();
        }
        let t = -(x.m_eff * x.theta_dot) / self.params.brake_time;
        // within the command box: with a declared torque error the delivered torque too
        common::sat_inf(&t, self.command_limit().min())
    }

    /// The emergency brake (no solver produced a command): the braking law pulled towards
    /// the holding torque `τ_hold` until the arm-reaction contract rows hold,
    /// `τ = τ_hold + s (τ_brake − τ_hold)` with the largest `s ∈ [0, 1]` that keeps every
    /// contract row ([`Self::hard_rows`]) — the attitude filter's certificate assumes the
    /// arm's reaction on the base stays within `arm_reaction_budget` whatever the robotic
    /// filter does, its emergencies included. The joints then decelerate at `s` times the
    /// braking law's rate. When the rows cannot hold even at `τ_hold` (the budget below
    /// the declared torque error's share) `s = 0`. The command box comes first: where
    /// `τ_hold` is beyond it, `s` is at least what brings the command into the box.
    pub fn emergency_brake(&self, x: &RoboticInput) -> Vector7 {
        let brake = self.brake(x);
        let hold = hold_torque(x);
        if !(common::finite(&hold) && common::finite(&x.reaction)) {
            return brake;
        }
        let d = brake - hold;
        let rows = self.hard_rows(x);
        // along the segment every row is `at_hold + s slope ≥ 0`
        let along = |r: &Row<NJ>| (r.a.dot(&hold) + r.c, r.a.dot(&d));
        let contract = rows[2 * NJ..].iter().map(along).fold(1.0f64, |s, (h, m)| {
            if m < 0.0 { s.min((h / -m).max(0.0)) } else { s }
        });
        // the box first: the brake (s = 1) is in it, so a lower bound below 1 exists
        let in_box = rows[..2 * NJ].iter().map(along).fold(0.0f64, |s, (h, m)| {
            if h < 0.0 && m > 0.0 { s.max(-h / m) } else { s }
        });
        let s = contract.max(in_box).min(1.0);
        if s >= 1.0 {
            return brake;
        }
        let lim = self.command_limit();
        (hold + d * s).zip_map(&lim, |u, l| u.clamp(-l, l))
    }

    /// The filter's command when its nominal is missing: the safety QP on the substitute.
    pub fn backup(&mut self, x: &RoboticInput) -> FilterOutput<NJ, N> {
        self.filter_with(x, None)
    }

    /// One filter step: safe `τ_M` closest to `tau_nom` subject to the 63 barrier rows, the
    /// contract rows and `‖τ_M‖∞ ≤ T_M`.
    pub fn filter(&mut self, x: &RoboticInput, tau_nom: &Vector7) -> FilterOutput<NJ, N> {
        self.filter_with(x, Some(tau_nom))
    }

    /// [`Self::filter`] with the nominal possibly missing.
    pub fn filter_with(
        &mut self,
        x: &RoboticInput,
        tau_nom: Option<&Vector7>,
    ) -> FilterOutput<NJ, N> {
        step::filter_with(self, x, tau_nom)
    }

    /// The a-posteriori certificate: solve with the sample's own prediction (the `local`
    /// rows), then check the command against rows whose in-sample bounds are valid for its
    /// own accelerations; if it falls short, solve with those rows and check again. Writes
    /// the rows the command was solved with (`s.solved`) and, when certified, the rows that
    /// certify it (`s.certifying`).
    fn certify(
        &mut self,
        x: &RoboticInput,
        p: &Prepared,
        u_nom: &Vector7,
        local: &[Row<NJ>; N],
        s: &mut RowsBehind,
    ) -> Certificate {
        let caps_of = |u: &Vector7| Caps::of(&(x.a * u + x.drift + x.xi), u);
        let res = self.engine.solve(u_nom, local, &p.weights, &p.hard);
        let mut c = Certificate {
            res,
            iterations: res.iterations,
        };
        if !matches!(res.kind, Kind::Skipped | Kind::Solved) {
            return c;
        }
        // the torques matter only for a declared torque error
        let torque_matters = !self.params.joint_torque_error.is_zero();
        // the caps the rows `c.res` was solved with were built for (None: the sample's own
        // prediction, the loosest rows); the bounds grow with them joint by joint, so rows
        // built for the larger of both are tighter than those
        let mut solved_cap: Option<Caps> = None;
        for _ in 0..CERTIFY_ROUNDS {
            let own = caps_of(&c.res.u);
            let cap = solved_cap.map_or(own, |s| s.sup(&own));
            // the certifying rows' offsets with the normals every level shares: `phi`
            // of the certifying rows, bit for bit, without building them
            let off = self.barrier_offsets(x, &p.terms, Level::Certified(cap));
            if local
                .iter()
                .zip(&off)
                .all(|(r, c0)| c0 + r.a.dot(&c.res.u) >= 0.0)
            {
                // inside rows valid for its own accelerations: certified. It is the
                // minimiser of the rows it was solved with (`s.solved`, the dump's
                // problem), not necessarily of the certifying rows (`safe-capture
                // verify-qp` measured up to 3e-2 of the bound between the two under
                // attack when the dump held the certifying rows).
                s.certifying = Some(with_offsets(local, &off));
                break;
            }
            // the next candidate may accelerate more; bound it by twice as much
            let grown = cap.grown();
            let rows = self.barrier_rows(x, &p.terms, Level::Certified(grown), &[0.0; N]);
            let next = self.engine.solve(u_nom, &rows, &p.weights, &p.hard);
            c.iterations += next.iterations;
            if !matches!(next.kind, Kind::Skipped | Kind::Solved) {
                break;
            }
            c.res = next;
            s.solved = Some(rows);
            solved_cap = Some(grown);
            if grown.covers(&caps_of(&c.res.u), torque_matters) {
                // the rows' bounds cover the new command's accelerations (and torques)
                s.certifying = Some(rows);
                break;
            }
        }
        c
    }

    /// The command and how it came about, over all solves of the step (no multipliers
    /// are recorded): first the a-posteriori certificate, whose command is verified with
    /// the servicer model; where it fails (near the limits) or does not verify, the
    /// verification path (sampled-data rows only: the paper's rows are for comparison);
    /// otherwise the last solve as it is, the braking law when it failed. Writes the rows
    /// behind the command into `behind`.
    fn command(
        &mut self,
        x: &RoboticInput,
        p: &Prepared,
        u_nom: &Vector7,
        local: &[Row<NJ>; N],
        behind: &mut RowsBehind,
    ) -> Outcome<NJ> {
        let c = self.certify(x, p, u_nom, local, behind);
        let mut o = Outcome {
            kind: c.res.kind,
            u: c.res.u,
            violation: 0.0,
            iterations: c.iterations,
            // the multipliers of the solve the dump's rows are (`behind.solved`)
            row_duals: c.res.row_duals,
            bound_duals: c.res.bound_duals,
            second_opinion: false,
        };
        let mut refuted = None;
        if behind.certifying.is_some() {
            let verdict = self.verify_certified(x, p, &o.u, &mut o.iterations);
            if verdict.is_none_or(|v| v.ok) {
                if o.kind != Kind::Skipped {
                    o.kind = Kind::Solved;
                }
                o.second_opinion = c.res.second_opinion;
                return o;
            }
            refuted = verdict.map(|verdict| Refuted {
                verdict,
                candidate: Verified {
                    u: o.u,
                    rows: behind.solved.unwrap_or(*local),
                    violation: 0.0,
                    second_opinion: c.res.second_opinion,
                    row_duals: o.row_duals,
                    bound_duals: o.bound_duals,
                },
            });
            behind.certifying = None;
        }
        let verified = if self.params.formulation == Formulation::SampledData {
            self.verified(x, p, u_nom, refuted, &mut o.iterations)
        } else {
            None
        };
        if let Some(v) = verified {
            (o.kind, o.violation) = if v.violation > 0.0 {
                (Kind::Relaxed, v.violation)
            } else {
                (Kind::Solved, 0.0)
            };
            o.u = v.u;
            o.second_opinion = v.second_opinion;
            (o.row_duals, o.bound_duals) = (v.row_duals, v.bound_duals);
            behind.solved = Some(v.rows);
            behind.certifying = Some(v.rows);
            return o;
        }
        match c.res.kind {
            Kind::Relaxed => o.violation = c.res.violation,
            Kind::Failed => o.u = self.emergency_brake(x),
            Kind::Skipped | Kind::Solved => {}
        }
        o
    }

    /// The command the envelope bounds certified, verified on the sample the servicer
    /// model predicts ([`Self::verify`]): every command of the sampled-data formulation is
    /// verified so, which makes its certificate independent of the configured jerk bounds
    /// — they only decide how often the cheap certificate is enough (docs/SAFETY.md, "The
    /// arm at 10 Hz"). A bound the arm exceeds shows as a verdict that is not `ok`; the
    /// command then goes to the verification path. `None` without a model, or for the
    /// paper's rows: the bounds' certificate stands alone.
    fn verify_certified(
        &mut self,
        x: &RoboticInput,
        p: &Prepared,
        u: &Vector7,
        iterations: &mut u32,
    ) -> Option<Verdict> {
        let robot = self.robot.clone()?;
        if self.params.formulation != Formulation::SampledData {
            return None;
        }
        *iterations += 1;
        let v = self.verify(&robot, x, &p.terms, u, &p.weights);
        if !v.ok {
            self.bounds_refuted += 1;
        }
        Some(v)
    }

    /// The verification path: solve with the sample's own prediction, simulate the sample,
    /// tighten the rows that fell short, repeat. Returns the first verified command (with its
    /// rows and, if it came from the relaxed problem, its violation), or — when none verifies
    /// within [`MAX_VERIFY_ROUNDS`] — the candidate whose worst barrier over the sample is
    /// best, flagged as relaxed. A command the bounds certified that did not verify
    /// (`refuted`) starts it: its shortfalls are the first margins, and it is a candidate
    /// too. `None` without a model or when every solve failed (and nothing was refuted).
    /// `iterations` counts the solver's iterations and one per verification.
    fn verified(
        &mut self,
        x: &RoboticInput,
        p: &Prepared,
        u_nom: &Vector7,
        refuted: Option<Refuted>,
        iterations: &mut u32,
    ) -> Option<Verified> {
        let robot = self.robot.clone()?;
        let mut margin = [0.0; N];
        let mut best: Option<(f64, Verified)> = None;
        // the torques the rows take the declared torque error for: the holding torque's
        // (a safe command near the limits is close to it), then every candidate's as well
        let mut torque = hold_torque(x).abs();
        if let Some(r) = refuted {
            for (m, s) in margin.iter_mut().zip(&r.verdict.shortfall) {
                *m += VERIFY_GAIN * s;
            }
            torque = torque.sup(&r.candidate.u.abs());
            best = Some((r.verdict.worst, r.candidate));
        }
        for _ in 0..MAX_VERIFY_ROUNDS {
            let rows = self.barrier_rows(x, &p.terms, Level::Local(torque), &margin);
            let res = self.engine.solve(u_nom, &rows, &p.weights, &p.hard);
            *iterations += res.iterations;
            if res.kind == Kind::Failed {
                break;
            }
            torque = torque.sup(&res.u.abs());
            let v = self.verify(&robot, x, &p.terms, &res.u, &p.weights);
            *iterations += 1;
            let candidate = Verified {
                u: res.u,
                rows,
                violation: 0.0,
                second_opinion: res.second_opinion,
                row_duals: res.row_duals,
                bound_duals: res.bound_duals,
            };
            if v.ok {
                let violation = if res.kind == Kind::Relaxed {
                    res.violation
                } else {
                    0.0
                };
                return Some(Verified {
                    violation,
                    ..candidate
                });
            }
            if best.as_ref().is_none_or(|b| v.worst > b.0) {
                best = Some((v.worst, candidate));
            }
            for (m, s) in margin.iter_mut().zip(&v.shortfall) {
                *m += VERIFY_GAIN * s;
            }
        }
        // a sample whose integration failed reports a full violation (the command itself
        // is still inside the box: the relaxed problem's hard rows hold)
        best.map(|(worst, v)| Verified {
            violation: if worst.is_finite() {
                (-worst).max(f64::MIN_POSITIVE)
            } else {
                1.0
            },
            ..v
        })
    }

    /// Integrates one sample under `tau` with the servicer model exactly as the simulator
    /// does (RK4 at the physics step; base force and torque held in the body frame) and
    /// checks every row's conditions on the true trajectory. With a declared torque error
    /// `|Δτ_k| ≤ e_k` the sample is also integrated under `τ + e_k 1_k` for every joint
    /// `k`, and every barrier and rate is lowered by `VERIFY_SECOND_ORDER · Σ_k |change|`:
    /// the worst case over the box of the errors to first order, the coupling of the
    /// joints inside the sample included.
    fn verify(
        &self,
        robot: &Robot,
        x: &RoboticInput,
        t0: &RoboticTerms,
        tau: &Vector7,
        weights: &[f64; N],
    ) -> Verdict {
        let p = &self.params;
        let mut verdict = Verdict {
            ok: true,
            shortfall: [0.0; N],
            worst: f64::INFINITY,
        };
        let te = &p.joint_torque_error;
        let perturbed = if te.is_zero() { 0 } else { NJ };
        let inputs = held_inputs(x, tau, &te.at(tau));
        let around = x.around.unwrap_or_else(Surroundings::far);
        let mut states = [Sampled::start(x, &around); NJ + 1];
        let mut target = x.around.map(|a| TargetMotion::start(&a));
        let accel = x.force_b.norm() / x.total_mass;
        let h = p.physics_step;
        let steps = ((p.period / h).round() as usize).max(1);
        let Some(base) = robot.base_sphere() else {
            verdict.ok = false;
            verdict.worst = f64::NEG_INFINITY;
            return verdict;
        };
        for step in 1..=steps {
            for (st, u) in states.iter_mut().zip(&inputs).take(perturbed + 1) {
                let Some(next) = link_target::rk4_sampled(robot, st, u, x.total_mass, h) else {
                    verdict.ok = false;
                    verdict.worst = f64::NEG_INFINITY;
                    return verdict;
                };
                *st = next;
            }
            if let Some(t) = target.as_mut() {
                *t = t.step(&p.target_inertia, &p.target_inertia_inv, h);
            }
            let s = step as f64 * h;
            let snap = |k: usize| self.snapshot(robot, &states[k], target.as_ref());
            let nominal = snap(0);
            let (hv, hd) = self.barriers_along(base, &nominal);
            let others: [ArmSnapshot; NJ] =
                std::array::from_fn(|k| if k < perturbed { snap(k + 1) } else { nominal });
            // what the prediction leaves out: the differential gravity on the CoM
            let gravity = link_target::gravity_margin(&around, accel, s);
            let (dh, dhd) = self.error_effect(
                base,
                &nominal,
                &others[..perturbed],
                target.as_ref(),
                gravity,
            );
            let h: [f64; N] = std::array::from_fn(|j| hv[j] - dh[j]);
            let hdot: [f64; N] = std::array::from_fn(|j| hd[j] - dhd[j]);
            if !self.check_rows(&mut verdict, t0, weights, (&h, &hdot), s, step == steps) {
                return verdict;
            }
        }
        verdict
    }

    /// Every row's (C1) at the physics step `s` [s] into the sample and, at its end
    /// (`last`), its next-sample condition, with the barriers and rates `h`, `hdot`
    /// lowered by the declared errors; `false` (a violation no margin repairs) when one of
    /// them is not finite.
    fn check_rows(
        &self,
        verdict: &mut Verdict,
        t0: &RoboticTerms,
        weights: &[f64; N],
        (h, hdot): (&[f64; N], &[f64; N]),
        s: f64,
        last: bool,
    ) -> bool {
        for j in 0..N {
            let hj = h[j];
            if !(hj.is_finite() && hdot[j].is_finite()) {
                // a barrier the sample cannot evaluate is a violation, never a margin
                // (as a sample whose integration failed)
                verdict.ok = false;
                verdict.worst = f64::NEG_INFINITY;
                return false;
            }
            verdict.worst = verdict.worst.min(hj / weights[j]);
            if hj < 0.0 {
                // C1: the barrier inside the sample
                let short = if is_rel_deg_two(j) {
                    2.0 * -hj / (s * s)
                } else {
                    -hj / s
                };
                verdict.fail(j, short);
            }
            if last && let Some(short) = self.next_sample_shortfall(j, t0, hj, hdot[j], s) {
                verdict.fail(j, short);
            }
        }
        true
    }

    /// How far the declared torque error may lower every barrier and rate ([`NAMES`]
    /// order) at `nominal`, from the snapshots `perturbed` under each joint's error alone.
    /// With `r = VERIFY_SECOND_ORDER`, the joints' angles and rates deviate by at most
    /// `Δθ_i = r Σ_k |θ_i,k − θ_i|`, `Δθ̇_i` likewise, the spheres' centres and velocities
    /// by `Δc = r Σ_k ‖c_k − c‖`, `Δv` likewise; then
    /// * joint rate: `Δh = Δθ̇_i`;
    /// * joint angle (`h = (θ − θ_min)(θ_max − θ)`, `ḣ = k θ̇`): `Δh = |k| Δθ + Δθ²`,
    ///   `Δḣ = |k| Δθ̇ + 2|θ̇| Δθ + 2 Δθ Δθ̇`;
    /// * link sphere (`h = ‖d‖² − (ρ + R)²`, `ḣ = 2 dᵀv`): `Δh = 2‖d‖ Δc + Δc²`,
    ///   `Δḣ = 2 (Δc ‖v‖ + ‖d‖ Δv + Δc Δv)`, for the link–target rows with the centres
    ///   and velocities in F_R (the base's attitude and the system CoM's offset moved by
    ///   the error too) and `d`, `v` against the nearest keep-out sphere.
    fn error_effect(
        &self,
        base: &CollisionSphere,
        nominal: &ArmSnapshot,
        perturbed: &[ArmSnapshot],
        tm: Option<&TargetMotion>,
        gravity: (f64, f64),
    ) -> ([f64; N], [f64; N]) {
        let (mut dh, mut dhd) = ([0.0; N], [0.0; N]);
        let r = VERIFY_SECOND_ORDER;
        let sum = |f: &dyn Fn(&ArmSnapshot) -> f64| r * perturbed.iter().map(f).sum::<f64>();
        let p = &self.params;
        let n = nominal;
        for i in 0..NJ {
            let dq = sum(&|o| (o.theta[i] - n.theta[i]).abs());
            let dv = sum(&|o| (o.theta_dot[i] - n.theta_dot[i]).abs());
            let k = (p.theta_max[i] + p.theta_min[i] - 2.0 * n.theta[i]).abs();
            dh[i] = k * dq + dq * dq;
            dhd[i] = k * dv + 2.0 * n.theta_dot[i].abs() * dq + 2.0 * dq * dv;
            dh[NJ + i] = dv;
            dh[2 * NJ + i] = dv;
        }
        let grow = |d: f64, v: f64, dc: f64, dvel: f64| {
            (
                2.0 * d * dc + dc * dc,
                2.0 * (dc * v + d * dvel + dc * dvel),
            )
        };
        for s in 0..NS {
            let dc = sum(&|o| (o.centers[s] - n.centers[s]).norm());
            let dvel = sum(&|o| (o.velocities[s] - n.velocities[s]).norm());
            let d = (n.centers[s] - base.center).norm();
            let v = n.velocities[s].norm();
            (dh[3 * NJ + s], dhd[3 * NJ + s]) = grow(d, v, dc, dvel);
            let (Some(radius), Some(tm)) = (n.radii[s], tm) else {
                continue;
            };
            let dc = sum(&|o| (o.world[s] - n.world[s]).norm()) + gravity.0;
            let dvel = sum(&|o| (o.world_v[s] - n.world_v[s]).norm()) + gravity.1;
            // every keep-out sphere lowered by its own distance's share; the lowest decides
            let (low, low_dot) = link_target::lowered(
                &self.params.target,
                &n.world[s],
                &n.world_v[s],
                radius,
                tm,
                dc,
                dvel,
            );
            dh[LINK_TARGET + s] = n.target_h[s] - low;
            dhd[LINK_TARGET + s] = n.target_hdot[s] - low_dot;
        }
        (dh, dhd)
    }

    /// The state `st` of the verification with every arm sphere's centre and velocity in
    /// the base frame and in F_R, and its barrier against the target `tm` (a sphere whose
    /// state cannot be evaluated has no radius: its barriers read 0, as before).
    fn snapshot(&self, robot: &Robot, st: &Sampled, tm: Option<&TargetMotion>) -> ArmSnapshot {
        let (th, thd) = (&st.theta, &st.theta_dot);
        let kin = robot.kinematics_vel(th, thd);
        let mut snap = ArmSnapshot {
            theta: *th,
            theta_dot: *thd,
            centers: [Vector3::zeros(); NS],
            velocities: [Vector3::zeros(); NS],
            radii: [None; NS],
            world: [Vector3::zeros(); NS],
            world_v: [Vector3::zeros(); NS],
            target_h: [0.0; NS],
            target_hdot: [0.0; NS],
        };
        for (k, (idx, _)) in robot.arm_spheres().take(NS).enumerate() {
            if let Some(sp) = robot.sphere_state(&kin, idx) {
                snap.centers[k] = sp.center;
                snap.velocities[k] = sp.jacobian * thd;
                snap.radii[k] = Some(sp.radius);
            }
        }
        let Some(tm) = tm else {
            // no target known: the rows' constant value
            snap.target_h = [link_target::FAR_M * link_target::FAR_M; NS];
            return snap;
        };
        let (com, com_v) = robot.com_motion(&kin);
        let a = link_target::along(
            &self.params.target,
            &snap.centers,
            &snap.velocities,
            &snap.radii,
            &com,
            &com_v,
            st,
            tm,
        );
        (snap.target_h, snap.target_hdot, snap.world, snap.world_v) = (a.h, a.hdot, a.pos, a.vel);
        snap
    }

    /// Every barrier `h` and the rates `ḣ` of the relative-degree-two ones (joint angles,
    /// link spheres) at a snapshot of the verification, [`NAMES`] order.
    fn barriers_along(&self, base: &CollisionSphere, a: &ArmSnapshot) -> ([f64; N], [f64; N]) {
        let p = &self.params;
        let (th, thd) = (&a.theta, &a.theta_dot);
        let mut hv = [0.0; N];
        let mut hd = [0.0; N];
        for i in 0..NJ {
            let k = p.theta_max[i] + p.theta_min[i] - 2.0 * th[i];
            hv[i] = (th[i] - p.theta_min[i]) * (p.theta_max[i] - th[i]);
            hd[i] = thd[i] * k;
            hv[NJ + i] = p.theta_dot_max[i] - thd[i];
            hv[2 * NJ + i] = thd[i] + p.theta_dot_max[i];
        }
        for k in 0..NS {
            if let Some(radius) = a.radii[k] {
                let d = a.centers[k] - base.center;
                let rr = radius + base.radius;
                hv[3 * NJ + k] = d.dot(&d) - rr * rr;
                hd[3 * NJ + k] = 2.0 * d.dot(&a.velocities[k]);
                hv[LINK_TARGET + k] = a.target_h[k];
                hd[LINK_TARGET + k] = a.target_hdot[k];
            }
        }
        (hv, hd)
    }

    /// How much larger row `j`'s `ḧ` (or `ḣ`) needed to be for its next-sample condition
    /// to hold at the sample's end `s` with barrier value `h` and rate `ḣ` — (C2) for a
    /// relative-degree-two row, the discretised rate condition for a joint-rate row —
    /// `None` when it holds.
    fn next_sample_shortfall(
        &self,
        j: usize,
        t0: &RoboticTerms,
        h: f64,
        hd: f64,
        s: f64,
    ) -> Option<f64> {
        let p = &self.params;
        if is_rel_deg_two(j) {
            let (h0, hd0) = if j < NJ {
                (t0.theta[j].h, t0.theta[j].hdot)
            } else {
                (t0.sphere(j).h, t0.sphere(j).hdot)
            };
            let mu = if j < NJ { p.u_max_theta } else { p.u_max_lb };
            let kappa = (-p.gamma * p.period).exp() * braking_barrier(h0, hd0, mu);
            let got = braking_barrier(h, hd, mu);
            let gain = 0.5 * s * s + hd.abs() * s / mu;
            (got < kappa).then(|| (kappa - got) / gain)
        } else {
            let h0 = if j < 2 * NJ {
                t0.theta_dot_max[j - NJ].h
            } else {
                t0.theta_dot_min[j - 2 * NJ].h
            };
            let g = p.gamma_theta_dot;
            let floor = p.eps_theta_dot / g;
            let target = (-g * p.period).exp() * (h0 - floor) + floor;
            (h < target).then(|| (target - h) / s)
        }
    }

    /// How many commands the envelope bounds certified did not verify on the servicer
    /// model's sample (each then went to the verification path): how often the arm left
    /// the configured jerk bounds, a link–target row's next-sample condition failed (those
    /// rows have no in-sample bound), or the model could not be integrated over the sample.
    pub fn bounds_refuted(&self) -> u64 {
        self.bounds_refuted
    }

    /// Verification only: force the solver even when the nominal is feasible.
    pub fn set_skip_enabled(&mut self, on: bool) {
        self.engine.set_skip_enabled(on);
    }

    /// The certified barrier rows for a command that does not accelerate the joints
    /// ([`NAMES`] order), their weights and the hard rows
    /// (input bounds, then the contract) at `x` — for verification and inspection.
    pub fn rows(&self, x: &RoboticInput) -> Option<(Vec<Row<NJ>>, Vec<f64>, Vec<Row<NJ>>)> {
        let t = self.terms(x).ok()?;
        let caps = Caps::of(&Vector7::zeros(), &hold_torque(x));
        let rows = self.barrier_rows(x, &t, Level::Certified(caps), &[0.0; N]);
        Some((
            rows.to_vec(),
            self.weights().to_vec(),
            self.hard_rows(x).to_vec(),
        ))
    }

    /// The last QP (the rows the command was finally solved with) for `--dump-qp`.
    pub fn dump_qp(&self) -> crate::QpDump {
        self.last.dump()
    }
}

/// The held inputs `[f_B; τ_B; τ_M]` of the verification: input 0 the command `tau`, input
/// `k` the command with joint `k − 1`'s declared error `e_{k−1}` added.
fn held_inputs(x: &RoboticInput, tau: &Vector7, e: &Vector7) -> [Vector13; NJ + 1] {
    std::array::from_fn(|k| {
        let mut u = Vector13::zeros();
        u.fixed_rows_mut::<3>(0).copy_from(&x.force_b);
        u.fixed_rows_mut::<3>(3).copy_from(&x.torque_b);
        u.fixed_rows_mut::<NJ>(6).copy_from(tau);
        if k > 0 {
            u[6 + k - 1] += e[k - 1];
        }
        u
    })
}

/// `τ_hold = c_eff = −M_eff (b + ξ)`: the torque that holds the joint rates (`θ̈ = 0`).
fn hold_torque(x: &RoboticInput) -> Vector7 {
    -(x.m_eff * (x.drift + x.xi))
}

/// One RK4 step of the servicer's internal state `(θ, θ̇, ω_B)` under the held input `u`,
/// with exactly the simulator's arithmetic (`sc_sim`'s RK4 on these components).
pub fn rk4_internal(
    robot: &Robot,
    th: &Vector7,
    thd: &Vector7,
    w: &Vector3<f64>,
    u: &Vector13,
    h: f64,
) -> Option<(Vector7, Vector7, Vector3<f64>)> {
    let f = |th: &Vector7,
             thd: &Vector7,
             w: &Vector3<f64>|
     -> Option<(Vector7, Vector7, Vector3<f64>)> {
        let a = robot.forward_dynamics_sim(th, w, thd, u)?;
        Some((
            *thd,
            a.fixed_rows::<NJ>(6).into(),
            a.fixed_rows::<3>(3).into(),
        ))
    };
    let (k1t, k1d, k1w) = f(th, thd, w)?;
    let (k2t, k2d, k2w) = f(
        &(th + k1t * (h / 2.0)),
        &(thd + k1d * (h / 2.0)),
        &(w + k1w * (h / 2.0)),
    )?;
    let (k3t, k3d, k3w) = f(
        &(th + k2t * (h / 2.0)),
        &(thd + k2d * (h / 2.0)),
        &(w + k2w * (h / 2.0)),
    )?;
    let (k4t, k4d, k4w) = f(&(th + k3t * h), &(thd + k3d * h), &(w + k3w * h))?;
    let th1 = th + (k1t + k2t * 2.0 + k3t * 2.0 + k4t) * (h / 6.0);
    let thd1 = thd + (k1d + k2d * 2.0 + k3d * 2.0 + k4d) * (h / 6.0);
    let w1 = w + (k1w + k2w * 2.0 + k3w * 2.0 + k4w) * (h / 6.0);
    (common::finite(&th1) && common::finite(&thd1) && common::finite(&w1))
        .then_some((th1, thd1, w1))
}

/// Computes the filter's precomputed terms from the servicer model for joint state
/// `(θ, θ̇)`, base angular velocity `omega_b` [rad/s, F_B] and the upstream safe base wrench
/// `[f_B,SF; τ_B,SF]` [N, N m; F_B, about the base origin]: `A = M_eff⁻¹`,
/// `b = −A c_free`, `ξ_rob = −A K [f_B; τ_B]`, the 21 arm spheres with `J`, `J̇θ̇`, and the
/// arm's reaction `Q` on the base. `None` when the model has no base sphere, not exactly 21
/// arm spheres, or the dynamics are singular / non-finite.
pub fn robotic_input_from_model(
    robot: &Robot,
    theta: &Vector7,
    theta_dot: &Vector7,
    omega_b: &Vector3<f64>,
    f_b_sf: &Vector3<f64>,
    tau_b_sf: &Vector3<f64>,
) -> Option<RoboticInput> {
    if !(common::finite(theta)
        && common::finite(theta_dot)
        && common::finite(omega_b)
        && common::finite(f_b_sf)
        && common::finite(tau_b_sf))
    {
        return None;
    }
    let wrench = Vector6::new(
        f_b_sf.x, f_b_sf.y, f_b_sf.z, tau_b_sf.x, tau_b_sf.y, tau_b_sf.z,
    );
    let red = robot.reduced_arm_dynamics(theta, theta_dot, omega_b, &wrench)?;
    let a = red.m_eff.cholesky()?.inverse();
    let base_dyn = robot.base_angular_dynamics(theta, theta_dot, omega_b, f_b_sf)?;
    let reaction = base_dyn.q;
    let base = robot.base_sphere()?;
    let kin = robot.kinematics_vel(theta, theta_dot);
    let mut spheres = [SphereTerms::default(); NS];
    let mut n = 0;
    for (idx, _) in robot.arm_spheres() {
        if n >= NS {
            return None;
        }
        let s = robot.sphere_state(&kin, idx)?;
        spheres[n] = SphereTerms {
            center: s.center,
            jacobian: s.jacobian,
            jdot_qdot: s.jdot_qdot,
            radius: s.radius,
        };
        n += 1;
    }
    if n != NS {
        return None;
    }
    Some(RoboticInput {
        theta: *theta,
        theta_dot: *theta_dot,
        a,
        m_eff: red.m_eff,
        drift: -(a * red.c_free),
        xi: -(a * red.xi),
        spheres,
        base_center: base.center,
        base_radius: base.radius,
        reaction,
        omega_b: *omega_b,
        force_b: *f_b_sf,
        torque_b: *tau_b_sf,
        com: robot.com_terms(&kin),
        omega_dot_b0: base_dyn.r + base_dyn.p * tau_b_sf,
        total_mass: robot.total_mass(),
        around: None,
    })
}

/// The robotic filter's own parts of the shared step ([`crate::step`]): its 63 rows, the
/// a-posteriori certificate, the verification with the servicer model and its braking law.
impl FilterStep<NJ, N> for RoboticFilter {
    type Input = RoboticInput;
    type Prepared = Prepared;

    fn bound(&self) -> f64 {
        self.params.torque_max
    }

    fn take_tally(&mut self) -> SolverTally {
        self.engine.take_tally()
    }

    fn last_problem(&mut self) -> &mut LastProblem<NJ> {
        &mut self.last
    }

    fn prepare(&self, x: &RoboticInput) -> Result<Prepared, Invalid> {
        Self::checked(x)?;
        Ok(Prepared {
            terms: self.terms_of(x),
            weights: self.weights(),
            hard: self.hard_rows(x),
        })
    }

    /// The braking law from the input alone (zero when it cannot be evaluated).
    fn refused(&self, x: &RoboticInput) -> Vector7 {
        clamp_box(&self.brake(x), self.params.torque_max).0
    }

    fn barrier_values(p: &Prepared) -> [f64; N] {
        p.terms.h()
    }

    fn braking_law(&self, x: &RoboticInput, _: &Prepared) -> Vector7 {
        self.brake(x)
    }

    fn emergency(&self, x: &RoboticInput, _: &Prepared) -> Vector7 {
        self.emergency_brake(x)
    }

    /// The command ([`RoboticFilter::command`]) with the rows it was solved with and the
    /// rows that certify it, kept here (they are large).
    fn solve_qp(
        &mut self,
        x: &RoboticInput,
        p: &Prepared,
        u_nom: &Vector7,
        report: &mut FilterReport<N>,
    ) -> Actuated<NJ> {
        let local = self.barrier_rows(x, &p.terms, Level::Local(hold_torque(x).abs()), &[0.0; N]);
        let mut behind = RowsBehind {
            solved: None,
            certifying: None,
        };
        let outcome = self.command(x, p, u_nom, &local, &mut behind);
        let solved = Solved {
            outcome: &outcome,
            rows: behind.solved.as_ref().unwrap_or(&local),
            weights: &p.weights,
            hard: &p.hard,
            certifying: behind.certifying.as_ref().unwrap_or(&local),
        };
        step::conclude(self, x, p, u_nom, solved, report)
    }
}

impl SafetyFilter<NJ, N> for RoboticFilter {
    const SUBSYSTEM: Subsystem = Subsystem::Robotic;
    const NAMES: [&'static str; N] = NAMES;
    type Input = RoboticInput;

    /// The robotic input with the upstream safe base force and torque (ξ_rob); `None`
    /// when the model cannot be evaluated (non-finite state or wrench, singular dynamics).
    fn input(&self, model: &Robot, o: &Observation, xi: &Coupling) -> Option<RoboticInput> {
        let x = robotic_input_from_model(
            model,
            &o.theta,
            &o.theta_dot,
            &o.omega_b,
            &xi.force_b,
            &xi.torque_b,
        )?;
        Some(RoboticInput {
            around: Some(Surroundings::from_observation(o)),
            ..x
        })
    }

    fn filter_with(&mut self, x: &RoboticInput, nominal: Option<&Vector7>) -> FilterOutput<NJ, N> {
        RoboticFilter::filter_with(self, x, nominal)
    }

    fn dump_qp(&self) -> crate::QpDump {
        RoboticFilter::dump_qp(self)
    }

    fn set_skip_enabled(&mut self, on: bool) {
        RoboticFilter::set_skip_enabled(self, on)
    }

    fn set_solver_settings(&mut self, settings: sc_qp::Settings) {
        self.engine.set_settings(settings);
    }

    fn input_bound(&self) -> f64 {
        self.params.torque_max
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampled::{RelDeg1, RelDeg2};

    /// The bit-pattern checks equal their definitions on the awkward values.
    #[test]
    fn input_checks_equal_their_definitions() {
        let vals = [
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            5e-324,
            1.0,
            -1.0,
            2.0,
            2.0f64.next_up(),
            -2.0f64.next_up(),
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -f64::NAN,
        ];
        for &a in &vals {
            for &b in &vals {
                let m = nalgebra::Vector2::new(a, b);
                let finite = a.is_finite() && b.is_finite();
                assert_eq!(common::finite(&m), finite, "{a} {b}");
                for max in [0.0, -0.0, 2.0, f64::MAX, f64::INFINITY, -1.0, f64::NAN] {
                    let want = finite && m.amax() <= max;
                    assert_eq!(finite_in(&m, max), want, "{a} {b} max {max}");
                }
            }
        }
    }

    /// `tr_mul` is `mᵀ v` bit for bit (the link rows' normals and telemetry depend on it).
    #[test]
    fn tr_mul_equals_the_transpose_product_bitwise() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            // wide magnitudes and both signs: rounding differs with the summation order
            let u = (seed >> 11) as f64 / (1u64 << 53) as f64;
            (u - 0.5) * 10f64.powi(((seed >> 3) % 9) as i32 - 4)
        };
        for _ in 0..2000 {
            let m = Matrix7::from_fn(|_, _| next());
            let v = Vector7::from_fn(|_, _| next());
            let j = Matrix3x7::from_fn(|_, _| next());
            let d = Vector3::from_fn(|_, _| next());
            let want = m.transpose() * v;
            let got = tr_mul(&m, &v);
            assert!(
                want.iter()
                    .zip(got.iter())
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
            let want = j.transpose() * d;
            let got = tr_mul(&j, &d);
            assert!(
                want.iter()
                    .zip(got.iter())
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
        }
    }

    /// The default scenario and a moving arm near its limits, the base turning and
    /// pushed: every term of the robotic input non-zero.
    fn moving_arm() -> (sc_scenario::Scenario, RoboticInput) {
        let s = crate::test_draws::default_scenario();
        let robot = Robot::from_urdf_file(&s.urdf_path()).unwrap();
        let theta = Vector7::from(s.safety.robotic.theta_max_rad) * 0.8;
        let theta_dot = Vector7::from_fn(|i, _| 0.05 * (i as f64 - 3.0));
        let (w, fb, tb) = (
            Vector3::new(0.01, -0.02, 0.03),
            Vector3::new(1.0, -2.0, 0.5),
            Vector3::new(0.3, 0.1, -0.2),
        );
        let x = robotic_input_from_model(&robot, &theta, &theta_dot, &w, &fb, &tb).unwrap();
        (s, x)
    }

    /// The emergency brake keeps the arm-reaction contract the attitude filter relies on:
    /// a fast arm whose plain braking law breaks it is braked more gently, within it; a
    /// slow one gets the plain braking law.
    #[test]
    fn the_emergency_brake_keeps_the_arm_reaction_contract() {
        let (s, x) = moving_arm();
        let f = RoboticFilter::new(RoboticParams::from_scenario(&s));
        let holds = |x: &RoboticInput, u: &Vector7| {
            f.hard_rows(x)[2 * NJ..]
                .iter()
                .all(|r| r.a.dot(u) + r.c >= -1e-12)
        };
        let fast = RoboticInput {
            theta_dot: x.theta_dot * 20.0,
            ..x
        };
        assert!(
            !holds(&fast, &f.brake(&fast)),
            "the plain brake breaks the contract"
        );
        let u = f.emergency_brake(&fast);
        assert!(
            holds(&fast, &u) && u.amax() <= f.command_limit().min(),
            "{u}"
        );
        // still a brake: it takes kinetic energy out of the joints
        assert!(u.dot(&fast.theta_dot) < 0.0);
        let slow = RoboticInput {
            theta_dot: x.theta_dot * 1e-3,
            ..x
        };
        assert!(holds(&slow, &f.brake(&slow)));
        assert_eq!(f.emergency_brake(&slow), f.brake(&slow));
    }

    /// The rows built from offsets and normals are the sampled-data rows of their
    /// definition (`RelDeg2::row_at`, `RelDeg1::row_at`), and the certificate's offsets with
    /// the shared normals are the rows of that level, bit for bit, at every level (what
    /// lets the filter check a command without building them).
    #[test]
    fn offsets_and_normals_are_the_rows_of_every_level() {
        let (s, x) = moving_arm();
        let f = RoboticFilter::new(RoboticParams::from_scenario(&s));
        let t = f.terms(&x).ok().unwrap();
        let local = f.barrier_rows(&x, &t, Level::Local(Vector7::zeros()), &[0.0; N]);
        // the rows as the sampled-data formulation defines them, row by row through
        // `RelDeg2::row_at` / `RelDeg1::row_at` (the reference the offsets must equal)
        let reference = |level: Level| -> [Row<NJ>; N] {
            let p = &f.params;
            let (bt, br, blb) = match level {
                Level::Certified(c) => f.certified_bounds(&x, &c.accel, &Disturbance::none()),
                Level::Local(_) => (
                    [SampleBounds {
                        period: p.period,
                        m2: 0.0,
                        m3: 0.0,
                    }; NJ],
                    [RateBounds {
                        period: p.period,
                        d: 0.0,
                        j: 0.0,
                    }; NJ],
                    [SampleBounds {
                        period: p.period,
                        m2: 0.0,
                        m3: 0.0,
                    }; 2 * NS],
                ),
            };
            let decay = Decay::linear(p.gamma).at(p.period);
            let rate = RateDecay::new(p.gamma_theta_dot, p.eps_theta_dot, p.period);
            std::array::from_fn(|j| {
                if j < NJ {
                    RelDeg2::from(t.theta[j]).row_at(&bt[j], p.u_max_theta, &decay)
                } else if j < 2 * NJ {
                    RelDeg1::from(t.theta_dot_max[j - NJ]).row_at(&br[j - NJ], &rate)
                } else if j < 3 * NJ {
                    RelDeg1::from(t.theta_dot_min[j - 2 * NJ]).row_at(&br[j - 2 * NJ], &rate)
                } else {
                    RelDeg2::from(*t.sphere(j)).row_at(&blb[j - 3 * NJ], p.u_max_lb, &decay)
                }
            })
        };
        for qdd in [
            Vector7::zeros(),
            Vector7::repeat(3.0),
            Vector7::from_fn(|i, _| i as f64),
        ] {
            let caps = Caps::of(&qdd, &Vector7::zeros());
            for level in [Level::Local(Vector7::zeros()), Level::Certified(caps)] {
                let rows = reference(level);
                let built = f.barrier_rows(&x, &t, level, &[0.0; N]);
                for (a, b) in rows.iter().zip(&built) {
                    assert_eq!(a.c.to_bits(), b.c.to_bits());
                    assert!(
                        a.a.iter()
                            .zip(b.a.iter())
                            .all(|(p, q)| p.to_bits() == q.to_bits())
                    );
                }
                let off = f.barrier_offsets(&x, &t, level);
                let rebuilt = with_offsets(&local, &off);
                for (a, b) in rows.iter().zip(&rebuilt) {
                    assert_eq!(a.c.to_bits(), b.c.to_bits());
                    assert!(
                        a.a.iter()
                            .zip(b.a.iter())
                            .all(|(p, q)| p.to_bits() == q.to_bits())
                    );
                }
            }
        }
    }

    /// With a declared torque error, the sample's own rows (`Local`) are the sampled-data
    /// rows of their definition with `M₂` (rates: `D`) = the row's worst case over the box,
    /// `Σ_k |a_jk| e_k`, `e = rel |τ̄| + bias` written out here from the profile's numbers;
    /// the certified rows are tighter than without the error, row by row; and the torque
    /// box keeps the delivered torque `τ (1 + rel) + bias` within `T_M`.
    #[test]
    fn a_declared_torque_error_lowers_every_row_by_its_worst_case() {
        let (s, x) = moving_arm();
        let exact = RoboticFilter::new(RoboticParams::from_scenario(&s));
        let a = sc_scenario::Uncertainty::profile("realistic", std::path::Path::new("."))
            .unwrap()
            .actuators;
        let mut params = RoboticParams::from_scenario(&s);
        params.joint_torque_error = TorqueError::from_actuators(&a);
        let f = RoboticFilter::new(params);
        let t = f.terms(&x).ok().unwrap();
        let tau = Vector7::from_fn(|i, _| 0.3 * (i as f64 - 2.5));
        let (sc, r) = (a.joint_torque_scale_rel, a.joint_torque_ripple_rel);
        let e = tau.abs() * (sc + r + sc * r) + Vector7::repeat(a.joint_torque_bias_nm);
        let p = &f.params;
        let decay = Decay::linear(p.gamma).at(p.period);
        let rate = RateDecay::new(p.gamma_theta_dot, p.eps_theta_dot, p.period);
        let rel2 = |r: &RelDegTwo<NJ>, mu: f64| {
            let b = SampleBounds {
                period: p.period,
                m2: r.hddot_u.abs().dot(&e),
                m3: 0.0,
            };
            RelDeg2::from(*r).row_at(&b, mu, &decay)
        };
        let rel1 = |r: &RelDegOne<NJ>| {
            let b = RateBounds {
                period: p.period,
                d: r.hdot_u.abs().dot(&e),
                j: 0.0,
            };
            RelDeg1::from(*r).row_at(&b, &rate)
        };
        let want: [Row<NJ>; N] = std::array::from_fn(|j| {
            if j < NJ {
                rel2(&t.theta[j], p.u_max_theta)
            } else if j < 2 * NJ {
                rel1(&t.theta_dot_max[j - NJ])
            } else if j < 3 * NJ {
                rel1(&t.theta_dot_min[j - 2 * NJ])
            } else {
                rel2(t.sphere(j), p.u_max_lb)
            }
        });
        let got = f.barrier_rows(&x, &t, Level::Local(tau.abs()), &[0.0; N]);
        for (j, (a, b)) in want.iter().zip(&got).enumerate() {
            assert!(
                (a.c - b.c).abs() <= 1e-12 * (1.0 + a.c.abs()),
                "{}",
                NAMES[j]
            );
        }
        let plain = exact.barrier_rows(&x, &t, Level::Local(tau.abs()), &[0.0; N]);
        // tighter wherever the torque moves the row (link 1's spheres lie on joint 1's axis)
        let moved = |j: usize| t.normal(j).amax() > 0.0;
        for j in 0..N {
            assert!(got[j].c <= plain[j].c, "{}", NAMES[j]);
            assert!(!moved(j) || got[j].c < plain[j].c, "{}", NAMES[j]);
        }
        let caps = Caps::of(&(x.a * tau + x.drift + x.xi), &tau);
        let cert = f.barrier_offsets(&x, &t, Level::Certified(caps));
        let cert_plain = exact.barrier_offsets(&x, &t, Level::Certified(caps));
        for j in 0..N {
            assert!(cert[j] <= cert_plain[j], "{}", NAMES[j]);
            assert!(!moved(j) || cert[j] < cert_plain[j], "{}", NAMES[j]);
        }
        // the box: the delivered torque of a command on the bound is T_M (1 − BOX_MARGIN)
        let lim = f.command_limit();
        let delivered = lim * (1.0 + sc + r + sc * r) + Vector7::repeat(a.joint_torque_bias_nm);
        let box_max = p.torque_max * (1.0 - BOX_MARGIN);
        assert!(
            delivered.iter().all(|d| (d - box_max).abs() <= 1e-12),
            "{delivered}"
        );
        assert!(exact.command_limit().iter().all(|l| *l == box_max));
        // the hard rows: the box at the command limit, the contract less |Q| e(limit)
        let hard = f.hard_rows(&x);
        let q_err =
            x.reaction.abs() * (lim * (sc + r + sc * r) + Vector7::repeat(a.joint_torque_bias_nm));
        let q_hold = x.reaction * hold_torque(&x);
        for (k, row) in hard.iter().enumerate() {
            let want = if k < 2 * NJ {
                lim[k / 2]
            } else {
                let i = (k - 2 * NJ) / 2;
                let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
                p.arm_reaction_budget[i] - sign * q_hold[i] - q_err[i]
            };
            assert!(
                (row.c - want).abs() <= 1e-15 * (1.0 + want.abs()),
                "hard row {k}"
            );
        }
        // and the braking law stays inside the command box
        let fast = RoboticInput {
            theta_dot: Vector7::repeat(10.0),
            ..x
        };
        assert!(f.brake(&fast).amax() <= lim.min());
    }
}
