//! The robotic filter's rows that keep the arm off the target's body (issue #26 item 5;
//! beyond the paper, which covers only the arm against its own base), and the sample's
//! prediction its verification checks them on.
//!
//! Per arm sphere `i` (centre `p_i,B(θ)` in F_B) against the nearest keep-out sphere `k`
//! of the target (`c_k,T` in F_T, [`crate::arm_target`]), in F_R with the system CoM
//! `r_c` (relative to the target's CoM) and `q_i = p_i,B − c_B(θ)` (`c_B` the system CoM
//! in F_B):
//!
//! ```text
//! d   = r_c + R_RB q_i − R_RT c_k,T,           h = ‖d‖² − (ρ_i + ρ_k)²        [m²]
//! ḋ   = v_c + R_RB (ω_B × q_i + (J_i − J_c) θ̇) − R_RT (ω_T × c_k,T)
//! d̈   = f_R/m + R_RB (ω̇_B × q_i + ω_B × (ω_B × q_i) + 2 ω_B × (J_i − J_c) θ̇
//!            + (J_i − J_c) θ̈ + J̇_i θ̇ − J̇_c θ̇) − R_RT (ω̇_T × c + ω_T × (ω_T × c))
//! ḧ   = 2‖ḋ‖² + 2 dᵀ d̈,   θ̈ = A τ + b + ξ,   ω̇_B = ω̇_B,0 + Q τ
//! ```
//!
//! so `∂ḧ/∂τ = 2 (R_RB ((J_i − J_c) A − [q_i]_× Q))ᵀ d`: the arm moves its spheres both
//! through its joints and through the base's reaction; the system CoM moves only under the
//! upstream safe force (internal forces do not move it). The target's tumble and the base's
//! motion under the upstream commands are the known coupling.
//!
//! Several keep-out spheres: the row is the smooth minimum of the per-sphere barriers
//! ([`soft_min`]), `s = −ln(Σ_k e^{−κ h_k})/κ ≤ min_k h_k` with
//! `ṡ = Σ w_k ḣ_k`, `s̈ = Σ w_k ḧ_k − κ Σ w_k (ḣ_k − ṡ)²`, `w_k = e^{−κ h_k} / Σ_j e^{−κ h_j}`
//! (`κ` [1/m²], [`TargetBody::sharpness`]): one barrier per arm sphere whose gradient
//! pushes away from every keep-out sphere it is near, and `s ≥ 0` keeps every `h_k ≥ 0`.
//! The verification checks (C1) and (C2) on `s` itself. With one sphere `s` is that
//! sphere's barrier, bit for bit.

use crate::arm_target::TargetBody;
use crate::barrier::RelDegTwo;
use crate::robotic::{Matrix3x7, NJ, NS, RoboticInput, SphereTerms, Vector7};
use nalgebra::{Matrix3, Vector3, Vector4};
use sc_core::Observation;
use sc_models::quat::{self, Quat};
use sc_multibody::{Robot, Vector13};
use sc_scenario::{MAX_DECLARED_KEEP_OUT_SPHERES, MAX_KEEP_OUT_SPHERES};

// every sphere a scenario may declare is one the rows combine
const _: () = assert!(MAX_DECLARED_KEEP_OUT_SPHERES <= MAX_KEEP_OUT_SPHERES);

/// Where the servicer and the target are at the sample's start (knowledge, like every
/// other input of the filter).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surroundings {
    /// `q_RB`: base attitude, F_B → F_R.
    pub q_rb: Quat,
    /// System CoM relative to the target's CoM [m] and its inertial velocity [m/s], F_R.
    pub com_r: Vector3<f64>,
    pub com_v_r: Vector3<f64>,
    /// `q_RT`: target attitude, F_T → F_R.
    pub q_rt: Quat,
    /// Target body rate [rad/s] and its derivative [rad/s²], F_T.
    pub omega_t: Vector3<f64>,
    pub omega_dot_t: Vector3<f64>,
    /// Mean motion of the orbit [rad/s]: bounds the differential gravity the prediction
    /// leaves out.
    pub mean_motion: f64,
}

/// Accepted distance of the system CoM from the target [m] and mean motion [rad/s]
/// (beyond them the input is refused: the braking law applies).
pub const MAX_RANGE_M: f64 = 1e5;
pub const MAX_MEAN_MOTION: f64 = 1.0;
/// Where [`Surroundings::far`] puts the target [m].
pub const FAR_M: f64 = 1e3;

impl Surroundings {
    /// From the observation (the estimate with a declared uncertainty).
    pub fn from_observation(o: &Observation) -> Self {
        Self {
            q_rb: o.q_rb,
            com_r: o.com_r,
            com_v_r: o.com_v_r,
            q_rt: o.q_rt,
            omega_t: o.omega_t,
            omega_dot_t: o.omega_dot_t,
            mean_motion: o.mean_motion,
        }
    }

