//! Shared fixtures of the sc-cbf integration tests: the default scenario, the servicer
//! model, realistic filter inputs built from the model (the way `sc-mission` builds them —
//! replicated here, sc-mission is not a dependency), deterministic random numbers and an
//! independent QP toolbox (KKT multipliers, brute-force active sets, Clarabel references).
#![allow(dead_code)]

use nalgebra::{DMatrix, DVector, SMatrix, SVector, Vector3, Vector6};
use sc_cbf::attitude::{tidal_acceleration, xi_att_from_force};
use sc_cbf::robotic::{Vector7, robotic_input_from_model};
use sc_cbf::{AttitudeInput, RoboticInput, TranslationalInput};
use sc_models::quat::{self, Quat};
use sc_multibody::Robot;
use sc_scenario::Scenario;
use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

#[allow(unused_imports)] // not every test binary uses every tool
pub use sc_cbf::verify::{Qp, clarabel, kkt, nnls};

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

pub fn scenario() -> Scenario {
    static S: OnceLock<Scenario> = OnceLock::new();
    S.get_or_init(|| {
        Scenario::load(&root().join(sc_scenario::DEFAULT_SCENARIO)).expect("scenario loads")
    })
    .clone()
}

/// The servicer model of the default scenario (loaded once).
pub fn robot() -> Arc<Robot> {
    static R: OnceLock<Arc<Robot>> = OnceLock::new();
    R.get_or_init(|| Arc::new(Robot::from_urdf_file(&scenario().urdf_path()).expect("URDF loads")))
        .clone()
}

/// The servicer's total mass [kg] (what `SafetyLayer::from_scenario` gives the filters).
pub fn mass() -> f64 {
    robot().total_mass()
}

pub fn mean_motion(s: &Scenario) -> f64 {
    let a = s.orbit.earth_radius_m + s.orbit.altitude_m;
    (s.orbit.earth_mu_m3_s2 / (a * a * a)).sqrt()
}

/// `q_HR` at time `t` on the circular orbit: F_H turns at `ω_H = n ẑ_H` relative to the
/// inertially fixed F_R, so `R_HR(t) = R_z(−n t) R_HR(0)`.
pub fn q_hr_at(s: &Scenario, n: f64, t: f64) -> Quat {
    quat::mul(
        &quat::from_axis_angle(&Vector3::z(), -n * t),
        &s.reference_frame.attitude_in_hill,
    )
}

/// Translational input for the servicer CoM at `r_r` moving at `v_r` (both in the
/// inertially fixed F_R), attitude `q_rb`, body rate `omega_b`, at t = 0 of the circular
/// orbit: `r_H = R_HR r_R`, `v_H = R_HR v_R − ω_H × r_H`.
pub fn tr_input(
    s: &Scenario,
    r_r: Vector3<f64>,
    v_r: Vector3<f64>,
    q_rb: Quat,
    omega_b: Vector3<f64>,
) -> TranslationalInput {
    let n = mean_motion(s);
    let q_hr = s.reference_frame.attitude_in_hill;
    let r_hr = quat::to_matrix(&q_hr);
    let r_h = r_hr * r_r;
    let w = Vector3::new(0.0, 0.0, n);
    let mut x = TranslationalInput::circular(r_h, r_hr * v_r - w.cross(&r_h), q_hr, n, q_rb);
    x.omega_b = omega_b;
    x
}

/// The target's tumbling motion: grasping point `R_RT(t) p_G,T` in F_R and its first two
/// derivatives, and `ω_T` in F_R (the default target spins about a principal axis, so
/// `ω_T` is constant and `R_RT(t) = exp(t [ω_T]×)`).
pub fn grasp_at(s: &Scenario, t: f64) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let wt = Vector3::from(s.target.initial_omega_rad_s);
    let q_rt0 = s.target.initial_attitude;
    let w_r = quat::to_matrix(&q_rt0) * wt;
    let q = quat::mul(&quat::from_axis_angle(&w_r, w_r.norm() * t), &q_rt0);
    let p = quat::to_matrix(&q) * Vector3::from(s.target.grasp_point_m);
    let v = w_r.cross(&p);
    (p, v, w_r.cross(&v), w_r)
}

