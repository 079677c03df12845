//! Translational safety filter (paper Sec. "CBFs for the Translational Subsystem",
//! QP eq. "translation_qp").
//!
//! State `x_tr = [r_H; v_H]`: servicer base origin relative to the target CoM in the Hill
//! frame `F_H` [m, m/s]; Clohessy–Wiltshire dynamics (paper eq. "rel motion system")
//! `r̈_H = a_CW(r_H, v_H) + f_H/m` with mean motion `n` and servicer mass `m`; input the
//! force `f_H` [N] in `F_H`. First in the causal order: `ξ_tr = 0`.
//!
//! Input bounds: the safe force is actuated in the body frame, `f_B,SF = R_BH f_H,SF`. To
//! guarantee the paper's `‖f_B‖∞ ≤ F` the box is imposed on `f_B` itself, i.e. the six
//! rows `±R_BH f_H ≤ F` (not a box on `f_H`, which would allow `‖f_B‖∞` up to √3 F).

use crate::barrier::{RelDegTwo, Row};
use crate::common::{
    self, BOX_MARGIN, FilterOutput, FilterReport, FilterStatus, clamp_box, faults, in_range3,
    unit_quat,
};
use crate::qp::{QpDump, QpEngine, QpOutcome, SolverParams};
use nalgebra::{Matrix3, Vector3};
use sc_models::quat::{self, Quat};
use std::time::Instant;

/// Constraint names in report order.
pub const NAMES: [&str; 2] = ["approach_corridor", "collision_avoidance_zone"];
/// Number of constraints.
pub const N: usize = 2;

/// Accepted state range: `MIN_RANGE_M ≤ ‖r_H‖ ≤ MAX_RANGE_M` (the corridor's cone is not
/// differentiable at its apex), `‖v_H‖ ≤ MAX_SPEED_M_S`, `‖ω_H‖, ‖ω̇_H‖ ≤ MAX_FRAME_RATE`.
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
    /// ε_AC [m/s], ε_CAZ [m²/s].
    pub eps_ac: f64,
    pub eps_caz: f64,
    /// u_max of H for the corridor [m/s²] and the CAZ [m²/s²] (see [`crate::barrier`]).
    pub u_max_ac: f64,
    pub u_max_caz: f64,
    /// `F` of `‖f_B‖∞ ≤ F` [N].
    pub force_max: f64,
    /// T of the fallback brake `f_H = sat(−m v_H / T)` [s].
    pub brake_time: f64,
    pub solver: SolverParams,
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
            eps_ac: t.eps_ac,
            eps_caz: t.eps_caz,
            u_max_ac: t.u_max_ac_m_s2,
            u_max_caz: t.u_max_caz_m2_s2,
            force_max: s.limits.force_max_n,
            brake_time: s.safety.fallback.translational_brake_time_s,
            solver: SolverParams::from_scenario(s),
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
}

