//! The safety monitor: every barrier of the safety layer evaluated from the **true
//! state** (the simulator's), independently of what any filter reports.
//!
//! Telemetry, `summary.json`, the red-team campaigns and the partition's recorder take
//! their barrier values from here, at every control step and at every physics step in
//! between, so a filter that falls back, crashes or lies cannot hide a violation.
//!
//! The formulas are the paper's barrier definitions written out once more, on purpose
//! without the filters' code paths (no derivatives, no rows):
//!
//! * approach corridor, paper eq. "CBF-AC": `h = d_Rᵀ r − ‖r‖ cos ψ_AC` [m];
//! * collision-avoidance zone, eq. "CBF-CAZ": `h = ‖r‖² − R_CAZ²` [m²];
//! * line of sight, eq. "CBF-ATT": `h = d_Bᵀ R_BR s_R − cos β_ATT`,
//!   `s_R = (R_RT p_G,T − r)/‖·‖`;
//! * body-rate limits, eq. "CBF-omega": `ω_max,i − ω_i`, `ω_i − ω_min,i` [rad/s];
//! * joint angles, eq. "CBF-joint-angle": `(θ_i − θ_min,i)(θ_max,i − θ_i)` [rad²];
//! * joint rates, eq. "CBF-joint-velocity": `θ̇_max,i ∓ θ̇_i` [rad/s];
//! * link–base spheres, eq. "CBF-link-base": `‖p_i(θ) − c_base‖² − (ρ_i + R_base)²` [m²];
//! * arm and base against the target's keep-out spheres (not the paper's,
//!   [`crate::arm_target`]): `min_k ‖p_i − c_k‖² − (ρ_i + ρ_k)²` [m²].
//!
//! `r` is the servicer's **system centre of mass** relative to the target's, in the
//! inertially fixed reference frame F_R (where the corridor axis `d_R` is constant): the
//! point whose motion the Clohessy–Wiltshire model describes exactly (docs/SAFETY.md).

use crate::arm_target::TargetBody;
use crate::{arm_target, attitude, robotic, translational};
use nalgebra::Vector3;
use sc_core::BarrierState;
use sc_models::quat;
use sc_multibody::{Robot, Vector7};
use std::sync::Arc;

/// Number of barriers: 2 translational + 7 attitude + 63 robotic, then the base against
/// the target, which only the monitor evaluates.
pub const N_ALL: usize = N_FILTERED + arm_target::N;
/// The barriers the filters enforce (the first ones, in causal order).
pub const N_FILTERED: usize = translational::N + attitude::N + robotic::N;

/// Every barrier value, in [`crate::names`] order (translational, attitude, robotic).
pub type Barriers = [f64; N_ALL];

/// The geometry of every barrier, from the scenario and the servicer model.
#[derive(Debug, Clone)]
pub struct Monitor {
    axis_r: Vector3<f64>,
    cos_psi: f64,
    r_caz: f64,
    boresight_b: Vector3<f64>,
    cos_beta: f64,
    omega_max: Vector3<f64>,
    omega_min: Vector3<f64>,
    theta_min: Vector7,
    theta_max: Vector7,
    theta_dot_max: Vector7,
    target: TargetBody,
    robot: Arc<Robot>,
}

impl Monitor {
    /// From the scenario's `[safety.*]` tables and the servicer model.
    pub fn from_scenario(s: &sc_scenario::Scenario, robot: Arc<Robot>) -> Self {
        let t = &s.safety.translational;
        let a = &s.safety.attitude;
        let r = &s.safety.robotic;
        Self {
            axis_r: Vector3::from(t.corridor_axis).normalize(),
            cos_psi: t.corridor_half_angle_deg.to_radians().cos(),
            r_caz: t.caz_radius_m,
            boresight_b: Vector3::from(s.servicer.boresight_body).normalize(),
            cos_beta: a.los_half_angle_deg.to_radians().cos(),
            omega_max: Vector3::from(a.omega_max_rad_s),
            omega_min: Vector3::from(a.omega_min_rad_s),
            theta_min: Vector7::from(r.theta_min_rad),
            theta_max: Vector7::from(r.theta_max_rad),
            theta_dot_max: Vector7::from(r.theta_dot_max_rad_s),
            target: TargetBody::from_scenario(s),
            robot,
        }
    }

