//! Attitude safety filter (paper Sec. "CBFs for the Attitude Subsystem", QP eq.
//! "attitude_qp").
//!
//! State `x_att = [q_RB; ω_B]` (scalar-first quaternion rotating F_B into F_R; body rate in
//! F_B [rad/s]); dynamics paper eqs. "Attitude kinematics"/"Attitude dynamics"
//! `I ω̇ = τ_B − ω × (I ω)`; input the body torque `τ_B` [N m] in F_B.
//!
//! Coupling `ξ_att`: the line-of-sight barrier depends on where the servicer *is*, so its
//! second derivative contains the servicer's relative translational acceleration in F_R,
//! `a_R = a_drift,R + f_R,SF / m`, where `f_R,SF = R_RB f_B,SF` is the upstream safe force of
//! the translational filter. `ξ_att = f_R,SF / m` [m/s²] is passed in by the caller
//! ([`xi_att_from_force`]); it enters `ḧ_ATT`'s drift only.

use crate::barrier::{RelDegOne, RelDegTwo, Row};
use crate::common::{
    self, BOX_MARGIN, FilterOutput, FilterReport, FilterStatus, clamp_box, faults, in_range3,
    unit_quat,
};
use crate::qp::{QpDump, QpEngine, QpOutcome, SolverParams};
use nalgebra::{Matrix3, Vector3};
use sc_models::quat::{self, Quat};
use std::time::Instant;

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
    /// γ_h [1/s], ε_ATT [1/s], u_max of H_ATT [1/s²].
    pub gamma: f64,
    pub eps_att: f64,
    pub u_max_att: f64,
    /// Per-axis rate limits `ω_min ≤ ω_B ≤ ω_max` [rad/s].
    pub omega_max: Vector3<f64>,
    pub omega_min: Vector3<f64>,
    /// γ_ω [1/s], ε_ω [rad/s²].
    pub gamma_omega: f64,
    pub eps_omega: f64,
    /// `‖τ_B‖∞ ≤ T` [N m].
    pub torque_max: f64,
    /// T of the fallback `τ_B = sat(−I (ω_B − ω_T,B)/T)` [s].
    pub brake_time: f64,
    pub solver: SolverParams,
}