    /// The target [`FAR_M`] away at rest, everything aligned: what the verification
    /// integrates the base with when no target is known (the rows then read a constant).
    pub fn far() -> Self {
        Self {
            q_rb: [1.0, 0.0, 0.0, 0.0],
            com_r: Vector3::new(FAR_M, 0.0, 0.0),
            com_v_r: Vector3::zeros(),
            q_rt: [1.0, 0.0, 0.0, 0.0],
            omega_t: Vector3::zeros(),
            omega_dot_t: Vector3::zeros(),
            mean_motion: 0.0,
        }
    }

    /// Finite, unit attitudes (to 1e-6), within the accepted ranges.
    pub fn valid(&self, max_rate: f64, max_accel: f64) -> bool {
        let unit = |q: &Quat| q.iter().all(|v| v.is_finite()) && (quat::norm(q) - 1.0).abs() < 1e-6;
        let within = |v: &Vector3<f64>, m: f64| v.iter().all(|c| c.is_finite() && c.abs() <= m);
        unit(&self.q_rb)
            && unit(&self.q_rt)
            && within(&self.com_r, MAX_RANGE_M)
            && within(&self.com_v_r, MAX_RANGE_M)
            && within(&self.omega_t, max_rate)
            && within(&self.omega_dot_t, max_accel)
            && (0.0..=MAX_MEAN_MOTION).contains(&self.mean_motion)
    }
}

/// `[v]_×`.
fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// A keep-out sphere's centre, velocity and acceleration in F_R at the target's attitude
/// `r_rt`, rate `w` and its derivative `wd` (F_T), with its radius.
fn keep_out(
    c_t: &Vector3<f64>,
    r_rt: &Matrix3<f64>,
    w: &Vector3<f64>,
    wd: &Vector3<f64>,
) -> [Vector3<f64>; 3] {
    [
        r_rt * c_t,
        r_rt * w.cross(c_t),
        r_rt * (wd.cross(c_t) + w.cross(&w.cross(c_t))),
    ]
}

/// The weights `w_k = e^{−κ(h_k − h_min)} / Σ_j e^{−κ(h_j − h_min)}` (written into `w`)
/// and the smooth minimum `s = h_min − ln(Σ_j e^{−κ(h_j − h_min)})/κ` of `h` (module doc),
/// `None` when a value is not finite or there is none. One value is returned as it is.
fn soft_min(h: &[f64], kappa: f64, w: &mut [f64]) -> Option<f64> {
    if h.is_empty() || h.len() > w.len() || h.iter().any(|v| !v.is_finite()) {
        return None;
    }
    if h.len() == 1 {
        w[0] = 1.0;
        return Some(h[0]);
    }
    let min = h.iter().copied().fold(f64::INFINITY, f64::min);
    let mut sum = 0.0;
    for (wk, hk) in w.iter_mut().zip(h) {
        *wk = (-kappa * (hk - min)).exp();
        sum += *wk;
    }
    for wk in w.iter_mut().take(h.len()) {
        *wk /= sum;
    }
    Some(min - sum.ln() / kappa)
}

/// `ṡ = Σ w_k ḣ_k` and the curvature term `κ Σ w_k (ḣ_k − ṡ)²` of `s̈` (module doc).
fn soft_min_rate(w: &[f64], hdot: &[f64], kappa: f64) -> (f64, f64) {
    if hdot.len() == 1 {
        return (hdot[0], 0.0);
    }
    let sdot: f64 = w.iter().zip(hdot).map(|(a, b)| a * b).sum();
    let spread: f64 = w
        .iter()
        .zip(hdot)
        .map(|(a, b)| a * (b - sdot).powi(2))
        .sum();
    (sdot, kappa * spread)
}

/// The row of arm sphere `s` against the keep-out spheres of `body`: their smooth minimum
/// (module doc; with one sphere, its own row).
pub fn link_target(s: &SphereTerms, x: &RoboticInput, body: &TargetBody) -> RelDegTwo<NJ> {
    let far = RelDegTwo {
        h: FAR_M * FAR_M,
        hdot: 0.0,
        hddot_drift: 0.0,
        hddot_u: Vector7::zeros(),
    };
    let Some(a) = &x.around else {
        // no target known (an input from the model alone): a constant far value
        return far;
    };
    let r_rb = quat::to_matrix(&a.q_rb);
    let r_rt = quat::to_matrix(&a.q_rt);
    let w = &x.omega_b;
    let jr: Matrix3x7 = s.jacobian - x.com.jacobian;
    let q = s.center - x.com.position;
    let v = jr * x.theta_dot;
    let p = a.com_r + r_rb * q;
    let pdot = a.com_v_r + r_rb * (w.cross(&q) + v);
    let rel0 = jr * (x.drift + x.xi) + s.jdot_qdot - x.com.jdot_qdot;
    let inner = x.omega_dot_b0.cross(&q) + w.cross(&w.cross(&q)) + w.cross(&v) * 2.0 + rel0;
    let pdd0 = r_rb * (x.force_b / x.total_mass + inner);
    let g: Matrix3x7 = r_rb * (jr * x.a - skew(&q) * x.reaction);
    let mut rows = [far; MAX_KEEP_OUT_SPHERES];
    let n = body.spheres().len().min(MAX_KEEP_OUT_SPHERES);
    for (row, sp) in rows.iter_mut().zip(body.spheres()) {
        let [c, cdot, cdd] = keep_out(
            &Vector3::from(sp.center_m),
            &r_rt,
            &a.omega_t,
            &a.omega_dot_t,
        );
        let d = p - c;
        let dd = pdot - cdot;
        let rr = s.radius + sp.radius_m;
        *row = RelDegTwo {
            h: d.dot(&d) - rr * rr,
            hdot: 2.0 * d.dot(&dd),
            hddot_drift: 2.0 * dd.dot(&dd) + 2.0 * d.dot(&(pdd0 - cdd)),
            hddot_u: g.transpose() * d * 2.0,
        };
    }
    combine(&rows[..n], body.sharpness())
}

