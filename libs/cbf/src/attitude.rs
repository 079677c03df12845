//! Attitude safety filter (paper Sec. "CBFs for the Attitude Subsystem", QP eq.
//! "attitude_qp").
//!
//! State `x_att = [q_RB; ω_B]` (scalar-first quaternion rotating F_B into F_R; body rate in
//! F_B [rad/s]); input the body torque `τ_B` [N m] in F_B. The paper's rigid-body model
//! `I ω̇ = τ_B − ω × (I ω)` (eq. "Attitude dynamics") is replaced by the base's exact
//! angular dynamics in the coupled multibody servicer
//! (`sc_multibody::Robot::base_angular_dynamics`),
//! `ω̇_B = P_L τ_B + r_L + Q (τ_M − τ_hold)`: `P_L`, `r_L` the base with the arm locked
//! (its joint rates held; `r_L` carries the velocity products of the moving arm and the
//! torque of the upstream force about the system CoM, known), and `Q (τ_M − τ_hold)` the
//! reaction of whatever the downstream arm does beyond holding itself, bounded by a
//! contract the robotic filter enforces, `|(Q (τ_M − τ_hold))_i| ≤ β_i`
//! (`arm_reaction_budget_rad_s2`) — the backward coupling the paper leaves uncompensated.
//!
//! Coupling `ξ_att`: the line-of-sight barrier depends on where the servicer *is*, so its
//! second derivative contains the servicer's relative translational acceleration in F_R,
//! `a_R = a_drift,R + f_R,SF / m`, where `f_R,SF = R_RB f_B,SF` is the upstream safe force of
//! the translational filter. `ξ_att = f_R,SF / m` [m/s²] is passed in by the caller
//! ([`xi_att_from_force`]); it enters `ḧ_ATT`'s drift only.

use crate::barrier::{RelDegOne, RelDegTwo, Row};
use crate::common::{
    self, BOX_MARGIN, FilterOutput, FilterReport, clamp_box, in_range3, unit_quat,
};
use crate::engine::{Engine, LastProblem, Outcome, SolverTally};
use crate::filter::{Coupling, SafetyFilter};
use crate::sampled::{Decay, RateBounds, RateDecay, RelDeg1, RelDeg2, SampleBounds};
use crate::step::{self, Actuated, FilterStep, Invalid, Solved};
use crate::{Formulation, qp::SolverParams};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use sc_core::{Observation, Subsystem};
use sc_models::quat::{self, Quat};
use sc_multibody::Robot;

/// Constraint names in report order.
pub const NAMES: [&str; 7] = [
    "line_of_sight",
    "omega_max_x",
    "omega_max_y",
    "omega_max_z",
    "omega_min_x",
    "omega_min_y",
    "omega_min_z",
];
/// Number of constraints.
pub const N: usize = 7;
/// Rows of the QP: the [`NAMES`] rows, then the four boresight-rate rows of the certified
/// set ([`boresight_rate`]).
pub const ROWS: usize = N + 4;
/// Priority tiers of the rows in the relaxed problem ([`crate::engine`]): the rates
/// (the six limits and the boresight's rate) first, the line of sight after them.
pub const TIERS: [u8; ROWS] = [1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];

/// Accepted ranges: `‖ω_B‖, ‖ω_T,B‖ ≤ MAX_RATE_RAD_S`; positions `≤ MAX_RANGE_M`,
/// velocities `≤ MAX_SPEED_M_S`, accelerations (incl. ξ) `≤ MAX_ACCEL_M_S2`; the LOS
/// distance `‖R_RT p_G,T − r_R‖ ≥ MIN_LOS_M` (direction undefined below).
pub const MAX_RATE_RAD_S: f64 = 10.0;
pub const MAX_RANGE_M: f64 = 1e5;
pub const MAX_SPEED_M_S: f64 = 1e3;
pub const MAX_ACCEL_M_S2: f64 = 1e3;
pub const MIN_LOS_M: f64 = 1e-6;

/// Parameters of the attitude filter (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct AttitudeParams {
    /// Boresight `d_B` (unit, F_B).
    pub boresight_b: Vector3<f64>,
    /// `cos β_ATT`.
    pub cos_beta: f64,
    /// γ_h [1/s], ε_ATT [1/s], μ of H_ATT [1/s²] (`u_max_att_per_s2`).
    pub gamma: f64,
    pub eps_att: f64,
    pub u_max_att: f64,
    /// The decay (C2) allows `H_ATT`: the paper's `γ_h` near the cone's edge, steeper
    /// closer to its axis than the knee ([`Decay`]).
    pub decay: Decay,
    /// Per-axis rate limits `ω_min ≤ ω_B ≤ ω_max` [rad/s].
    pub omega_max: Vector3<f64>,
    pub omega_min: Vector3<f64>,
    /// γ_ω [1/s], ε_ω [rad/s²].
    pub gamma_omega: f64,
    pub eps_omega: f64,
    /// Certified set: `|e_kᵀω_B| ≤ w̄` across the boresight [rad/s] ([`boresight_rate`])
    /// and its γ [1/s].
    pub boresight_rate_max: f64,
    pub gamma_boresight: f64,
    /// `‖τ_B‖∞ ≤ T` [N m].
    pub torque_max: f64,
    /// T of the braking law `τ_B = sat(−P⁻¹ (ω_B − ω_T,B)/T)` [s]: the substitute nominal
    /// and the backup command.
    pub brake_time: f64,
    pub solver: SolverParams,
    /// Sample length `T` [s].
    pub period: f64,
    pub formulation: Formulation,
    /// The contract with the robotic filter: `|(Q τ_M)_i| ≤ β_i` [rad/s²], the arm's
    /// reaction on the base's angular acceleration (the robotic filter enforces it).
    pub arm_reaction_budget: Vector3<f64>,
    /// The contract with the robotic filter: the joint torque the base wrench may take
    /// from each joint, `|(K [f_B; τ_B])_j| ≤ κ_j` [N m].
    pub joint_coupling_budget: SVector<f64, 7>,
    /// Bound on `|ω̈_B,i|` over the certified set [rad/s³].
    pub jerk_bound: f64,
    /// The servicer's mass [kg] and force bound [N]: the relative motion of the line of
    /// sight inside a sample.
    pub mass: f64,
    pub force_max: f64,
}

