//! Translational safety filter (paper Sec. "CBFs for the Translational Subsystem",
//! QP eq. "translation_qp").
//!
//! State `x_tr = [r_H; v_H]`: the servicer's system centre of mass relative to the target
//! CoM in the Hill frame `F_H` [m, m/s] — the point whose motion the Clohessy–Wiltshire
//! model (paper eq. "rel motion system") `r̈_H = a_CW(r_H, v_H) + f_H/m` describes exactly
//! (the arm's internal forces do not move it), with mean motion `n` and the servicer's total
//! mass `m`; input the force `f_H` [N] in `F_H`. First in the causal order: `ξ_tr = 0`.
//!
//! Rows: the sampled-data rows of [`crate::sampled`] (default), or the paper's
//! continuous-time rows (`safety.formulation = "paper"`, for comparison). The bounds on
//! the model's error inside one sample ([`TranslationalFilter::sample_bounds`]) come from
//! the CW model, the force bound and the body rate: the force is held in the body frame,
//! which turns by at most `Ω T` inside the sample.
//!
//! Input bounds: the safe force is actuated in the body frame, `f_B,SF = R_BH f_H,SF`. To
//! guarantee the paper's `‖f_B‖∞ ≤ F` the box is imposed on `f_B` itself, i.e. the six
//! rows `±R_BH f_H ≤ F` (not a box on `f_H`, which would allow `‖f_B‖∞` up to √3 F).

use crate::barrier::{RelDegOne, RelDegTwo, Row};
use crate::common::{
    self, BOX_MARGIN, FilterOutput, FilterReport, clamp_box, in_range3, unit_quat,
};
use crate::engine::Kind;
use crate::engine::{Engine, LastProblem, SolverTally};
use crate::filter::{Coupling, SafetyFilter};
use crate::sampled::{self, RateBounds, RelDeg1, RelDeg2, SampleBounds};
use crate::step::{self, Actuated, FilterStep, Invalid, Solved};
use crate::translational_margins::{ForceError, InertialMotion, TranslationalErrors, Unknowns};
use crate::{Formulation, los_contract, qp::SolverParams};
use nalgebra::{Matrix3, Vector3};
use sc_core::{Observation, Subsystem};
use sc_models::quat::{self, Quat};
use sc_multibody::Robot;

/// Constraint names in report order.
pub const NAMES: [&str; 2] = ["approach_corridor", "collision_avoidance_zone"];
/// Number of constraints.
pub const N: usize = 2;
/// Rows of the QP besides the force box: the [`NAMES`] rows, the tangential-speed row and
/// the line-of-sight contract's ([`crate::los_contract`]).
pub const ROWS: usize = N + 1 + los_contract::ROWS;
/// Priority tier of each row in the relaxed problem (0 first): the barriers and the
/// tangential-speed limit before the line-of-sight contract, so that a contract that
/// cannot hold never buys a corridor or zone violation.
pub const TIERS: [u8; ROWS] = [0, 0, 0, 1, 1, 1, 1];
/// A row that never binds: the contract's rows where they are not defined.
const NEVER_BINDING: Row<3> = Row {
    a: Vector3::new(0.0, 0.0, 0.0),
    c: 1.0,
};

/// `rows` with the line-of-sight contract's (tier 1) made [`NEVER_BINDING`].
fn without_contract(rows: &[Row<3>; ROWS]) -> [Row<3>; ROWS] {
    std::array::from_fn(|i| {
        if TIERS[i] == 0 {
            rows[i]
        } else {
            NEVER_BINDING
        }
    })
}

/// Accepted state range: `MIN_RANGE_M ≤ ‖r_H‖ ≤ MAX_RANGE_M` (the corridor's cone is not
/// differentiable at its apex), `‖v_H‖ ≤ MAX_SPEED_M_S`, `‖ω_H‖, ‖ω̇_H‖ ≤ MAX_FRAME_RATE`. (A
/// grasping point or target rate outside these ranges drops the line-of-sight contract's
/// rows only: [`TranslationalFilter::los_rows`].)
pub const MIN_RANGE_M: f64 = 1e-6;
pub const MAX_RANGE_M: f64 = 1e5;
pub const MAX_SPEED_M_S: f64 = 1e3;
pub const MAX_FRAME_RATE: f64 = 1.0;

/// Parameters of the translational filter (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct TranslationalParams {
    /// Servicer mass m [kg].
    pub mass: f64,
    /// Mean motion n of the circular target orbit [rad/s] (CW drift).
    pub mean_motion: f64,
    /// Corridor axis `d_R` (unit, F_R).
    pub axis_r: Vector3<f64>,
    /// `cos ψ_AC`.
    pub cos_psi: f64,
    /// `R_CAZ` [m].
    pub r_caz: f64,
    /// γ_h [1/s].
    pub gamma: f64,
    /// Share of the corridor's braking authority at the wall the cone's curvature may take
    /// [-] ([`tangential_coefficient`]).
    pub curvature_share: f64,
    /// ε_AC [m/s], ε_CAZ [m²/s].
    pub eps_ac: f64,
    pub eps_caz: f64,
    /// u_max of H for the corridor [m/s²] and the CAZ [m²/s²] (see [`crate::barrier`]).
    pub u_max_ac: f64,
    pub u_max_caz: f64,
    /// `F` of `‖f_B‖∞ ≤ F` [N].
    pub force_max: f64,
    /// T of the braking law `f_H = sat(−m v_H / T)` [s]: the substitute nominal and the
    /// backup command.
    pub brake_time: f64,
    pub solver: SolverParams,
    /// Sample length `T` of the zero-order hold [s].
    pub period: f64,
    /// Which rows: the sampled-data rows or the paper's.
    pub formulation: Formulation,
    /// Bound on the base body rate `‖ω_B‖` inside the certified set [rad/s] (the attitude
    /// filter keeps `|ω_i| ≤ ω_max,i` between samples): how far the body-fixed force turns.
    pub omega_bound: f64,
    /// Radius of the target's circular orbit [m] (bounds the CW linearisation error).
    pub orbit_radius: f64,
    /// The declared errors the rows budget for (docs/SAFETY.md, "Margins for the declared
    /// errors"); `None`: none declared (the `exact` profile), the rows are the nominal ones.
    pub errors: Option<TranslationalErrors>,
    /// The line-of-sight contract `w_tr` [rad/s] ([`crate::los_contract`]).
    pub los_speed_budget: f64,
    /// γ of the line-of-sight contract's rows [1/s].
    pub gamma_los_speed: f64,
    /// The fixed reference of the contract's axes ([`los_contract::reference`], F_R).
    pub los_reference: Vector3<f64>,
    /// `κ ≥ λ_max/λ_min` of the target's inertia with its declared error: its rate stays
    /// within `κ ‖ω_T‖` and `‖ω̇_T‖ ≤ κ ‖ω_T‖²` (torque free, `‖Iω‖` conserved).
    pub target_inertia_ratio: f64,
}

