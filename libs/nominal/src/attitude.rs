//! Nominal attitude controller: boresight pointing at the grasping point and, in the
//! synchronisation phase, angular-rate synchronisation with the tumbling target
//! (paper, Sec. "Concept of Operations", phase II, and Sec. "Nominal Controllers").
//!
//! The paper uses an attitude MPC [Stadler2026] with its constraints removed
//! ([`AttitudeLaw::Mpc`], [`crate::attitude_mpc`]); the feedback acts on the pointing and
//! rate errors defined here, with gyroscopic and reference-rate feed-forward,
//! ```text
//! τ_B = u(φ ê, ω_B − ω_ref) + ω_B × (I ω_B) + I ω̇_ref ,
//! ```
//! where `u = K_x [−φ ê; ω_B − ω_ref]` for the MPC and, for the simpler geometric PD
//! ([`AttitudeLaw::Pd`]), `u = k_p φ ê + k_ω (ω_ref − ω_B)`.
//! * `φ ê` (F_B): the smallest rotation that turns the boresight `d_B` onto the
//!   line of sight `s_B = R_BR s_R` (paper, eq. of `s_R(t)`), `ê ∥ d_B × s_B`,
//!   `φ = ∠(d_B, s_B)`; the rotation about the boresight is left free.
//! * **point** mode: `ω_ref` is the inertial rate of the line of sight,
//!   `ω_LOS = s_R × (v_G,R − v_R) / ρ` expressed in F_B, and `k_ω = k_d`.
//! * **point and sync** mode: `ω_ref = R_BT ω_T` (the target's rate expressed in
//!   F_B), and `k_ω = k_sync`. `ω̇_ref = −ω_B × ω_ref + R_BT ω̇_T` (torque-free
//!   target, Euler's equation with the target inertia).
//! * **gripper alignment** (point and sync, optional, [`AttitudeController::with_alignment`]):
//!   the rotation about the boresight is no longer free — the gripper axis `g_B` is turned
//!   onto the grasping fixture's axis `a_B = R_BT a_T`, both projected on the plane normal
//!   to the boresight, by adding `ψ d_B` to the pointing error, with `ψ` the signed angle
//!   from `g⊥` to `a⊥` about `d_B`. The fixture is a bar, so `a` and `−a` are the same and
//!   `ψ ∈ (−π/2, π/2]`. Once aligned the servicer turns rigidly with the target and the
//!   fixture stays where the arm expects it; until then the catch-up in roll comes on top
//!   of the target's rate.
//!
//! The law is deliberately **unaware of the line-of-sight cone** (β_ATT) and of the
//! angular-rate limits: with the servicer off the target's spin axis, the target
//! rate is not consistent with keeping the grasping point on the boresight, and the
//! stiff rate loop transiently drags the boresight out of the cone at the switch to
//! synchronisation, which the attitude safety filter must prevent. `τ_B` [N m] is
//! **not saturated**.

use crate::attitude_mpc::AttitudeMpc;
use nalgebra::Matrix3;
use sc_models::quat::{self, Quat};
use sc_models::{Mat3, Vec3};

/// Which reference the attitude controller tracks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AttitudeTask {
    /// Boresight on the grasping point, rate reference = line-of-sight rate.
    Point,
    /// Boresight on the grasping point, rate reference = target rate.
    PointAndSync,
}

/// The feedback law of [`AttitudeController`].
#[derive(Debug, Clone, PartialEq)]
pub enum AttitudeLaw {
    /// Geometric PD with the gains below.
    Pd(AttitudeGains),
    /// The unconstrained condensed MPC (same gain in both tasks).
    Mpc(Box<AttitudeMpc>),
}

/// Gains of the PD law ([`AttitudeLaw::Pd`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeGains {
    /// `k_p` [N m/rad].
    pub kp: f64,
    /// `k_d`, rate gain in point mode [N m s/rad].
    pub kd: f64,
    /// `k_sync`, rate gain in sync mode [N m s/rad].
    pub k_sync: f64,
}

/// Observation needed by the attitude controller. SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeInput {
    /// `q_RB`: servicer attitude, rotates F_B vectors into F_R.
    pub q_rb: Quat,
    /// `ω_B`: servicer angular velocity w.r.t. F_R (= inertial), in F_B [rad/s].
    pub omega_b: Vec3,
    /// Servicer inertia about its centre of mass, in F_B [kg m²].
    pub inertia_b: Mat3,
    /// `r_R`: servicer base origin w.r.t. the target CoM, in F_R [m].
    pub r_r: Vec3,
    /// `v_R = ṙ_R` in F_R [m/s].
    pub v_r: Vec3,
    /// Grasping point w.r.t. the target CoM, `R_RT p_G,T`, in F_R [m].
    pub grasp_r: Vec3,
    /// Its time derivative in F_R [m/s].
    pub grasp_vel_r: Vec3,
    /// `q_RT`: target attitude, rotates F_T vectors into F_R.
    pub q_rt: Quat,
    /// `ω_T`: target angular velocity, in F_T [rad/s].
    pub omega_t: Vec3,
}

