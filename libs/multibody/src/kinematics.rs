//! Arm kinematics in the servicer BASE frame `F_B` (the base is held fixed): body poses,
//! point and end-effector positions, Jacobians and the drift terms `J̇ θ̇`.
//!
//! Paper: `p_{E,B} = f_FK(θ)`, `ṗ_{E,B} = J_E(θ) θ̇` (robotic subsystem), and the collision
//! sphere centres `p_i(θ)` of the link-base CBF `h_LB,i`.

use nalgebra::{Matrix3, SMatrix, Vector3, Vector6};

use crate::model::Robot;
use crate::spatial::{Transform, axis_angle};
use crate::{Matrix3x7, Matrix6x7, NJ, Vector7};

/// Kinematic state of every body for one `(θ, θ̇)`, all in the base frame.
///
/// Index `k` = body (0 = base, `k` = arm link after joint `k`). Velocities and accelerations are
/// relative to the base (base frame held fixed) and the accelerations are those for `θ̈ = 0`,
/// i.e. the velocity-product terms that give `J̇ θ̇`.
#[derive(Clone, Copy, Debug)]
pub struct Kinematics {
    /// Pose of body `k` in the base frame.
    pub pose: [Transform; NJ + 1],
    /// Joint axes `z_j` in the base frame (unit), joint `j` (0-based) moves body `j + 1`.
    pub axis: [Vector3<f64>; NJ],
    /// Angular velocity of body `k` (rad/s, base frame).
    pub omega: [Vector3<f64>; NJ + 1],
    /// Velocity of the origin of body `k` (m/s, base frame).
    pub vel: [Vector3<f64>; NJ + 1],
    /// Angular acceleration of body `k` at `θ̈ = 0` (rad/s², base frame).
    pub alpha: [Vector3<f64>; NJ + 1],
    /// Classical acceleration of the origin of body `k` at `θ̈ = 0` (m/s², base frame).
    pub acc: [Vector3<f64>; NJ + 1],
}

/// The system centre of mass relative to the base, base frame ([`Robot::com_terms`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ComTerms {
    /// `c(θ)` [m].
    pub position: Vector3<f64>,
    /// `J_c = ∂c/∂θ` [m/rad].
    pub jacobian: Matrix3x7,
    /// `J_c θ̇` [m/s].
    pub velocity: Vector3<f64>,
    /// `J̇_c θ̇` [m/s²].
    pub jdot_qdot: Vector3<f64>,
}

/// Position, Jacobian and drift of a collision-sphere centre (base frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereState {
    /// Body carrying the sphere (0 = base).
    pub link: usize,
    /// Centre `p_i(θ)` in the base frame (m).
    pub center: Vector3<f64>,
    /// Radius `ρ_i` (m).
    pub radius: f64,
    /// `∂p_i/∂θ` (m/rad), base frame.
    pub jacobian: Matrix3x7,
    /// `J̇_i θ̇` (m/s²): acceleration of the centre for `θ̈ = 0`, base frame.
    pub jdot_qdot: Vector3<f64>,
}

impl Robot {
    /// Placement of body `k + 1` in body `k` for joint angle `q` (rad).
    #[inline]
    pub(crate) fn joint_placement(&self, k: usize, q: f64) -> Transform {
        let j = &self.joints[k];
        Transform::new(j.origin.rot * axis_angle(&j.axis, q), j.origin.trans)
    }

    /// Forward kinematics for joint angles `theta` (rad) with `θ̇ = 0`.
    pub fn kinematics(&self, theta: &Vector7) -> Kinematics {
        self.kinematics_vel(theta, &Vector7::zeros())
    }