/// The part of the servicer's state the attitude filter's input is built from.
#[derive(Debug, Clone, Copy)]
pub struct ServicerState {
    pub theta: Vector7,
    pub theta_dot: Vector7,
    pub omega_b: Vector3<f64>,
    pub q_rb: Quat,
    /// System CoM relative to the target CoM, F_R [m], and its velocity [m/s].
    pub com_r: Vector3<f64>,
    pub com_v_r: Vector3<f64>,
    /// Time of the target's tumbling motion [s].
    pub t: f64,
    /// Upstream safe force, F_B [N].
    pub f_b: Vector3<f64>,
}

impl ServicerState {
    pub fn rest(s: &Scenario, com_r: Vector3<f64>, q_rb: Quat) -> Self {
        Self {
            theta: theta0(s),
            theta_dot: Vector7::zeros(),
            omega_b: Vector3::zeros(),
            q_rb,
            com_r,
            com_v_r: Vector3::zeros(),
            t: 0.0,
            f_b: Vector3::zeros(),
        }
    }
}

/// The attitude filter's input from the model, as `sc_mission::stages::attitude_input`
/// builds it: the base with the arm locked (`P_L`, `r_L` under the upstream force), the
/// wrench map's torque columns and the force's share for the contract rows, the tidal
/// drift of the CoM, `ξ_att = R_RB f_B / m`.
pub fn att_input(s: &Scenario, robot: &Robot, x: &ServicerState) -> AttitudeInput {
    let m = robot.total_mass();
    let bd = robot
        .base_angular_dynamics(&x.theta, &x.theta_dot, &x.omega_b, &x.f_b)
        .expect("base dynamics");
    let wrench = Vector6::new(x.f_b.x, x.f_b.y, x.f_b.z, 0.0, 0.0, 0.0);
    let red = robot
        .reduced_arm_dynamics(&x.theta, &x.theta_dot, &x.omega_b, &wrench)
        .expect("reduced dynamics");
    let radial_r = quat::to_matrix(&quat::conj(&s.reference_frame.attitude_in_hill)) * Vector3::x();
    let (g, gv, ga, w_t) = grasp_at(s, x.t);
    let k_tau: SMatrix<f64, 7, 3> = red.wrench_map.fixed_columns::<3>(3).into();
    AttitudeInput {
        q_rb: x.q_rb,
        omega_b: x.omega_b,
        p: bd.p_locked,
        r: bd.r_locked,
        r_r: x.com_r,
        v_r: x.com_v_r,
        a_drift_r: tidal_acceleration(mean_motion(s), &radial_r, &x.com_r),
        grasp_r: g,
        grasp_vel_r: gv,
        grasp_acc_r: ga,
        xi_r: xi_att_from_force(&x.f_b, &x.q_rb, m),
        omega_target_b: quat::to_matrix(&x.q_rb).transpose() * w_t,
        joint_coupling: k_tau,
        joint_coupling_force: red.xi,
    }
}

/// The attitude `q_RB` that points the boresight `d_B` exactly at the grasping point from
/// `com_r` (shortest rotation from F_R), then turned by `err` [rad] about the body axis
/// `axis` made perpendicular to the boresight (so the pointing error is `|err|`).
pub fn pointing(s: &Scenario, com_r: &Vector3<f64>, t: f64, axis: &Vector3<f64>, err: f64) -> Quat {
    let d = Vector3::from(s.servicer.boresight_body).normalize();
    let los = (grasp_at(s, t).0 - com_r).normalize();
    let c = d.cross(&los);
    let q0 = quat::from_axis_angle(&c, c.norm().atan2(d.dot(&los)));
    let perp = axis - d * d.dot(axis);
    let perp = if perp.norm() > 1e-9 {
        perp
    } else {
        d.cross(&Vector3::z()) + d.cross(&Vector3::y())
    };
    quat::mul(&q0, &quat::from_axis_angle(&perp, err))
}

/// Robotic input from the model with a small base rate and upstream wrench.
pub fn rob_input(robot: &Robot, theta: Vector7, theta_dot: Vector7) -> RoboticInput {
    robotic_input_from_model(
        robot,
        &theta,
        &theta_dot,
        &Vector3::new(0.01, -0.02, 0.005),
        &Vector3::new(3.0, -2.0, 1.0),
        &Vector3::new(1.0, 2.0, -0.5),
    )
    .expect("model terms")
}

