//! Shared fixtures of the sc-cbf integration tests.
#![allow(dead_code)]

use nalgebra::{Matrix3, Vector3};
use sc_cbf::robotic::{Vector7, robotic_input_from_model};
use sc_cbf::{AttitudeInput, RoboticInput, TranslationalInput};
use sc_models::quat;
use sc_multibody::Robot;
use sc_scenario::Scenario;
use std::path::PathBuf;

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

pub fn scenario() -> Scenario {
    Scenario::load(&root().join(sc_scenario::DEFAULT_SCENARIO)).expect("scenario loads")
}

pub fn robot() -> Robot {
    Robot::from_urdf_file(&scenario().urdf_path()).expect("URDF loads")
}

/// Servicer mass used by the translational tests [kg].
pub const MASS: f64 = 270.0;

pub fn mean_motion(s: &Scenario) -> f64 {
    let a = s.orbit.earth_radius_m + s.orbit.altitude_m;
    (s.orbit.earth_mu_m3_s2 / (a * a * a)).sqrt()
}

/// Translational input with the servicer at `r_r` (F_R) moving at `v_r` (F_R components
/// of the Hill-frame rate), attitude `q_rb`.
pub fn tr_input(
    s: &Scenario,
    r_r: Vector3<f64>,
    v_r: Vector3<f64>,
    q_rb: quat::Quat,
) -> TranslationalInput {
    let q_hr = s.reference_frame.attitude_in_hill;
    let r_hr = quat::to_matrix(&q_hr);
    TranslationalInput::circular(r_hr * r_r, r_hr * v_r, q_hr, mean_motion(s), q_rb)
}

pub fn inertia() -> Matrix3<f64> {
    Matrix3::new(55.2, 1.2, -0.8, 1.2, 46.0, 0.5, -0.8, 0.5, 50.8)
}

/// Attitude input: servicer at `r_r`, attitude `q_rb`, rate `w`; target tumbling about
/// -x_R at 0.08 rad/s, grasping point at angle `phase`.
pub fn att_input(
    r_r: Vector3<f64>,
    q_rb: quat::Quat,
    w: Vector3<f64>,
    phase: f64,
) -> AttitudeInput {
    let wt = Vector3::new(-0.08, 0.0, 0.0);
    let p_t = Vector3::new(-0.55, 0.12, 0.0);
    let r_rt = quat::to_matrix(&quat::from_axis_angle(&wt, wt.norm() * phase));
    let p = r_rt * p_t;
    let pd = wt.cross(&p);
    let pdd = wt.cross(&pd);
    AttitudeInput {
        q_rb,
        omega_b: w,
        inertia: inertia(),
        r_r,
        v_r: Vector3::new(0.01, -0.002, 0.001),
        a_drift_r: Vector3::new(1e-6, -2e-6, 0.0),
        grasp_r: p,
        grasp_vel_r: pd,
        grasp_acc_r: pdd,
        xi_r: Vector3::new(0.004, -0.01, 0.003),
        omega_target_b: quat::to_matrix(&q_rb).transpose() * (r_rt * wt),
    }
}

pub fn rob_input(robot: &Robot, theta: Vector7, theta_dot: Vector7) -> RoboticInput {
    robotic_input_from_model(
        robot,
        &theta,
        &theta_dot,
        &Vector3::new(0.01, -0.02, 0.005),
        &Vector3::new(3.0, -2.0, 1.0),
        &Vector3::new(1.0, 2.0, -0.5),
    )
    .expect("model terms")
}

pub fn theta0(s: &Scenario) -> Vector7 {
    Vector7::from(s.servicer.initial_theta_rad)
}

/// Deterministic pseudo-random numbers in [-1, 1] (no rand dependence in tests).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    pub fn v3(&mut self, s: f64) -> Vector3<f64> {
        Vector3::new(self.next() * s, self.next() * s, self.next() * s)
    }
    pub fn v7(&mut self, s: f64) -> Vector7 {
        Vector7::from_fn(|_, _| self.next() * s)
    }
}