impl TranslationalParams {
    /// From `[limits]`, `[safety]`, `[safety.translational]`, `[safety.solver]`,
    /// `[safety.fallback]` and the orbit (n = √(μ/a³)); `mass` from the servicer model.
    pub fn from_scenario(s: &sc_scenario::Scenario, mass: f64) -> Self {
        let t = &s.safety.translational;
        let a = s.orbit.earth_radius_m + s.orbit.altitude_m;
        Self {
            mass,
            mean_motion: (s.orbit.earth_mu_m3_s2 / (a * a * a)).sqrt(),
            axis_r: Vector3::from(t.corridor_axis).normalize(),
            cos_psi: t.corridor_half_angle_deg.to_radians().cos(),
            r_caz: t.caz_radius_m,
            gamma: s.safety.gamma_per_s,
            curvature_share: t.curvature_share(),
            eps_ac: t.eps_ac,
            eps_caz: t.eps_caz,
            u_max_ac: t.u_max_ac_m_s2,
            u_max_caz: t.u_max_caz_m2_s2,
            force_max: s.limits.force_max_n,
            brake_time: s.safety.fallback.translational_brake_time_s,
            solver: SolverParams::from_scenario(s),
            period: s.mission.control_period_s,
            formulation: s.safety.formulation,
            omega_bound: Vector3::from(s.safety.attitude.omega_max_rad_s)
                .abs()
                .sup(&Vector3::from(s.safety.attitude.omega_min_rad_s).abs())
                .norm(),
            orbit_radius: a,
            errors: None,
            los_speed_budget: t.los_speed_budget(),
            gamma_los_speed: t.los_speed_gamma(),
            los_reference: los_contract::reference(&Vector3::from(t.corridor_axis).normalize()),
            target_inertia_ratio: s.target_inertia_ratio(),
        }
    }

    /// [`Self::from_scenario`] with the scenario's declared errors for the model `robot`
    /// (its mass the filter's `m`), in the sampled-data formulation (the paper's rows
    /// have no margins).
    pub fn from_model(s: &sc_scenario::Scenario, robot: &Robot) -> Self {
        let errors = TranslationalErrors::new(&s.uncertainty_bounds(), robot);
        Self {
            errors: (s.safety.formulation == Formulation::SampledData && !errors.is_zero())
                .then_some(errors),
            ..Self::from_scenario(s, robot.total_mass())
        }
    }
}

/// Everything the translational filter needs at one control step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TranslationalInput {
    /// `r_H` [m] in F_H.
    pub r_h: Vector3<f64>,
    /// `v_H = ṙ_H` [m/s] (derivative in the rotating F_H).
    pub v_h: Vector3<f64>,
    /// `q_HR(t)`: rotates F_R vectors into F_H (so `d_H = R_HR d_R`).
    pub q_hr: Quat,
    /// `ω_H`: angular velocity of F_H w.r.t. inertial, in F_H [rad/s] (`[0,0,n]` circular).
    pub omega_h: Vector3<f64>,
    /// `ω̇_H` in F_H [rad/s²] (zero on a circular orbit).
    pub omega_dot_h: Vector3<f64>,
    /// `q_RB`: servicer attitude (rotates F_B into F_R); gives `R_BH` for the force box.
    pub q_rb: Quat,
    /// Base body rate ω_B [rad/s, F_B]: how fast the body-fixed force turns.
    pub omega_b: Vector3<f64>,
    /// Bounds on the error of `r_H` [m] and `v_H` [m/s] against the plant's true CoM
    /// ([`crate::knowledge::ComKnowledge::com_error`]); zero when nothing is declared.
    pub com_error: (f64, f64),
    /// The grasping point relative to the target's CoM in F_R [m] and its velocity [m/s]:
    /// the line of sight of the contract ([`crate::los_contract`]).
    pub grasp_r: Vector3<f64>,
    /// The grasping point's velocity relative to the target's CoM in F_R [m/s].
    pub grasp_v_r: Vector3<f64>,
    /// The target's rate `‖ω_T‖` [rad/s].
    pub target_spin: f64,
}

impl TranslationalInput {
    /// Input on a circular orbit: `ω_H = [0, 0, n]`, `ω̇_H = 0`, base at rest.
    pub fn circular(r_h: Vector3<f64>, v_h: Vector3<f64>, q_hr: Quat, n: f64, q_rb: Quat) -> Self {
        Self {
            r_h,
            v_h,
            q_hr,
            omega_h: Vector3::new(0.0, 0.0, n),
            omega_dot_h: Vector3::zeros(),
            q_rb,
            omega_b: Vector3::zeros(),
            com_error: (0.0, 0.0),
            grasp_r: Vector3::zeros(),
            grasp_v_r: Vector3::zeros(),
            target_spin: 0.0,
        }
    }
}

/// CW drift acceleration `a_CW = [3n²r₁ + 2n v₂, −2n v₁, −n² r₃]` [m/s²] (paper eq. "rel
/// motion system" without the input).
pub fn cw_drift(n: f64, r: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(
        3.0 * n * n * r.x + 2.0 * n * v.y,
        -2.0 * n * v.x,
        -n * n * r.z,
    )
}

/// The time-varying corridor axis in F_H and its derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorridorAxis {
    /// `d_H = R_HR d_R`.
    pub d: Vector3<f64>,
    /// `ḋ_H = −ω_H × d_H` (F_R is inertially fixed, F_H rotates at ω_H).
    pub d_dot: Vector3<f64>,
    /// `d̈_H = −ω̇_H × d_H − ω_H × ḋ_H`.
    pub d_ddot: Vector3<f64>,
}

/// Corridor axis `d_H(t) = R_HR(t) d_R` (paper Sec. "Conical Approach Corridor").
pub fn corridor_axis(
    r_hr: &Matrix3<f64>,
    axis_r: &Vector3<f64>,
    omega_h: &Vector3<f64>,
    omega_dot_h: &Vector3<f64>,
) -> CorridorAxis {
    let d = r_hr * axis_r;
    let d_dot = -omega_h.cross(&d);
    let d_ddot = -omega_dot_h.cross(&d) - omega_h.cross(&d_dot);
    CorridorAxis { d, d_dot, d_ddot }
}

/// Conical approach corridor, paper eq. "CBF-AC":
/// `h_AC = d_Hᵀ r_H − ‖r_H‖ cos ψ_AC` [m], with
/// `ḣ = ḋᵀr + (d − r̂ cos ψ)ᵀ v` and
/// `ḧ = d̈ᵀr + 2ḋᵀv + (d − r̂ cos ψ)ᵀ(a_drift + f/m) − cos ψ (vᵀv − (r̂ᵀv)²)/‖r‖`.
/// `a_drift` is the CW drift; requires `‖r‖ > 0`.
pub fn approach_corridor(
    r: &Vector3<f64>,
    v: &Vector3<f64>,
    axis: &CorridorAxis,
    a_drift: &Vector3<f64>,
    mass: f64,
    cos_psi: f64,
) -> RelDegTwo<3> {
    let rn = r.norm();
    let rhat = r / rn;
    let g = axis.d - rhat * cos_psi;
    let rv = rhat.dot(v);
    RelDegTwo {
        h: axis.d.dot(r) - rn * cos_psi,
        hdot: axis.d_dot.dot(r) + g.dot(v),
        hddot_drift: axis.d_ddot.dot(r) + 2.0 * axis.d_dot.dot(v) + g.dot(a_drift)
            - cos_psi * (v.dot(v) - rv * rv) / rn,
        hddot_u: g / mass,
    }
}