/// The smooth minimum of the per-sphere rows (module doc): one row as it is, none the
/// target far away, a value that is not finite a non-finite row (which the filter refuses).
fn combine(rows: &[RelDegTwo<NJ>], kappa: f64) -> RelDegTwo<NJ> {
    match rows {
        [] => RelDegTwo {
            h: FAR_M * FAR_M,
            hdot: 0.0,
            hddot_drift: 0.0,
            hddot_u: Vector7::zeros(),
        },
        [one] => *one,
        _ => {
            let n = rows.len().min(MAX_KEEP_OUT_SPHERES);
            let (mut h, mut hdot) = ([0.0; MAX_KEEP_OUT_SPHERES], [0.0; MAX_KEEP_OUT_SPHERES]);
            for (k, r) in rows.iter().take(n).enumerate() {
                (h[k], hdot[k]) = (r.h, r.hdot);
            }
            let mut w = [0.0; MAX_KEEP_OUT_SPHERES];
            let Some(sv) = soft_min(&h[..n], kappa, &mut w) else {
                return RelDegTwo {
                    h: f64::NAN,
                    ..rows[0]
                };
            };
            let (sdot, curvature) = soft_min_rate(&w[..n], &hdot[..n], kappa);
            let mut out = RelDegTwo {
                h: sv,
                hdot: sdot,
                hddot_drift: -curvature,
                hddot_u: Vector7::zeros(),
            };
            for (wk, r) in w.iter().zip(rows) {
                out.hddot_drift += wk * r.hddot_drift;
                out.hddot_u += r.hddot_u * *wk;
            }
            out
        }
    }
}

/// The servicer's state the verification integrates: the joints, the base's rate and
/// attitude, and the system CoM relative to the target's (F_R).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sampled {
    pub theta: Vector7,
    pub theta_dot: Vector7,
    pub omega_b: Vector3<f64>,
    pub q_rb: Vector4<f64>,
    pub com_r: Vector3<f64>,
    pub com_v_r: Vector3<f64>,
}

impl Sampled {
    pub fn start(x: &RoboticInput, around: &Surroundings) -> Self {
        let q = around.q_rb;
        Self {
            theta: x.theta,
            theta_dot: x.theta_dot,
            omega_b: x.omega_b,
            q_rb: Vector4::new(q[0], q[1], q[2], q[3]),
            com_r: around.com_r,
            com_v_r: around.com_v_r,
        }
    }

    pub fn q(&self) -> Quat {
        [self.q_rb[0], self.q_rb[1], self.q_rb[2], self.q_rb[3]]
    }
}

