//! Deterministic per-run seeds and the dispersed parameters of a run.

use crate::config::MonteCarloConfig;
use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

/// Redraws allowed before a configuration is declared unsatisfiable.
pub const MAX_DRAWS: usize = 10_000;

/// Seed of run `k` of a campaign: the first word of ChaCha8 keyed by the campaign seed on
/// stream `k`. Depends on nothing else, so any shard or rerun derives the same seed.
pub fn run_seed(campaign_seed: u64, k: usize) -> u64 {
    let mut rng = ChaCha8Rng::seed_from_u64(campaign_seed);
    rng.set_stream(k as u64);
    rng.next_u64()
}

fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The dispersed parameters of one run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Dispersion {
    /// Initial distance of the base origin from the target CoM [m].
    pub distance_m: f64,
    /// Angle between the initial position and the corridor axis [deg].
    pub off_axis_deg: f64,
    /// Azimuth of the initial position about the corridor axis [deg].
    pub azimuth_deg: f64,
    /// The resulting initial position in F_R [m].
    pub position_r_m: [f64; 3],
    /// Initial line-of-sight angle from the boresight [deg].
    pub initial_los_deg: f64,
    /// Target tumbling rate w [rad/s]; ω_T = w · axis_t.
    pub tumble_rate_rad_s: f64,
    pub omega_t_rad_s: [f64; 3],
    /// Draws needed (rejections + 1).
    pub draws: usize,
}

/// Two unit vectors completing `d` to an orthonormal basis.
fn basis(d: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let pick = if d.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = (pick - d * d.dot(&pick)).normalize();
    (e1, d.cross(&e1))
}

/// Angle between the boresight and the line of sight from `r_r` to the grasping point at
/// t = 0 (servicer attitude = F_R) [deg].
pub fn initial_los_deg(s: &sc_scenario::Scenario, r_r: &Vector3<f64>) -> f64 {
    let q_rt = s.target.initial_attitude;
    let g = sc_models::quat::rotate(&q_rt, &Vector3::from(s.target.grasp_point_m));
    let los = g - r_r;
    let d = Vector3::from(s.servicer.boresight_body);
    let c = los.dot(&d) / (los.norm() * d.norm());
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Why no dispersion could be sampled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SampleError {
    #[error(
        "no initial position within the line-of-sight margin after {} draws; reduce initial_position.los_margin_deg or the corridor cap",
        MAX_DRAWS
    )]
    OutsideLineOfSight,
}

/// Samples run `seed`'s dispersion for scenario `s`. Errors when no draw in
/// [`MAX_DRAWS`] satisfies the line-of-sight margin.
pub fn sample(
    cfg: &MonteCarloConfig,
    s: &sc_scenario::Scenario,
    seed: u64,
) -> Result<Dispersion, SampleError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let p = &cfg.initial_position;
    let axis = Vector3::from(s.safety.translational.corridor_axis);
    let axis = axis / axis.norm();
    let (e1, e2) = basis(&axis);
    let cap = (s.safety.translational.corridor_half_angle_deg - p.corridor_margin_deg).to_radians();
    let los_max = s.safety.attitude.los_half_angle_deg - p.los_margin_deg;
    let r = &cfg.target_rate;
    let w = r.rate_min_rad_s + uniform(&mut rng) * (r.rate_max_rad_s - r.rate_min_rad_s);
    for draw in 1..=MAX_DRAWS {
        let (u1, u2, u3) = (uniform(&mut rng), uniform(&mut rng), uniform(&mut rng));
        let cos_a = 1.0 - u1 * (1.0 - cap.cos());
        let a = cos_a.clamp(-1.0, 1.0).acos();
        let phi = std::f64::consts::TAU * u2;
        let dist = p.distance_min_m + u3 * (p.distance_max_m - p.distance_min_m);
        let dir = axis * a.cos() + (e1 * phi.cos() + e2 * phi.sin()) * a.sin();
        let pos = dir * dist;
        let los = initial_los_deg(s, &pos);
        if los <= los_max {
            return Ok(Dispersion {
                distance_m: dist,
                off_axis_deg: a.to_degrees(),
                azimuth_deg: phi.to_degrees(),
                position_r_m: pos.into(),
                initial_los_deg: los,
                tumble_rate_rad_s: w,
                omega_t_rad_s: [w * r.axis_t[0], w * r.axis_t[1], w * r.axis_t[2]],
                draws: draw,
            });
        }
    }
    Err(SampleError::OutsideLineOfSight)
}

/// The scenario of a run: `base` with the dispersion applied.
pub fn apply(base: &sc_scenario::Scenario, d: &Dispersion) -> sc_scenario::Scenario {
    let mut s = base.clone();
    s.servicer.initial_position_m = d.position_r_m;
    s.target.initial_omega_rad_s = d.omega_t_rad_s;
    s
}