impl AttitudeParams {
    pub fn from_scenario(s: &sc_scenario::Scenario, mass: f64) -> Self {
        let a = &s.safety.attitude;
        Self {
            boresight_b: Vector3::from(s.servicer.boresight_body).normalize(),
            cos_beta: a.los_half_angle_deg.to_radians().cos(),
            gamma: s.safety.gamma_per_s,
            eps_att: a.eps_att,
            u_max_att: a.u_max_att_per_s2,
            decay: Decay {
                gamma: s.safety.gamma_per_s,
                // H ≤ h ≤ cos θ − cos β while turning away from the axis: H above the knee
                // only closer to the axis than the knee's angle
                knee: a.los_decay_knee_deg.to_radians().cos()
                    - a.los_half_angle_deg.to_radians().cos(),
                gamma_inner: a.gamma_los_inner_per_s,
            },
            omega_max: Vector3::from(a.omega_max_rad_s),
            omega_min: Vector3::from(a.omega_min_rad_s),
            gamma_omega: a.gamma_omega_per_s,
            eps_omega: a.eps_omega,
            boresight_rate_max: a.boresight_rate_max_rad_s,
            gamma_boresight: a.gamma_boresight_rate_per_s,
            torque_max: s.limits.torque_max_nm,
            brake_time: s.safety.fallback.attitude_brake_time_s,
            solver: SolverParams::from_scenario(s),
            period: s.mission.control_period_s,
            formulation: s.safety.formulation,
            arm_reaction_budget: Vector3::from(a.arm_reaction_budget_rad_s2),
            joint_coupling_budget: SVector::<f64, 7>::from(a.joint_coupling_budget_nm),
            jerk_bound: a.angular_jerk_bound_rad_s3,
            mass,
            force_max: s.limits.force_max_n,
        }
    }
}

/// Everything the attitude filter needs at one control step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeInput {
    /// `q_RB` (rotates F_B into F_R).
    pub q_rb: Quat,
    /// `ω_B` [rad/s] in F_B.
    pub omega_b: Vector3<f64>,
    /// The base's angular dynamics with the arm locked, `ω̇_B = P τ_B + r` (+ the arm's
    /// reaction beyond holding, bounded by the contract): `P` [1/(kg m²)] and `r` [rad/s²]
    /// with the upstream safe force acting.
    pub p: Matrix3<f64>,
    pub r: Vector3<f64>,
    /// Servicer system CoM relative to the target CoM, in F_R [m] (the line of sight is
    /// measured from it).
    pub r_r: Vector3<f64>,
    /// `v_R = ṙ_R` [m/s] (F_R is non-rotating).
    pub v_r: Vector3<f64>,
    /// Relative drift acceleration of the CoM in F_R without its own thrust [m/s²]
    /// (e.g. [`tidal_acceleration`]).
    pub a_drift_r: Vector3<f64>,
    /// Grasping point `R_RT(t) p_G,T` in F_R [m], its first and second time derivative.
    pub grasp_r: Vector3<f64>,
    pub grasp_vel_r: Vector3<f64>,
    pub grasp_acc_r: Vector3<f64>,
    /// `ξ_att = R_RB f_B,SF / m` [m/s²]: the upstream safe force's acceleration, F_R.
    pub xi_r: Vector3<f64>,
    /// Target angular velocity expressed in F_B [rad/s].
    pub omega_target_b: Vector3<f64>,
    /// The joint torque the base wrench takes to hold the arm, `K [f_B; τ_B]`
    /// (`sc_multibody::ReducedArmDynamics::wrench_map`): its torque columns [N m per N m]
    /// and the upstream force's share [N m] — the contract rows `|K_j [f_B; τ_B]| ≤ κ_j`.
    pub joint_coupling: SMatrix<f64, 7, 3>,
    pub joint_coupling_force: SVector<f64, 7>,
}

/// `ξ_att = R_RB f_B,SF / m` from the translational filter's actuated safe force.
pub fn xi_att_from_force(f_b_sf: &Vector3<f64>, q_rb: &Quat, mass: f64) -> Vector3<f64> {
    quat::to_matrix(q_rb) * f_b_sf / mass
}

/// Relative (tidal) acceleration of a point at `r_r` from the target CoM on a circular
/// orbit of mean motion `n`, in an inertially fixed frame: `n² (3 (êᵀr) ê − r)`, `ê` the
/// unit radial direction of the target in that frame.
pub fn tidal_acceleration(n: f64, radial_unit: &Vector3<f64>, r_r: &Vector3<f64>) -> Vector3<f64> {
    (radial_unit * (3.0 * radial_unit.dot(r_r)) - r_r) * (n * n)
}

/// Unit line of sight `s_R = ρ/‖ρ‖`, `ρ = R_RT p_G,T − r_R` (paper eq. for `s_R(t)`), with
/// `ṡ` and `s̈` for `ρ̇`, `ρ̈` (all in F_R).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineOfSight {
    pub s: Vector3<f64>,
    pub s_dot: Vector3<f64>,
    pub s_ddot: Vector3<f64>,
}