/// One RK4 step of [`Sampled`] under the held input `u` ([f_B; τ_B; τ_M]): the joints and
/// the base's rate exactly as [`crate::robotic::rk4_internal`] (the same arithmetic, so
/// the same bits), the attitude by its kinematics and the CoM under `f_R = R_RB f_B`
/// (`m` the servicer's mass) — the differential gravity left out and bounded by
/// [`gravity_margin`]. The attitude is renormalised after the step, as the simulator does.
pub(crate) fn rk4_sampled(
    robot: &Robot,
    st: &Sampled,
    u: &Vector13,
    m: f64,
    h: f64,
) -> Option<Sampled> {
    let force: Vector3<f64> = u.fixed_rows::<3>(0).into();
    let f = |s: &Sampled| -> Option<Sampled> {
        let a = robot.forward_dynamics_sim(&s.theta, &s.omega_b, &s.theta_dot, u)?;
        let q = s.q();
        let qd = quat::kinematics(&q, &s.omega_b);
        Some(Sampled {
            theta: s.theta_dot,
            theta_dot: a.fixed_rows::<NJ>(6).into(),
            omega_b: a.fixed_rows::<3>(3).into(),
            q_rb: Vector4::new(qd[0], qd[1], qd[2], qd[3]),
            com_r: s.com_v_r,
            com_v_r: quat::to_matrix(&q) * force / m,
        })
    };
    let add = |s: &Sampled, k: &Sampled, c: f64| Sampled {
        theta: s.theta + k.theta * c,
        theta_dot: s.theta_dot + k.theta_dot * c,
        omega_b: s.omega_b + k.omega_b * c,
        q_rb: s.q_rb + k.q_rb * c,
        com_r: s.com_r + k.com_r * c,
        com_v_r: s.com_v_r + k.com_v_r * c,
    };
    let k1 = f(st)?;
    let k2 = f(&add(st, &k1, h / 2.0))?;
    let k3 = f(&add(st, &k2, h / 2.0))?;
    let k4 = f(&add(st, &k3, h))?;
    let mut y = Sampled {
        theta: st.theta + (k1.theta + k2.theta * 2.0 + k3.theta * 2.0 + k4.theta) * (h / 6.0),
        theta_dot: st.theta_dot
            + (k1.theta_dot + k2.theta_dot * 2.0 + k3.theta_dot * 2.0 + k4.theta_dot) * (h / 6.0),
        omega_b: st.omega_b
            + (k1.omega_b + k2.omega_b * 2.0 + k3.omega_b * 2.0 + k4.omega_b) * (h / 6.0),
        q_rb: st.q_rb + (k1.q_rb + k2.q_rb * 2.0 + k3.q_rb * 2.0 + k4.q_rb) * (h / 6.0),
        com_r: st.com_r + (k1.com_r + k2.com_r * 2.0 + k3.com_r * 2.0 + k4.com_r) * (h / 6.0),
        com_v_r: st.com_v_r
            + (k1.com_v_r + k2.com_v_r * 2.0 + k3.com_v_r * 2.0 + k4.com_v_r) * (h / 6.0),
    };
    let n = y.q_rb.norm();
    y.q_rb /= n;
    let finite = y
        .theta
        .iter()
        .chain(y.theta_dot.iter())
        .chain(y.omega_b.iter())
        .all(|v| v.is_finite())
        && y.q_rb
            .iter()
            .chain(y.com_r.iter())
            .chain(y.com_v_r.iter())
            .all(|v| v.is_finite());
    finite.then_some(y)
}

/// The target's attitude and rate over the sample: torque-free (Euler's equations with
/// the declared inertia), RK4 at the physics step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TargetMotion {
    pub q_rt: Vector4<f64>,
    pub omega_t: Vector3<f64>,
}

impl TargetMotion {
    pub fn start(a: &Surroundings) -> Self {
        let q = a.q_rt;
        Self {
            q_rt: Vector4::new(q[0], q[1], q[2], q[3]),
            omega_t: a.omega_t,
        }
    }

    pub fn step(&self, inertia: &Matrix3<f64>, inertia_inv: &Matrix3<f64>, h: f64) -> Self {
        let f = |s: &TargetMotion| {
            let q = [s.q_rt[0], s.q_rt[1], s.q_rt[2], s.q_rt[3]];
            let qd = quat::kinematics(&q, &s.omega_t);
            let wd =
                sc_models::attitude::euler(inertia, inertia_inv, &s.omega_t, &Vector3::zeros());
            (Vector4::new(qd[0], qd[1], qd[2], qd[3]), wd)
        };
        let add = |s: &TargetMotion, k: &(Vector4<f64>, Vector3<f64>), c: f64| TargetMotion {
            q_rt: s.q_rt + k.0 * c,
            omega_t: s.omega_t + k.1 * c,
        };
        let k1 = f(self);
        let k2 = f(&add(self, &k1, h / 2.0));
        let k3 = f(&add(self, &k2, h / 2.0));
        let k4 = f(&add(self, &k3, h));
        let mut y = TargetMotion {
            q_rt: self.q_rt + (k1.0 + k2.0 * 2.0 + k3.0 * 2.0 + k4.0) * (h / 6.0),
            omega_t: self.omega_t + (k1.1 + k2.1 * 2.0 + k3.1 * 2.0 + k4.1) * (h / 6.0),
        };
        y.q_rt /= y.q_rt.norm();
        y
    }

    /// `R_RT`.
    pub fn rotation(&self) -> Matrix3<f64> {
        quat::to_matrix(&[self.q_rt[0], self.q_rt[1], self.q_rt[2], self.q_rt[3]])
    }
}

/// What the prediction leaves out after `s` seconds [m, m/s]: the differential gravity,
/// at most `3 n² ‖r‖` (the tidal tensor's largest eigenvalue is `2 n²`; the rest covers
/// its higher orders) over the distance the CoM can reach, `‖r‖ ≤ ‖r₀‖ + ‖v₀‖ s + ½ a s²`.
pub(crate) fn gravity_margin(a: &Surroundings, accel: f64, s: f64) -> (f64, f64) {
    let reach = a.com_r.norm() + a.com_v_r.norm() * s + 0.5 * accel * s * s;
    let g = 3.0 * a.mean_motion * a.mean_motion * reach;
    (0.5 * g * s * s, g * s)
}

