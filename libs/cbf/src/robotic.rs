//! Robotic safety filter (paper Sec. "CBFs for the Robotic Subsystem", QP eq.
//! "robotic_qp").
//!
//! State `x_rob = [θ; θ̇]` (rad, rad/s); input the joint torques `τ_M` [N m]. The filter
//! core is IPC- and model-free: it takes the *precomputed* reduced free-floating arm
//! dynamics in control-affine form
//!
//! ```text
//! θ̈ = A τ_M + b + ξ_rob,    A = M_eff⁻¹,  b = −M_eff⁻¹ c_free,  ξ_rob = −M_eff⁻¹ K [f_B; τ_B]
//! ```
//!
//! where `ξ_rob` [rad/s²] is the effect on the arm of the base acceleration produced by the
//! upstream safe force and torque (`K` the wrench map of the Schur-reduced dynamics), and per
//! collision sphere its centre `p_i`, Jacobian `J_i` and `J̇_i θ̇` in the base frame F_B.
//! [`robotic_input_from_model`] computes all of these from `sc_multibody`.

use crate::attitude::box_rows;
use crate::barrier::{RelDegOne, RelDegTwo, Row};
use crate::common::{
    self, BOX_MARGIN, FilterOutput, FilterReport, FilterStatus, clamp_box, faults,
};
use crate::qp::{QpDump, QpEngine, QpOutcome, SolverParams};
use nalgebra::{SMatrix, SVector, Vector3, Vector6};
use sc_multibody::Robot;

/// Joint-space vector and matrix.
pub type Vector7 = SVector<f64, 7>;
pub type Matrix7 = SMatrix<f64, 7, 7>;
/// Point Jacobian (3×7).
pub type Matrix3x7 = SMatrix<f64, 3, 7>;

/// Number of joints, link collision spheres, constraints.
pub const NJ: usize = 7;
pub const NS: usize = 21;
pub const N: usize = 3 * NJ + NS;

/// Constraint names in report order: `theta_1..7`, `theta_dot_max_1..7`,
/// `theta_dot_min_1..7`, `link_base_<link>_<k>` (link 1..7, sphere k 1..3 along the link).
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
];

/// Accepted ranges: `|θ_i| ≤ MAX_ANGLE_RAD`, `|θ̇_i| ≤ MAX_RATE_RAD_S`, drift and coupling
/// accelerations `≤ MAX_ACCEL`, `A` entries `≤ MAX_GAIN`, sphere centres `≤ MAX_REACH_M`.
pub const MAX_ANGLE_RAD: f64 = 100.0;
pub const MAX_RATE_RAD_S: f64 = 100.0;
pub const MAX_ACCEL: f64 = 1e6;
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
    /// `M_eff` [kg m²] (used by the fallback `τ_M = sat(−M θ̇/T)`).
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
}

/// Parameters of the robotic filter.
#[derive(Debug, Clone, PartialEq)]
pub struct RoboticParams {
    pub theta_min: Vector7,
    pub theta_max: Vector7,
    /// Symmetric `|θ̇_i| ≤ θ̇_max,i` [rad/s].
    pub theta_dot_max: Vector7,
    /// γ_h [1/s], ε_θ [rad²/s], u_max of H_θ [rad²/s²].
    pub gamma: f64,
    pub eps_theta: f64,
    pub u_max_theta: f64,
    /// γ_θ̇ [1/s], ε_θ̇ [rad/s²].
    pub gamma_theta_dot: f64,
    pub eps_theta_dot: f64,
    /// ε_LB [m²/s], u_max of H_LB [m²/s²].
    pub eps_lb: f64,
    pub u_max_lb: f64,
    /// `‖τ_M‖∞ ≤ T_M` [N m].
    pub torque_max: f64,
    /// T of the fallback `τ_M = sat(−M θ̇ / T)` [s].
    pub brake_time: f64,
    pub solver: SolverParams,
}

impl RoboticParams {
    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        let r = &s.safety.robotic;
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
    let jtd = s.jacobian.transpose() * d;
    let rr = s.radius + x.base_radius;
    RelDegTwo {
        h: d.dot(&d) - rr * rr,
        hdot: 2.0 * d.dot(&v),
        hddot_drift: 2.0 * v.dot(&v) + 2.0 * jtd.dot(&(x.drift + x.xi)) + 2.0 * d.dot(&s.jdot_qdot),
        hddot_u: x.a.transpose() * jtd * 2.0,
    }
}

/// All barrier terms of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoboticTerms {
    pub theta: [RelDegTwo<NJ>; NJ],
    pub theta_dot_max: [RelDegOne<NJ>; NJ],
    pub theta_dot_min: [RelDegOne<NJ>; NJ],
    pub link_base: [RelDegTwo<NJ>; NS],
}

impl RoboticTerms {
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
        }
        h
    }
}

enum Invalid {
    State,
    Coupling,
}

/// The robotic CBF-QP safety filter (paper eq. "robotic_qp").
pub struct RoboticFilter {
    pub params: RoboticParams,
    qp: QpEngine,
}

fn finite_in<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>, max: f64) -> bool {
    common::finite(m) && m.amax() <= max
}