impl TranslationalInput {
    /// Input on a circular orbit: `ω_H = [0, 0, n]`, `ω̇_H = 0`.
    pub fn circular(r_h: Vector3<f64>, v_h: Vector3<f64>, q_hr: Quat, n: f64, q_rb: Quat) -> Self {
        Self {
            r_h,
            v_h,
            q_hr,
            omega_h: Vector3::new(0.0, 0.0, n),
            omega_dot_h: Vector3::zeros(),
            q_rb,
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

/// Validated, preprocessed input.
struct Prepared {
    r_bh: Matrix3<f64>,
    terms: [RelDegTwo<3>; N],
    rows: [Row<3>; N],
}

/// The translational CBF-QP safety filter (paper eq. "translation_qp").
pub struct TranslationalFilter {
    pub params: TranslationalParams,
    qp: QpEngine,
}

impl TranslationalFilter {
    pub fn new(params: TranslationalParams) -> Self {
        let qp = QpEngine::new(3, N, 6, 3f64.sqrt() * params.force_max, &params.solver);
        Self { params, qp }
    }

    /// Filter for servicer mass `mass` [kg] with the scenario's parameters.
    pub fn from_scenario(s: &sc_scenario::Scenario, mass: f64) -> Self {
        Self::new(TranslationalParams::from_scenario(s, mass))
    }

    /// The barrier terms `(h, ḣ, ḧ_drift, ∂ḧ/∂f_H)` of both constraints, in [`NAMES`]
    /// order, or `None` for an invalid state.
    pub fn constraints(&self, x: &TranslationalInput) -> Option<[RelDegTwo<3>; N]> {
        self.prepare(x).map(|p| p.terms)
    }

    fn prepare(&self, x: &TranslationalInput) -> Option<Prepared> {
        let p = &self.params;
        let rn = x.r_h.norm();
        if !in_range3(&x.r_h, MAX_RANGE_M)
            || rn < MIN_RANGE_M
            || !in_range3(&x.v_h, MAX_SPEED_M_S)
            || !in_range3(&x.omega_h, MAX_FRAME_RATE)
            || !in_range3(&x.omega_dot_h, MAX_FRAME_RATE)
        {
            return None;
        }
        let q_hr = unit_quat(&x.q_hr)?;
        let q_rb = unit_quat(&x.q_rb)?;
        let r_hr = quat::to_matrix(&q_hr);
        let r_bh = (r_hr * quat::to_matrix(&q_rb)).transpose();
        let axis = corridor_axis(&r_hr, &p.axis_r, &x.omega_h, &x.omega_dot_h);
        let a0 = cw_drift(p.mean_motion, &x.r_h, &x.v_h);
        let terms = [
            approach_corridor(&x.r_h, &x.v_h, &axis, &a0, p.mass, p.cos_psi),
            collision_avoidance_zone(&x.r_h, &x.v_h, &a0, p.mass, p.r_caz),
        ];
        let rows = [
            terms[0].row(p.gamma, p.eps_ac, p.u_max_ac),
            terms[1].row(p.gamma, p.eps_caz, p.u_max_caz),
        ];
        if rows.iter().all(Row::is_finite) && common::finite(&r_bh) {
            Some(Prepared { r_bh, terms, rows })
        } else {
            None
        }
    }

    /// Bounded fallback `f_H = sat(−m v_H / T)`, saturated so that `‖R_BH f_H‖∞ ≤ F`
    /// (direction kept); zero when the state is invalid.
    pub fn fallback(&self, x: &TranslationalInput) -> (Vector3<f64>, Vector3<f64>) {
        match self.prepare(x) {
            Some(p) => self.fallback_prepared(x, &p),
            None => (Vector3::zeros(), Vector3::zeros()),
        }
    }

    fn fallback_prepared(
        &self,
        x: &TranslationalInput,
        p: &Prepared,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let f_b = p.r_bh * (-self.params.mass * x.v_h / self.params.brake_time);
        let f_b = common::sat_inf(&f_b, self.params.force_max * (1.0 - BOX_MARGIN));
        (p.r_bh.transpose() * f_b, f_b)
    }

    /// One filter step: safe `f_H` (and `f_B = R_BH f_H` in `actuated`) closest to
    /// `f_nom_h` subject to `Φ_AC ≥ 0`, `Φ_CAZ ≥ 0` and `‖f_B‖∞ ≤ F`.
    pub fn filter(&mut self, x: &TranslationalInput, f_nom_h: &Vector3<f64>) -> FilterOutput<3, N> {
        let t0 = Instant::now();
        let mut report = FilterReport::<N>::default();
        let out = self.filter_inner(x, f_nom_h, &mut report);
        report.solve_time_ns = t0.elapsed().as_nanos().min(u64::MAX as u128) as u64;
        FilterOutput {
            u: out.0,
            actuated: out.1,
            report,
        }
    }

    fn filter_inner(
        &mut self,
        x: &TranslationalInput,
        f_nom_h: &Vector3<f64>,
        report: &mut FilterReport<N>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let fmax = self.params.force_max;
        let Some(p) = self.prepare(x) else {
            report.faults |= faults::INVALID_STATE;
            report.status = FilterStatus::Fallback;
            return (Vector3::zeros(), Vector3::zeros());
        };
        for (i, t) in p.terms.iter().enumerate() {
            report.h[i] = t.h;
        }
        let mut f_h;
        if !common::nominal_valid(f_nom_h, fmax) {
            report.faults |= faults::INVALID_NOMINAL;
            report.status = FilterStatus::Fallback;
            f_h = self.fallback_prepared(x, &p).0;
        } else {
            let mut rows_a = [0.0; 3 * N];
            let mut rows_c = [0.0; N];
            for (i, r) in p.rows.iter().enumerate() {
                rows_a[3 * i..3 * i + 3].copy_from_slice(r.a.as_slice());
                rows_c[i] = r.c;
            }
            let mut g = [0.0; 18];
            for k in 0..3 {
                for j in 0..3 {
                    g[3 * k + j] = p.r_bh[(k, j)];
                    g[9 + 3 * k + j] = -p.r_bh[(k, j)];
                }
            }
            let g_max = [fmax * (1.0 - BOX_MARGIN); 6];
            let mut u = [0.0; 3];
            let res = self
                .qp
                .solve(f_nom_h.as_slice(), &rows_a, &rows_c, &g, &g_max, &mut u);
            report.iterations = res.iterations;
            report.slack = res.slack;
            f_h = Vector3::from(u);
            match res.outcome {
                QpOutcome::Skipped => report.status = FilterStatus::Skipped,
                QpOutcome::Solved => report.status = FilterStatus::Solved,
                QpOutcome::Relaxed => {
                    report.status = FilterStatus::Relaxed;
                    report.faults |= faults::QP_INFEASIBLE_RELAXED;
                }
                QpOutcome::Failed => {
                    report.status = FilterStatus::Fallback;
                    report.faults |= faults::QP_FAILED_FALLBACK;
                    f_h = self.fallback_prepared(x, &p).0;
                }
            }
        }
        // Last line of defence: the actuated force must be finite and inside the box.
        let f_b = p.r_bh * f_h;
        let (f_b_c, clamped) = clamp_box(&f_b, fmax);
        if clamped || !common::finite(&f_h) {
            report.faults |= faults::OUTPUT_CLAMPED;
            f_h = p.r_bh.transpose() * f_b_c;
        }
        common::evaluate_rows(&p.rows, &f_h, report);
        (f_h, f_b_c)
    }

    /// Verification only: force the solver even when the nominal is feasible.
    pub fn set_skip_enabled(&mut self, on: bool) {
        self.qp.set_skip_enabled(on);
    }

    /// Multipliers λ_i ≥ 0 of the barrier rows of the last solve, in [`NAMES`] order.
    pub fn row_duals(&self) -> &[f64] {
        self.qp.row_duals()
    }

    /// The last QP handed to the solver (for `--dump-qp`).
    pub fn dump_qp(&self) -> QpDump {
        self.qp.dump()
    }
}