/// Spherical collision avoidance zone, paper eq. "CBF-CAZ":
/// `h_CAZ = ‖r_H‖² − R_CAZ²` [m²], `ḣ = 2rᵀv`, `ḧ = 2vᵀv + 2rᵀ(a_drift + f/m)`.
pub fn collision_avoidance_zone(
    r: &Vector3<f64>,
    v: &Vector3<f64>,
    a_drift: &Vector3<f64>,
    mass: f64,
    r_caz: f64,
) -> RelDegTwo<3> {
    RelDegTwo {
        h: r.dot(r) - r_caz * r_caz,
        hdot: 2.0 * r.dot(v),
        hddot_drift: 2.0 * v.dot(v) + 2.0 * r.dot(a_drift),
        hddot_u: r * (2.0 / mass),
    }
}

/// The tangential-speed coefficient `c_t` [m/s²] of [`tangential_speed`]: the servicer's
/// speed across the line to the target may not exceed `√(c_t ‖r‖)`, so that the cone's
/// curvature `cos ψ ‖v_⊥‖²/‖r‖` never takes more than `curvature_share` of the braking
/// authority `sin ψ F/m − μ_AC` that keeps it inside the corridor. Non-positive when
/// `μ_AC` exceeds the authority (a configuration error).
pub fn tangential_coefficient(p: &TranslationalParams) -> f64 {
    let sin_psi = (1.0 - p.cos_psi * p.cos_psi).max(0.0).sqrt();
    p.curvature_share * (sin_psi * p.force_max / p.mass - p.u_max_ac) / p.cos_psi
}

/// Tangential-speed limit, a constraint of the certified set (not one of the paper's
/// barriers; docs/SAFETY.md, "The corridor's curvature"): `h_t = c_t ‖r‖ − ‖v_⊥‖² ≥ 0` in the
/// inertially fixed F_R, `v_⊥ = v − r̂ (r̂ᵀv)` the velocity across the line to the target.
/// Relative degree one: `ḣ_t = c_t r̂ᵀv − 2 v_⊥ᵀ a + 2 (r̂ᵀv) ‖v_⊥‖²/‖r‖` with
/// `a = a_drift + R_RH f_H / m`, so `∂ḣ_t/∂f_H = −2 R_HR v_⊥ / m`.
pub fn tangential_speed(
    r: &Vector3<f64>,
    v: &Vector3<f64>,
    a_drift: &Vector3<f64>,
    r_hr: &Matrix3<f64>,
    mass: f64,
    c_t: f64,
) -> RelDegOne<3> {
    let rn = r.norm();
    let rhat = r / rn;
    let rv = rhat.dot(v);
    let v_perp = v - rhat * rv;
    let vp2 = v_perp.dot(&v_perp);
    RelDegOne {
        h: c_t * rn - vp2,
        hdot_drift: c_t * rv + 2.0 * rv * vp2 / rn - 2.0 * v_perp.dot(a_drift),
        hdot_u: r_hr * v_perp * (-2.0 / mass),
    }
}

/// Validated, preprocessed input.
pub(crate) struct Prepared {
    r_bh: Matrix3<f64>,
    terms: [RelDegTwo<3>; N],
    /// The barrier rows ([`NAMES`] order), the tangential-speed row and the line-of-sight
    /// contract's four — with declared errors, those for every command in the force box.
    rows: [Row<3>; ROWS],
    weights: [f64; ROWS],
    bounds: [Row<3>; 6],
    /// With declared errors: what the rows for a smaller force are built from.
    known: Option<KnownInputs>,
}

/// The terms the rows for declared errors are rebuilt from for another force bound
/// ([`TranslationalFilter::known_rows`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct KnownInputs {
    axis: CorridorAxis,
    tangential: RelDegOne<3>,
    /// The CoM's position and velocity and the tide in the inertially fixed F_R.
    r_r: Vector3<f64>,
    v_r: Vector3<f64>,
    tide: Vector3<f64>,
    /// `R_HR`.
    r_hr: Matrix3<f64>,
}

/// Rounds of [`TranslationalFilter::solve_known`] before the rows for the whole force box.
pub const FORCE_CAP_ROUNDS: usize = 4;
/// Growth of the force bound between two rounds [-].
pub const FORCE_CAP_GROWTH: f64 = 1.25;
/// Halvings of the share of the declared errors when no command is certified
/// ([`TranslationalFilter::solve_degraded`]): the share to 1/64.
pub const DEGRADE_ROUNDS: usize = 6;

/// The translational CBF-QP safety filter (paper eq. "translation_qp").
pub struct TranslationalFilter {
    pub params: TranslationalParams,
    engine: Engine<3, { ROWS + 6 }>,
    last: LastProblem<3>,
}

impl TranslationalFilter {
    pub fn new(params: TranslationalParams) -> Self {
        Self {
            params,
            engine: Engine::new(),
            last: LastProblem::with_capacity(ROWS, 6),
        }
    }

    /// Filter for servicer mass `mass` [kg] with the scenario's parameters.
    pub fn from_scenario(s: &sc_scenario::Scenario, mass: f64) -> Self {
        Self::new(TranslationalParams::from_scenario(s, mass))
    }

    /// The barrier terms `(h, ḣ, ḧ_drift, ∂ḧ/∂f_H)` of both constraints, in [`NAMES`]
    /// order, or `None` for an invalid state.
    pub fn constraints(&self, x: &TranslationalInput) -> Option<[RelDegTwo<3>; N]> {
        self.prepare(x).ok().map(|p| p.terms)
    }

    /// The bounds on the model's error inside one sample, per barrier ([`NAMES`] order),
    /// for a state `(r, v)` with body rate `ω_B` (derivation: docs/SAFETY.md).
    ///
    /// With `A` the largest acceleration (CW drift + `√3 F/m`, the box's corner), speeds
    /// `V ≤ ‖v‖ + AT`, distances in `[R_min, R]` over the sample, and the jerk
    /// `J = 3n²V + 2nA + (√3F/m)(Ω + n)` (`Ω = max(‖ω_B‖, ω_bound)`: the held body-fixed
    /// force turns with the body relative to F_H):
    /// * CAZ (`ḧ = 2‖v‖² + 2rᵀa`): `M₃ = 6VA + 2RJ`;
    /// * corridor (`ḧ = d̈ᵀr + 2ḋᵀv + gᵀa − cos ψ ‖v_⊥‖²/‖r‖`, `g = d − r̂ cos ψ`):
    ///   `M₃ = n³R + 3n²V + 3nA + (n + V/R_min)A + G J + cos ψ (2VA/R_min + 3V³/R_min²)`;
    /// * `M₂`: the CW linearisation of gravity, `≤ 3n²R²/a` in acceleration, times the
    ///   barrier's gradient.
    pub fn sample_bounds(
        &self,
        r: &Vector3<f64>,
        v: &Vector3<f64>,
        omega_b: &Vector3<f64>,
        axis: &CorridorAxis,
    ) -> ([SampleBounds; N], RateBounds) {
        self.sample_bounds_known(r, v, omega_b, axis, (0.0, 0.0, 0.0), 1.0)
    }