impl RoboticFilter {
    pub fn new(params: RoboticParams) -> Self {
        let qp = QpEngine::new(NJ, N, 2 * NJ, params.torque_max, &params.solver);
        Self { params, qp }
    }

    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        Self::new(RoboticParams::from_scenario(s))
    }

    fn state_valid(x: &RoboticInput) -> bool {
        finite_in(&x.theta, MAX_ANGLE_RAD)
            && finite_in(&x.theta_dot, MAX_RATE_RAD_S)
            && finite_in(&x.a, MAX_GAIN)
            && finite_in(&x.m_eff, MAX_GAIN)
            && finite_in(&x.drift, MAX_ACCEL)
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
    }

    /// Barrier terms for a valid input (`None` otherwise).
    pub fn constraints(&self, x: &RoboticInput) -> Option<RoboticTerms> {
        self.prepare(x).ok().map(|(t, _)| t)
    }

    fn prepare(&self, x: &RoboticInput) -> Result<(RoboticTerms, [Row<NJ>; N]), Invalid> {
        if !Self::state_valid(x) {
            return Err(Invalid::State);
        }
        if !finite_in(&x.xi, MAX_ACCEL) {
            return Err(Invalid::Coupling);
        }
        let p = &self.params;
        let terms = RoboticTerms {
            theta: std::array::from_fn(|i| joint_angle(i, x, p.theta_min[i], p.theta_max[i])),
            theta_dot_max: std::array::from_fn(|i| joint_velocity(i, x, p.theta_dot_max[i])[0]),
            theta_dot_min: std::array::from_fn(|i| joint_velocity(i, x, p.theta_dot_max[i])[1]),
            link_base: std::array::from_fn(|k| link_base(&x.spheres[k], x)),
        };
        let rows: [Row<NJ>; N] = std::array::from_fn(|j| {
            if j < NJ {
                terms.theta[j].row(p.gamma, p.eps_theta, p.u_max_theta)
            } else if j < 2 * NJ {
                terms.theta_dot_max[j - NJ].row(p.gamma_theta_dot, p.eps_theta_dot)
            } else if j < 3 * NJ {
                terms.theta_dot_min[j - 2 * NJ].row(p.gamma_theta_dot, p.eps_theta_dot)
            } else {
                terms.link_base[j - 3 * NJ].row(p.gamma, p.eps_lb, p.u_max_lb)
            }
        });
        if rows.iter().all(Row::is_finite) {
            Ok((terms, rows))
        } else {
            Err(Invalid::State)
        }
    }

    /// Bounded fallback `τ_M = sat(−M_eff θ̇ / T)` (direction kept); zero when the state is
    /// invalid.
    pub fn fallback(&self, x: &RoboticInput) -> Vector7 {
        if !(finite_in(&x.theta_dot, MAX_RATE_RAD_S) && finite_in(&x.m_eff, MAX_GAIN)) {
            return Vector7::zeros();
        }
        let t = -(x.m_eff * x.theta_dot) / self.params.brake_time;
        common::sat_inf(&t, self.params.torque_max * (1.0 - BOX_MARGIN))
    }

    /// One filter step: safe `τ_M` closest to `tau_nom` subject to the 42 CBF rows and
    /// `‖τ_M‖∞ ≤ T_M`.
    pub fn filter(&mut self, x: &RoboticInput, tau_nom: &Vector7) -> FilterOutput<NJ, N> {
        let t0 = std::time::Instant::now();
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
        x: &RoboticInput,
        tau_nom: &Vector7,
        report: &mut FilterReport<N>,
    ) -> Vector7 {
        let tmax = self.params.torque_max;
        let (terms, rows) = match self.prepare(x) {
            Ok(p) => p,
            Err(Invalid::State) => {
                report.faults |= faults::INVALID_STATE;
                return Vector7::zeros();
            }
            Err(Invalid::Coupling) => {
                report.faults |= faults::INVALID_COUPLING;
                return clamp_box(&self.fallback(x), tmax).0;
            }
        };
        report.h = terms.h();
        let mut tau;
        if !common::nominal_valid(tau_nom, tmax) {
            report.faults |= faults::INVALID_NOMINAL;
            tau = self.fallback(x);
        } else {
            let mut rows_a = [0.0; NJ * N];
            let mut rows_c = [0.0; N];
            for (i, r) in rows.iter().enumerate() {
                rows_a[NJ * i..NJ * (i + 1)].copy_from_slice(r.a.as_slice());
                rows_c[i] = r.c;
            }
            let (g, g_max) = box_rows::<NJ, { 2 * NJ * NJ }, { 2 * NJ }>(tmax);
            let mut u = [0.0; NJ];
            let res = self
                .qp
                .solve(tau_nom.as_slice(), &rows_a, &rows_c, &g, &g_max, &mut u);
            report.iterations = res.iterations;
            report.slack = res.slack;
            tau = Vector7::from(u);
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
                    tau = self.fallback(x);
                }
            }
        }
        let (tau, clamped) = clamp_box(&tau, tmax);
        if clamped {
            report.faults |= faults::OUTPUT_CLAMPED;
        }
        common::evaluate_rows(&rows, &tau, report);
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

/// Computes the filter's precomputed terms from the servicer model for joint state
/// `(θ, θ̇)`, base angular velocity `omega_b` [rad/s, F_B] and the upstream safe base wrench
/// `[f_B,SF; τ_B,SF]` [N, N m; F_B, about the base origin]: `A = M_eff⁻¹`,
/// `b = −A c_free`, `ξ_rob = −A K [f_B; τ_B]`, and the 21 arm spheres with `J`, `J̇θ̇`.
/// `None` when the model has no base sphere, not exactly 21 arm spheres, or the dynamics
/// are singular / non-finite.
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
    })
}