/// Result of one attitude step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeCommand {
    /// Nominal torque `τ_B,nom` in F_B [N m], unsaturated. Zero when `valid` is false.
    pub tau_b: Vec3,
    /// Angle between boresight and line of sight [rad].
    pub pointing_error_rad: f64,
    /// `ω_B − ω_ref` in F_B [rad/s].
    pub rate_error: Vec3,
    /// False on non-finite input, a non-normalisable quaternion or a degenerate
    /// line of sight (grasping point at the base origin); the torque is then zero.
    pub valid: bool,
}

impl AttitudeCommand {
    fn invalid() -> Self {
        Self {
            tau_b: Vec3::zeros(),
            pointing_error_rad: 0.0,
            rate_error: Vec3::zeros(),
            valid: false,
        }
    }
}

/// Pointing / rate-synchronisation law (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct AttitudeController {
    law: AttitudeLaw,
    /// Boresight `d_B` (unit, F_B).
    boresight: Vec3,
    /// Target inertia and its inverse (F_T), for `ω̇_T`; `None` ⇒ `ω̇_T = 0`.
    target_inertia: Option<(Mat3, Mat3)>,
    /// Gripper axis `g_B` (unit, F_B) and fixture axis `a_T` (unit, F_T) aligned in sync
    /// mode; `None`: the rotation about the boresight is left free.
    alignment: Option<(Vec3, Vec3)>,
}

impl AttitudeController {
    /// `boresight` is normalised; `target_inertia` (F_T, kg m²) is used for the
    /// feed-forward of the target's torque-free angular acceleration (ignored if
    /// not invertible). Returns `None` on non-finite gains or a zero boresight.
    pub fn new(
        gains: AttitudeGains,
        boresight: Vec3,
        target_inertia: Option<Mat3>,
    ) -> Option<Self> {
        Self::with_law(AttitudeLaw::Pd(gains), boresight, target_inertia)
    }

    /// As [`Self::new`], with either feedback law.
    pub fn with_law(
        law: AttitudeLaw,
        boresight: Vec3,
        target_inertia: Option<Mat3>,
    ) -> Option<Self> {
        let ok = match &law {
            AttitudeLaw::Pd(g) => [g.kp, g.kd, g.k_sync]
                .iter()
                .all(|g| g.is_finite() && *g >= 0.0),
            AttitudeLaw::Mpc(_) => true,
        };
        let n = boresight.norm();
        if !ok || !n.is_finite() || n < 1e-9 {
            return None;
        }
        let target_inertia = target_inertia.and_then(|i| i.try_inverse().map(|inv| (i, inv)));
        Some(Self {
            law,
            boresight: boresight / n,
            target_inertia,
            alignment: None,
        })
    }

    /// Also aligns the gripper axis `gripper_b` (F_B) with the fixture axis `fixture_t`
    /// (F_T) about the boresight in sync mode (module doc). Both are normalised; `None` if
    /// either is zero, non-finite or parallel to the boresight.
    pub fn with_alignment(mut self, gripper_b: Vec3, fixture_t: Vec3) -> Option<Self> {
        let unit = |v: Vec3| {
            let n = v.norm();
            (n.is_finite() && n > 1e-9).then(|| v / n)
        };
        let (g, a) = (unit(gripper_b)?, unit(fixture_t)?);
        if g.cross(&self.boresight).norm() < 1e-3 {
            return None;
        }
        self.alignment = Some((g, a));
        Some(self)
    }

    /// The feedback law.
    pub fn law(&self) -> &AttitudeLaw {
        &self.law
    }