    /// [`Self::sample_bounds`] for every true state within `(ē_r, ē_v, ē_ω)` of the
    /// estimate `(r, v, ω_B)` and a force scaled by at most `k_hi`: the ranges start from
    /// `‖r‖ ± ē_r`, `‖v‖ + ē_v`, `‖ω_B‖ + ē_ω`, the force's acceleration is `k_hi √3F/m`
    /// and the corridor's gradient may be `cos ψ · chord` longer. `ē_v` bounds the error
    /// of `v` itself, in F_H: the CoM's inertial velocity error plus `‖ω_H‖ē_r` (the
    /// frame's rotation acting on the position's error), as `known_rows` passes it.
    pub fn sample_bounds_known(
        &self,
        r: &Vector3<f64>,
        v: &Vector3<f64>,
        omega_b: &Vector3<f64>,
        axis: &CorridorAxis,
        err: (f64, f64, f64),
        k_hi: f64,
    ) -> ([SampleBounds; N], RateBounds) {
        let p = &self.params;
        let t = p.period;
        let n = p.mean_motion;
        let f_acc = 3f64.sqrt() * p.force_max / p.mass * k_hi;
        let (rn_est, vn) = (r.norm(), v.norm() + err.1);
        let rn = rn_est + err.0;
        // fixed point of A(R, V), V(A), R(A): n is tiny, two passes are plenty
        let mut a = f_acc + 3.0 * n * n * rn + 2.0 * n * vn;
        let (mut vv, mut rr) = (vn, rn);
        for _ in 0..2 {
            vv = vn + a * t;
            rr = rn + vn * t + 0.5 * a * t * t;
            a = f_acc + 3.0 * n * n * rr + 2.0 * n * vv;
        }
        let r_min = (rn_est - err.0 - vn * t - 0.5 * a * t * t).max(1e-3);
        let omega = (omega_b.norm() + err.2).max(p.omega_bound) + n;
        let jerk = 3.0 * n * n * vv + 2.0 * n * a + f_acc * omega;
        let grav = 3.0 * n * n * rr * rr / p.orbit_radius;
        let rhat = r / rn_est.max(1e-12);
        let g_now = (axis.d - rhat * p.cos_psi).norm()
            + p.cos_psi * crate::translational_margins::direction_chord(err.0, rn_est);
        let g_max = (1.0 + p.cos_psi).min(g_now + t * (n + vv / r_min));
        let m3_ac = n * n * n * rr
            + 3.0 * n * n * vv
            + 3.0 * n * a
            + (n + vv / r_min) * a
            + g_max * jerk
            + p.cos_psi * (2.0 * vv * a / r_min + 3.0 * vv * vv * vv / (r_min * r_min));
        let m3_caz = 6.0 * vv * a + 2.0 * rr * jerk;
        // tangential speed: |ḧ_t| ≤ c_t(A + V²/R) + 2A(A + V²/R) + 2VJ + 6AV²/R + 4V⁴/R²
        let c_t = tangential_coefficient(p).max(0.0);
        let curv = a + vv * vv / r_min;
        let j_t = c_t * curv
            + 2.0 * a * curv
            + 2.0 * vv * jerk
            + 6.0 * a * vv * vv / r_min
            + 4.0 * vv.powi(4) / (r_min * r_min);
        (
            [
                SampleBounds {
                    period: t,
                    m2: g_max * grav,
                    m3: m3_ac,
                },
                SampleBounds {
                    period: t,
                    m2: 2.0 * rr * grav,
                    m3: m3_caz,
                },
            ],
            RateBounds {
                period: t,
                d: 2.0 * vv * grav,
                j: j_t,
            },
        )
    }

    /// The corridor, zone and tangential-speed rows ([`NAMES`] order, then the tangential
    /// speed) of the formulation, with their weights in the relaxed problem — each row's
    /// violation measured against the deceleration the formulation budgets for it.
    fn barrier_rows(
        &self,
        x: &TranslationalInput,
        r_hr: &Matrix3<f64>,
        axis: &CorridorAxis,
        terms: &[RelDegTwo<3>; N],
    ) -> ([Row<3>; ROWS], [f64; ROWS], Option<KnownInputs>) {
        let p = &self.params;
        let mu = [p.u_max_ac, p.u_max_caz];
        let c_t = tangential_coefficient(p);
        // the tangential speed in the inertially fixed F_R (where the corridor is fixed)
        let r_rh = r_hr.transpose();
        let r_r = r_rh * x.r_h;
        let v_r = r_rh * (x.v_h + x.omega_h.cross(&x.r_h));
        let radial = r_rh * Vector3::x();
        let tidal = (radial * (3.0 * radial.dot(&r_r)) - r_r) * (p.mean_motion * p.mean_motion);
        let tangential = tangential_speed(&r_r, &v_r, &tidal, r_hr, p.mass, c_t);
        let known = p.errors.as_ref().map(|_| KnownInputs {
            axis: *axis,
            tangential,
            r_r,
            v_r,
            tide: tidal,
            r_hr: *r_hr,
        });
        let rows: [Row<3>; ROWS] = match (p.formulation, &p.errors, &known) {
            (Formulation::SampledData, Some(errors), Some(k)) => {
                self.known_rows(x, terms, k, errors.force, self.full_force(), 1.0)
            }
            (Formulation::SampledData, _, _) => {
                let (b, bt) = self.sample_bounds(&x.r_h, &x.v_h, &x.omega_b, axis);
                let own = [
                    RelDeg2::from(terms[0]).row(&b[0], mu[0], p.gamma),
                    RelDeg2::from(terms[1]).row(&b[1], mu[1], p.gamma),
                    RelDeg1::from(tangential).row(&bt, p.gamma, 0.0),
                ];
                let los = self.los_rows(x, r_hr, &r_r, &v_r, &tidal, (0.0, ForceError::NONE));
                std::array::from_fn(|i| if i < N + 1 { own[i] } else { los[i - N - 1] })
            }
            (Formulation::Paper, _, _) => {
                let own = [
                    terms[0].row(p.gamma, p.eps_ac, p.u_max_ac),
                    terms[1].row(p.gamma, p.eps_caz, p.u_max_caz),
                ];
                // the paper has no tangential limit nor line-of-sight contract: rows that
                // never bind
                std::array::from_fn(|i| {
                    own.get(i).copied().unwrap_or(Row {
                        a: Vector3::zeros(),
                        c: 1.0,
                    })
                })
            }
        };
        let tangential_weight = 2.0 * (c_t.max(0.0) * p.r_caz).sqrt() * p.force_max / p.mass;
        let weights = std::array::from_fn(|i| match i {
            0 => p.u_max_ac,
            1 => p.u_max_caz,
            2 => tangential_weight,
            // the contract's rows: measured against the thrust's acceleration across
            _ => p.force_max / p.mass,
        });
        (rows, weights, known)
    }