    /// Forward kinematics with joint rates `theta_dot` (rad/s): poses, body velocities and the
    /// `θ̈ = 0` accelerations, all relative to and expressed in the base frame.
    pub fn kinematics_vel(&self, theta: &Vector7, theta_dot: &Vector7) -> Kinematics {
        let z3 = Vector3::zeros();
        let mut k = Kinematics {
            pose: [Transform::IDENTITY; NJ + 1],
            axis: [z3; NJ],
            omega: [z3; NJ + 1],
            vel: [z3; NJ + 1],
            alpha: [z3; NJ + 1],
            acc: [z3; NJ + 1],
        };
        for i in 0..NJ {
            let pose = k.pose[i].compose(&self.joint_placement(i, theta[i]));
            let z = pose.rot * self.joints[i].axis;
            let r = pose.trans - k.pose[i].trans;
            let (w0, a0) = (k.omega[i], k.alpha[i]);
            let wz = z * theta_dot[i];
            k.pose[i + 1] = pose;
            k.axis[i] = z;
            k.omega[i + 1] = w0 + wz;
            k.vel[i + 1] = k.vel[i] + w0.cross(&r);
            k.alpha[i + 1] = a0 + w0.cross(&wz);
            k.acc[i + 1] = k.acc[i] + a0.cross(&r) + w0.cross(&w0.cross(&r));
        }
        k
    }

    /// Position (base frame, m) of the point `local` (m, body-`link` frame).
    /// Returns `None` for `link > 7`.
    pub fn point_position(
        &self,
        kin: &Kinematics,
        link: usize,
        local: &Vector3<f64>,
    ) -> Option<Vector3<f64>> {
        kin.pose.get(link).map(|p| p.act_point(local))
    }

    /// Linear Jacobian `∂p/∂θ` (3×7, m/rad, base frame) of a point fixed on body `link`.
    /// Columns of joints beyond `link` are zero. `None` for `link > 7`.
    pub fn point_jacobian(
        &self,
        kin: &Kinematics,
        link: usize,
        local: &Vector3<f64>,
    ) -> Option<Matrix3x7> {
        let p = self.point_position(kin, link, local)?;
        let mut j = Matrix3x7::zeros();
        for i in 0..link {
            let col = kin.axis[i].cross(&(p - kin.pose[i + 1].trans));
            j.set_column(i, &col);
        }
        Some(j)
    }

    /// `J̇ θ̇` of a point fixed on body `link` (m/s², base frame): its acceleration for
    /// `θ̈ = 0` at the `θ̇` given to [`Robot::kinematics_vel`]. `None` for `link > 7`.
    pub fn point_jdot_qdot(
        &self,
        kin: &Kinematics,
        link: usize,
        local: &Vector3<f64>,
    ) -> Option<Vector3<f64>> {
        let pose = kin.pose.get(link)?;
        let r = pose.rot * local;
        let w = kin.omega[link];
        Some(kin.acc[link] + kin.alpha[link].cross(&r) + w.cross(&w.cross(&r)))
    }

    /// The servicer's system centre of mass relative to the base (base frame, the base
    /// held fixed) at the kinematic state `kin` of [`Robot::kinematics_vel`]: its position
    /// `c` [m], Jacobian `J_c = ∂c/∂θ` [m/rad], velocity `J_c θ̇` [m/s] and `J̇_c θ̇` [m/s²]
    /// — the mass-weighted sum of every body's CoM point (the base's fixed).
    pub fn com_terms(&self, kin: &Kinematics) -> ComTerms {
        let mut t = ComTerms {
            position: Vector3::zeros(),
            jacobian: Matrix3x7::zeros(),
            velocity: Vector3::zeros(),
            jdot_qdot: Vector3::zeros(),
        };
        for (k, inertia) in self.inertias.iter().enumerate() {
            if inertia.mass <= 0.0 {
                continue;
            }
            let local = inertia.h / inertia.mass;
            let w = inertia.mass / self.total_mass;
            let (Some(p), Some(j), Some(a)) = (
                self.point_position(kin, k, &local),
                self.point_jacobian(kin, k, &local),
                self.point_jdot_qdot(kin, k, &local),
            ) else {
                continue;
            };
            let r = kin.pose[k].rot * local;
            t.position += p * w;
            t.jacobian += j * w;
            t.velocity += (kin.vel[k] + kin.omega[k].cross(&r)) * w;
            t.jdot_qdot += a * w;
        }
        t
    }

