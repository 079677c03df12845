//! Reproducible random draws for the unit tests (one generator for every module's tests),
//! and the default scenario they start from.

use nalgebra::Vector3;
use sc_multibody::{NJ, Robot};
use sc_scenario::uncertainty::ModelBounds;

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

/// The shipped default scenario (`config/scenario.toml`).
pub fn default_scenario() -> sc_scenario::Scenario {
    sc_scenario::Scenario::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../config/scenario.toml"
    )))
    .unwrap()
}

/// A uniform draw in `[-e, e]`, the ends half the time (the bounds' worst cases).
pub fn pick(seed: &mut u64, e: f64) -> f64 {
    let u = lcg(seed);
    if u < 0.25 {
        -e
    } else if u < 0.5 {
        e
    } else {
        e * (2.0 * lcg(seed) - 1.0)
    }
}

/// A plant at a random point of the declared mass-property box — the quantities the
/// simulator draws (the base's mass, inertia and CoM, each link's mass and inertia), with
/// the corners favoured ([`pick`]) and the CoM's offset at least half its bound.
pub fn plant(seed: &mut u64, r: &Robot, m: &ModelBounds) -> Robot {
    let com = ball(seed, 1.0).normalize() * m.servicer_com_m * (0.5 + 0.5 * lcg(seed));
    let mut p = r
        .with_body_mass_properties(
            0,
            1.0 + pick(seed, m.servicer_mass_rel),
            1.0 + pick(seed, m.servicer_inertia_rel),
            com,
        )
        .unwrap();
    for k in 1..=NJ {
        p = p
            .with_body_mass_properties(
                k,
                1.0 + pick(seed, m.link_mass_rel),
                1.0 + pick(seed, m.link_inertia_rel),
                Vector3::zeros(),
            )
            .unwrap();
    }
    p
}
