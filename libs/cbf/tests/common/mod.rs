//! Shared fixtures of the sc-cbf integration tests: the default scenario, the servicer
//! model, realistic filter inputs built from the model (the way `sc-mission` builds them —
//! replicated here, sc-mission is not a dependency), deterministic random numbers and an
//! independent QP toolbox (KKT multipliers, brute-force active sets, Clarabel references).
#![allow(dead_code)]

use nalgebra::{DMatrix, DVector, SMatrix, SVector, Vector3, Vector6};
use sc_cbf::attitude::{tidal_acceleration, xi_att_from_force};
use sc_cbf::barrier::Row;
use sc_cbf::common::NOMINAL_RANGE;
use sc_cbf::robotic::{Vector7, robotic_input_from_model};
use sc_cbf::{
    AttitudeInput, FilterOutput, FilterStatus, QpDump, RoboticInput, TranslationalInput, faults,
};
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
    let (grasp_r, grasp_v_r, _, omega_t) = grasp_at(s, 0.0);
    (x.grasp_r, x.grasp_v_r, x.target_spin) = (grasp_r, grasp_v_r, omega_t.norm());
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

// ------------------------------------------------------------------ filter cases and QP checks
// ------------------------------------------------------------------ cases

/// States near the corridor wall or the CAZ, moving towards the boundary, with random
/// nominal forces up to 1.5 F.
pub fn tr_cases(seed: u64, count: usize) -> Vec<(TranslationalInput, Vector3<f64>)> {
    let s = scenario();
    let fmax = s.limits.force_max_n;
    let mut rng = Lcg(seed);
    (0..count)
        .map(|k| {
            let ang = (3.8 + 1.3 * rng.next()).to_radians();
            let phi = std::f64::consts::PI * rng.next();
            let dir = Vector3::new(-ang.cos(), ang.sin() * phi.cos(), ang.sin() * phi.sin());
            let dist = if k % 2 == 0 {
                4.5 + 3.0 * rng.next()
            } else {
                2.0 + 0.3 * rng.next()
            };
            let out = Vector3::new(0.0, phi.cos(), phi.sin());
            let v = -dir * (0.03 * (1.0 + rng.next()))
                + out * (0.004 * (1.0 + rng.next()))
                + rng.v3(0.003);
            let x = tr_input(&s, dir * dist, v, rng.unit_quat(), rng.v3(0.1));
            (x, rng.v3(1.5 * fmax))
        })
        .collect()
}

/// Pointing errors of 2–5° (the cone is 5°), body rates up to 0.06 rad/s per axis, random
/// arm states, upstream forces and nominal torques up to 1.5 T (many of these states are
/// outside the braking-safe set: relaxed).
pub fn att_cases(seed: u64, count: usize) -> Vec<(AttitudeInput, Vector3<f64>)> {
    let s = scenario();
    let robot = robot();
    let tmax = s.limits.torque_max_nm;
    let mut rng = Lcg(seed);
    (0..count)
        .map(|_| {
            let com = Vector3::new(-2.8, 0.0, 0.0) + rng.v3(0.3);
            let t = 40.0 * (1.0 + rng.next());
            let st = ServicerState {
                theta: theta_inside(&s, &mut rng, 0.1),
                theta_dot: rng.v7(0.1),
                omega_b: rng.v3(0.06),
                q_rb: pointing(
                    &s,
                    &com,
                    t,
                    &rng.v3(1.0),
                    (3.5 + 1.5 * rng.next()).to_radians(),
                ),
                com_r: com,
                com_v_r: rng.v3(0.02),
                t,
                f_b: rng.v3(5.0),
            };
            (att_input(&s, &robot, &st), rng.v3(1.5 * tmax))
        })
        .collect()
}

/// One joint close to a limit and moving towards it, random nominal torques.
pub fn rob_cases(seed: u64, count: usize) -> Vec<(RoboticInput, Vector7)> {
    let s = scenario();
    let robot = robot();
    let mut rng = Lcg(seed);
    (0..count)
        .map(|_| {
            let mut th = theta_inside(&s, &mut rng, 0.15);
            let j = ((rng.next() + 1.0) * 3.5) as usize % 7;
            let up = rng.next() > 0.0;
            let mut thd = rng.v7(0.1);
            if up {
                th[j] = s.safety.robotic.theta_max_rad[j] - 0.05 * (1.2 + rng.next());
                thd[j] = 0.2;
            } else {
                th[j] = s.safety.robotic.theta_min_rad[j] + 0.05 * (1.2 + rng.next());
                thd[j] = -0.2;
            }
            (rob_input(&robot, th, thd), rng.v7(2.5))
        })
        .collect()
}