    /// Every barrier at state `x`. Never panics; a non-finite state gives NaN values,
    /// which every consumer counts as a violation.
    pub fn evaluate(&self, x: &BarrierState) -> Barriers {
        let mut h = [f64::NAN; N_ALL];
        // translational (paper eqs. CBF-AC, CBF-CAZ)
        let r = &x.com_r;
        h[0] = self.axis_r.dot(r) - r.norm() * self.cos_psi;
        h[1] = r.dot(r) - self.r_caz * self.r_caz;
        // attitude (CBF-ATT, CBF-omega)
        let o = translational::N;
        let rho = x.grasp_r - r;
        let r_br = quat::to_matrix(&x.q_rb).transpose();
        h[o] = self.boresight_b.dot(&(r_br * (rho / rho.norm()))) - self.cos_beta;
        for i in 0..3 {
            h[o + 1 + i] = self.omega_max[i] - x.omega_b[i];
            h[o + 4 + i] = x.omega_b[i] - self.omega_min[i];
        }
        // robotic (CBF-joint-angle, CBF-joint-velocity, CBF-link-base)
        let o = translational::N + attitude::N;
        let nj = robotic::NJ;
        for i in 0..nj {
            let th = x.theta[i];
            h[o + i] = (th - self.theta_min[i]) * (self.theta_max[i] - th);
            h[o + nj + i] = self.theta_dot_max[i] - x.theta_dot[i];
            h[o + 2 * nj + i] = x.theta_dot[i] + self.theta_dot_max[i];
        }
        if x.theta.iter().all(|v| v.is_finite()) {
            self.spheres(x, &mut h);
        }
        h
    }

    /// The sphere barriers: link–base (CBF-link-base) and arm–target
    /// ([`crate::arm_target`]); left NaN where the model has no such sphere.
    fn spheres(&self, x: &BarrierState, h: &mut Barriers) {
        let o = translational::N + attitude::N + 3 * robotic::NJ;
        let ot = translational::N + attitude::N + robotic::LINK_TARGET;
        let Some(base) = self.robot.base_sphere() else {
            return;
        };
        let kin = self.robot.kinematics(&x.theta);
        let r_rb = quat::to_matrix(&x.q_rb);
        let r_rt = quat::to_matrix(&x.q_rt);
        let in_r = |p: &Vector3<f64>| x.base_r + r_rb * p;
        for (k, (idx, _)) in self.robot.arm_spheres().take(robotic::NS).enumerate() {
            if let Some(sp) = self.robot.sphere_state(&kin, idx) {
                let d = sp.center - base.center;
                let rr = sp.radius + base.radius;
                h[o + k] = d.dot(&d) - rr * rr;
                h[ot + k] = self.target.clearance(&in_r(&sp.center), sp.radius, &r_rt);
            }
        }
        h[N_FILTERED] = self
            .target
            .clearance(&in_r(&base.center), base.radius, &r_rt);
    }
}

/// Componentwise minimum of two barrier vectors (NaN wins: a NaN sample is never hidden).
pub fn min_into(acc: &mut Barriers, h: &Barriers) {
    for (a, b) in acc.iter_mut().zip(h) {
        if a.is_nan() || b.is_nan() {
            *a = f64::NAN;
        } else if *b < *a {
            *a = *b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_is_never_hidden_by_min() {
        let mut a = [1.0; N_ALL];
        let mut b = [2.0; N_ALL];
        b[3] = f64::NAN;
        b[4] = -1.0;
        min_into(&mut a, &b);
        assert!(a[3].is_nan());
        assert_eq!(a[4], -1.0);
        assert_eq!(a[0], 1.0);
        let c = [0.5; N_ALL];
        min_into(&mut a, &c);
        assert!(a[3].is_nan(), "a later finite sample must not erase a NaN");
    }
}