impl AttitudeParams {
    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        let a = &s.safety.attitude;
        Self {
            boresight_b: Vector3::from(s.servicer.boresight_body).normalize(),
            cos_beta: a.los_half_angle_deg.to_radians().cos(),
            gamma: s.safety.gamma_per_s,
            eps_att: a.eps_att,
            u_max_att: a.u_max_att_per_s2,
            omega_max: Vector3::from(a.omega_max_rad_s),
            omega_min: Vector3::from(a.omega_min_rad_s),
            gamma_omega: a.gamma_omega_per_s,
            eps_omega: a.eps_omega,
            torque_max: s.limits.torque_max_nm,
            brake_time: s.safety.fallback.attitude_brake_time_s,
            solver: SolverParams::from_scenario(s),
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
    /// Servicer inertia `I` about its CoM in F_B [kg m²] (symmetric positive definite).
    pub inertia: Matrix3<f64>,
    /// Servicer position `r_R` relative to the target CoM, in F_R [m].
    pub r_r: Vector3<f64>,
    /// `v_R = ṙ_R` [m/s] (F_R is non-rotating).
    pub v_r: Vector3<f64>,
    /// Relative drift acceleration of the servicer in F_R without its own thrust [m/s²]
    /// (e.g. [`tidal_acceleration`]).
    pub a_drift_r: Vector3<f64>,
    /// Grasping point `R_RT(t) p_G,T` in F_R [m], its first and second time derivative.
    pub grasp_r: Vector3<f64>,
    pub grasp_vel_r: Vector3<f64>,
    pub grasp_acc_r: Vector3<f64>,
    /// `ξ_att = R_RB f_B,SF / m` [m/s²]: the upstream safe force's acceleration, F_R.
    pub xi_r: Vector3<f64>,
    /// Target angular velocity expressed in F_B [rad/s] (used by the fallback only).
    pub omega_target_b: Vector3<f64>,
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
/// `ḧ = (ω̇×d + ω×(ω×d))ᵀ s_B + 2 (ω×d)ᵀ ṡ_B + dᵀ s̈_B`, `ω̇ = I⁻¹(τ − ω×Iω)`, so
/// `∂ḧ/∂τ = I⁻¹ (d × s_B)`. ξ_att is inside `s̈` (through `ρ̈`).
pub fn line_of_sight(
    r_br: &Matrix3<f64>,
    omega: &Vector3<f64>,
    inertia: &Matrix3<f64>,
    inertia_inv: &Matrix3<f64>,
    d_b: &Vector3<f64>,
    los: &LineOfSight,
    cos_beta: f64,
) -> RelDegTwo<3> {
    let s_b = r_br * los.s;
    let sd_b = r_br * los.s_dot;
    let sdd_b = r_br * los.s_ddot;
    let wxd = omega.cross(d_b);
    let dxs = d_b.cross(&s_b);
    let wdot0 = -(inertia_inv * omega.cross(&(inertia * omega)));
    RelDegTwo {
        h: d_b.dot(&s_b) - cos_beta,
        hdot: wxd.dot(&s_b) + d_b.dot(&sd_b),
        hddot_drift: wdot0.dot(&dxs)
            + omega.cross(&wxd).dot(&s_b)
            + 2.0 * wxd.dot(&sd_b)
            + d_b.dot(&sdd_b),
        hddot_u: inertia_inv * dxs,
    }
}

/// Angular-rate limits, paper eq. "CBF-omega": `h⁺_i = ω_max,i − ω_i`,
/// `h⁻_i = ω_i − ω_min,i` [rad/s]; relative degree one with `ω̇ = I⁻¹(τ − ω×Iω)`.
/// Returns `[h⁺_x, h⁺_y, h⁺_z, h⁻_x, h⁻_y, h⁻_z]`.
pub fn omega_limits(
    omega: &Vector3<f64>,
    inertia: &Matrix3<f64>,
    inertia_inv: &Matrix3<f64>,
    omega_max: &Vector3<f64>,
    omega_min: &Vector3<f64>,
) -> [RelDegOne<3>; 6] {
    let wdot0 = -(inertia_inv * omega.cross(&(inertia * omega)));
    std::array::from_fn(|k| {
        let i = k % 3;
        let row: Vector3<f64> = inertia_inv.row(i).transpose();
        if k < 3 {
            RelDegOne {
                h: omega_max[i] - omega[i],
                hdot_drift: -wdot0[i],
                hdot_u: -row,
            }
        } else {
            RelDegOne {
                h: omega[i] - omega_min[i],
                hdot_drift: wdot0[i],
                hdot_u: row,
            }
        }
    })
}

/// `I` symmetrised and its inverse, if finite, symmetric (1e-9 relative) and positive definite.
pub fn checked_inertia(i: &Matrix3<f64>) -> Option<(Matrix3<f64>, Matrix3<f64>)> {
    if !common::finite(i) {
        return None;
    }
    let n = i.norm();
    if !(n > 0.0 && n < 1e12) || (i - i.transpose()).norm() > 1e-9 * n {
        return None;
    }
    let s = (i + i.transpose()) * 0.5;
    let inv = s.cholesky()?.inverse();
    common::finite(&inv).then_some((s, inv))
}

/// All barrier terms of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeTerms {
    pub los: RelDegTwo<3>,
    pub omega: [RelDegOne<3>; 6],
}

struct Prepared {
    inertia: Matrix3<f64>,
    terms: AttitudeTerms,
    rows: [Row<3>; N],
}

enum Invalid {
    State,
    Coupling,
}

/// The attitude CBF-QP safety filter (paper eq. "attitude_qp").
pub struct AttitudeFilter {
    pub params: AttitudeParams,
    qp: QpEngine,
}

impl AttitudeFilter {
    pub fn new(params: AttitudeParams) -> Self {
        let qp = QpEngine::new(3, N, 6, params.torque_max, &params.solver);
        Self { params, qp }
    }

    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        Self::new(AttitudeParams::from_scenario(s))
    }

    /// Barrier terms for a valid input (`None` otherwise).
    pub fn constraints(&self, x: &AttitudeInput) -> Option<AttitudeTerms> {
        self.prepare(x).ok().map(|p| p.terms)
    }

    fn prepare(&self, x: &AttitudeInput) -> Result<Prepared, Invalid> {
        let p = &self.params;
        let ok = in_range3(&x.omega_b, MAX_RATE_RAD_S)
            && in_range3(&x.omega_target_b, MAX_RATE_RAD_S)
            && in_range3(&x.r_r, MAX_RANGE_M)
            && in_range3(&x.grasp_r, MAX_RANGE_M)
            && in_range3(&x.v_r, MAX_SPEED_M_S)
            && in_range3(&x.grasp_vel_r, MAX_SPEED_M_S)
            && in_range3(&x.a_drift_r, MAX_ACCEL_M_S2)
            && in_range3(&x.grasp_acc_r, MAX_ACCEL_M_S2);
        if !ok {
            return Err(Invalid::State);
        }
        let q = unit_quat(&x.q_rb).ok_or(Invalid::State)?;
        let (inertia, inertia_inv) = checked_inertia(&x.inertia).ok_or(Invalid::State)?;
        let rho = x.grasp_r - x.r_r;
        if rho.norm() < MIN_LOS_M {
            return Err(Invalid::State);
        }
        if !in_range3(&x.xi_r, MAX_ACCEL_M_S2) {
            return Err(Invalid::Coupling);
        }
        let rho_dot = x.grasp_vel_r - x.v_r;
        let rho_ddot = x.grasp_acc_r - x.a_drift_r - x.xi_r;
        let los_dir = line_of_sight_direction(&rho, &rho_dot, &rho_ddot);
        let r_br = quat::to_matrix(&q).transpose();
        let los = line_of_sight(
            &r_br,
            &x.omega_b,
            &inertia,
            &inertia_inv,
            &p.boresight_b,
            &los_dir,
            p.cos_beta,
        );
        let omega = omega_limits(
            &x.omega_b,
            &inertia,
            &inertia_inv,
            &p.omega_max,
            &p.omega_min,
        );
        let mut rows = [los.row(p.gamma, p.eps_att, p.u_max_att); N];
        for (k, o) in omega.iter().enumerate() {
            rows[1 + k] = o.row(p.gamma_omega, p.eps_omega);
        }
        if !rows.iter().all(Row::is_finite) {
            return Err(Invalid::State);
        }
        Ok(Prepared {
            inertia,
            terms: AttitudeTerms { los, omega },
            rows,
        })
    }

