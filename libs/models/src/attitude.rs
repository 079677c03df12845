//! Rigid-body attitude motion (paper, eqs. "Attitude kinematics" and "Attitude dynamics").

use crate::quat::{self, Quat};
use crate::{Mat3, Vec3};

/// Euler's equation `I ω̇ = τ − ω × (I ω)` solved for ω̇ [rad/s²], body frame.
pub fn euler(inertia: &Mat3, inertia_inv: &Mat3, omega: &Vec3, torque: &Vec3) -> Vec3 {
    inertia_inv * (torque - omega.cross(&(inertia * omega)))
}

/// State derivative `(q̇, ω̇)` of a rigid body with body-frame torque `torque`.
pub fn derivative(
    inertia: &Mat3,
    inertia_inv: &Mat3,
    q: &Quat,
    omega: &Vec3,
    torque: &Vec3,
) -> (Quat, Vec3) {
    (
        quat::kinematics(q, omega),
        euler(inertia, inertia_inv, omega, torque),
    )
}

/// Rotational kinetic energy ½ ωᵀ I ω [J].
pub fn kinetic_energy(inertia: &Mat3, omega: &Vec3) -> f64 {
    0.5 * omega.dot(&(inertia * omega))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torque_free_motion_conserves_energy_and_inertial_momentum() {
        let i = Mat3::from_diagonal(&Vec3::new(1200.0, 900.0, 800.0));
        let ii = i.try_inverse().unwrap();
        let mut q = quat::IDENTITY;
        let mut w = Vec3::new(-0.08, 0.01, 0.02);
        let e0 = kinetic_energy(&i, &w);
        let h0 = quat::rotate(&q, &(i * w));
        let dt = 0.01;
        for _ in 0..20_000 {
            let f = |q: &Quat, w: &Vec3| derivative(&i, &ii, q, w, &Vec3::zeros());
            let add = |q: &Quat, d: &Quat, s: f64| {
                [
                    q[0] + d[0] * s,
                    q[1] + d[1] * s,
                    q[2] + d[2] * s,
                    q[3] + d[3] * s,
                ]
            };
            let (k1q, k1w) = f(&q, &w);
            let (k2q, k2w) = f(&add(&q, &k1q, dt / 2.0), &(w + k1w * dt / 2.0));
            let (k3q, k3w) = f(&add(&q, &k2q, dt / 2.0), &(w + k2w * dt / 2.0));
            let (k4q, k4w) = f(&add(&q, &k3q, dt), &(w + k3w * dt));
            for k in 0..4 {
                q[k] += dt / 6.0 * (k1q[k] + 2.0 * k2q[k] + 2.0 * k3q[k] + k4q[k]);
            }
            q = quat::normalized(&q).unwrap();
            w += (k1w + 2.0 * k2w + 2.0 * k3w + k4w) * (dt / 6.0);
        }
        assert!((kinetic_energy(&i, &w) - e0).abs() < 1e-10 * e0);
        assert!((quat::rotate(&q, &(i * w)) - h0).norm() < 1e-9 * h0.norm());
    }
}