// ------------------------------------------------------------------ helpers

pub fn assert_output_sane<const M: usize, const N: usize>(o: &FilterOutput<M, N>, bound: f64) {
    assert!(
        o.u.iter().chain(o.actuated.iter()).all(|x| x.is_finite()),
        "{o:?}"
    );
    assert!(
        o.actuated.amax() <= bound,
        "{} > {bound}",
        o.actuated.amax()
    );
}

/// KKT at the solution of `qp` (multipliers of our own): rows hold and the stationarity
/// residual vanishes, both relative to the input bound.
pub fn check_kkt(qp: &Qp, u: &DVector<f64>, bound: f64, what: &str) {
    let (viol, stat, lam) = kkt(qp, u, 1e-9 * bound);
    assert!(
        viol <= 1e-9 * bound,
        "{what}: a row is violated by {viol:e}"
    );
    assert!(
        stat <= 1e-9 * bound,
        "{what}: stationarity residual {stat:e}, λ = {lam:?}"
    );
}

/// The engine's barrier multipliers (`dump.row_duals`) are those of `½‖u − u_nom‖²`:
/// `u − u_nom = Σ λ_i a_i` over all active rows (note: `QpDump`'s documentation states the
/// Clarabel engine's convention `2(u − u_nom) = Σ λ_i a_i − Gᵀμ`). Compared with ours where
/// the multipliers are unique (active rows independent); returns how many positive
/// multipliers were compared.
pub fn check_duals(d: &QpDump, qp: &Qp, u: &DVector<f64>, bound: f64, what: &str) -> usize {
    let (_, _, lam) = kkt(qp, u, 1e-9 * bound);
    let active: Vec<usize> = (0..lam.len()).filter(|&i| lam[i] > 0.0).collect();
    if active.is_empty() {
        return 0;
    }
    let a = nalgebra::DMatrix::from_fn(qp.m(), active.len(), |r, c| qp.a[active[c]][r]);
    if active.len() > qp.m() || a.rank(1e-9) < active.len() {
        return 0;
    }
    for (i, (engine, ours)) in d.row_duals.iter().zip(&lam).enumerate().take(qp.nb) {
        assert!(
            (engine - ours).abs() <= 1e-6 * (ours.abs() + engine.abs()) + 1e-12,
            "{what}: row {i} multiplier {engine} vs KKT {ours}"
        );
    }
    (0..qp.nb).filter(|&i| lam[i] > 0.0).count()
}

pub fn near(a: &DVector<f64>, b: &DVector<f64>, tol: f64) -> bool {
    (a - b).amax() <= tol
}

// ------------------------------------------------------------------ relaxed problem

/// Scales of the nominal along one direction: from a tenth of the bound to the largest
/// nominal still accepted (`NOMINAL_RANGE × bound`).
pub const SCALES: [f64; 5] = [0.1, 1.0, 10.0, 100.0, 0.999 * NOMINAL_RANGE];

/// What the relaxed checks found, for the report line.
#[derive(Default, Debug)]
pub struct RelaxedStats {
    pub cases: usize,
    /// Commands compared with Clarabel's projection, and the largest distance to it
    /// relative to `bound + ‖u_nom‖∞`.
    pub compared: usize,
    pub worst: f64,
    /// Largest relative deviation of Clarabel's LP values from the exact ones.
    pub lp_deviation: f64,
}

