//! Scalar-first quaternions `[q0, q1, q2, q3]` and their rotation matrices.
//!
//! `q_AB` rotates vectors from frame B into frame A. Composition:
//! `q_AC = q_AB ⊗ q_BC`.

use crate::{Mat3, Vec3};
use nalgebra::{Matrix4x3, Quaternion, UnitQuaternion};

/// Scalar-first quaternion `[q0, q1, q2, q3]`.
pub type Quat = [f64; 4];

/// The identity rotation.
pub const IDENTITY: Quat = [1.0, 0.0, 0.0, 0.0];

/// Converts to nalgebra's unit quaternion (normalising).
pub fn to_unit(q: &Quat) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// Converts nalgebra's unit quaternion to the scalar-first array.
pub fn from_unit(u: &UnitQuaternion<f64>) -> Quat {
    [u.w, u.i, u.j, u.k]
}

/// Euclidean norm of the four components.
pub fn norm(q: &Quat) -> f64 {
    (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt()
}

/// `q / |q|`; returns `None` for a zero or non-finite quaternion.
pub fn normalized(q: &Quat) -> Option<Quat> {
    let n = norm(q);
    if !n.is_finite() || n < 1e-12 {
        return None;
    }
    Some([q[0] / n, q[1] / n, q[2] / n, q[3] / n])
}

/// Hamilton product `a ⊗ b`.
pub fn mul(a: &Quat, b: &Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// Conjugate (the inverse rotation for a unit quaternion).
pub fn conj(q: &Quat) -> Quat {
    [q[0], -q[1], -q[2], -q[3]]
}

/// Rotation matrix `R(q_AB)` with `v_A = R v_B` (q assumed unit).
pub fn to_matrix(q: &Quat) -> Mat3 {
    let [w, x, y, z] = *q;
    Mat3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )
}

/// Quaternion of a rotation matrix (Shepperd's method), scalar part made non-negative.
pub fn from_matrix(m: &Mat3) -> Quat {
    let u = UnitQuaternion::from_matrix(m);
    let q = from_unit(&u);
    if q[0] < 0.0 {
        [-q[0], -q[1], -q[2], -q[3]]
    } else {
        q
    }
}

/// Rotates `v_B` into frame A: `R(q_AB) v_B`.
pub fn rotate(q: &Quat, v: &Vec3) -> Vec3 {
    to_matrix(q) * v
}

/// The matrix `S_q(q)` of the attitude kinematics `q̇ = ½ S_q(q) ω` (paper, eq. "Attitude
/// kinematics"), with ω expressed in the body frame.
pub fn s_q(q: &Quat) -> Matrix4x3<f64> {
    let [q0, q1, q2, q3] = *q;
    Matrix4x3::new(-q1, -q2, -q3, q0, -q3, q2, q3, q0, -q1, -q2, q1, q0)
}

/// `q̇ = ½ S_q(q) ω_B` (paper, eq. "Attitude kinematics").
pub fn kinematics(q: &Quat, omega_body: &Vec3) -> Quat {
    let d = s_q(q) * omega_body * 0.5;
    [d[0], d[1], d[2], d[3]]
}

/// Exact rotation increment for a constant body rate over `dt`: `q ⊗ exp(½ ω dt)`.
pub fn integrate_body_rate(q: &Quat, omega_body: &Vec3, dt: f64) -> Quat {
    let angle = omega_body.norm() * dt;
    if angle.abs() < 1e-300 {
        return *q;
    }
    let axis = omega_body / omega_body.norm();
    let (s, c) = (0.5 * angle).sin_cos();
    let dq = [c, axis.x * s, axis.y * s, axis.z * s];
    mul(q, &dq)
}

/// Quaternion from an axis (need not be unit) and an angle [rad].
pub fn from_axis_angle(axis: &Vec3, angle: f64) -> Quat {
    let n = axis.norm();
    if n < 1e-300 {
        return IDENTITY;
    }
    let (s, c) = (0.5 * angle).sin_cos();
    [c, axis.x / n * s, axis.y / n * s, axis.z / n * s]
}

/// Skew-symmetric cross-product matrix `[v]×`.
pub fn skew(v: &Vec3) -> Mat3 {
    Mat3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Rotation vector (axis·angle, angle in [0, π]) of the error quaternion `q`.
pub fn rotation_vector(q: &Quat) -> Vec3 {
    let q = if q[0] < 0.0 {
        [-q[0], -q[1], -q[2], -q[3]]
    } else {
        *q
    };
    let v = Vec3::new(q[1], q[2], q[3]);
    let s = v.norm();
    if s < 1e-15 {
        return 2.0 * v;
    }
    let angle = 2.0 * s.atan2(q[0]);
    v * (angle / s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rand_q(k: f64) -> Quat {
        normalized(&[0.3 + k, -0.7 * k, 0.2, 0.5 - k]).unwrap()
    }

    #[test]
    fn matrix_matches_nalgebra_and_roundtrips() {
        for k in [0.0, 0.3, 1.7, -2.1] {
            let q = rand_q(k);
            let m = to_matrix(&q);
            let n = to_unit(&q).to_rotation_matrix().into_inner();
            assert!((m - n).norm() < 1e-14);
            let q2 = from_matrix(&m);
            let same = (0..4).all(|i| (q[i] - q2[i]).abs() < 1e-12)
                || (0..4).all(|i| (q[i] + q2[i]).abs() < 1e-12);
            assert!(same, "{q:?} vs {q2:?}");
        }
    }

    #[test]
    fn product_composes_rotations() {
        let a = rand_q(0.4);
        let b = rand_q(-1.2);
        let v = Vec3::new(0.3, -1.0, 2.0);
        let lhs = to_matrix(&mul(&a, &b)) * v;
        let rhs = to_matrix(&a) * (to_matrix(&b) * v);
        assert!((lhs - rhs).norm() < 1e-13);
        assert!((to_matrix(&conj(&a)) - to_matrix(&a).transpose()).norm() < 1e-14);
    }

    #[test]
    fn kinematics_matches_finite_difference_of_exact_rotation() {
        let q = rand_q(0.9);
        let w = Vec3::new(0.1, -0.2, 0.05);
        let dt = 1e-6;
        let qp = integrate_body_rate(&q, &w, dt);
        let qm = integrate_body_rate(&q, &w, -dt);
        let qd = kinematics(&q, &w);
        for i in 0..4 {
            let fd = (qp[i] - qm[i]) / (2.0 * dt);
            assert!(
                (fd - qd[i]).abs() < 1e-9,
                "component {i}: {fd} vs {}",
                qd[i]
            );
        }
    }

    #[test]
    fn rotation_vector_inverts_axis_angle() {
        let axis = Vec3::new(1.0, 2.0, -0.5).normalize();
        for angle in [0.0, 1e-9, 0.3, 3.0] {
            let rv = rotation_vector(&from_axis_angle(&axis, angle));
            assert!((rv - axis * angle).norm() < 1e-12);
        }
    }

    #[test]
    fn normalized_rejects_zero_and_nan() {
        assert!(normalized(&[0.0; 4]).is_none());
        assert!(normalized(&[f64::NAN, 0.0, 0.0, 1.0]).is_none());
    }
}