    /// Bounded fallback `τ_B = sat(−I (ω_B − ω_T,B)/T)` (direction kept), zero when the
    /// state is invalid.
    pub fn fallback(&self, x: &AttitudeInput) -> Vector3<f64> {
        match checked_inertia(&x.inertia) {
            Some((i, _))
                if in_range3(&x.omega_b, MAX_RATE_RAD_S)
                    && in_range3(&x.omega_target_b, MAX_RATE_RAD_S) =>
            {
                self.fallback_with(&i, x)
            }
            _ => Vector3::zeros(),
        }
    }

    fn fallback_with(&self, inertia: &Matrix3<f64>, x: &AttitudeInput) -> Vector3<f64> {
        let t = -(inertia * (x.omega_b - x.omega_target_b)) / self.params.brake_time;
        common::sat_inf(&t, self.params.torque_max * (1.0 - BOX_MARGIN))
    }

    /// One filter step: safe `τ_B` closest to `tau_nom` subject to `Φ_ATT ≥ 0`,
    /// `φ⁺_ω,i ≥ 0`, `φ⁻_ω,i ≥ 0` and `‖τ_B‖∞ ≤ T`.
    pub fn filter(&mut self, x: &AttitudeInput, tau_nom: &Vector3<f64>) -> FilterOutput<3, N> {
        let t0 = Instant::now();
        let mut report = FilterReport::<N>::default();
        let u = self.filter_inner(x, tau_nom, &mut report);
        report.solve_time_ns = t0.elapsed().as_nanos().min(u64::MAX as u128) as u64;
        FilterOutput {
            u,
            actuated: u,
            report,
        }
    }

    fn filter_inner(
        &mut self,
        x: &AttitudeInput,
        tau_nom: &Vector3<f64>,
        report: &mut FilterReport<N>,
    ) -> Vector3<f64> {
        let tmax = self.params.torque_max;
        let p = match self.prepare(x) {
            Ok(p) => p,
            Err(Invalid::State) => {
                report.faults |= faults::INVALID_STATE;
                return Vector3::zeros();
            }
            Err(Invalid::Coupling) => {
                report.faults |= faults::INVALID_COUPLING;
                let u = self.fallback(x);
                return clamp_box(&u, tmax).0;
            }
        };
        report.h[0] = p.terms.los.h;
        for (k, o) in p.terms.omega.iter().enumerate() {
            report.h[1 + k] = o.h;
        }
        let mut tau;
        if !common::nominal_valid(tau_nom, tmax) {
            report.faults |= faults::INVALID_NOMINAL;
            report.status = FilterStatus::Fallback;
            tau = self.fallback_with(&p.inertia, x);
        } else {
            let mut rows_a = [0.0; 3 * N];
            let mut rows_c = [0.0; N];
            for (i, r) in p.rows.iter().enumerate() {
                rows_a[3 * i..3 * i + 3].copy_from_slice(r.a.as_slice());
                rows_c[i] = r.c;
            }
            let (g, g_max) = box_rows::<3, 18, 6>(tmax);
            let mut u = [0.0; 3];
            let res = self
                .qp
                .solve(tau_nom.as_slice(), &rows_a, &rows_c, &g, &g_max, &mut u);
            report.iterations = res.iterations;
            report.slack = res.slack;
            tau = Vector3::from(u);
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
                    tau = self.fallback_with(&p.inertia, x);
                }
            }
        }
        let (tau, clamped) = clamp_box(&tau, tmax);
        if clamped {
            report.faults |= faults::OUTPUT_CLAMPED;
        }
        common::evaluate_rows(&p.rows, &tau, report);
        tau
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

/// Box rows `[I; −I] u ≤ limit (1 − BOX_MARGIN)` for `M` inputs (`G` is `2M × M`
/// row-major, `GM = 2M·M`, `G2 = 2M`).
pub(crate) fn box_rows<const M: usize, const GM: usize, const G2: usize>(
    limit: f64,
) -> ([f64; GM], [f64; G2]) {
    let mut g = [0.0; GM];
    for k in 0..M {
        g[k * M + k] = 1.0;
        g[(M + k) * M + k] = -1.0;
    }
    (g, [limit * (1.0 - BOX_MARGIN); G2])
}
