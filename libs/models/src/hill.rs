//! The Hill frame `F_H` of the target orbit: R-bar (radial), V-bar (along-track,
//! completing the triad), H-bar (orbit normal), and relative-state transforms
//! between the inertial frame and `F_H`.

use crate::{Mat3, Vec3};

/// Below this sine of the angle between position and velocity, `r × v` gives no
/// direction and the orbit no plane (zero gravity: the target rests, or moves
/// radially); [`HillFrame::from_inertial_or`] then takes the given normal. 1e-12 is
/// far above the rounding of `r × v` (1e-16) and far below any orbit (sin = 1 on a
/// circular one).
pub const DEGENERATE_ORBIT_SINE: f64 = 1e-12;

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
        Self::from_inertial_or(r, v, &Vec3::z())
    }

    /// [`Self::from_inertial`], also where the orbit has no plane (`r × v` ≈ 0, see
    /// [`DEGENERATE_ORBIT_SINE`]; μ = 0 with the target at rest): Ĥ is then `normal`
    /// made perpendicular to R̂ (any perpendicular if `normal` is parallel to it), and
    /// the frame does not rotate (`|h|` = 0). With no gravity the body moves on a straight
    /// line with constant `h`, so the rates below hold as for a Keplerian orbit.
    pub fn from_inertial_or(r: &Vec3, v: &Vec3, normal: &Vec3) -> Self {
        let h = r.cross(v);
        let rn = r.norm();
        let x = r / rn;
        let z = if h.norm() > DEGENERATE_ORBIT_SINE * rn * v.norm() {
            h / h.norm()
        } else {
            let n = normal - x * x.dot(normal);
            if n.norm() > DEGENERATE_ORBIT_SINE * normal.norm() {
                n.normalize()
            } else {
                // any unit vector perpendicular to x
                let e = if x.x.abs() < x.y.abs().max(x.z.abs()) {
                    Vec3::x()
                } else {
                    Vec3::y()
                };
                (e - x * x.dot(&e)).normalize()
            }
        };
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

    #[test]
    fn zero_gravity_frame_is_fixed_and_finite() {
        let e = TwoBody { mu: 0.0 };
        let (inc, raan) = (0.7, 0.2);
        let (r, v) = e.circular_state(6_978_137.0, inc, raan, 0.4);
        assert_eq!(v, Vec3::zeros());
        let normal = TwoBody::orbit_normal(inc, raan);
        let f = HillFrame::from_inertial_or(&r, &v, &normal);
        assert!(f.c_hi.iter().all(|x| x.is_finite()));
        assert!((f.c_hi * f.c_hi.transpose() - Mat3::identity()).norm() < 1e-14);
        assert!((f.c_hi.determinant() - 1.0).abs() < 1e-14);
        assert_eq!((f.omega, f.omega_dot), (Vec3::zeros(), Vec3::zeros()));
        // the frame gravity would give this orbit: R̂ along r, Ĥ the orbit's normal
        let g = TwoBody {
            mu: 3.986_004_418e14,
        };
        let (rg, vg) = g.circular_state(6_978_137.0, inc, raan, 0.4);
        let orbiting = HillFrame::from_inertial(&rg, &vg);
        assert!((f.c_hi - orbiting.c_hi).norm() < 1e-12);
        // a normal along r still gives a right-handed frame
        let f = HillFrame::from_inertial_or(&r, &v, &r);
        assert!((f.c_hi.determinant() - 1.0).abs() < 1e-14);
        assert!((f.c_hi * r.normalize() - Vec3::x()).norm() < 1e-14);
        // the relative state of a body at rest stays at rest in the fixed frame
        let (rh, vh) = f.relative_to_hill(&Vec3::new(1.0, 2.0, 3.0), &Vec3::zeros());
        assert!((rh.norm() - 14f64.sqrt()).abs() < 1e-14 && vh == Vec3::zeros());
    }

    #[test]
    fn orbit_normal_is_that_of_the_circular_orbit() {
        let e = TwoBody {
            mu: 3.986_004_418e14,
        };
        for (inc, raan, u) in [(0.0, 0.0, 0.0), (0.7, 0.2, 0.4), (2.5, -1.0, 3.0)] {
            let (r, v) = e.circular_state(7.0e6, inc, raan, u);
            let h = r.cross(&v).normalize();
            assert!((h - TwoBody::orbit_normal(inc, raan)).norm() < 1e-14);
        }
    }
}
