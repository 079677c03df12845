//! Two-body orbital mechanics in an Earth-centred inertial frame.

use crate::Vec3;

/// Point-mass (two-body) gravity field of the central body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoBody {
    /// Gravitational parameter μ [m³/s²].
    pub mu: f64,
}

impl TwoBody {
    /// Gravitational acceleration at `r` [m, inertial]: `-μ r / |r|³` [m/s²].
    pub fn gravity(&self, r: &Vec3) -> Vec3 {
        let rn = r.norm();
        -self.mu / (rn * rn * rn) * r
    }

    /// Differential gravity `g(r_ref + δ) − g(r_ref)` [m/s²], evaluated without
    /// cancellation (Battin's f(q) form), so that relative motion keeps full
    /// precision at metre separations from a 7000 km orbit.
    pub fn differential_gravity(&self, r_ref: &Vec3, delta: &Vec3) -> Vec3 {
        let r2 = r_ref.norm_squared();
        let q = delta.dot(&(2.0 * r_ref + delta)) / r2;
        let s = (1.0 + q).powf(1.5);
        let f = q * (3.0 + 3.0 * q + q * q) / (1.0 + s);
        let rs = (r_ref + delta).norm();
        -self.mu / (rs * rs * rs) * (delta - f * r_ref)
    }

    /// Mean motion of a circular orbit of radius `a` [m]: `n = √(μ/a³)` [rad/s].
    pub fn mean_motion(&self, a: f64) -> f64 {
        (self.mu / (a * a * a)).sqrt()
    }

    /// Unit normal of the orbital plane with inclination `inc` and right ascension of
    /// the ascending node `raan` [rad]: the direction of `r × v` of
    /// [`Self::circular_state`], defined by the geometry alone (also for μ = 0).
    pub fn orbit_normal(inc: f64, raan: f64) -> Vec3 {
        let (si, ci) = inc.sin_cos();
        let (so, co) = raan.sin_cos();
        Vec3::new(si * so, -si * co, ci)
    }

    /// Specific orbital energy `v²/2 − μ/|r|` [J/kg].
    pub fn specific_energy(&self, r: &Vec3, v: &Vec3) -> f64 {
        0.5 * v.norm_squared() - self.mu / r.norm()
    }

    /// Inertial position and velocity on a circular orbit of radius `a` [m] with
    /// inclination `inc`, right ascension of the ascending node `raan` and
    /// argument of latitude `u` [rad]. With μ = 0 (zero gravity) the speed is 0: the
    /// body rests at that position.
    pub fn circular_state(&self, a: f64, inc: f64, raan: f64, u: f64) -> (Vec3, Vec3) {
        let (su, cu) = u.sin_cos();
        let (si, ci) = inc.sin_cos();
        let (so, co) = raan.sin_cos();
        let r = a * Vec3::new(cu * co - su * ci * so, cu * so + su * ci * co, su * si);
        let vc = (self.mu / a).sqrt();
        let v = vc * Vec3::new(-su * co - cu * ci * so, -su * so + cu * ci * co, cu * si);
        (r, v)
    }
}

/// Specific angular momentum `r × v` [m²/s].
pub fn angular_momentum(r: &Vec3, v: &Vec3) -> Vec3 {
    r.cross(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    const EARTH: TwoBody = TwoBody {
        mu: 3.986_004_418e14,
    };

    #[test]
    fn differential_gravity_matches_direct_difference() {
        let (r, _) = EARTH.circular_state(6_978_137.0, 0.9, 0.3, 1.1);
        let d = Vec3::new(3.0, -4.0, 12.0);
        let direct = EARTH.gravity(&(r + d)) - EARTH.gravity(&r);
        let battin = EARTH.differential_gravity(&r, &d);
        // direct difference carries ~1e-15·8 m/s² of cancellation noise
        assert!((direct - battin).norm() < 1e-13, "{direct} vs {battin}");
        // and the leading-order tidal term −μ/r³ (d − 3 (r̂·d) r̂)
        let rn = r.norm();
        let rh = r / rn;
        let tidal = -EARTH.mu / rn.powi(3) * (d - 3.0 * rh.dot(&d) * rh);
        // second-order terms are O(|d|/r) ≈ 2e-6 of the tidal term
        assert!((tidal - battin).norm() < 1e-5 * tidal.norm());
    }

    #[test]
    fn circular_state_is_circular() {
        let a = 6_978_137.0;
        let (r, v) = EARTH.circular_state(a, 0.5, 1.0, 2.0);
        assert!((r.norm() - a).abs() < 1e-6);
        assert!(r.dot(&v).abs() < 1e-3);
        assert!((v.norm() - (EARTH.mu / a).sqrt()).abs() < 1e-9);
        let h = angular_momentum(&r, &v);
        assert!((h.norm() - a * v.norm()).abs() < 1e-3);
    }
}
