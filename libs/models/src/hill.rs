//! The Hill frame `F_H` of the target orbit: R-bar (radial), V-bar (along-track,
//! completing the triad), H-bar (orbit normal), and relative-state transforms
//! between the inertial frame and `F_H`.

use crate::{Mat3, Vec3};

/// The Hill frame at one instant, built from the target's inertial state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HillFrame {
    /// `C_HI`: rotates inertial vectors into the Hill frame (rows R̂, V̂, Ĥ).
    pub c_hi: Mat3,
    /// Angular velocity of `F_H` w.r.t. the inertial frame, in `F_H` [rad/s].
    pub omega: Vec3,
    /// Angular acceleration of `F_H` w.r.t. the inertial frame, in `F_H` [rad/s²].
    pub omega_dot: Vec3,
}

impl HillFrame {
    /// Builds the Hill frame of a body on a Keplerian (unforced two-body) orbit at
    /// inertial position `r` [m] and velocity `v` [m/s]. The frame then rotates
    /// about Ĥ at `|h|/r²`, and that rate changes at `−2|h| ṙ / r³`.
    pub fn from_inertial(r: &Vec3, v: &Vec3) -> Self {
        let h = r.cross(v);
        let rn = r.norm();
        let x = r / rn;
        let z = h / h.norm();
        let y = z.cross(&x);
        let c_hi = Mat3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
        let rate = h.norm() / (rn * rn);
        let r_dot = r.dot(v) / rn;
        let rate_dot = -2.0 * h.norm() * r_dot / (rn * rn * rn);
        Self {
            c_hi,
            omega: Vec3::new(0.0, 0.0, rate),
            omega_dot: Vec3::new(0.0, 0.0, rate_dot),
        }
    }

    /// Inertial relative state (δr, δv) → Hill-frame relative position and its
    /// derivative in the rotating frame: `r_H = C δr`, `v_H = C (δv − ω × δr)`.
    pub fn relative_to_hill(&self, dr: &Vec3, dv: &Vec3) -> (Vec3, Vec3) {
        let r_h = self.c_hi * dr;
        let v_h = self.c_hi * dv - self.omega.cross(&r_h);
        (r_h, v_h)
    }

    /// Inverse of [`Self::relative_to_hill`].
    pub fn hill_to_relative(&self, r_h: &Vec3, v_h: &Vec3) -> (Vec3, Vec3) {
        let dr = self.c_hi.transpose() * r_h;
        let dv = self.c_hi.transpose() * (v_h + self.omega.cross(r_h));
        (dr, dv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::orbit::TwoBody;

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        let e = TwoBody {
            mu: 3.986_004_418e14,
        };
        let (r, v) = e.circular_state(6_978_137.0, 0.7, 0.2, 0.4);
        let f = HillFrame::from_inertial(&r, &v);
        assert!((f.c_hi * f.c_hi.transpose() - Mat3::identity()).norm() < 1e-14);
        assert!((f.c_hi.determinant() - 1.0).abs() < 1e-14);
        assert!((f.omega.z - e.mean_motion(6_978_137.0)).abs() < 1e-15);
        // V-bar is along the velocity on a circular orbit
        assert!((f.c_hi * v.normalize() - Vec3::y()).norm() < 1e-12);
    }

    #[test]
    fn relative_state_roundtrip() {
        let e = TwoBody {
            mu: 3.986_004_418e14,
        };
        let (r, v) = e.circular_state(6_978_137.0, 0.7, 0.2, 0.4);
        let f = HillFrame::from_inertial(&r, &v);
        let (rh, vh) = f.relative_to_hill(&Vec3::new(1.0, 2.0, 3.0), &Vec3::new(-0.1, 0.2, 0.05));
        let (dr, dv) = f.hill_to_relative(&rh, &vh);
        assert!((dr - Vec3::new(1.0, 2.0, 3.0)).norm() < 1e-14);
        assert!((dv - Vec3::new(-0.1, 0.2, 0.05)).norm() < 1e-14);
    }
}