/// Every arm sphere against the keep-out spheres at one step of the verification
/// ([`along`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Along {
    /// The smooth minimum `s` [m²] and `ṡ` [m²/s] (module doc).
    pub h: [f64; NS],
    pub hdot: [f64; NS],
    /// The spheres' centres [m] and velocities [m/s] in F_R.
    pub pos: [Vector3<f64>; NS],
    pub vel: [Vector3<f64>; NS],
}

/// Every arm sphere's barrier against the keep-out spheres (their smooth minimum) at one
/// step of the verification: the spheres' centres and velocities in F_B (`centers`, `velocities`,
/// `None` radius where a sphere could not be evaluated: its values stay 0), the system
/// CoM's position and velocity in F_B (`com`, `com_v`), the servicer's state `st` and the
/// target's `tm`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn along(
    body: &TargetBody,
    centers: &[Vector3<f64>; NS],
    velocities: &[Vector3<f64>; NS],
    radii: &[Option<f64>; NS],
    com: &Vector3<f64>,
    com_v: &Vector3<f64>,
    st: &Sampled,
    tm: &TargetMotion,
) -> Along {
    let r_rb = quat::to_matrix(&st.q());
    let r_rt = tm.rotation();
    let zero = [Vector3::zeros(); NS];
    let mut out = Along {
        h: [0.0; NS],
        hdot: [0.0; NS],
        pos: zero,
        vel: zero,
    };
    for k in 0..NS {
        let q = centers[k] - com;
        let v = velocities[k] - com_v;
        out.pos[k] = st.com_r + r_rb * q;
        out.vel[k] = st.com_v_r + r_rb * (st.omega_b.cross(&q) + v);
        let Some(radius) = radii[k] else { continue };
        (out.h[k], out.hdot[k]) = clearance(body, &out.pos[k], &out.vel[k], radius, &r_rt, tm);
    }
    out
}

/// The barrier `s` [m²] and `ṡ` [m²/s] (module doc) of an arm sphere at `pos`, `vel` (F_R)
/// with radius `radius` against the keep-out spheres of `body`, the target at attitude
/// `r_rt` turning as `tm`; a value that is not finite is a violation (`−∞`), never a
/// clearance.
fn clearance(
    body: &TargetBody,
    pos: &Vector3<f64>,
    vel: &Vector3<f64>,
    radius: f64,
    r_rt: &Matrix3<f64>,
    tm: &TargetMotion,
) -> (f64, f64) {
    let (mut h, mut hdot) = ([0.0; MAX_KEEP_OUT_SPHERES], [0.0; MAX_KEEP_OUT_SPHERES]);
    let n = body.spheres().len().min(MAX_KEEP_OUT_SPHERES);
    for (j, sp) in body.spheres().iter().take(n).enumerate() {
        let [c, cdot, _] = keep_out(
            &Vector3::from(sp.center_m),
            r_rt,
            &tm.omega_t,
            &Vector3::zeros(),
        );
        let d = pos - c;
        let dd = vel - cdot;
        let rr = radius + sp.radius_m;
        h[j] = d.dot(&d) - rr * rr;
        hdot[j] = 2.0 * d.dot(&dd);
    }
    if n == 0 {
        // no keep-out sphere: the target far away, as the rows read it
        return (FAR_M * FAR_M, 0.0);
    }
    let mut w = [0.0; MAX_KEEP_OUT_SPHERES];
    match soft_min(&h[..n], body.sharpness(), &mut w) {
        Some(sv) => (sv, soft_min_rate(&w[..n], &hdot[..n], body.sharpness()).0),
        None => (f64::NEG_INFINITY, 0.0),
    }
}