/// `s = ρ/L`, `ṡ = (ρ̇ − s L̇)/L`, `s̈ = (ρ̈ − 2 ṡ L̇ − s L̈)/L` with `L = ‖ρ‖`,
/// `L̇ = sᵀρ̇`, `L̈ = (‖ρ̇‖² + ρᵀρ̈ − L̇²)/L`.
pub fn line_of_sight_direction(
    rho: &Vector3<f64>,
    rho_dot: &Vector3<f64>,
    rho_ddot: &Vector3<f64>,
) -> LineOfSight {
    let l = rho.norm();
    let s = rho / l;
    let l_dot = s.dot(rho_dot);
    let s_dot = (rho_dot - s * l_dot) / l;
    let l_ddot = (rho_dot.dot(rho_dot) + rho.dot(rho_ddot) - l_dot * l_dot) / l;
    let s_ddot = (rho_ddot - s_dot * (2.0 * l_dot) - s * l_ddot) / l;
    LineOfSight { s, s_dot, s_ddot }
}

/// Line-of-sight cone, paper eq. "CBF-ATT": `h_ATT = d_Bᵀ R_BR(q) s_R(t) − cos β_ATT`.
/// With `s_B = R_BR s`, `ṡ_B = R_BR ṡ`, `s̈_B = R_BR s̈`:
/// `ḣ = (ω×d)ᵀ s_B + dᵀ ṡ_B`,
/// `ḧ = ω̇ᵀ(d × s_B) + (ω×(ω×d))ᵀ s_B + 2 (ω×d)ᵀ ṡ_B + dᵀ s̈_B` with `ω̇ = P τ + r`, so
/// `∂ḧ/∂τ = Pᵀ (d × s_B)`. ξ_att is inside `s̈` (through `ρ̈`).
pub fn line_of_sight(
    r_br: &Matrix3<f64>,
    omega: &Vector3<f64>,
    p: &Matrix3<f64>,
    r: &Vector3<f64>,
    d_b: &Vector3<f64>,
    los: &LineOfSight,
    cos_beta: f64,
) -> RelDegTwo<3> {
    let s_b = r_br * los.s;
    let sd_b = r_br * los.s_dot;
    let sdd_b = r_br * los.s_ddot;
    let wxd = omega.cross(d_b);
    let dxs = d_b.cross(&s_b);
    RelDegTwo {
        h: d_b.dot(&s_b) - cos_beta,
        hdot: wxd.dot(&s_b) + d_b.dot(&sd_b),
        hddot_drift: r.dot(&dxs)
            + omega.cross(&wxd).dot(&s_b)
            + 2.0 * wxd.dot(&sd_b)
            + d_b.dot(&sdd_b),
        hddot_u: p.transpose() * dxs,
    }
}

/// Angular-rate limits, paper eq. "CBF-omega": `h⁺_i = ω_max,i − ω_i`,
/// `h⁻_i = ω_i − ω_min,i` [rad/s]; relative degree one with `ω̇ = P τ + r`.
/// Returns `[h⁺_x, h⁺_y, h⁺_z, h⁻_x, h⁻_y, h⁻_z]`.
pub fn omega_limits(
    omega: &Vector3<f64>,
    p: &Matrix3<f64>,
    r: &Vector3<f64>,
    omega_max: &Vector3<f64>,
    omega_min: &Vector3<f64>,
) -> [RelDegOne<3>; 6] {
    std::array::from_fn(|k| {
        let i = k % 3;
        let row: Vector3<f64> = p.row(i).transpose();
        if k < 3 {
            RelDegOne {
                h: omega_max[i] - omega[i],
                hdot_drift: -r[i],
                hdot_u: -row,
            }
        } else {
            RelDegOne {
                h: omega[i] - omega_min[i],
                hdot_drift: r[i],
                hdot_u: row,
            }
        }
    })
}

/// Two unit axes across the boresight `d` (unit): `e₁ ⊥ d`, `e₂ = d × e₁` — the scenario's
/// envelope computes its steady-state rates on the same axes
/// ([`sc_scenario::envelope::across_boresight`], one definition).
pub fn across_boresight(d: &Vector3<f64>) -> [Vector3<f64>; 2] {
    sc_scenario::envelope::across_boresight(&[d.x, d.y, d.z]).map(Vector3::from)
}

/// The boresight's rate across itself, constraints of the certified set (not among the
/// paper's barriers; docs/SAFETY.md, "Line of sight"): `h = w̄ ∓ e_kᵀω ≥ 0` for the two
/// axes `e_k` across the boresight ([`across_boresight`]), so that the boresight's tip
/// moves at most `√2 w̄`. Rate limits like [`omega_limits`] on rotated axes: relative
/// degree one, `ḣ = ∓e_kᵀ(P τ + r)`. Order `[+e₁, +e₂, −e₁, −e₂]`.
pub fn boresight_rate(
    omega: &Vector3<f64>,
    p: &Matrix3<f64>,
    r: &Vector3<f64>,
    d: &Vector3<f64>,
    w_max: f64,
) -> [RelDegOne<3>; 4] {
    let e = across_boresight(d);
    std::array::from_fn(|k| {
        let sign = if k < 2 { 1.0 } else { -1.0 };
        let ek = e[k % 2] * sign;
        RelDegOne {
            h: w_max - ek.dot(omega),
            hdot_drift: -ek.dot(r),
            hdot_u: -(p.transpose() * ek),
        }
    })
}

/// All barrier terms of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeTerms {
    pub los: RelDegTwo<3>,
    pub omega: [RelDegOne<3>; 6],
    /// The certified set's boresight-rate limits ([`boresight_rate`]).
    pub boresight: [RelDegOne<3>; 4],
}

