//! Robotic controller on the scenario's URDF arm: DLS IK and PD computed torque.

use nalgebra::Vector3;
use sc_multibody::{Robot, Vector7};
use sc_nominal::robotic::{RoboticController, RoboticGains};
use sc_scenario::Scenario;
use std::path::Path;

fn setup() -> (Robot, RoboticController, Vector7) {
    let s =
        Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml"))
            .unwrap();
    let robot = Robot::from_urdf_file(&s.urdf_path()).unwrap();
    let nr = &s.nominal.robotic;
    let ctl = RoboticController::new(
        RoboticGains {
            kp: nr.kp_per_s2,
            kd: nr.kd_per_s,
            ik_iterations: nr.ik_iterations,
            ik_damping: nr.ik_damping,
            ik_tolerance: nr.ik_tolerance_m,
        },
        &robot,
    )
    .unwrap();
    (robot, ctl, Vector7::from(s.servicer.initial_theta_rad))
}

#[test]
fn ik_reaches_reachable_points() {
    let (robot, ctl, theta0) = setup();
    // grasping point seen from the GfC point, and other points in the workspace
    for p in [
        Vector3::new(1.65, 0.12, 0.0),
        Vector3::new(1.65, -0.12, 0.05),
        Vector3::new(1.3, 0.3, -0.4),
        Vector3::new(1.9, 0.0, 0.2),
    ] {
        let sol = ctl.inverse_kinematics(&robot, &p, &theta0);
        let reached = robot.ee_position(&robot.kinematics(&sol.theta));
        assert!(
            sol.converged,
            "{p:?}: error {} after {} it",
            sol.error_m, sol.iterations
        );
        assert!((reached - p).norm() <= ctl.gains().ik_tolerance * 1.0001);
        assert!((reached - p).norm() - sol.error_m < 1e-12);
        let (lo, hi, _, _) = robot.joint_limit_arrays();
        for i in 0..7 {
            assert!(sol.theta[i] >= lo[i] && sol.theta[i] <= hi[i]);
        }
    }
}

#[test]
fn ik_reports_unreachable_points_without_nan() {
    let (robot, ctl, theta0) = setup();
    for p in [
        Vector3::new(6.0, 0.0, 0.0),
        Vector3::new(0.0, 0.0, 5.0),
        Vector3::new(-3.0, 1.0, 1.0),
    ] {
        let sol = ctl.inverse_kinematics(&robot, &p, &theta0);
        assert!(!sol.converged);
        assert!(sol.error_m.is_finite() && sol.error_m > 0.5);
        assert!(sol.theta.iter().all(|x| x.is_finite()));
        assert_eq!(sol.iterations, ctl.gains().ik_iterations);
    }
    // non-finite goal or start: reported, no panic, no NaN
    let sol = ctl.inverse_kinematics(&robot, &Vector3::new(f64::NAN, 0.0, 0.0), &theta0);
    assert!(!sol.converged && sol.theta.iter().all(|x| x.is_finite()));
    let mut bad = theta0;
    bad[3] = f64::INFINITY;
    let sol = ctl.inverse_kinematics(&robot, &Vector3::new(1.6, 0.0, 0.0), &bad);
    assert!(!sol.converged && sol.theta.iter().all(|x| x.is_finite()));
}

/// RK4 of the fixed-base arm `M θ̈ + C θ̇ = τ` with the controller in the loop (ZOH at
/// 0.1 s, 10 substeps).
fn simulate(
    robot: &Robot,
    ctl: &RoboticController,
    theta0: Vector7,
    goal: Vector7,
    seconds: f64,
) -> (Vector7, Vector7) {
    let (mut th, mut thd) = (theta0, Vector7::zeros());
    let h = 0.01;
    for _ in 0..(seconds / 0.1).round() as usize {
        let c = ctl.computed_torque(robot, &th, &thd, &goal, &Vector7::zeros());
        assert!(c.valid);
        let f =
            |th: &Vector7, thd: &Vector7| robot.arm_forward_dynamics(th, thd, &c.tau_m).unwrap();
        for _ in 0..10 {
            let a1 = f(&th, &thd);
            let (t2, v2) = (th + thd * (h / 2.0), thd + a1 * (h / 2.0));
            let a2 = f(&t2, &v2);
            let (t3, v3) = (th + v2 * (h / 2.0), thd + a2 * (h / 2.0));
            let a3 = f(&t3, &v3);
            let (t4, v4) = (th + v3 * h, thd + a3 * h);
            let a4 = f(&t4, &v4);
            th += (thd + 2.0 * v2 + 2.0 * v3 + v4) * (h / 6.0);
            thd += (a1 + 2.0 * a2 + 2.0 * a3 + a4) * (h / 6.0);
        }
    }
    (th, thd)
}

#[test]
fn computed_torque_drives_fixed_base_arm_to_ik_goal() {
    let (robot, ctl, theta0) = setup();
    let p = Vector3::new(1.65, 0.12, 0.0);
    let goal = ctl.inverse_kinematics(&robot, &p, &theta0);
    assert!(goal.converged);
    // k_p = 0.6, k_d = 1.6: ζ ≈ 1, ω_n ≈ 0.77 rad/s; 25 s ≈ 20 time constants
    let (th, thd) = simulate(&robot, &ctl, theta0, goal.theta, 25.0);
    let e = (th - goal.theta).amax();
    let ee = robot.ee_position(&robot.kinematics(&th));
    assert!(e < 1e-4, "joint error {e}");
    assert!(thd.amax() < 1e-4);
    assert!((ee - p).norm() < 1e-3);
}

#[test]
fn computed_torque_holds_and_rejects_bad_input() {
    let (robot, ctl, theta0) = setup();
    let c = ctl.computed_torque(
        &robot,
        &theta0,
        &Vector7::zeros(),
        &theta0,
        &Vector7::zeros(),
    );
    assert!(c.valid && c.tau_m.amax() < 1e-12);
    let mut bad = Vector7::zeros();
    bad[2] = f64::NAN;
    let c = ctl.computed_torque(&robot, &theta0, &bad, &theta0, &Vector7::zeros());
    assert!(!c.valid && c.tau_m == Vector7::zeros());
}