/// The relaxed command against the lexicographic LPs (Clarabel; exact vertices for ≤ 3
/// inputs) + Clarabel's projection, for nominals of every magnitude along `dir`: `t*` is
/// the same bits for all of them and equals the reference's; the command is the
/// projection of the nominal onto the rows with the reference's allowances (KKT with
/// multipliers of our own, and Clarabel's own solution where it resolves it).
#[allow(clippy::too_many_arguments)] // a test helper: each argument is one axis of the check
pub fn check_relaxed<const M: usize>(
    what: &str,
    bound: f64,
    u_inf: f64,
    rows: &(Vec<Row<M>>, Vec<f64>, Vec<Row<M>>),
    tiers: &[u8],
    dir: &SVector<f64, M>,
    stats: &mut RelaxedStats,
    mut run: impl FnMut(&SVector<f64, M>) -> (SVector<f64, M>, FilterStatus, f64, u32),
) {
    let (barrier, w, hard) = rows;
    let mut t_ref = None;
    stats.cases += 1;
    // the allowances do not depend on the nominal (that is the point): computed once
    let lex = lexicographic_tiered(&Qp::from_rows(dir, barrier, hard), w, tiers)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    stats.lp_deviation = stats.lp_deviation.max(lex.clarabel_lp_deviation);
    for k in SCALES {
        let un = dir * (k * bound / dir.amax());
        let (u, status, t, flags) = run(&un);
        assert_eq!(status, FilterStatus::Relaxed, "{what}: scale {k}");
        assert_ne!(flags & faults::QP_INFEASIBLE_RELAXED, 0);
        assert!(t > 0.0);
        // the allowance cannot be bought: t* is the same for every nominal, bit for bit
        match t_ref {
            None => t_ref = Some(t),
            Some(t0) => assert_eq!(
                t.to_bits(),
                f64::to_bits(t0),
                "{what}: t* {t} at scale {k} vs {t0}"
            ),
        }
        let qp = Qp::from_rows(&un, barrier, hard);
        let t_tol = if M <= 3 { 1e-9 } else { 1e-6 };
        assert!(
            (t - lex.t1).abs() <= t_tol * lex.t1,
            "{what}: t* {t} vs reference {}",
            lex.t1
        );
        // the projection onto the relaxed rows, to 1e-7 of the problem's scale (the rows'
        // gains differ by orders of magnitude: the allowances of later rounds are only as
        // exact as the earlier rows' positions)
        let u = dvec(&u);
        let scale = bound + un.amax();
        let (viol, stat, _) = kkt(&qp.relaxed(&lex.allowance), &u, 1e-7 * scale);
        assert!(
            viol <= 1e-7 * scale && stat <= 1e-7 * scale,
            "{what} scale {k}: KKT violation {viol:e}, stationarity {stat:e}"
        );
        let relaxed = qp.relaxed(&lex.allowance);
        let resolved = clarabel(&relaxed, u_inf).filter(|u_cl| {
            // a reference that breaks the rows itself (interior-point tolerance on an
            // ill-conditioned problem) is not one
            let (v, st, _) = kkt(&relaxed, u_cl, 1e-7 * scale);
            v <= 1e-9 * scale && st <= 1e-7 * scale
        });
        if let Some(u_cl) = resolved {
            stats.compared += 1;
            let err = (&u - &u_cl).amax() / scale;
            stats.worst = stats.worst.max(err);
            assert!(err <= 1e-6, "{what} scale {k}: {u} vs Clarabel {u_cl}");
        }
        // no barrier row is violated by more than t* of its weight, every hard row holds
        let us = SVector::<f64, M>::from_column_slice(u.as_slice());
        for (i, r) in barrier.iter().enumerate() {
            assert!(
                r.phi(&us) >= -w[i] * t * (1.0 + 1e-6) - 1e-9 * bound,
                "{what}: row {i}"
            );
        }
        for r in hard {
            assert!(r.phi(&us) >= -1e-12 * scale);
        }
    }
}

/// A nominal, missing one time in ten.
pub fn maybe<const M: usize>(rng: &mut Lcg, u: SVector<f64, M>) -> Option<SVector<f64, M>> {
    (rng.next() > -0.8).then_some(u)
}

/// A robotic input near the start (the nominal is often feasible) or anywhere inside the
/// limits, moving; its nominal near the holding torque or anywhere, missing one time in
/// ten.
pub fn rob_draw(rng: &mut Lcg) -> (RoboticInput, Option<Vector7>) {
    let s = scenario();
    let robot = robot();
    let x = if rng.next() > 0.0 {
        rob_input(&robot, theta0(&s) + rng.v7(1e-3), rng.v7(1e-3))
    } else {
        rob_input(&robot, theta_inside(&s, rng, 0.0), rng.v7(0.3))
    };
    let hold = -(x.m_eff * (x.drift + x.xi));
    let k = if rng.next() > 0.0 { 1e-3 } else { 1.5 };
    let u = hold + rng.v7(k * s.limits.joint_torque_max_nm);
    (x, maybe(rng, u))
}