    /// The QP with declared errors: the rows for a force bound `c` certify a command of
    /// `‖f‖ ≤ c` only ([`Self::rising_cap`]). First from the nominal's norm (a feasible
    /// nominal is certified by its own rows); when that finds nothing, from zero (the rows
    /// get stricter as `c` grows, so a large nominal must not hide a certified smaller
    /// command); then the rows for every command in the box. Nothing certified: the rows
    /// with a feasible share of the margins ([`Self::solve_degraded`]). Certified means
    /// every barrier row at its full margins; the line-of-sight contract may be relaxed
    /// ([`Self::solve_certifying`]).
    fn solve_known(
        &mut self,
        x: &TranslationalInput,
        p: &Prepared,
        k: &KnownInputs,
        force: ForceError,
        u_nom: &Vector3<f64>,
        report: &mut FilterReport<N>,
    ) -> Actuated<3> {
        let full = self.full_force();
        let from_nominal = u_nom.norm().min(full);
        let starts = [from_nominal, 0.0];
        let tries = if from_nominal > 0.0 {
            &starts[..]
        } else {
            &starts[1..]
        };
        for &start in tries {
            if let Some((outcome, rows)) = self.rising_cap(x, p, k, force, u_nom, start) {
                return self.conclude_solved(x, p, u_nom, &outcome, &rows, report);
            }
        }
        if let Some(outcome) = self.solve_certifying(u_nom, &p.rows, p) {
            return self.conclude_solved(x, p, u_nom, &outcome, &p.rows, report);
        }
        self.solve_degraded(x, p, k, force, u_nom, report)
    }

    /// The QP on `rows` when it certifies every barrier row at its full margins: solved,
    /// or relaxed in the line-of-sight contract's tier only (the barriers and the
    /// tangential limit alone are feasible, so the lexicographic relaxation gives them no
    /// allowance). `None` otherwise.
    fn solve_certifying(
        &mut self,
        u_nom: &Vector3<f64>,
        rows: &[Row<3>; ROWS],
        p: &Prepared,
    ) -> Option<crate::engine::Outcome<3>> {
        let outcome = self.solve_rows(u_nom, rows, p);
        match outcome.kind {
            Kind::Solved | Kind::Skipped => Some(outcome),
            Kind::Relaxed => {
                let barriers = without_contract(rows);
                let tier0 = self.engine.solve_hard(u_nom, &barriers, &p.bounds);
                tier0.map(|_| outcome)
            }
            _ => None,
        }
    }

    /// Solves with the rows for the force bound `c` from `start`: a solution of
    /// `‖f‖ ≤ c` is certified; a larger one raises `c` to its norm × [`FORCE_CAP_GROWTH`]
    /// (at most [`FORCE_CAP_ROUNDS`] solves, `c ≤ √3F`). `None` when the rows become
    /// infeasible or the rounds run out.
    fn rising_cap(
        &mut self,
        x: &TranslationalInput,
        p: &Prepared,
        k: &KnownInputs,
        force: ForceError,
        u_nom: &Vector3<f64>,
        start: f64,
    ) -> Option<(crate::engine::Outcome<3>, [Row<3>; ROWS])> {
        let full = self.full_force();
        let mut cap = start;
        for _ in 0..FORCE_CAP_ROUNDS {
            let rows = self.known_rows(x, &p.terms, k, force, cap, 1.0);
            let outcome = self.solve_certifying(u_nom, &rows, p)?;
            let size = outcome.u.norm();
            if size <= cap {
                return Some((outcome, rows));
            }
            if cap >= full {
                return None;
            }
            cap = (size.max(cap) * FORCE_CAP_GROWTH).min(full);
        }
        None
    }

    /// No command is certified for the declared errors: the command of the rows with the
    /// share `λ` of the declared errors that are still feasible, found by bisection — the
    /// largest when feasibility falls with `λ`, not proven in general (for every command
    /// in the box; bisection, [`DEGRADE_ROUNDS`] halvings), flagged
    /// [`crate::common::faults::MARGINS_DEGRADED`] with the violation `1 − λ` (the share of the margins
    /// given up). `λ = 0` is the nominal
    /// model's rows; when even they are infeasible, their relaxed problem as without
    /// declared errors. Never the relaxed problem of infeasible margins, which can give up
    /// the zone for the corridor (docs/SAFETY.md). The line-of-sight contract is left out
    /// of these rows: with the barriers' margins already given up it must not cost them
    /// more (the step is flagged either way).
    fn solve_degraded(
        &mut self,
        x: &TranslationalInput,
        p: &Prepared,
        k: &KnownInputs,
        force: ForceError,
        u_nom: &Vector3<f64>,
        report: &mut FilterReport<N>,
    ) -> Actuated<3> {
        let full = self.full_force();
        let nominal_rows = without_contract(&self.known_rows(x, &p.terms, k, force, full, 0.0));
        let first = self.solve_rows(u_nom, &nominal_rows, p);
        if !matches!(first.kind, Kind::Solved | Kind::Skipped) {
            return self.conclude_solved(x, p, u_nom, &first, &nominal_rows, report);
        }
        let (mut best, mut best_rows, mut share) = (first, nominal_rows, 0.0);
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..DEGRADE_ROUNDS {
            let mid = 0.5 * (lo + hi);
            let rows = without_contract(&self.known_rows(x, &p.terms, k, force, full, mid));
            let outcome = self.solve_rows(u_nom, &rows, p);
            if matches!(outcome.kind, Kind::Solved | Kind::Skipped) {
                (best, best_rows, share, lo) = (outcome, rows, mid, mid);
            } else {
                hi = mid;
            }
        }
        // a solution of the degraded rows (verify-qp checks it as such), flagged apart
        // from the relaxed problem; never "skipped" (that says every declared row held)
        best.kind = Kind::Solved;
        best.violation = 1.0 - share;
        report.faults |= crate::common::faults::MARGINS_DEGRADED;
        self.conclude_solved(x, p, u_nom, &best, &best_rows, report)
    }

    /// [`step::conclude`] for a solve on `rows` (the barrier rows first).
    fn conclude_solved(
        &mut self,
        x: &TranslationalInput,
        p: &Prepared,
        u_nom: &Vector3<f64>,
        outcome: &crate::engine::Outcome<3>,
        rows: &[Row<3>; ROWS],
        report: &mut FilterReport<N>,
    ) -> Actuated<3> {
        let solved = Solved {
            outcome,
            rows,
            weights: &p.weights,
            hard: &p.bounds,
            certifying: &rows[..N],
        };
        step::conclude(self, x, p, u_nom, solved, report)
    }