/// Validated, preprocessed input.
pub(crate) struct Prepared {
    /// `P⁻¹`: the base's articulated inertia [kg m²] (for the braking law).
    inertia: Matrix3<f64>,
    terms: AttitudeTerms,
    /// Rows valid for any torque in the box ([`NAMES`] order, then the boresight rate).
    rows: [Row<3>; ROWS],
    weights: [f64; ROWS],
    rho: Vector3<f64>,
}

/// A command certified by an acceleration cap and the QP it was solved with: the barrier
/// rows for that cap and the hard rows with the cap's rows.
struct Capped {
    outcome: Outcome<3>,
    rows: [Row<3>; ROWS],
    hard: [Row<3>; HARD + 6],
}

/// Caps on the body's angular acceleration per axis [rad/s²] that the certificate tries
/// after the nominal's own; the certified command nearest the nominal wins
/// (docs/SAFETY.md, "Line of sight").
pub const ACCEL_CAPS: [f64; 7] = [0.32, 0.16, 0.08, 0.04, 0.02, 0.01, 0.005];

fn p_formulation_sampled(p: &AttitudeParams) -> bool {
    p.formulation == Formulation::SampledData
}

/// The attitude CBF-QP safety filter (paper eq. "attitude_qp").
pub struct AttitudeFilter {
    pub params: AttitudeParams,
    engine: Engine<3, { ROWS + HARD + 6 }>,
    bounds: [Row<3>; 6],
    last: LastProblem<3>,
}

/// Hard rows: the torque box (6) and the joint-coupling contract (14).
const HARD: usize = 6 + 14;

/// `P` symmetric positive definite (to 1e-9 relative) with finite inverse: `(P, P⁻¹)`.
pub fn checked_gain(p: &Matrix3<f64>) -> Option<(Matrix3<f64>, Matrix3<f64>)> {
    if !common::finite(p) {
        return None;
    }
    let n = p.norm();
    if !(n > 0.0 && n < 1e12) || (p - p.transpose()).norm() > 1e-9 * n {
        return None;
    }
    let s = (p + p.transpose()) * 0.5;
    let inv = s.cholesky()?.inverse();
    common::finite(&inv).then_some((s, inv))
}

impl AttitudeFilter {
    pub fn new(params: AttitudeParams) -> Self {
        let lim = params.torque_max * (1.0 - BOX_MARGIN);
        let bounds = std::array::from_fn(|i| {
            let mut a = Vector3::zeros();
            a[i / 2] = if i % 2 == 0 { -1.0 } else { 1.0 };
            Row { a, c: lim }
        });
        Self {
            params,
            engine: Engine::new(),
            bounds,
            last: LastProblem::with_capacity(ROWS, HARD + 6),
        }
    }

    pub fn from_scenario(s: &sc_scenario::Scenario, mass: f64) -> Self {
        Self::new(AttitudeParams::from_scenario(s, mass))
    }

    /// Barrier terms for a valid input (`None` otherwise).
    pub fn constraints(&self, x: &AttitudeInput) -> Option<AttitudeTerms> {
        self.prepare(x).ok().map(|p| p.terms)
    }

    /// Bounds on the model's error inside one sample for a command whose body angular
    /// acceleration at the sample is at most `accel = (‖ω̇‖, ‖ω̇ − d(dᵀω̇)‖)` [rad/s²]
    /// (`None`: any torque in the box): the line of sight's `(M₂, M₃)` and the rate rows'
    /// `(D, J)` (derivation: docs/SAFETY.md, "Line of sight").
    ///
    /// Only the rotation *across* the boresight moves it, so the bound keeps the body rate
    /// `W` and its part across the boresight `W⊥` apart: with `β` the arm's contract and `j`
    /// the configured bound on `|ω̈_i|`, `α = ‖ω̇‖ + ‖β‖ + √3 jT`, `α⊥` likewise from the
    /// part across, `W = ‖ω‖ + αT`, `W⊥ = ‖ω × d‖ + α⊥T`. The line of sight `s = ρ/L` of
    /// `ρ = p_G − r` changes at most at `σ₁ = V/L`, `σ₂ = A/L + 2V²/L²`,
    /// `σ₃ = J/L + 6VA/L² + 6V³/L³` with `V, A, J` the bounds on `ρ̇, ρ̈, ρ⃛` over the sample
    /// (servicer thrust `√3F/m` turning at `W`, grasping point on the target tumbling at
    /// `ω_T`). With `e₀ = ‖d × s_B‖` at the sample, `ė = σ₁ + W⊥ + We` its rate and
    /// `e = e₀ + ėT`, differentiating `ḧ = ω̇ᵀ(d × s_B) + 2(ω×d)ᵀṡ_B − (ω×d)ᵀ(ω×s_B) + dᵀs̈_B`:
    /// `M₂ = e₀‖β‖`,
    /// `M₃ = ė‖β‖ + √3 j e + α⊥(σ₁ + W⊥ + We) + 2α⊥σ₁ + 2W⊥(σ₂ + Wσ₁)
    ///       + α⊥(W⊥ + We) + W⊥α + W⊥W(σ₁ + W⊥ + We) + σ₃ + W⊥σ₂`.
    pub fn sample_bounds(
        &self,
        x: &AttitudeInput,
        rho: &Vector3<f64>,
        accel: Option<(f64, f64)>,
    ) -> (SampleBounds, [RateBounds; 6], [RateBounds; 4]) {
        let p = &self.params;
        let t = p.period;
        let jerk = p.jerk_bound;
        let beta = p.arm_reaction_budget.norm();
        let d = p.boresight_b;
        let (acc, acc_perp) = accel.unwrap_or_else(|| {
            // ‖P τ + r‖ over the torque box: ‖P‖₂ ≤ √(‖P‖₁‖P‖∞)
            let n1 = (0..3)
                .map(|j| x.p.column(j).abs().sum())
                .fold(0.0, f64::max);
            let ni = (0..3).map(|i| x.p.row(i).abs().sum()).fold(0.0, f64::max);
            let a = (n1 * ni).sqrt() * 3f64.sqrt() * p.torque_max + x.r.norm();
            (a, a)
        });
        let grow = beta + 3f64.sqrt() * jerk * t;
        let alpha = acc + grow;
        let alpha_p = acc_perp + grow;
        let w = x.omega_b.norm() + alpha * t;
        let w_p = x.omega_b.cross(&d).norm() + alpha_p * t;
        // relative motion of the line of sight
        let wt = x.omega_target_b.norm();
        let pg = x.grasp_r.norm();
        let f_acc = 3f64.sqrt() * p.force_max / p.mass;
        let a_rel = f_acc + x.a_drift_r.norm() + 2.0 * wt * wt * pg;
        let v_rel = (x.grasp_vel_r - x.v_r).norm() + a_rel * t;
        let j_rel = f_acc * w + 3.0 * wt * wt * wt * pg;
        let l = (rho.norm() - v_rel * t).max(1e-3);
        let s1 = v_rel / l;
        let s2 = a_rel / l + 2.0 * v_rel * v_rel / (l * l);
        let s3 = j_rel / l + 6.0 * v_rel * a_rel / (l * l) + 6.0 * v_rel.powi(3) / l.powi(3);
        let r_br = quat::to_matrix(&x.q_rb).transpose();
        let s_b = r_br * (rho / rho.norm());
        let e0 = d.cross(&s_b).norm();
        let e_dot = s1 + w_p + w * e0;
        let e = (e0 + e_dot * t).min(1.0);
        let e_dot = s1 + w_p + w * e;
        let m3 = e_dot * beta
            + 3f64.sqrt() * jerk * e
            + alpha_p * (s1 + w_p + w * e)
            + 2.0 * alpha_p * s1
            + 2.0 * w_p * (s2 + w * s1)
            + alpha_p * (w_p + w * e)
            + w_p * alpha
            + w_p * w * (s1 + w_p + w * e)
            + s3
            + w_p * s2;
        let los = SampleBounds {
            period: t,
            m2: e0 * beta,
            m3,
        };
        let rate = std::array::from_fn(|k| RateBounds {
            period: t,
            d: p.arm_reaction_budget[k % 3],
            j: jerk,
        });
        // the boresight rates: e_kᵀω̇ has the arm's reaction Σ|e_k,i|β_i unknown, and
        // |e_kᵀω̈| ≤ Σ|e_k,i| j
        let e = across_boresight(&d);
        let boresight = std::array::from_fn(|k| {
            let l1 = e[k % 2].abs();
            RateBounds {
                period: t,
                d: l1.dot(&p.arm_reaction_budget),
                j: l1.sum() * jerk,
            }
        });
        (los, rate, boresight)
    }