/// A lower bound on the barrier `s` and its rate `ṡ` (module doc) of an arm sphere at
/// `pos`, `vel` (F_R) with radius `radius` when its centre may be off by `dc` and its
/// velocity by `dv`. Per keep-out sphere `h_k` lies within `±(2‖d‖dc + dc²)` and `ḣ_k`
/// is at least `a_k = ḣ_k − 2(dc‖ḋ‖ + ‖d‖dv + dc dv)` (as for the link–base rows); `s`
/// grows with every `h_k`, so `s(h − Δ)` bounds it, and `ṡ = Σ w_k ḣ_k ≥ a_max + Σ w̄_k
/// (a_k − a_max)` with `w̄_k` the largest weight `h_k`'s interval and the others' allow
/// (`e^{−κ h_k,low} / (e^{−κ h_k,low} + Σ_{j≠k} e^{−κ h_j,high})`). With one sphere: its
/// `h − Δ` and `a`.
pub(crate) fn lowered(
    body: &TargetBody,
    pos: &Vector3<f64>,
    vel: &Vector3<f64>,
    radius: f64,
    tm: &TargetMotion,
    dc: f64,
    dv: f64,
) -> (f64, f64) {
    let r_rt = tm.rotation();
    let n = body.spheres().len().min(MAX_KEEP_OUT_SPHERES);
    let (mut low, mut high, mut a) = (
        [0.0; MAX_KEEP_OUT_SPHERES],
        [0.0; MAX_KEEP_OUT_SPHERES],
        [0.0; MAX_KEEP_OUT_SPHERES],
    );
    for (j, sp) in body.spheres().iter().take(n).enumerate() {
        let [c, cdot, _] = keep_out(
            &Vector3::from(sp.center_m),
            &r_rt,
            &tm.omega_t,
            &Vector3::zeros(),
        );
        let d = pos - c;
        let dd = vel - cdot;
        let rr = radius + sp.radius_m;
        let (dn, vn) = (d.norm(), dd.norm());
        let h = d.dot(&d) - rr * rr;
        low[j] = h - (2.0 * dn * dc + dc * dc);
        high[j] = h + (2.0 * dn * dc + dc * dc);
        a[j] = 2.0 * d.dot(&dd) - 2.0 * (dc * vn + dn * dv + dc * dv);
    }
    if n == 0 {
        // no keep-out sphere: the target far away, as the rows read it
        return (FAR_M * FAR_M, 0.0);
    }
    let kappa = body.sharpness();
    let mut w = [0.0; MAX_KEEP_OUT_SPHERES];
    let Some(s_low) = soft_min(&low[..n], kappa, &mut w) else {
        return (f64::NEG_INFINITY, 0.0);
    };
    if n == 1 {
        return (s_low, a[0]);
    }
    let (low, high, a) = (&low[..n], &high[..n], &a[..n]);
    let a_max = a.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let m = low.iter().copied().fold(f64::INFINITY, f64::min);
    let e = |h: f64| (-kappa * (h - m)).exp();
    if !a_max.is_finite() || a.iter().any(|v| !v.is_finite()) {
        return (f64::NEG_INFINITY, 0.0);
    }
    let mut sdot = a_max;
    for j in 0..n {
        let others: f64 = (0..n).filter(|&i| i != j).map(|i| e(high[i])).sum();
        let w_max = e(low[j]) / (e(low[j]) + others);
        sdot += w_max.min(1.0) * (a[j] - a_max);
    }
    (s_low, sdot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robotic::robotic_input_from_model;
    use crate::test_draws::lcg;
    use nalgebra::UnitQuaternion;
    use std::path::Path;

    fn setup() -> (sc_scenario::Scenario, Robot) {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config");
        let s = sc_scenario::Scenario::load(&dir.join("scenario.toml")).unwrap();
        let robot = Robot::from_urdf_file(&dir.join("servicer.urdf")).unwrap();
        (s, robot)
    }

    /// Every arm sphere's `h` against the target at the state `st`, `tm`.
    fn h_at(robot: &Robot, body: &TargetBody, st: &Sampled, tm: &TargetMotion) -> [f64; NS] {
        let kin = robot.kinematics_vel(&st.theta, &st.theta_dot);
        let mut centers = [Vector3::zeros(); NS];
        let mut velocities = [Vector3::zeros(); NS];
        let mut radii = [None; NS];
        for (k, (idx, _)) in robot.arm_spheres().take(NS).enumerate() {
            let sp = robot.sphere_state(&kin, idx).unwrap();
            centers[k] = sp.center;
            velocities[k] = sp.jacobian * st.theta_dot;
            radii[k] = Some(sp.radius);
        }
        let com = robot.com_terms(&kin);
        along(
            body,
            &centers,
            &velocities,
            &radii,
            &com.position,
            &com.velocity,
            st,
            tm,
        )
        .h
    }

    /// The smooth minimum lies at most `ln(K)/κ` below the smallest value, its weights sum
    /// to one, one value comes back as it is, and a value that is not finite is refused.
    #[test]
    fn the_smooth_minimum_is_within_ln_k_over_kappa_below_the_minimum() {
        let mut w = [0.0; MAX_KEEP_OUT_SPHERES];
        assert_eq!(soft_min(&[0.123], 200.0, &mut w), Some(0.123));
        assert_eq!(w[0], 1.0);
        let mut seed = 7u64;
        for _ in 0..500 {
            let n = 2 + (lcg(&mut seed) * (MAX_KEEP_OUT_SPHERES - 1) as f64) as usize;
            let h: Vec<f64> = (0..n).map(|_| 0.05 * lcg(&mut seed) - 0.01).collect();
            let kappa = 1.0 + 1000.0 * lcg(&mut seed);
            let sv = soft_min(&h, kappa, &mut w).unwrap();
            let min = h.iter().copied().fold(f64::INFINITY, f64::min);
            assert!(sv <= min, "{sv} > {min}");
            assert!(
                sv >= min - (n as f64).ln() / kappa - 1e-15,
                "{sv} {min} {n} {kappa}"
            );
            assert!((w[..n].iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
        assert_eq!(soft_min(&[0.1, f64::NAN], 200.0, &mut w), None);
        assert_eq!(soft_min(&[0.1, f64::INFINITY], 200.0, &mut w), None);
        assert_eq!(soft_min(&[], 200.0, &mut w), None);
    }

    /// [`lowered`] bounds `s` and `ṡ` from below for every arm sphere centre within `dc`
    /// and velocity within `dv` of the nominal ones (corners of the balls included), with
    /// several keep-out spheres at sharp and soft `κ`.
    #[test]
    fn lowered_bounds_the_smooth_barrier_for_every_centre_within_the_error() {
        use crate::test_draws::ball;
        let sphere = |c: [f64; 3], r: f64| sc_scenario::TargetSphere {
            center_m: c,
            radius_m: r,
        };
        let spheres = vec![
            sphere([0.0, 0.0, 0.0], 0.45),
            sphere([-0.5, -0.25, 0.0], 0.15),
            sphere([-0.45, 0.0, 0.35], 0.12),
        ];
        let mut seed = 11u64;
        for kappa in [2.0, 200.0, 5000.0] {
            let body = TargetBody::new(spheres.clone(), kappa);
            for _ in 0..300 {
                let pos = Vector3::new(-0.8, 0.0, 0.0) + ball(&mut seed, 0.4);
                let vel = ball(&mut seed, 0.3);
                let radius = 0.03 + 0.05 * lcg(&mut seed);
                let tm = TargetMotion {
                    q_rt: Vector4::new(1.0, 0.0, 0.0, 0.0),
                    omega_t: ball(&mut seed, 0.1),
                };
                let (dc, dv) = (0.02 * lcg(&mut seed), 0.02 * lcg(&mut seed));
                let (s_low, sdot_low) = lowered(&body, &pos, &vel, radius, &tm, dc, dv);
                for _ in 0..20 {
                    let (mut ep, mut ev) = (ball(&mut seed, dc), ball(&mut seed, dv));
                    if lcg(&mut seed) < 0.5 {
                        ep *= dc / ep.norm().max(1e-300);
                        ev *= dv / ev.norm().max(1e-300);
                    }
                    let r_rt = tm.rotation();
                    let (sv, sdot) = clearance(&body, &(pos + ep), &(vel + ev), radius, &r_rt, &tm);
                    assert!(sv >= s_low - 1e-12, "κ {kappa}: s {sv} < {s_low}");
                    assert!(sdot >= sdot_low - 1e-12, "κ {kappa}: ṡ {sdot} < {sdot_low}");
                }
            }
        }
    }

    /// The filter's link–target barriers (from the system CoM) equal the safety monitor's
    /// (from the base origin, written independently), and `base_target` is the base's
    /// zone against the keep-out sphere, at random states with the target tumbling.
    #[test]
    fn the_monitor_and_the_rows_agree_on_the_arm_target_barriers() {
        use crate::monitor::{Monitor, N_FILTERED};
        use sc_core::BarrierState;
        let (s, robot) = setup();
        let robot = std::sync::Arc::new(robot);
        let body = TargetBody::from_scenario(&s);
        let monitor = Monitor::from_scenario(&s, robot.clone());
        let mut seed = 0x9e37_79b9u64;
        let mut r = || 2.0 * lcg(&mut seed) - 1.0;
        for _ in 0..50 {
            let theta =
                Vector7::from(s.servicer.initial_theta_rad) + Vector7::from_fn(|_, _| 0.5 * r());
            let q = |a: f64, b: f64, c: f64| {
                let u = UnitQuaternion::from_euler_angles(a, b, c);
                [u.w, u.i, u.j, u.k]
            };
            let (q_rb, q_rt) = (q(r(), r(), r()), q(r(), r(), r()));
            let com_r = Vector3::new(-1.8 + 0.3 * r(), 0.4 * r(), 0.4 * r());
            let c_b = robot.center_of_mass(&theta);
            let base_r = com_r - quat::to_matrix(&q_rb) * c_b;
            let around = Surroundings {
                q_rb,
                com_r,
                com_v_r: Vector3::zeros(),
                q_rt,
                omega_t: Vector3::zeros(),
                omega_dot_t: Vector3::zeros(),
                mean_motion: 0.0,
            };
            let z = Vector3::zeros();
            let x =
                robotic_input_from_model(&robot, &theta, &Vector7::zeros(), &z, &z, &z).unwrap();
            let x = RoboticInput {
                around: Some(around),
                ..x
            };
            let h = monitor.evaluate(&BarrierState {
                t: 0.0,
                com_r,
                q_rb,
                omega_b: z,
                grasp_r: z,
                theta,
                theta_dot: Vector7::zeros(),
                base_r,
                q_rt,
            });
            let first = N_FILTERED - NS;
            for k in 0..NS {
                let row = link_target(&x.spheres[k], &x, &body);
                let m = h[first + k];
                assert!(
                    (row.h - m).abs() < 1e-12 * (1.0 + m.abs()),
                    "sphere {k}: {} vs {m}",
                    row.h
                );
            }
            let base = robot.base_sphere().unwrap();
            let c = base_r + quat::to_matrix(&q_rb) * base.center;
            let rr = base.radius + s.target.collision_spheres[0].radius_m;
            let centre =
                quat::to_matrix(&q_rt) * Vector3::from(s.target.collision_spheres[0].center_m);
            let want = (c - centre).norm_squared() - rr * rr;
            assert!((h[N_FILTERED] - want).abs() < 1e-12 * (1.0 + want.abs()));
        }
    }

    /// The rows' `h`, `ḣ` and `ḧ = drift + ∂ḧ/∂τ·τ` equal central differences of the
    /// barrier along the motion the verification integrates (the joints, the base's rate
    /// and attitude, the system CoM under the upstream force, the target's torque-free
    /// tumble) under a held command, at states with everything moving: base rotating,
    /// upstream force and torque, arm moving, target tumbling off its axes.
    #[test]
    fn link_target_rows_match_finite_differences() {
        let (s, robot) = setup();
        // the scenario's one sphere, and the bus with an appendage under a soft κ, so
        // that both spheres carry weight and the smooth minimum's curvature term counts
        let bus = s.target.collision_spheres[0];
        let appendage = sc_scenario::TargetSphere {
            center_m: [-1.0, 0.3, 0.0],
            radius_m: 0.3,
        };
        for body in [
            TargetBody::from_scenario(&s),
            TargetBody::new(vec![bus, appendage], 2.0),
        ] {
            rows_match_finite_differences(&s, &robot, &body);
        }
    }

    fn rows_match_finite_differences(s: &sc_scenario::Scenario, robot: &Robot, body: &TargetBody) {
        let inertia = Matrix3::from_row_slice(&s.target.inertia_kg_m2.concat());
        let inertia_inv = inertia.try_inverse().unwrap();
        let mut seed = 0x1234_5678u64;
        let mut r = || 2.0 * lcg(&mut seed) - 1.0;
        for case in 0..20 {
            let theta =
                Vector7::from(s.servicer.initial_theta_rad) + Vector7::from_fn(|_, _| 0.3 * r());
            let theta_dot = Vector7::from_fn(|_, _| 0.2 * r());
            let w = Vector3::new(0.05 * r(), 0.05 * r(), 0.05 * r());
            let f = Vector3::new(5.0 * r(), 5.0 * r(), 5.0 * r());
            let tb = Vector3::new(5.0 * r(), 5.0 * r(), 5.0 * r());
            let tau = Vector7::from_fn(|_, _| 1.5 * r());
            let unit = |a: f64, b: f64, c: f64| {
                let q = UnitQuaternion::from_euler_angles(a, b, c);
                [q.w, q.i, q.j, q.k]
            };
            let omega_t = Vector3::new(-0.1 + 0.03 * r(), 0.03 * r(), 0.03 * r());
            let around = Surroundings {
                q_rb: unit(0.2 * r(), 0.2 * r(), 0.2 * r()),
                com_r: Vector3::new(-2.0 + 0.3 * r(), 0.3 * r(), 0.3 * r()),
                com_v_r: Vector3::new(0.05 * r(), 0.05 * r(), 0.05 * r()),
                q_rt: unit(r(), r(), r()),
                omega_t,
                omega_dot_t: sc_models::attitude::euler(
                    &inertia,
                    &inertia_inv,
                    &omega_t,
                    &Vector3::zeros(),
                ),
                mean_motion: 0.0,
            };
            let x = robotic_input_from_model(robot, &theta, &theta_dot, &w, &f, &tb).unwrap();
            let x = RoboticInput {
                around: Some(around),
                ..x
            };
            let mut u = Vector13::zeros();
            u.fixed_rows_mut::<3>(0).copy_from(&f);
            u.fixed_rows_mut::<3>(3).copy_from(&tb);
            u.fixed_rows_mut::<NJ>(6).copy_from(&tau);
            let dt = 1e-4;
            let start = Sampled::start(&x, &around);
            let tm0 = TargetMotion::start(&around);
            let at = |step: f64| {
                let st = rk4_sampled(robot, &start, &u, x.total_mass, step).unwrap();
                let tm = tm0.step(&inertia, &inertia_inv, step);
                h_at(robot, body, &st, &tm)
            };
            let (hm, h0, hp) = (at(-dt), h_at(robot, body, &start, &tm0), at(dt));
            for k in 0..NS {
                let row = link_target(&x.spheres[k], &x, body);
                let hdot = (hp[k] - hm[k]) / (2.0 * dt);
                let hddot = (hp[k] - 2.0 * h0[k] + hm[k]) / (dt * dt);
                let want = row.hddot_drift + row.hddot_u.dot(&tau);
                assert!(
                    (row.h - h0[k]).abs() < 1e-12 * (1.0 + h0[k].abs()),
                    "case {case} sphere {k}: h"
                );
                assert!(
                    (row.hdot - hdot).abs() < 1e-7 * (1.0 + hdot.abs()),
                    "case {case} sphere {k}: ḣ {} vs {hdot}",
                    row.hdot
                );
                assert!(
                    (want - hddot).abs() < 1e-4 * (1.0 + hddot.abs()),
                    "case {case} sphere {k}: ḧ {want} vs {hddot}"
                );
            }
        }
    }
}