    /// The QP on `rows` with the prepared weights and force box, relaxed in [`TIERS`].
    fn solve_rows(
        &mut self,
        u_nom: &Vector3<f64>,
        rows: &[Row<3>; ROWS],
        p: &Prepared,
    ) -> crate::engine::Outcome<3> {
        self.engine
            .solve_tiered(u_nom, rows, &p.weights, &TIERS, &p.bounds)
    }

    /// `√3 F` [N]: the largest force the box `‖f_B‖∞ ≤ F` admits.
    fn full_force(&self) -> f64 {
        3f64.sqrt() * self.params.force_max
    }

    /// The sampled-data rows for every true state and force the declared errors admit
    /// ([`crate::translational_margins`]): each barrier's `δh`, `δḣ` make its requirement
    /// the measurement-robust one ([`sampled::phi_required_known`]), its `δφ` adds to `M₂`,
    /// and the offset holds for every scale of the delivered force.
    ///
    /// `force_cap` [N] bounds `‖f_H‖` of the commands the rows are for (the gradients'
    /// turn and the force's misalignment act on it); `√3F` covers every command in the
    /// box. The in-sample bounds and `ψ_max` are always the whole box's.
    fn known_rows(
        &self,
        x: &TranslationalInput,
        terms: &[RelDegTwo<3>; N],
        k: &KnownInputs,
        force: ForceError,
        force_cap: f64,
        share: f64,
    ) -> [Row<3>; ROWS] {
        let p = &self.params;
        let axis = &k.axis;
        let force = force.share(share);
        let (e_r, e_v) = if share == 1.0 {
            x.com_error
        } else {
            (x.com_error.0 * share, x.com_error.1 * share)
        };
        // the CoM's velocity error is inertial; in the rotating F_H it gains ‖ω_H‖ē_r
        let err = crate::knowledge::in_hill((e_r, e_v), &x.omega_h);
        let rate_err = share
            * self
                .params
                .errors
                .as_ref()
                .map_or(0.0, |e| e.com.rate_rad_s);
        let (b, bt) = self.sample_bounds_known(
            &x.r_h,
            &x.v_h,
            &x.omega_b,
            axis,
            (err.0, err.1, rate_err),
            force.k_hi,
        );
        let a0 = cw_drift(p.mean_motion, &x.r_h, &x.v_h);
        let f_acc = force_cap / p.mass;
        let u = Unknowns::new(&x.r_h, &x.v_h, err, &a0, p.mean_motion, f_acc, force);
        let rhat = x.r_h / u.rn;
        let v_along = rhat.dot(&x.v_h);
        let v_perp = (x.v_h - rhat * v_along).norm();
        let g = (axis.d - rhat * p.cos_psi).norm();
        let rates = (axis.d_dot.norm(), axis.d_ddot.norm());
        let unknown = [u.corridor(g, p.cos_psi, rates, v_along, v_perp), u.zone()];
        let decay = sampled::Decay::linear(p.gamma).at(p.period);
        let mu = [p.u_max_ac, p.u_max_caz];
        let rows: [Row<3>; N] = std::array::from_fn(|i| {
            let t = terms[i];
            let (state, dphi) = unknown[i];
            let bounds = SampleBounds {
                m2: b[i].m2 + dphi,
                ..b[i]
            };
            let reach = t.hddot_u.norm() * 3f64.sqrt() * p.force_max * force.k_hi;
            let psi_max = t.hddot_drift.abs() + reach + bounds.m2;
            let req =
                sampled::phi_required_known(t.h, t.hdot, &state, &bounds, mu[i], &decay, psi_max);
            Row {
                a: t.hddot_u,
                c: force.scaled_offset(t.hddot_drift - req),
            }
        });
        let tangential = self.tangential_known_row(k, &u, &bt, force);
        let los = self.los_rows(x, &k.r_hr, &k.r_r, &k.v_r, &k.tide, (force_cap, force));
        std::array::from_fn(|i| match i {
            0 | 1 => rows[i],
            2 => tangential,
            _ => los[i - N - 1],
        })
    }

    /// The tangential-speed row of [`Self::known_rows`] (relative degree one, in F_R): the
    /// lowest consistent `h_t` and `D + δḣ_t`, its offset for every force scale.
    fn tangential_known_row(
        &self,
        k: &KnownInputs,
        u: &Unknowns,
        bt: &RateBounds,
        force: ForceError,
    ) -> Row<3> {
        let p = &self.params;
        let tangential = &k.tangential;
        let rr_hat = k.r_r / k.r_r.norm();
        let along = rr_hat.dot(&k.v_r);
        let motion = InertialMotion {
            speed: k.v_r.norm(),
            along,
            v_perp: (k.v_r - rr_hat * along).norm(),
            tide: k.tide.norm(),
        };
        // |c_t|: the term's error bound holds for either sign
        let c_t = tangential_coefficient(p).abs();
        let (dh_t, dd_t) = u.tangential(c_t, p.mean_motion, &motion);
        let rate = RateBounds {
            d: bt.d + dd_t,
            ..*bt
        };
        let rate_decay = sampled::RateDecay::new(p.gamma, 0.0, p.period);
        let req_t = sampled::hdot_required_known(tangential.h, dh_t, &rate, &rate_decay);
        Row {
            a: tangential.hdot_u,
            c: force.scaled_offset(tangential.hdot_drift - req_t),
        }
    }

    /// The line-of-sight contract's rows ([`crate::los_contract`]) at the CoM `r`, `v` and
    /// tide in F_R. `force = (cap, error)`: with declared errors, the delivered force may
    /// turn by `θ̄` for commands up to `cap` [N] (in `D`) and its scale acts on the offsets;
    /// the navigation errors are not in these rows (docs/SAFETY.md).
    fn los_rows(
        &self,
        x: &TranslationalInput,
        r_hr: &Matrix3<f64>,
        r: &Vector3<f64>,
        v: &Vector3<f64>,
        tide: &Vector3<f64>,
        force: (f64, ForceError),
    ) -> [Row<3>; los_contract::ROWS] {
        let p = &self.params;
        let (cap, err) = force;
        let grasp_known = in_range3(&x.grasp_r, MAX_RANGE_M)
            && in_range3(&x.grasp_v_r, MAX_SPEED_M_S)
            && (0.0..=MAX_FRAME_RATE).contains(&x.target_spin);
        let line = los_contract::LineOfSight {
            rho: x.grasp_r - r,
            rho_dot: x.grasp_v_r - v,
            v: *v,
            tide: *tide,
        };
        let w = p.los_speed_budget;
        let Some((terms, sigma)) =
            los_contract::terms(&line, &p.los_reference, r_hr, p.mass, w).filter(|_| grasp_known)
        else {
            // outside the certified set (no valid grasping point, a line of sight too short
            // or too far off the corridor axis): the barriers' rows still filter
            return [NEVER_BINDING; los_contract::ROWS];
        };
        let motion = self.los_sample_motion(x, r, v, err, cap);
        let bounds = los_contract::bounds(line.rho.norm(), sigma, w, &motion);
        let decay = sampled::RateDecay::new(p.gamma_los_speed, 0.0, p.period);
        let rows = terms.map(|t| {
            let row = RelDeg1::from(t).row_at(&bounds, &decay);
            Row {
                c: err.scaled_offset(row.c),
                ..row
            }
        });
        if rows.iter().all(Row::is_finite) {
            rows
        } else {
            [NEVER_BINDING; los_contract::ROWS]
        }
    }