    /// The sampled-data rows ([`NAMES`] order) for commands with body acceleration at most
    /// `accel` (`None`: any torque in the box).
    fn sampled_rows(
        &self,
        x: &AttitudeInput,
        rho: &Vector3<f64>,
        t: &AttitudeTerms,
        accel: Option<(f64, f64)>,
    ) -> [Row<3>; ROWS] {
        let p = &self.params;
        let (b_los, b_rate, b_w) = self.sample_bounds(x, rho, accel);
        // every bound is for one control period: the decays evaluated once
        let los = p.decay.at(p.period);
        let omega = RateDecay::new(p.gamma_omega, p.eps_omega, p.period);
        let boresight = RateDecay::new(p.gamma_boresight, p.eps_omega, p.period);
        let mut rows = [RelDeg2::from(t.los).row_at(&b_los, p.u_max_att, &los); ROWS];
        for (k, o) in t.omega.iter().enumerate() {
            rows[1 + k] = RelDeg1::from(*o).row_at(&b_rate[k], &omega);
        }
        for (k, o) in t.boresight.iter().enumerate() {
            rows[N + k] = RelDeg1::from(*o).row_at(&b_w[k], &boresight);
        }
        rows
    }

    /// The braking law `τ_B = sat(−P⁻¹ (ω_B − ω_T,B)/T)` (direction kept): hold the
    /// target's rate. The substitute nominal and the backup when the solver fails; zero
    /// when the state is invalid.
    pub fn brake(&self, x: &AttitudeInput) -> Vector3<f64> {
        match checked_gain(&x.p) {
            Some((_, i))
                if in_range3(&x.omega_b, MAX_RATE_RAD_S)
                    && in_range3(&x.omega_target_b, MAX_RATE_RAD_S) =>
            {
                self.brake_with(&i, x)
            }
            _ => Vector3::zeros(),
        }
    }

    /// The torque box and the contract rows `κ_j ∓ (K_f f_B + K_τ τ_B)_j ≥ 0`.
    fn hard_rows(&self, x: &AttitudeInput) -> [Row<3>; HARD] {
        std::array::from_fn(|k| {
            if k < 6 {
                self.bounds[k]
            } else {
                let j = (k - 6) / 2;
                let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
                Row {
                    a: x.joint_coupling.row(j).transpose() * sign,
                    c: self.params.joint_coupling_budget[j] + sign * x.joint_coupling_force[j],
                }
            }
        })
    }

    /// The emergency brake (no solver produced a command): the braking law scaled,
    /// `τ_B = s τ_brake` with the largest `s ∈ [0, 1]` that keeps every joint-coupling
    /// contract row ([`Self::hard_rows`]) — the robotic filter's certificate assumes the
    /// base wrench stays within `joint_coupling_budget_nm` whatever the attitude filter
    /// does, its emergencies included. The base then brakes at `s` times the braking
    /// law's rate. Where the rows fail even at zero torque (the upstream force's share
    /// beyond the budget), `s = 0`: no torque of ours adds to it. `s τ_brake` stays in the
    /// torque box with `τ_brake`.
    pub fn emergency_brake(&self, x: &AttitudeInput) -> Vector3<f64> {
        self.within_contract(x, self.brake(x))
    }

