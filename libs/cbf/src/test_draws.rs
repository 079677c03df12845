//! Reproducible random draws for the unit tests (one generator for every module's tests).

use nalgebra::Vector3;

/// A uniform draw in `[0, 1)` from a 64-bit linear congruential generator.
pub fn lcg(s: &mut u64) -> f64 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*s >> 11) as f64 / (1u64 << 53) as f64
}

/// A draw in the ball of `radius`, never within 1e-3 of its centre (so it can be
/// normalised).
pub fn ball(seed: &mut u64, radius: f64) -> Vector3<f64> {
    loop {
        let v = Vector3::from_fn(|_, _| 2.0 * lcg(seed) - 1.0);
        if v.norm() <= 1.0 && v.norm() > 1e-3 {
            return v * radius;
        }
    }
}