    /// The system centre of mass's position [m] and velocity `J_c θ̇` [m/s] relative to the
    /// base (base frame) — [`Robot::com_terms`] without its Jacobians (the same sums, the
    /// same bits), for a caller that needs the motion only.
    pub fn com_motion(&self, kin: &Kinematics) -> (Vector3<f64>, Vector3<f64>) {
        let (mut c, mut v) = (Vector3::zeros(), Vector3::zeros());
        for (k, inertia) in self.inertias.iter().enumerate() {
            if inertia.mass <= 0.0 || k >= kin.pose.len() {
                continue;
            }
            let local = inertia.h / inertia.mass;
            let w = inertia.mass / self.total_mass;
            let r = kin.pose[k].rot * local;
            c += kin.pose[k].act_point(&local) * w;
            v += (kin.vel[k] + kin.omega[k].cross(&r)) * w;
        }
        (c, v)
    }

    /// Pose of the end-effector frame in the base frame.
    pub fn ee_pose(&self, kin: &Kinematics) -> Transform {
        let f = self.ee_frame();
        kin.pose[f.body].compose(&f.placement)
    }

    /// End-effector position `p_{E,B} = f_FK(θ)` (m, base frame).
    pub fn ee_position(&self, kin: &Kinematics) -> Vector3<f64> {
        self.ee_pose(kin).trans
    }

    /// End-effector orientation: rotation matrix from the EE frame to the base frame.
    pub fn ee_rotation(&self, kin: &Kinematics) -> Matrix3<f64> {
        self.ee_pose(kin).rot
    }

    /// Geometric Jacobian `J_E` (6×7) of the end effector in the base frame:
    /// rows `[linear velocity of the EE origin (m/s); angular velocity (rad/s)]` per rad/s.
    pub fn ee_jacobian(&self, kin: &Kinematics) -> Matrix6x7 {
        let f = self.ee_frame();
        let p = self.ee_position(kin);
        let mut j = Matrix6x7::zeros();
        for i in 0..f.body {
            let z = kin.axis[i];
            let lin = z.cross(&(p - kin.pose[i + 1].trans));
            j.fixed_view_mut::<3, 1>(0, i).copy_from(&lin);
            j.fixed_view_mut::<3, 1>(3, i).copy_from(&z);
        }
        j
    }

    /// `J̇_E θ̇` (6): `[classical linear acceleration of the EE origin (m/s²); angular
    /// acceleration (rad/s²)]` for `θ̈ = 0`, base frame.
    pub fn ee_jdot_qdot(&self, kin: &Kinematics) -> Vector6<f64> {
        let f = self.ee_frame();
        let lin = self
            .point_jdot_qdot(kin, f.body, &f.placement.trans)
            .unwrap_or_default();
        let ang = kin.alpha[f.body];
        Vector6::new(lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)
    }

    /// State of collision sphere `idx` (index into [`Robot::collision_spheres`]).
    pub fn sphere_state(&self, kin: &Kinematics, idx: usize) -> Option<SphereState> {
        let s = self.spheres.get(idx)?;
        Some(SphereState {
            link: s.link,
            center: self.point_position(kin, s.link, &s.center)?,
            radius: s.radius,
            jacobian: self.point_jacobian(kin, s.link, &s.center)?,
            jdot_qdot: self.point_jdot_qdot(kin, s.link, &s.center)?,
        })
    }

    /// Fill `out` with the states of the collision spheres (in [`Robot::collision_spheres`]
    /// order) without allocating; returns how many were written (`min(out.len(), n)`).
    pub fn sphere_states_into(&self, kin: &Kinematics, out: &mut [SphereState]) -> usize {
        let mut n = 0;
        for (slot, idx) in out.iter_mut().zip(0..self.spheres.len()) {
            if let Some(s) = self.sphere_state(kin, idx) {
                *slot = s;
                n += 1;
            }
        }
        n
    }

    /// States of all collision spheres (allocates; convenience for non-real-time code).
    pub fn sphere_states(&self, kin: &Kinematics) -> Vec<SphereState> {
        (0..self.spheres.len())
            .filter_map(|i| self.sphere_state(kin, i))
            .collect()
    }
}

impl Default for SphereState {
    fn default() -> Self {
        SphereState {
            link: 0,
            center: Vector3::zeros(),
            radius: 0.0,
            jacobian: SMatrix::zeros(),
            jdot_qdot: Vector3::zeros(),
        }
    }
}