    /// `s brake` with the largest `s ∈ [0, 1]` that keeps every contract row at `x`.
    fn within_contract(&self, x: &AttitudeInput, brake: Vector3<f64>) -> Vector3<f64> {
        let rows = self.hard_rows(x);
        // along the segment from zero every contract row is `at_zero + s slope ≥ 0`
        let s = rows[6..].iter().fold(1.0f64, |s, r| {
            let (at_zero, slope) = (r.c, r.a.dot(&brake));
            if !(at_zero.is_finite() && slope.is_finite()) {
                0.0
            } else if slope < 0.0 {
                s.min((at_zero / -slope).max(0.0))
            } else if at_zero < 0.0 {
                0.0
            } else {
                s
            }
        });
        if s >= 1.0 { brake } else { brake * s }
    }

    fn brake_with(&self, inertia: &Matrix3<f64>, x: &AttitudeInput) -> Vector3<f64> {
        let t = -(inertia * (x.omega_b - x.omega_target_b)) / self.params.brake_time;
        common::sat_inf(&t, self.params.torque_max * (1.0 - BOX_MARGIN))
    }

    /// The filter's command when its nominal is missing: the safety QP on the substitute
    /// nominal (the braking law).
    pub fn backup(&mut self, x: &AttitudeInput) -> FilterOutput<3, N> {
        self.filter_with(x, None)
    }

    /// One filter step: safe `τ_B` closest to `tau_nom` subject to the line-of-sight and
    /// rate rows and `‖τ_B‖∞ ≤ T`. An invalid nominal is replaced by the substitute.
    pub fn filter(&mut self, x: &AttitudeInput, tau_nom: &Vector3<f64>) -> FilterOutput<3, N> {
        self.filter_with(x, Some(tau_nom))
    }

    /// [`Self::filter`] with the nominal possibly missing.
    pub fn filter_with(
        &mut self,
        x: &AttitudeInput,
        tau_nom: Option<&Vector3<f64>>,
    ) -> FilterOutput<3, N> {
        step::filter_with(self, x, tau_nom)
    }

    /// The input's checks: every quantity finite and in range, the attitude a unit
    /// quaternion, `P` symmetric positive definite, the line of sight defined, then the
    /// coupling ξ_att in range. The attitude, `(P, P⁻¹)` and `ρ = R_RT p_G,T − r_R`.
    fn checked(&self, x: &AttitudeInput) -> Result<Checked, Invalid> {
        let ok = in_range3(&x.omega_b, MAX_RATE_RAD_S)
            && in_range3(&x.omega_target_b, MAX_RATE_RAD_S)
            && in_range3(&x.r_r, MAX_RANGE_M)
            && in_range3(&x.grasp_r, MAX_RANGE_M)
            && in_range3(&x.v_r, MAX_SPEED_M_S)
            && in_range3(&x.grasp_vel_r, MAX_SPEED_M_S)
            && in_range3(&x.a_drift_r, MAX_ACCEL_M_S2)
            && in_range3(&x.grasp_acc_r, MAX_ACCEL_M_S2)
            && in_range3(&x.r, MAX_ACCEL_M_S2)
            && common::finite(&x.joint_coupling)
            && common::finite(&x.joint_coupling_force);
        if !ok {
            return Err(Invalid::State);
        }
        let q = unit_quat(&x.q_rb).ok_or(Invalid::State)?;
        let (gain, inertia) = checked_gain(&x.p).ok_or(Invalid::State)?;
        let rho = x.grasp_r - x.r_r;
        if rho.norm() < MIN_LOS_M {
            return Err(Invalid::State);
        }
        if !in_range3(&x.xi_r, MAX_ACCEL_M_S2) {
            return Err(Invalid::Coupling);
        }
        Ok(Checked {
            q,
            gain,
            inertia,
            rho,
        })
    }

    /// The barrier terms of paper eqs. "CBF-ATT" and "CBF-omega" and the boresight rate,
    /// with ξ_att in the line of sight's `ρ̈`.
    fn terms(&self, x: &AttitudeInput, c: &Checked) -> AttitudeTerms {
        let p = &self.params;
        let rho_dot = x.grasp_vel_r - x.v_r;
        let rho_ddot = x.grasp_acc_r - x.a_drift_r - x.xi_r;
        let los_dir = line_of_sight_direction(&c.rho, &rho_dot, &rho_ddot);
        let r_br = quat::to_matrix(&c.q).transpose();
        let los = line_of_sight(
            &r_br,
            &x.omega_b,
            &c.gain,
            &x.r,
            &p.boresight_b,
            &los_dir,
            p.cos_beta,
        );
        let omega = omega_limits(&x.omega_b, &c.gain, &x.r, &p.omega_max, &p.omega_min);
        let boresight = boresight_rate(
            &x.omega_b,
            &c.gain,
            &x.r,
            &p.boresight_b,
            p.boresight_rate_max,
        );
        AttitudeTerms {
            los,
            omega,
            boresight,
        }
    }

    /// The paper's rows (`safety.formulation = "paper"`, for comparison).
    fn paper_rows(&self, t: &AttitudeTerms) -> [Row<3>; ROWS] {
        let p = &self.params;
        let mut rows = [t.los.row(p.gamma, p.eps_att, p.u_max_att); ROWS];
        for (k, o) in t.omega.iter().enumerate() {
            rows[1 + k] = o.row(p.gamma_omega, p.eps_omega);
        }
        // the paper has no boresight-rate limit: rows that never bind
        for r in rows.iter_mut().skip(N) {
            *r = Row {
                a: Vector3::zeros(),
                c: 1.0,
            };
        }
        rows
    }