pub fn theta0(s: &Scenario) -> Vector7 {
    Vector7::from(s.servicer.initial_theta_rad)
}

/// Joint angles uniformly inside the safety limits, `margin` [rad] from them.
pub fn theta_inside(s: &Scenario, rng: &mut Lcg, margin: f64) -> Vector7 {
    let lo = Vector7::from(s.safety.robotic.theta_min_rad);
    let hi = Vector7::from(s.safety.robotic.theta_max_rad);
    Vector7::from_fn(|i, _| {
        let (a, b) = (lo[i] + margin, hi[i] - margin);
        0.5 * (a + b) + 0.5 * (b - a) * rng.next()
    })
}

/// Deterministic pseudo-random numbers in [-1, 1] (no rand dependence in tests).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    pub fn v3(&mut self, s: f64) -> Vector3<f64> {
        Vector3::new(self.next() * s, self.next() * s, self.next() * s)
    }
    pub fn v7(&mut self, s: f64) -> Vector7 {
        Vector7::from_fn(|_, _| self.next() * s)
    }
    pub fn unit_quat(&mut self) -> Quat {
        let q = [self.next(), self.next(), self.next(), self.next()];
        quat::normalized(&q).unwrap_or(quat::IDENTITY)
    }
}

// ------------------------------------------------------------------ QP toolbox

/// A QP `min ‖u − u_nom‖²  s.t.  c_i + a_i·u ≥ 0` (barrier rows first, then the hard rows),
/// in plain vectors.
/// The exact minimiser by enumerating active sets of at most `M` rows (the unique KKT
/// point of the strictly convex QP); `None` when infeasible. Exponential: small problems only.
pub fn brute_force(qp: &Qp) -> Option<DVector<f64>> {
    let m = qp.m();
    let n = qp.a.len();
    let un = &qp.u_nom;
    let scale = 1.0 + un.amax();
    let feasible =
        |u: &DVector<f64>| (0..n).all(|i| qp.phi(i, u) >= -1e-11 * scale * (1.0 + qp.a[i].norm()));
    let mut best: Option<(f64, DVector<f64>)> = None;
    let mut set = Vec::with_capacity(m);
    fn rec(start: usize, set: &mut Vec<usize>, m: usize, n: usize, f: &mut dyn FnMut(&[usize])) {
        f(set);
        if set.len() == m {
            return;
        }
        for i in start..n {
            set.push(i);
            rec(i + 1, set, m, n, f);
            set.pop();
        }
    }
    let mut consider = |set: &[usize]| {
        let k = set.len();
        let u = if k == 0 {
            un.clone()
        } else {
            let a = DMatrix::from_fn(k, m, |r, c| qp.a[set[r]][c]);
            let b = DVector::from_fn(k, |r, _| -qp.c[set[r]]);
            let aat = &a * a.transpose();
            let Some(ch) = aat.clone().cholesky() else {
                return;
            };
            // reject (nearly) dependent sets
            let an: f64 = set.iter().map(|&i| qp.a[i].norm_squared()).product();
            if aat.determinant() <= 1e-12 * an {
                return;
            }
            let lam = ch.solve(&(&b - &a * un));
            if lam.iter().any(|l| *l < -1e-12) {
                return;
            }
            un + a.transpose() * lam
        };
        if feasible(&u) {
            let c = (&u - un).norm_squared();
            if best.as_ref().is_none_or(|(bc, _)| c < *bc) {
                best = Some((c, u));
            }
        }
    };
    rec(0, &mut set, m, n, &mut consider);
    best.map(|b| b.1)
}

/// The reference solution of the lexicographic relaxed problem.
#[derive(Debug, Clone)]
pub struct Lexicographic {
    /// The first round's least violation `t₁`.
    pub t1: f64,
    /// The allowance `w_i t_i` (incl. the engine's rounding room) of every barrier row.
    pub allowance: Vec<f64>,
    /// Largest relative deviation of Clarabel's raw LP values from the exact vertex values
    /// (small problems only; 0 otherwise).
    pub clarabel_lp_deviation: f64,
}

