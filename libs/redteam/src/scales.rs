//! A characteristic scale of every barrier, so that margins of different units can be
//! compared: roughly the barrier's value at the middle of its safe range (the corridor on
//! its axis, a joint at mid-range, a rate at zero, a sphere touching the base's or the
//! target's centre).

use sc_cbf::monitor::{Barriers, N_ALL, N_FILTERED};
use sc_cbf::{attitude, robotic, translational};
use sc_multibody::Robot;
use sc_scenario::Scenario;

/// The scale of every barrier, in [`sc_cbf::names`] order (all > 0).
pub fn barrier_scales(s: &Scenario, robot: &Robot) -> Barriers {
    let t = &s.safety.translational;
    let a = &s.safety.attitude;
    let r = &s.safety.robotic;
    let psi = t.corridor_half_angle_deg.to_radians();
    let beta = a.los_half_angle_deg.to_radians();
    let mut scale = [1.0; N_ALL];
    scale[0] = 1.0 - psi.cos();
    scale[1] = t.caz_radius_m * t.caz_radius_m;
    let o = translational::N;
    scale[o] = 1.0 - beta.cos();
    for i in 0..3 {
        let span = a.omega_max_rad_s[i] - a.omega_min_rad_s[i];
        scale[o + 1 + i] = span;
        scale[o + 4 + i] = span;
    }
    let o = translational::N + attitude::N;
    let nj = robotic::NJ;
    for i in 0..nj {
        let half = 0.5 * (r.theta_max_rad[i] - r.theta_min_rad[i]);
        scale[o + i] = half * half;
        scale[o + nj + i] = 2.0 * r.theta_dot_max_rad_s[i];
        scale[o + 2 * nj + i] = 2.0 * r.theta_dot_max_rad_s[i];
    }
    if let Some(base) = robot.base_sphere() {
        for (k, (_, sp)) in robot.arm_spheres().take(robotic::NS).enumerate() {
            let rr = sp.radius + base.radius;
            scale[o + 3 * nj + k] = rr * rr;
        }
    }
    // arm and base against the target: a sphere touching the target's bounding sphere's
    // centre
    let target = sc_cbf::arm_target::TargetBody::from_scenario(s).bounding_radius();
    for (k, (_, sp)) in robot.arm_spheres().take(robotic::NS).enumerate() {
        let rr = sp.radius + target;
        scale[o + robotic::LINK_TARGET + k] = rr * rr;
    }
    if let Some(base) = robot.base_sphere() {
        let rr = base.radius + target;
        scale[N_FILTERED] = rr * rr;
    }
    for v in scale.iter_mut() {
        if !(v.is_finite() && *v > 0.0) {
            *v = 1.0;
        }
    }
    scale
}