    /// The relaxed problem's weights: each row's violation is measured against the
    /// deceleration the formulation budgets for it — μ (u_max of H) for the line of sight,
    /// the paper's ε_ω for a rate row.
    fn weights(&self) -> [f64; ROWS] {
        let p = &self.params;
        let mut weights = [0.0; ROWS];
        weights[0] = p.u_max_att;
        for w in weights.iter_mut().skip(1) {
            *w = p.eps_omega;
        }
        weights
    }

    /// The torque box and the contract rows, then the six rows `cap ∓ (P τ + r)_i ≥ 0`
    /// that keep the body's angular acceleration within `cap` per axis.
    fn capped_hard_rows(x: &AttitudeInput, hard: &[Row<3>; HARD], cap: f64) -> [Row<3>; HARD + 6] {
        std::array::from_fn(|k| {
            if k < HARD {
                return hard[k];
            }
            let i = (k - HARD) / 2;
            let row: Vector3<f64> = x.p.row(i).transpose();
            if (k - HARD).is_multiple_of(2) {
                Row {
                    a: -row,
                    c: cap - x.r[i],
                }
            } else {
                Row {
                    a: row,
                    c: cap + x.r[i],
                }
            }
        })
    }

    /// The certificate (docs/SAFETY.md, "The acceleration cap"): rows whose in-sample
    /// bounds hold for commands that accelerate the body by at most `cap` per axis, solved
    /// together with the rows that keep the command's acceleration within `cap` — any
    /// solution is certified. The caps tried: the nominal's own acceleration (the nearest
    /// command), then [`ACCEL_CAPS`] (easier for the barrier rows); the certified command
    /// nearest the nominal wins. `None` when no cap gives a hard solution.
    fn certified_by_caps(
        &mut self,
        x: &AttitudeInput,
        p: &Prepared,
        u_nom: &Vector3<f64>,
        hard: &[Row<3>; HARD],
    ) -> Option<Capped> {
        let first = (x.p * u_nom + x.r).amax();
        let floor = x.r.amax();
        let mut best: Option<(f64, Capped)> = None;
        for (k, cap) in std::iter::once(first).chain(ACCEL_CAPS).enumerate() {
            if cap < floor || (k > 0 && cap == first) {
                continue;
            }
            let c = 3f64.sqrt() * cap;
            let rows = self.sampled_rows(x, &p.rho, &p.terms, Some((c, c)));
            let with_cap = Self::capped_hard_rows(x, hard, cap);
            // only a hard solution is taken here (a relaxed one is not certified): an
            // infeasible cap costs no relaxation
            let Some(outcome) = self.engine.solve_hard(u_nom, &rows, &with_cap) else {
                continue;
            };
            let dist = if k == 0 {
                0.0
            } else {
                (outcome.u - u_nom).norm()
            };
            if k == 0 || best.as_ref().is_none_or(|b| dist < b.0) {
                let solution = Capped {
                    outcome,
                    rows,
                    hard: with_cap,
                };
                if k == 0 {
                    return Some(solution);
                }
                best = Some((dist, solution));
            }
            if dist == 0.0 {
                // the nominal itself: no later cap can come nearer
                break;
            }
        }
        best.map(|b| b.1)
    }

    /// Verification only: force the solver even when the nominal is feasible.
    pub fn set_skip_enabled(&mut self, on: bool) {
        self.engine.set_skip_enabled(on);
    }

    /// The last QP handed to the engine (for `--dump-qp`).
    pub fn dump_qp(&self) -> crate::QpDump {
        self.last.dump()
    }

    /// The rows ([`NAMES`] order, then the boresight rate), their weights and the hard rows (torque box,
    /// joint-coupling contract) at `x`.
    pub fn rows(&self, x: &AttitudeInput) -> Option<(Vec<Row<3>>, Vec<f64>, Vec<Row<3>>)> {
        let p = self.prepare(x).ok()?;
        Some((
            p.rows.to_vec(),
            p.weights.to_vec(),
            self.hard_rows(x).to_vec(),
        ))
    }
}
/// What [`AttitudeFilter::checked`] found valid.
struct Checked {
    /// The unit attitude `q_RB`.
    q: Quat,
    /// `(P, P⁻¹)`.
    gain: Matrix3<f64>,
    inertia: Matrix3<f64>,
    /// `ρ = R_RT p_G,T − r_R` [m, F_R].
    rho: Vector3<f64>,
}

/// The attitude filter's own parts of the shared step ([`crate::step`]): its rows, the
/// acceleration-cap certificate, the tiers of its relaxed problem and its braking law.
impl FilterStep<3, N> for AttitudeFilter {
    type Input = AttitudeInput;
    type Prepared = Prepared;

    fn bound(&self) -> f64 {
        self.params.torque_max
    }

    fn take_tally(&mut self) -> SolverTally {
        self.engine.take_tally()
    }

    fn last_problem(&mut self) -> &mut LastProblem<3> {
        &mut self.last
    }

    /// The rows valid for any torque in the box.
    fn prepare(&self, x: &AttitudeInput) -> Result<Prepared, Invalid> {
        let c = self.checked(x)?;
        let terms = self.terms(x, &c);
        let rows = match self.params.formulation {
            Formulation::SampledData => self.sampled_rows(x, &c.rho, &terms, None),
            Formulation::Paper => self.paper_rows(&terms),
        };
        if !rows.iter().all(Row::is_finite) {
            return Err(Invalid::State);
        }
        Ok(Prepared {
            inertia: c.inertia,
            terms,
            rows,
            weights: self.weights(),
            rho: c.rho,
        })
    }