/// The lexicographic min-max relaxation of the barrier rows (the first `nb`, weights `w`),
/// solved independently of `Engine`: each round's LP with Clarabel — whose duals give the
/// rows that make the round's violation necessary — and, for up to 3 inputs, its exact
/// value by vertex enumeration (for more inputs Clarabel's value, refined to the exact
/// vertex of the supporting rows when that vertex is feasible). The command is then the
/// projection of the nominal onto `qp.relaxed(&allowance)`. Independent of `qp.u_nom`.
pub fn lexicographic(qp: &Qp, w: &[f64]) -> Result<Lexicographic, String> {
    lexicographic_tiered(qp, w, &[])
}

/// [`lexicographic`] with priority tiers (`sc_cbf::engine`): tier by tier, the later
/// tiers' rows left out, the earlier tiers' allowances fixed. `t1` is then the largest
/// round value of all tiers (what the engine reports).
pub fn lexicographic_tiered(qp: &Qp, w: &[f64], tiers: &[u8]) -> Result<Lexicographic, String> {
    use clarabel::algebra::CscMatrix;
    use clarabel::solver::{
        DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
    };
    let m = qp.m();
    let n = qp.a.len();
    let nb = qp.nb;
    let mut fixed = vec![false; nb];
    let mut allow = vec![0.0; nb];
    let mut t1 = 0.0f64;
    let mut deviation = 0.0f64;
    let settings = |tol: f64| {
        let mut st = DefaultSettingsBuilder::<f64>::default().build().unwrap();
        st.verbose = false;
        st.max_iter = 500;
        st.tol_gap_abs = tol;
        st.tol_gap_rel = tol;
        st.tol_feas = tol;
        st
    };
    let tier = |i: usize| tiers.get(i).copied().unwrap_or(0);
    let last_tier = (0..nb).map(tier).max().unwrap_or(0);
    for current in 0..=last_tier {
        let in_tier = |i: usize| tier(i) == current;
        if !(0..nb).any(in_tier) {
            continue;
        }
        for round in 0..nb {
            // variables [u; t]: min t  s.t.  −a_i u − w_i t ≤ c_i (soft), −a_i u ≤ c_i + w_i t_i
            // (fixed), −g u ≤ c (hard), −t ≤ 0; later tiers' rows left out (0 ≤ 1)
            let cols = m + 1;
            let rows = n + 1;
            let mut dense = vec![vec![0.0; cols]; rows];
            let mut b = vec![0.0; rows];
            for i in 0..n {
                if i < nb && tier(i) > current {
                    b[i] = 1.0;
                    continue;
                }
                for (j, d) in dense[i].iter_mut().enumerate().take(m) {
                    *d = -qp.a[i][j];
                }
                b[i] = qp.c[i];
                if i < nb {
                    if fixed[i] {
                        b[i] += w[i] * allow[i];
                    } else if in_tier(i) {
                        dense[i][m] = -w[i];
                    }
                }
            }
            dense[n][m] = -1.0;
            let a = CscMatrix::from(&dense);
            let p = CscMatrix::<f64>::zeros((cols, cols));
            let mut q = vec![0.0; cols];
            q[m] = 1.0;
            let cones = [SupportedConeT::NonnegativeConeT(rows)];
            // tight tolerances first, looser ones if Clarabel stalls on an ill-conditioned LP
            let mut solved = None;
            for tol in [1e-12, 1e-10, 1e-8] {
                let mut s = DefaultSolver::new(&p, &q, &a, &b, &cones, settings(tol))
                    .map_err(|e| format!("{e:?}"))?;
                s.solve();
                if matches!(
                    s.solution.status,
                    SolverStatus::Solved | SolverStatus::AlmostSolved
                ) {
                    solved = Some(s);
                    break;
                }
            }
            let s = solved.ok_or(format!("LP round {round}: Clarabel failed"))?;
            let t_clarabel = s.solution.x[m];
            let z = &s.solution.z;
            let zmax = z[..n].iter().cloned().fold(0.0, f64::max);
            let mut t = t_clarabel;
            if cols <= 4 {
                let (exact, _) =
                    exact_lp_min_last(&dense, &b).ok_or(format!("LP round {round}: no vertex"))?;
                deviation = deviation.max((t_clarabel - exact).abs() / exact.abs().max(1e-9));
                t = exact;
            } else if t > 1e-9 {
                // crossover: the vertex of the supporting rows, accepted only when feasible and
                // close to Clarabel's value (an incomplete support gives some other point)
                let support: Vec<usize> = (0..n).filter(|&i| z[i] > 1e-6 * zmax).collect();
                let am = DMatrix::from_fn(support.len(), cols, |r, c| dense[support[r]][c]);
                let bv = DVector::from_fn(support.len(), |r, _| b[support[r]]);
                if let Ok(sol) = am.clone().svd(true, true).solve(&bv, 1e-13) {
                    let res = (&am * &sol - &bv).amax();
                    let feasible = (0..rows).all(|i| {
                        let lhs: f64 = (0..cols).map(|j| dense[i][j] * sol[j]).sum();
                        lhs <= b[i] + 1e-12 * (1.0 + b[i].abs())
                    });
                    if feasible
                        && res <= 1e-12 * (1.0 + bv.amax())
                        && (sol[m] - t).abs() <= 1e-7 * t
                    {
                        t = sol[m];
                    }
                }
            }
            if t <= 1e-10 {
                break;
            }
            t1 = t1.max(t);
            // the engine's documented rounding room on every allowance: t (1 + 1e-9) + 1e-12
            // (it enters the later rounds, and rows can be ill-conditioned enough for it to
            // matter)
            let t_allow = t * (1.0 + 1e-9) + 1e-12;
            let mut any = false;
            for i in 0..nb {
                if in_tier(i) && !fixed[i] && z[i] > 1e-6 * zmax {
                    fixed[i] = true;
                    allow[i] = t_allow;
                    any = true;
                }
            }
            if !any || (0..nb).filter(|i| in_tier(*i)).all(|i| fixed[i]) {
                for i in 0..nb {
                    if in_tier(i) && !fixed[i] {
                        fixed[i] = true;
                        allow[i] = t_allow;
                    }
                }
                break;
            }
        }
    }
    let allowance: Vec<f64> = (0..nb).map(|i| w[i] * allow[i]).collect();
    Ok(Lexicographic {
        t1,
        allowance,
        clarabel_lp_deviation: deviation,
    })
}

