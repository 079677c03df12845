//! What the guidance, navigation and control software knows of the state at one control
//! step: the simulator's report of its true state today (`sc_sim::Simulator::observe`),
//! the estimate of a navigation function tomorrow. Every nominal controller and every
//! safety filter builds its input from it.

use nalgebra::{SVector, Vector3};
use sc_models::quat::{self, Quat};

/// Joint-space vector of the 7-DoF arm (`sc_multibody::Vector7`).
type Vector7 = SVector<f64, 7>;

/// The measured state each subsystem needs, at time `t` (SI units, frames in the names:
/// `_h` Hill frame F_H, `_r` reference frame F_R, `_b` base frame F_B, `_t` target frame F_T).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Control steps since the start.
    pub step: u64,
    /// Mission time [s].
    pub t: f64,
    /// Servicer base origin relative to the target CoM, Hill frame [m] (x_tr of the paper).
    pub r_h: Vector3<f64>,
    /// Its derivative in the rotating Hill frame [m/s].
    pub v_h: Vector3<f64>,
    /// The same relative position in F_R [m].
    pub r_r: Vector3<f64>,
    /// Inertial derivative of `r_r`, in F_R [m/s].
    pub v_r: Vector3<f64>,
    /// `q_HR`: rotates F_R vectors into F_H (R_HR(t) of the paper).
    pub q_hr: Quat,
    /// Angular velocity of F_H w.r.t. inertial space, in F_H [rad/s].
    pub omega_h: Vector3<f64>,
    /// Angular acceleration of F_H w.r.t. inertial space, in F_H [rad/s²].
    pub omega_dot_h: Vector3<f64>,
    /// Mean motion of the target orbit, |ω_H| [rad/s].
    pub mean_motion: f64,
    /// `q_RB`: servicer attitude, rotates F_B vectors into F_R.
    pub q_rb: Quat,
    /// Servicer body rate ω_B [rad/s, F_B].
    pub omega_b: Vector3<f64>,
    /// Joint angles θ [rad] and rates θ̇ [rad/s].
    pub theta: Vector7,
    pub theta_dot: Vector7,
    /// `q_RT`: target attitude, rotates F_T vectors into F_R.
    pub q_rt: Quat,
    /// Target body rate ω_T [rad/s, F_T] and its derivative [rad/s², F_T].
    pub omega_t: Vector3<f64>,
    pub omega_dot_t: Vector3<f64>,
    /// Grasping point relative to the target CoM in F_R [m], and its inertial velocity
    /// [m/s] and acceleration [m/s²] in F_R.
    pub grasp_r: Vector3<f64>,
    pub grasp_v_r: Vector3<f64>,
    pub grasp_a_r: Vector3<f64>,
    /// Grasping point relative to the base origin, in F_B [m].
    pub grasp_b: Vector3<f64>,
    /// End-effector position relative to the base origin, in F_B [m].
    pub ee_b: Vector3<f64>,
    /// End-effector position relative to the target CoM, in F_R [m], and its inertial
    /// velocity in F_R [m/s].
    pub ee_r: Vector3<f64>,
    pub ee_v_r: Vector3<f64>,
    /// Servicer system centre of mass (bus + arm) relative to the target CoM, Hill frame
    /// [m], and its derivative in the rotating Hill frame [m/s]: the point whose motion the
    /// Clohessy–Wiltshire model describes exactly (internal forces of the arm do not move
    /// it), so the translational barriers and the line of sight are measured from it.
    pub com_h: Vector3<f64>,
    pub com_v_h: Vector3<f64>,
    /// The same in F_R [m] with its inertial velocity [m/s].
    pub com_r: Vector3<f64>,
    pub com_v_r: Vector3<f64>,
}

/// The part of the true state every safety barrier depends on (the safety monitor,
/// `sc_cbf::monitor`, evaluates every barrier from it — at the control steps from the
/// simulator's observation, between them from its physics steps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarrierState {
    /// Time [s].
    pub t: f64,
    /// Servicer system CoM relative to the target CoM, in F_R [m].
    pub com_r: Vector3<f64>,
    /// `q_RB`: base attitude, rotates F_B vectors into F_R.
    pub q_rb: Quat,
    /// Base body rate [rad/s, F_B].
    pub omega_b: Vector3<f64>,
    /// Grasping point relative to the target CoM, in F_R [m].
    pub grasp_r: Vector3<f64>,
    /// Joint angles [rad] and rates [rad/s].
    pub theta: Vector7,
    pub theta_dot: Vector7,
    /// Servicer base origin relative to the target CoM, in F_R [m] (where the arm is).
    pub base_r: Vector3<f64>,
    /// `q_RT`: target attitude, rotates F_T vectors into F_R (where its body is).
    pub q_rt: Quat,
}

impl Observation {
    /// What the barriers depend on, at this observation.
    pub fn barrier_state(&self) -> BarrierState {
        BarrierState {
            t: self.t,
            com_r: self.com_r,
            q_rb: self.q_rb,
            omega_b: self.omega_b,
            grasp_r: self.grasp_r,
            theta: self.theta,
            theta_dot: self.theta_dot,
            base_r: self.r_r,
            q_rt: self.q_rt,
        }
    }

    /// Distance end-effector ↔ grasping point [m].
    pub fn grasp_distance(&self) -> f64 {
        (self.ee_r - self.grasp_r).norm()
    }

    /// Relative speed end-effector ↔ grasping point [m/s].
    pub fn grasp_speed(&self) -> f64 {
        (self.ee_v_r - self.grasp_v_r).norm()
    }

    /// The grasping point relative to the base origin in F_B, `R_RB^T (grasp_r − r_r)`,
    /// from the attitude `q_RB`, the base position `r_r` and the grasping point `grasp_r`
    /// (both relative to the target CoM in F_R) — what `sc_sim::Simulator::observe` reports as
    /// `grasp_b`, so records rebuilt from telemetry get the same bits.
    pub fn grasp_in_base(q_rb: &Quat, r_r: &Vector3<f64>, grasp_r: &Vector3<f64>) -> Vector3<f64> {
        quat::to_matrix(q_rb).transpose() * (grasp_r - r_r)
    }

    /// Rate-synchronisation error ω_B − R_BT ω_T [rad/s, F_B].
    pub fn sync_error(&self) -> Vector3<f64> {
        let r_bt = quat::to_matrix(&quat::mul(&quat::conj(&self.q_rb), &self.q_rt));
        self.omega_b - r_bt * self.omega_t
    }
}