    /// The braking law from the input alone (zero when it cannot be evaluated).
    fn refused(&self, x: &AttitudeInput) -> Vector3<f64> {
        clamp_box(&self.brake(x), self.params.torque_max).0
    }

    fn barrier_values(p: &Prepared) -> [f64; N] {
        let mut h = [0.0; N];
        h[0] = p.terms.los.h;
        for (k, o) in p.terms.omega.iter().enumerate() {
            h[1 + k] = o.h;
        }
        h
    }

    fn braking_law(&self, x: &AttitudeInput, p: &Prepared) -> Vector3<f64> {
        self.brake_with(&p.inertia, x)
    }

    fn emergency(&self, x: &AttitudeInput, p: &Prepared) -> Vector3<f64> {
        self.within_contract(x, self.braking_law(x, p))
    }

    /// The acceleration-cap certificate (sampled-data rows); without one, the rows valid
    /// for any torque, relaxed in tiers ([`TIERS`]) when they cannot all hold.
    fn solve_qp(
        &mut self,
        x: &AttitudeInput,
        p: &Prepared,
        u_nom: &Vector3<f64>,
        report: &mut FilterReport<N>,
    ) -> Actuated<3> {
        let hard = self.hard_rows(x);
        let capped = if p_formulation_sampled(&self.params) {
            self.certified_by_caps(x, p, u_nom, &hard)
        } else {
            None
        };
        if let Some(c) = capped {
            let solved = Solved {
                outcome: &c.outcome,
                rows: &c.rows,
                weights: &p.weights,
                hard: &c.hard,
                certifying: &c.rows,
            };
            return step::conclude(self, x, p, u_nom, solved, report);
        }
        let outcome = self
            .engine
            .solve_tiered(u_nom, &p.rows, &p.weights, &TIERS, &hard);
        let solved = Solved {
            outcome: &outcome,
            rows: &p.rows,
            weights: &p.weights,
            hard: &hard,
            certifying: &p.rows,
        };
        step::conclude(self, x, p, u_nom, solved, report)
    }
}

impl SafetyFilter<3, N> for AttitudeFilter {
    const SUBSYSTEM: Subsystem = Subsystem::Attitude;
    const NAMES: [&'static str; N] = NAMES;
    type Input = AttitudeInput;

    /// The attitude input with the upstream safe force `xi.force_b` [N, F_B] as ξ_att —
    /// the CoM's acceleration along the line of sight, and its torque about the system
    /// CoM in the base dynamics. A non-finite state or force gives NaN dynamics, which the
    /// filter refuses (its braking law then applies), so the input always exists.
    fn input(&self, model: &Robot, o: &Observation, xi: &Coupling) -> Option<AttitudeInput> {
        Some(attitude_input(model, o, &xi.force_b))
    }

    fn filter_with(
        &mut self,
        x: &AttitudeInput,
        nominal: Option<&Vector3<f64>>,
    ) -> FilterOutput<3, N> {
        AttitudeFilter::filter_with(self, x, nominal)
    }

    fn dump_qp(&self) -> crate::QpDump {
        AttitudeFilter::dump_qp(self)
    }

    fn set_skip_enabled(&mut self, on: bool) {
        AttitudeFilter::set_skip_enabled(self, on)
    }

    fn set_solver_settings(&mut self, settings: sc_qp::Settings) {
        self.engine.set_settings(settings);
    }

    fn input_bound(&self) -> f64 {
        self.params.torque_max
    }
}

/// The attitude filter's input at the known state `o` with the actuated upstream safe
/// force `f_b_sf` [N, F_B] (ξ_att), evaluated with the servicer model `robot`.
pub fn attitude_input(robot: &Robot, o: &Observation, f_b_sf: &Vector3<f64>) -> AttitudeInput {
    let mass = robot.total_mass();
    let r_rh = quat::to_matrix(&quat::conj(&o.q_hr));
    let radial_r = r_rh * Vector3::x();
    let r_bt = quat::to_matrix(&quat::mul(&quat::conj(&o.q_rb), &o.q_rt));
    let nan3 = Vector3::from_element(f64::NAN);
    let nan73 = SMatrix::<f64, 7, 3>::from_element(f64::NAN);
    let nan7 = SVector::<f64, 7>::from_element(f64::NAN);
    let finite = f_b_sf.iter().all(|x| x.is_finite());
    let (p, r) = robot
        .base_angular_dynamics(&o.theta, &o.theta_dot, &o.omega_b, f_b_sf)
        .filter(|_| finite)
        .map(|d| (d.p_locked, d.r_locked))
        .unwrap_or((Matrix3::from_element(f64::NAN), nan3));
    let wrench = nalgebra::Vector6::new(f_b_sf.x, f_b_sf.y, f_b_sf.z, 0.0, 0.0, 0.0);
    let (k_tau, k_force) = robot
        .reduced_arm_dynamics(&o.theta, &o.theta_dot, &o.omega_b, &wrench)
        .filter(|_| finite)
        .map(|d| (d.wrench_map.fixed_columns::<3>(3).into(), d.xi))
        .unwrap_or((nan73, nan7));
    AttitudeInput {
        q_rb: o.q_rb,
        omega_b: o.omega_b,
        p,
        r,
        r_r: o.com_r,
        v_r: o.com_v_r,
        a_drift_r: tidal_acceleration(o.mean_motion, &radial_r, &o.com_r),
        grasp_r: o.grasp_r,
        grasp_vel_r: o.grasp_v_r,
        grasp_acc_r: o.grasp_a_r,
        xi_r: xi_att_from_force(f_b_sf, &o.q_rb, mass),
        omega_target_b: r_bt * o.omega_t,
        joint_coupling: k_tau,
        joint_coupling_force: k_force,
    }
}