/// `min x_last  s.t.  G x ≤ h` by enumerating vertices (small dimensions only): the exact
/// LP optimum `(value, supporting rows)`.
pub fn exact_lp_min_last(g: &[Vec<f64>], h: &[f64]) -> Option<(f64, Vec<usize>)> {
    let d = g[0].len();
    // unit rows: the tolerances below are distances
    let norms: Vec<f64> = g
        .iter()
        .map(|r| r.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-300))
        .collect();
    let g: Vec<Vec<f64>> = g
        .iter()
        .zip(&norms)
        .map(|(r, n)| r.iter().map(|x| x / n).collect())
        .collect();
    let h: Vec<f64> = h.iter().zip(&norms).map(|(x, n)| x / n).collect();
    let n = g.len();
    let mut best: Option<(f64, Vec<usize>)> = None;
    let mut idx: Vec<usize> = (0..d).collect();
    loop {
        let a = DMatrix::from_fn(d, d, |r, c| g[idx[r]][c]);
        let b = DVector::from_fn(d, |r, _| h[idx[r]]);
        if a.determinant().abs() > 1e-12
            && let Some(x) = a.clone().lu().solve(&b)
        {
            let ok = (0..n).all(|i| {
                let lhs: f64 = (0..d).map(|j| g[i][j] * x[j]).sum();
                lhs <= h[i] + 1e-11 * (1.0 + h[i].abs())
            });
            if ok && best.as_ref().is_none_or(|(t, _)| x[d - 1] < *t) {
                best = Some((x[d - 1], idx.clone()));
            }
        }
        // next combination
        let mut k = d;
        while k > 0 && idx[k - 1] == n - d + k - 1 {
            k -= 1;
        }
        if k == 0 {
            break;
        }
        idx[k - 1] += 1;
        for j in k..d {
            idx[j] = idx[j - 1] + 1;
        }
    }
    best
}

pub fn dvec<const M: usize>(v: &SVector<f64, M>) -> DVector<f64> {
    DVector::from_column_slice(v.as_slice())
}