    /// One control step. Allocation-free; never panics.
    pub fn command(&self, task: AttitudeTask, x: &AttitudeInput) -> AttitudeCommand {
        let fin3 = |v: &Vec3| v.iter().all(|c| c.is_finite());
        if !fin3(&x.omega_b)
            || !fin3(&x.r_r)
            || !fin3(&x.v_r)
            || !fin3(&x.grasp_r)
            || !fin3(&x.grasp_vel_r)
            || !fin3(&x.omega_t)
            || !x.inertia_b.iter().all(|c| c.is_finite())
        {
            return AttitudeCommand::invalid();
        }
        let (Some(q_rb), Some(q_rt)) = (quat::normalized(&x.q_rb), quat::normalized(&x.q_rt))
        else {
            return AttitudeCommand::invalid();
        };
        let r_rb = quat::to_matrix(&q_rb);
        let r_br = r_rb.transpose();
        let los = x.grasp_r - x.r_r;
        let rho = los.norm();
        if rho < 1e-6 {
            return AttitudeCommand::invalid();
        }
        let s_r = los / rho;
        let s_b = r_br * s_r;
        let d = self.boresight;
        let (phi, mut rot_err) = pointing_error(&d, &s_b);
        let w = x.omega_b;
        let (w_ref, w_ref_dot) = match task {
            AttitudeTask::Point => {
                let w_los_r = s_r.cross(&(x.grasp_vel_r - x.v_r)) / rho;
                let w_ref = r_br * w_los_r;
                (w_ref, -w.cross(&w_ref))
            }
            AttitudeTask::PointAndSync => self.sync_reference(x, &r_br, &q_rt),
        };
        if let (AttitudeTask::PointAndSync, Some((g, a_t))) = (task, &self.alignment) {
            let a = r_br * quat::to_matrix(&q_rt) * a_t;
            rot_err += d * roll_to_align(&d, g, &a);
        }
        let rate_error = w - w_ref;
        let feedback = match (&self.law, task) {
            (AttitudeLaw::Pd(g), AttitudeTask::Point) => g.kp * rot_err - g.kd * rate_error,
            (AttitudeLaw::Pd(g), AttitudeTask::PointAndSync) => {
                g.kp * rot_err - g.k_sync * rate_error
            }
            (AttitudeLaw::Mpc(m), _) => m.feedback(&-rot_err, &rate_error),
        };
        let tau = feedback + w.cross(&(x.inertia_b * w)) + x.inertia_b * w_ref_dot;
        if !fin3(&tau) {
            return AttitudeCommand::invalid();
        }
        AttitudeCommand {
            tau_b: tau,
            pointing_error_rad: phi,
            rate_error,
            valid: true,
        }
    }

    /// The reference rate of sync mode, the target's rate in F_B, and its derivative
    /// as seen in F_B (the target's torque-free Euler equation when its inertia is
    /// known, else a constant rate in F_T).
    fn sync_reference(&self, x: &AttitudeInput, r_br: &Matrix3<f64>, q_rt: &Quat) -> (Vec3, Vec3) {
        let w = x.omega_b;
        let r_bt: Matrix3<f64> = r_br * quat::to_matrix(q_rt);
        let w_ref = r_bt * x.omega_t;
        let w_t_dot = match &self.target_inertia {
            Some((it, it_inv)) => it_inv * (-x.omega_t.cross(&(it * x.omega_t))),
            None => Vec3::zeros(),
        };
        (w_ref, -w.cross(&w_ref) + r_bt * w_t_dot)
    }
}

/// The pointing error: the angle `φ` between the boresight `d` and the line of sight
/// `s_b` (both unit, F_B) and the rotation vector `φ·axis` that turns `d` onto `s_b`
/// (about any perpendicular axis when they are opposite).
fn pointing_error(d: &Vec3, s_b: &Vec3) -> (f64, Vec3) {
    let c = d.cross(s_b);
    let sin_phi = c.norm();
    let cos_phi = d.dot(s_b);
    let phi = sin_phi.atan2(cos_phi);
    let axis = if sin_phi > 1e-12 {
        c / sin_phi
    } else if cos_phi > 0.0 {
        Vec3::zeros()
    } else {
        any_perpendicular(d)
    };
    (phi, axis * phi)
}

/// The signed angle `ψ ∈ (−π/2, π/2]` about the unit vector `d` that turns the line of
/// `g` onto the line of `a`, both projected on the plane normal to `d`; 0 if a projection
/// vanishes.
pub fn roll_to_align(d: &Vec3, g: &Vec3, a: &Vec3) -> f64 {
    let gp = g - d * d.dot(g);
    let ap = a - d * d.dot(a);
    if gp.norm() < 1e-9 || ap.norm() < 1e-9 {
        return 0.0;
    }
    let psi = d.dot(&gp.cross(&ap)).atan2(gp.dot(&ap));
    let half = std::f64::consts::FRAC_PI_2;
    if psi > half {
        psi - std::f64::consts::PI
    } else if psi <= -half {
        psi + std::f64::consts::PI
    } else {
        psi
    }
}

/// A unit vector perpendicular to the unit vector `d`.
fn any_perpendicular(d: &Vec3) -> Vec3 {
    let e = if d.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    d.cross(&e).normalize()
}
