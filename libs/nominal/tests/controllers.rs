//! `NominalControllers` on the default scenario: phase switching, bad inputs,
//! determinism, and a grasp of the tumbling target's grasping point with the arm.

use sc_models::Vec3;
use sc_models::quat;
use sc_multibody::{Robot, Vector7};
use sc_nominal::{NominalControllers, NominalInput, SubsystemStatus};
use sc_scenario::Scenario;
use std::path::Path;

fn setup() -> (Scenario, NominalControllers) {
    let s =
        Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml"))
            .unwrap();
    let robot = Robot::from_urdf_file(&s.urdf_path()).unwrap();
    let c = NominalControllers::new(&s, robot).unwrap();
    (s, c)
}

fn initial_input(s: &Scenario, t: f64) -> NominalInput {
    let a = s.orbit.earth_radius_m + s.orbit.altitude_m;
    let n = (s.orbit.earth_mu_m3_s2 / (a * a * a)).sqrt();
    NominalInput {
        t,
        q_hr: s.reference_frame.attitude_in_hill,
        omega_h: Vec3::new(0.0, 0.0, n),
        r_r: Vec3::from(s.servicer.initial_position_m),
        v_r: Vec3::from(s.servicer.initial_velocity_m_s),
        q_rb: quat::IDENTITY,
        omega_b: Vec3::from(s.servicer.initial_omega_rad_s),
        q_rt: s.target.initial_attitude,
        omega_t: Vec3::from(s.target.initial_omega_rad_s),
        theta: Vector7::from(s.servicer.initial_theta_rad),
        theta_dot: Vector7::from(s.servicer.initial_theta_dot_rad_s),
    }
}

#[test]
fn phases_switch_the_configured_modes() {
    let (s, c) = setup();
    assert_eq!(c.phase_at(0.0), 0);
    assert_eq!(c.phase_at(59.95), 0);
    assert_eq!(c.phase_at(60.0), 1);
    assert_eq!(c.phase_at(120.0), 2);
    assert_eq!(c.phase_at(1e9), 2);
    for t in [0.0, 60.0, 120.0] {
        let out = c.command(&initial_input(&s, t));
        assert_eq!(out.phase, c.phase_at(t));
        assert_eq!(out.translational, SubsystemStatus::Active);
        assert_eq!(out.attitude, SubsystemStatus::Active);
        assert_eq!(out.robotic, SubsystemStatus::Active);
        assert!(out.f_h.iter().all(|x| x.is_finite()) && out.f_h.norm() > 0.0);
        assert_eq!(out.ik.is_some(), t >= 120.0);
    }
    // hold at the initial configuration at rest: zero joint torque
    let out = c.command(&initial_input(&s, 0.0));
    assert!(out.tau_m.amax() < 1e-12);
    // the initial boresight error is the LOS offset, a few degrees
    assert!(out.pointing_error_rad > 0.01 && out.pointing_error_rad < 0.1);
    // deterministic
    assert_eq!(out, c.command(&initial_input(&s, 0.0)));
}

#[test]
fn bad_inputs_give_flagged_zero_commands() {
    let (s, c) = setup();
    let mut x = initial_input(&s, 130.0);
    x.r_r.y = f64::NAN;
    let out = c.command(&x);
    assert_eq!(out.translational, SubsystemStatus::InvalidInput);
    assert_eq!(out.attitude, SubsystemStatus::InvalidInput);
    assert_eq!(out.robotic, SubsystemStatus::InvalidInput);
    assert_eq!(out.f_h, Vec3::zeros());
    assert_eq!(out.tau_b, Vec3::zeros());
    assert_eq!(out.tau_m, Vector7::zeros());

    let mut x = initial_input(&s, 10.0);
    x.theta[0] = f64::INFINITY;
    let out = c.command(&x);
    assert_eq!(out.translational, SubsystemStatus::Active);
    assert_eq!(out.attitude, SubsystemStatus::Active); // falls back to the hold inertia
    assert_eq!(out.robotic, SubsystemStatus::InvalidInput);

    let mut x = initial_input(&s, 10.0);
    x.q_hr = [0.0; 4];
    x.q_rt = [f64::NAN; 4];
    let out = c.command(&x);
    assert_eq!(out.translational, SubsystemStatus::InvalidInput);
    assert_eq!(out.attitude, SubsystemStatus::InvalidInput);
    assert_eq!(out.robotic, SubsystemStatus::Active);

    let out = c.command(&initial_input(&s, f64::NAN));
    assert_eq!(out.robotic, SubsystemStatus::InvalidInput);
    assert!(out.f_h == Vec3::zeros() && out.tau_m == Vector7::zeros());
}

#[test]
fn grasp_mode_reaches_the_tumbling_grasping_point() {
    // Base held at the GfC point, attitude F_R (boresight at the target), target
    // tumbling at ω_T; fixed-base arm dynamics with the nominal torques.
    let (s, c) = setup();
    let robot = c.robot().clone();
    let mut x = initial_input(&s, 120.0);
    x.r_r = Vec3::new(-2.2, 0.0, 0.0);
    x.v_r = Vec3::zeros();
    let w_t = x.omega_t;
    let h = 0.01;
    let mut dist = f64::INFINITY;
    let mut rel_speed = f64::INFINITY;
    for k in 0..400 {
        x.t = 120.0 + 0.1 * k as f64;
        let out = c.command(&x);
        assert_eq!(out.robotic, SubsystemStatus::Active);
        let tau = out.tau_m;
        for _ in 0..10 {
            let f =
                |th: &Vector7, thd: &Vector7| robot.arm_forward_dynamics(th, thd, &tau).unwrap();
            let (th, thd) = (x.theta, x.theta_dot);
            let a1 = f(&th, &thd);
            let (t2, v2) = (th + thd * (h / 2.0), thd + a1 * (h / 2.0));
            let a2 = f(&t2, &v2);
            let (t3, v3) = (th + v2 * (h / 2.0), thd + a2 * (h / 2.0));
            let a3 = f(&t3, &v3);
            let (t4, v4) = (th + v3 * h, thd + a3 * h);
            let a4 = f(&t4, &v4);
            x.theta += (thd + 2.0 * v2 + 2.0 * v3 + v4) * (h / 6.0);
            x.theta_dot += (a1 + 2.0 * a2 + 2.0 * a3 + a4) * (h / 6.0);
            x.q_rt = quat::normalized(&quat::integrate_body_rate(&x.q_rt, &w_t, h)).unwrap();
        }
        let (p_g, v_g) = c.grasp_point_r(&x.q_rt, &x.omega_t).unwrap();
        let kin = robot.kinematics(&x.theta);
        let p_e = x.r_r + robot.ee_position(&kin);
        let v_e = (robot.ee_jacobian(&kin) * x.theta_dot)
            .fixed_rows::<3>(0)
            .into_owned();
        dist = (p_e - p_g).norm();
        rel_speed = (v_e - v_g).norm();
    }
    eprintln!(
        "after 40 s of grasping: |p_E − p_G| = {dist:.2e} m, relative speed {rel_speed:.2e} m/s"
    );
    assert!(dist < s.mission.capture_tolerance_m);
    assert!(rel_speed < s.mission.capture_speed_tolerance_m_s);
}