    /// The bounds over one sample the contract's `J` and `D` rest on (inertial, F_R): the
    /// acceleration `A = k_hi √3F/m + 2n²R`, the speed `‖v‖ + AT`, the jerk of the body-held
    /// force turning at `Ω` and of the tide, `A_f Ω + 2n²V + 6n³R`; the grasping point's
    /// speed `min(κ‖ω_T‖‖p_G‖, ‖v_G‖ + a_G T)` and acceleration `a_G = (κ + 1)(κ‖ω_T‖)²‖p_G‖`;
    /// `D`: the gravity model's error and, with declared errors, the turn of the force. With
    /// declared navigation errors the CoM's range and speed grow by their bounds.
    fn los_sample_motion(
        &self,
        x: &TranslationalInput,
        r: &Vector3<f64>,
        v: &Vector3<f64>,
        err: ForceError,
        cap: f64,
    ) -> los_contract::SampleMotion {
        let p = &self.params;
        let (t, n) = (p.period, p.mean_motion);
        let (e_r, e_v) = x.com_error;
        let rate_err = p.errors.as_ref().map_or(0.0, |e| e.com.rate_rad_s);
        let f_acc = 3f64.sqrt() * p.force_max / p.mass * err.k_hi;
        let (r0, v0) = (r.norm() + e_r, v.norm() + e_v);
        let mut r_hi = r0 + v0 * t;
        let mut accel = f_acc + 2.0 * n * n * r_hi;
        let speed = v0 + accel * t;
        r_hi = r0 + speed * t;
        accel = f_acc + 2.0 * n * n * r_hi;
        let speed = v0 + accel * t;
        let omega = (x.omega_b.norm() + rate_err).max(p.omega_bound);
        let kappa = p.target_inertia_ratio;
        let spin = kappa * x.target_spin;
        let lever = x.grasp_r.norm();
        let grasp_accel = (kappa + 1.0) * spin * spin * lever;
        los_contract::SampleMotion {
            period: t,
            speed,
            accel,
            jerk: f_acc * omega + 2.0 * n * n * speed + 6.0 * n * n * n * r_hi,
            grasp_speed: (spin * lever).min(x.grasp_v_r.norm() + grasp_accel * t),
            grasp_accel,
            model_accel: 3.0 * n * n * r_hi * r_hi / p.orbit_radius
                + err.k_hi * cap * err.turn_rad / p.mass,
        }
    }

    /// `‖f_B‖∞ ≤ F` on the body-frame force `f_B = R_BH f_H`: the six rows
    /// `F(1 − margin) ∓ (R_BH f_H)_k ≥ 0`.
    fn force_box(&self, r_bh: &Matrix3<f64>) -> [Row<3>; 6] {
        let lim = self.params.force_max * (1.0 - BOX_MARGIN);
        std::array::from_fn(|i| {
            let k = i / 2;
            let sign = if i % 2 == 0 { -1.0 } else { 1.0 };
            Row {
                a: r_bh.row(k).transpose() * sign,
                c: lim,
            }
        })
    }

    /// The braking law `f_H = sat(−m v_H / T)`, saturated so that `‖R_BH f_H‖∞ ≤ F`
    /// (direction kept): the substitute nominal, and the backup command when the solver
    /// fails. Zero when the state is invalid.
    pub fn brake(&self, x: &TranslationalInput) -> (Vector3<f64>, Vector3<f64>) {
        match self.prepare(x) {
            Ok(p) => self.brake_prepared(x, &p),
            Err(_) => (Vector3::zeros(), Vector3::zeros()),
        }
    }

    fn brake_prepared(&self, x: &TranslationalInput, p: &Prepared) -> (Vector3<f64>, Vector3<f64>) {
        self.toward(&p.r_bh, &-x.v_h)
    }

    /// `f_H = sat(m (v_ref − v_H)/T)` in the force box (the braking law with a reference
    /// velocity `v_ref` [m/s, F_H]: the safe mode's retreat, [`crate::safe_mode`]); zero
    /// when the attitudes are not unit quaternions (a state the filter refuses anyway, as
    /// it does non-finite velocities, before it looks at any nominal).
    pub fn toward_velocity(&self, x: &TranslationalInput, v_ref: &Vector3<f64>) -> Vector3<f64> {
        // only the attitudes (the filter itself refuses an input it cannot prepare)
        match (unit_quat(&x.q_hr), unit_quat(&x.q_rb)) {
            (Some(q_hr), Some(q_rb)) => {
                let r_bh = (quat::to_matrix(&q_hr) * quat::to_matrix(&q_rb)).transpose();
                self.toward(&r_bh, &(v_ref - x.v_h)).0
            }
            _ => Vector3::zeros(),
        }
    }

    /// `sat(m Δv/T)` in the force box for the velocity error `Δv` [m/s, F_H], with `R_BH`
    /// `r_bh`: `(f_H, f_B)`.
    fn toward(&self, r_bh: &Matrix3<f64>, dv: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let f_b = r_bh * (self.params.mass * dv / self.params.brake_time);
        let f_b = common::sat_inf(&f_b, self.params.force_max * (1.0 - BOX_MARGIN));
        (r_bh.transpose() * f_b, f_b)
    }

    /// The filter's command when its nominal is missing: the safety QP on the substitute
    /// nominal (the braking law) — what the partition applies for a dead nominal or filter.
    pub fn backup(&mut self, x: &TranslationalInput) -> FilterOutput<3, N> {
        self.filter_with(x, None)
    }

    /// One filter step: safe `f_H` (and `f_B = R_BH f_H` in `actuated`) closest to
    /// `f_nom_h` subject to the corridor and zone rows and `‖f_B‖∞ ≤ F`. An invalid
    /// nominal is replaced by the substitute (flagged).
    pub fn filter(&mut self, x: &TranslationalInput, f_nom_h: &Vector3<f64>) -> FilterOutput<3, N> {
        self.filter_with(x, Some(f_nom_h))
    }

    /// [`Self::filter`] with the nominal possibly missing (`None`: silent, dead or late
    /// controller), then the QP runs on the substitute nominal (flagged).
    pub fn filter_with(
        &mut self,
        x: &TranslationalInput,
        f_nom_h: Option<&Vector3<f64>>,
    ) -> FilterOutput<3, N> {
        step::filter_with(self, x, f_nom_h)
    }

