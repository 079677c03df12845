//! Nominal robotic controller: joint-space PD computed torque (paper, Sec. "Nominal
//! Controllers", [Morton2025]) towards a damped-least-squares inverse-kinematics
//! solution of the grasping point.
//!
//! ```text
//! τ_M = M(θ) (K_p (θ_goal − θ) + K_d (θ̇_goal − θ̇)) + C(θ, θ̇) θ̇
//! ```
//! with the fixed-base arm model `M(θ) θ̈ + C(θ, θ̇) θ̇ = τ_M` of the paper's robotic
//! subsystem (so the closed loop on the fixed-base model is `ë + K_d ė + K_p e = 0`
//! for a constant goal). `θ̇_goal` is zero in hold mode; in grasp mode it is the DLS
//! joint rate that moves the end effector with the grasping point (relative to the
//! base), a velocity feed-forward that removes the ramp lag of a tumbling grasping
//! point; with `θ̇_goal = 0` the law is exactly `M (K_p e − K_d θ̇) + C θ̇`.
//!
//! The law ignores joint-angle, joint-rate, torque and link–base-collision limits;
//! `τ_M` [N m] is **not saturated** (the robotic safety filter enforces them).

use nalgebra::{Matrix3, Vector3};
use sc_multibody::{Matrix3x7, Robot, Vector7};

/// Gains and IK settings of [`RoboticController`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoboticGains {
    /// `K_p = k_p I` [1/s²].
    pub kp: f64,
    /// `K_d = k_d I` [1/s].
    pub kd: f64,
    /// Maximum number of DLS iterations per IK solve.
    pub ik_iterations: u32,
    /// DLS damping λ [m].
    pub ik_damping: f64,
    /// EE position error that counts as solved [m].
    pub ik_tolerance: f64,
}

/// Outcome of an IK solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkSolution {
    /// Best joint angles found (within the URDF joint limits) [rad]. For an
    /// unreachable point this is the closest configuration found.
    pub theta: Vector7,
    /// Remaining EE position error `|p_E(θ) − p_goal|` [m].
    pub error_m: f64,
    /// Iterations used.
    pub iterations: u32,
    /// `error_m ≤ tolerance`.
    pub converged: bool,
}

/// Result of one robotic step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoboticCommand {
    /// Nominal joint torques `τ_M,nom` [N m], unsaturated. Zero when `valid` is false.
    pub tau_m: Vector7,
    /// Joint-angle goal used [rad].
    pub theta_goal: Vector7,
    /// The IK outcome in grasp mode (`None` in hold mode).
    pub ik: Option<IkSolution>,
    /// False on non-finite input or a singular mass matrix (torque zero).
    pub valid: bool,
}

/// Largest joint step of one DLS iteration [rad]; keeps the linearisation honest.
const IK_MAX_STEP_RAD: f64 = 0.2;

/// Joint-space PD computed-torque controller with DLS IK.
#[derive(Debug, Clone, PartialEq)]
pub struct RoboticController {
    gains: RoboticGains,
    lower: Vector7,
    upper: Vector7,
}

impl RoboticController {
    /// The IK keeps the joints within the robot's URDF limits. Returns `None` on
    /// non-finite or negative gains, `λ ≤ 0` or a non-positive tolerance.
    pub fn new(gains: RoboticGains, robot: &Robot) -> Option<Self> {
        let ok = [gains.kp, gains.kd]
            .iter()
            .all(|g| g.is_finite() && *g >= 0.0)
            && gains.ik_damping.is_finite()
            && gains.ik_damping > 0.0
            && gains.ik_tolerance.is_finite()
            && gains.ik_tolerance > 0.0;
        if !ok {
            return None;
        }
        let (lo, hi, _, _) = robot.joint_limit_arrays();
        Some(Self {
            gains,
            lower: Vector7::from(lo),
            upper: Vector7::from(hi),
        })
    }

    /// The gains.
    pub fn gains(&self) -> &RoboticGains {
        &self.gains
    }