    /// Verification only: force the solver even when the nominal is feasible.
    pub fn set_skip_enabled(&mut self, on: bool) {
        self.engine.set_skip_enabled(on);
    }

    /// The last QP handed to the engine (for `--dump-qp`).
    pub fn dump_qp(&self) -> crate::QpDump {
        self.last.dump()
    }

    /// The rows (barrier rows in [`NAMES`] order, the tangential-speed row, the
    /// line-of-sight contract's four), their
    /// weights in the relaxed problem, and the six bound rows at state `x` — for
    /// verification and `--dump-qp`.
    pub fn rows(&self, x: &TranslationalInput) -> Option<(Vec<Row<3>>, Vec<f64>, Vec<Row<3>>)> {
        let p = self.prepare(x).ok()?;
        Some((p.rows.to_vec(), p.weights.to_vec(), p.bounds.to_vec()))
    }
}

/// The translational filter's own parts of the shared step ([`crate::step`]): its rows,
/// its braking law and its force box in the body frame.
impl FilterStep<3, N> for TranslationalFilter {
    type Input = TranslationalInput;
    type Prepared = Prepared;

    fn bound(&self) -> f64 {
        self.params.force_max
    }

    fn take_tally(&mut self) -> SolverTally {
        self.engine.take_tally()
    }

    fn last_problem(&mut self) -> &mut LastProblem<3> {
        &mut self.last
    }

    fn prepare(&self, x: &TranslationalInput) -> Result<Prepared, Invalid> {
        let p = &self.params;
        let rn = x.r_h.norm();
        if !in_range3(&x.r_h, MAX_RANGE_M)
            || rn < MIN_RANGE_M
            || !in_range3(&x.v_h, MAX_SPEED_M_S)
            || !in_range3(&x.omega_h, MAX_FRAME_RATE)
            || !in_range3(&x.omega_dot_h, MAX_FRAME_RATE)
            || !common::finite(&x.omega_b)
            || ![x.com_error.0, x.com_error.1]
                .iter()
                .all(|e| e.is_finite() && *e >= 0.0)
        {
            return Err(Invalid::State);
        }
        let q_hr = unit_quat(&x.q_hr).ok_or(Invalid::State)?;
        let q_rb = unit_quat(&x.q_rb).ok_or(Invalid::State)?;
        let r_hr = quat::to_matrix(&q_hr);
        let r_bh = (r_hr * quat::to_matrix(&q_rb)).transpose();
        let axis = corridor_axis(&r_hr, &p.axis_r, &x.omega_h, &x.omega_dot_h);
        let a0 = cw_drift(p.mean_motion, &x.r_h, &x.v_h);
        let terms = [
            approach_corridor(&x.r_h, &x.v_h, &axis, &a0, p.mass, p.cos_psi),
            collision_avoidance_zone(&x.r_h, &x.v_h, &a0, p.mass, p.r_caz),
        ];
        let (rows, weights, known) = self.barrier_rows(x, &r_hr, &axis, &terms);
        let bounds = self.force_box(&r_bh);
        if rows.iter().chain(&bounds).all(Row::is_finite) && common::finite(&r_bh) {
            Ok(Prepared {
                r_bh,
                terms,
                rows,
                weights,
                bounds,
                known,
            })
        } else {
            Err(Invalid::State)
        }
    }

    /// No force when the state cannot be trusted.
    fn refused(&self, _: &TranslationalInput) -> Vector3<f64> {
        Vector3::zeros()
    }

    fn barrier_values(p: &Prepared) -> [f64; N] {
        p.terms.map(|t| t.h)
    }

    fn braking_law(&self, x: &TranslationalInput, p: &Prepared) -> Vector3<f64> {
        self.brake_prepared(x, p).0
    }

    fn solve_qp(
        &mut self,
        x: &TranslationalInput,
        p: &Prepared,
        u_nom: &Vector3<f64>,
        report: &mut FilterReport<N>,
    ) -> Actuated<3> {
        if let (Some(errors), Some(k)) = (&self.params.errors, &p.known) {
            let force = errors.force;
            return self.solve_known(x, p, k, force, u_nom, report);
        }
        let outcome = self.solve_rows(u_nom, &p.rows, p);
        let solved = Solved {
            outcome: &outcome,
            rows: &p.rows,
            weights: &p.weights,
            hard: &p.bounds,
            certifying: &p.rows[..N],
        };
        step::conclude(self, x, p, u_nom, solved, report)
    }

    /// The actuated force `f_B = R_BH f_H` must be finite and inside the box; a clamped
    /// `f_B` is rotated back into the command.
    fn actuate(&self, p: &Prepared, f_h: Vector3<f64>) -> Actuated<3> {
        let f_b = p.r_bh * f_h;
        let (f_b_c, clamped) = clamp_box(&f_b, self.params.force_max);
        let flagged = clamped || !common::finite(&f_h);
        Actuated {
            u: if flagged {
                p.r_bh.transpose() * f_b_c
            } else {
                f_h
            },
            actuated: f_b_c,
            clamped: flagged,
        }
    }
}

impl SafetyFilter<3, N> for TranslationalFilter {
    const SUBSYSTEM: Subsystem = Subsystem::Translational;
    const NAMES: [&'static str; N] = NAMES;
    type Input = TranslationalInput;

    /// The servicer's system centre of mass relative to the target's, in the Hill frame
    /// (ξ_tr = 0: first in the causal order; no model needed).
    fn input(&self, robot: &Robot, o: &Observation, _: &Coupling) -> Option<TranslationalInput> {
        Some(TranslationalInput {
            r_h: o.com_h,
            v_h: o.com_v_h,
            q_hr: o.q_hr,
            omega_h: o.omega_h,
            omega_dot_h: o.omega_dot_h,
            q_rb: o.q_rb,
            omega_b: o.omega_b,
            com_error: match &self.params.errors {
                Some(e) => e.com.com_error(robot, &o.theta, &o.theta_dot, &o.omega_b),
                None => (0.0, 0.0),
            },
            grasp_r: o.grasp_r,
            grasp_v_r: o.grasp_v_r,
            target_spin: o.omega_t.norm(),
        })
    }

    fn filter_with(
        &mut self,
        x: &TranslationalInput,
        nominal: Option<&Vector3<f64>>,
    ) -> FilterOutput<3, N> {
        TranslationalFilter::filter_with(self, x, nominal)
    }

    fn dump_qp(&self) -> crate::QpDump {
        TranslationalFilter::dump_qp(self)
    }

    fn set_skip_enabled(&mut self, on: bool) {
        TranslationalFilter::set_skip_enabled(self, on)
    }

    fn set_solver_settings(&mut self, settings: sc_qp::Settings) {
        self.engine.set_settings(settings);
    }

    fn input_bound(&self) -> f64 {
        self.params.force_max
    }
}