    /// Damped-least-squares IK of the end-effector **position** `p_goal` (base frame
    /// F_B [m]), iterating from `theta0` [rad]:
    /// `Δθ = J_vᵀ (J_v J_vᵀ + λ² I)⁻¹ (p_goal − p_E(θ))`, step clipped to 0.2 rad,
    /// joints clamped to the URDF limits. Returns the best iterate. Never panics; a
    /// non-finite `p_goal`/`theta0` gives `converged = false`, `error_m = ∞` and
    /// `theta = theta0` clamped (or zeros if non-finite).
    pub fn inverse_kinematics(
        &self,
        robot: &Robot,
        p_goal: &Vector3<f64>,
        theta0: &Vector7,
    ) -> IkSolution {
        let lam2 = self.gains.ik_damping * self.gains.ik_damping;
        let start = if theta0.iter().all(|x| x.is_finite()) {
            self.clamp(theta0)
        } else {
            Vector7::zeros()
        };
        if !p_goal.iter().all(|x| x.is_finite()) || !theta0.iter().all(|x| x.is_finite()) {
            return IkSolution {
                theta: start,
                error_m: f64::INFINITY,
                iterations: 0,
                converged: false,
            };
        }
        let mut theta = start;
        let mut best = (f64::INFINITY, theta);
        let mut iterations = 0;
        for it in 0..=self.gains.ik_iterations {
            let kin = robot.kinematics(&theta);
            let e = p_goal - robot.ee_position(&kin);
            let err = e.norm();
            if !err.is_finite() {
                break;
            }
            if err < best.0 {
                best = (err, theta);
            }
            iterations = it;
            if err <= self.gains.ik_tolerance || it == self.gains.ik_iterations {
                break;
            }
            let jv: Matrix3x7 = robot.ee_jacobian(&kin).fixed_rows::<3>(0).into_owned();
            let a: Matrix3<f64> = jv * jv.transpose() + Matrix3::identity() * lam2;
            let Some(y) = a.cholesky().map(|c| c.solve(&e)) else {
                break;
            };
            let mut step: Vector7 = jv.transpose() * y;
            let m = step.amax();
            if m > IK_MAX_STEP_RAD {
                step *= IK_MAX_STEP_RAD / m;
            }
            theta = self.clamp(&(theta + step));
        }
        IkSolution {
            theta: best.1,
            error_m: best.0,
            iterations,
            converged: best.0 <= self.gains.ik_tolerance,
        }
    }

    /// DLS joint rate that gives the EE the velocity `v` (F_B, m/s) at `theta`.
    pub fn dls_rate(&self, robot: &Robot, theta: &Vector7, v: &Vector3<f64>) -> Vector7 {
        let lam2 = self.gains.ik_damping * self.gains.ik_damping;
        let kin = robot.kinematics(theta);
        let jv: Matrix3x7 = robot.ee_jacobian(&kin).fixed_rows::<3>(0).into_owned();
        let a: Matrix3<f64> = jv * jv.transpose() + Matrix3::identity() * lam2;
        match a.cholesky() {
            Some(c) => {
                let r = jv.transpose() * c.solve(v);
                if r.iter().all(|x| x.is_finite()) {
                    r
                } else {
                    Vector7::zeros()
                }
            }
            None => Vector7::zeros(),
        }
    }

    /// Computed torque towards `(theta_goal, theta_dot_goal)` on the fixed-base arm model.
    pub fn computed_torque(
        &self,
        robot: &Robot,
        theta: &Vector7,
        theta_dot: &Vector7,
        theta_goal: &Vector7,
        theta_dot_goal: &Vector7,
    ) -> RoboticCommand {
        let all_fin = |v: &Vector7| v.iter().all(|x| x.is_finite());
        let invalid = RoboticCommand {
            tau_m: Vector7::zeros(),
            theta_goal: *theta_goal,
            ik: None,
            valid: false,
        };
        if !all_fin(theta)
            || !all_fin(theta_dot)
            || !all_fin(theta_goal)
            || !all_fin(theta_dot_goal)
        {
            return invalid;
        }
        let m = robot.arm_mass_matrix(theta);
        let c = robot.arm_coriolis(theta, theta_dot);
        let acc =
            (theta_goal - theta) * self.gains.kp + (theta_dot_goal - theta_dot) * self.gains.kd;
        let tau = m * acc + c;
        if !all_fin(&tau) {
            return invalid;
        }
        RoboticCommand {
            tau_m: tau,
            theta_goal: *theta_goal,
            ik: None,
            valid: true,
        }
    }

    fn clamp(&self, theta: &Vector7) -> Vector7 {
        Vector7::from_fn(|i, _| theta[i].clamp(self.lower[i], self.upper[i]))
    }
}
