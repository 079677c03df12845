//! Kinematics: Jacobians vs finite differences of FK, J̇θ̇ vs finite differences of Jθ̇ along
//! a trajectory, and the design properties of config/servicer.urdf (stowed clearance, reach).

mod common;

use common::{Rng, robots, servicer};
use nalgebra::{Matrix3, Vector3};
use sc_multibody::{NJ, Robot, Vector7};

fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    let s = (m - m.transpose()) * 0.5;
    Vector3::new(s[(2, 1)], s[(0, 2)], s[(1, 0)])
}

fn unit(i: usize) -> Vector7 {
    let mut e = Vector7::zeros();
    e[i] = 1.0;
    e
}

#[test]
fn jacobians_match_finite_differences_of_fk() {
    let h = 1e-6;
    for (name, r) in robots() {
        let mut rng = Rng::new(7);
        for _ in 0..20 {
            let th = rng.theta(&r);
            let kin = r.kinematics(&th);
            let je = r.ee_jacobian(&kin);
            for j in 0..NJ {
                let kp = r.kinematics(&(th + unit(j) * h));
                let km = r.kinematics(&(th - unit(j) * h));
                let dp = (r.ee_position(&kp) - r.ee_position(&km)) / (2.0 * h);
                let dr = (r.ee_rotation(&kp) - r.ee_rotation(&km)) / (2.0 * h);
                let w = vee(&(dr * r.ee_rotation(&kin).transpose()));
                for k in 0..3 {
                    assert!(
                        (je[(k, j)] - dp[k]).abs() < 1e-8,
                        "{name} J_E lin ({k},{j})"
                    );
                    assert!(
                        (je[(3 + k, j)] - w[k]).abs() < 1e-8,
                        "{name} J_E ang ({k},{j})"
                    );
                }
                for (idx, s) in r.collision_spheres().iter().enumerate() {
                    let js = r.sphere_state(&kin, idx).unwrap().jacobian;
                    let pp = r.point_position(&kp, s.link, &s.center).unwrap();
                    let pm = r.point_position(&km, s.link, &s.center).unwrap();
                    let d = (pp - pm) / (2.0 * h);
                    for k in 0..3 {
                        assert!((js[(k, j)] - d[k]).abs() < 1e-8, "{name} sphere {idx} J");
                    }
                }
            }
        }
    }
}

#[test]
fn jdot_qdot_matches_finite_differences_along_trajectory() {
    // θ(t) = θ0 + θ̇ t (θ̈ = 0): d/dt [J(θ(t)) θ̇] = J̇ θ̇.
    let h = 1e-5;
    for (name, r) in robots() {
        let mut rng = Rng::new(11);
        for _ in 0..20 {
            let th = rng.theta(&r);
            let qd = rng.vec7(0.6);
            let kin = r.kinematics_vel(&th, &qd);
            let kp = r.kinematics(&(th + qd * h));
            let km = r.kinematics(&(th - qd * h));
            let fd = (r.ee_jacobian(&kp) * qd - r.ee_jacobian(&km) * qd) / (2.0 * h);
            let an = r.ee_jdot_qdot(&kin);
            assert!((fd - an).amax() < 1e-8, "{name} EE J̇θ̇: {fd} vs {an}");
            for (idx, st) in r.sphere_states(&kin).iter().enumerate() {
                let jp = r.sphere_state(&kp, idx).unwrap().jacobian * qd;
                let jm = r.sphere_state(&km, idx).unwrap().jacobian * qd;
                let fd = (jp - jm) / (2.0 * h);
                assert!((fd - st.jdot_qdot).amax() < 1e-8, "{name} sphere {idx} J̇θ̇");
                // velocity consistency: J θ̇ = velocity from the recursion
                let v = kin.vel[st.link]
                    + kin.omega[st.link].cross(&(st.center - kin.pose[st.link].trans));
                assert!((st.jacobian * qd - v).amax() < 1e-12);
            }
        }
    }
}

/// Minimum over the arm spheres of `‖p_i − c_base‖ − (ρ_i + R_base)` (m).
fn base_clearance(r: &Robot, th: &Vector7) -> f64 {
    let base = r.base_sphere().expect("base sphere");
    let kin = r.kinematics(th);
    r.sphere_states(&kin)
        .iter()
        .filter(|s| s.link > 0)
        .map(|s| (s.center - base.center).norm() - (s.radius + base.radius))
        .fold(f64::INFINITY, f64::min)
}

pub const THETA0_DEG: [f64; 7] = [0.0, -75.0, 0.0, 150.0, 0.0, -75.0, 0.0];

#[test]
fn servicer_design_properties() {
    let r = servicer();
    assert_eq!(r.joint_names().len(), 7);
    let arm_mass = r.total_mass() - r.base_mass();
    assert!((r.base_mass() - 250.0).abs() < 1e-12);
    assert!((15.0..=25.0).contains(&arm_mass), "arm mass {arm_mass}");
    assert!(r.base_com().norm() < 1e-15, "base origin is the bus CoM");
    let (lo, hi, vel, eff) = r.joint_limit_arrays();
    for i in 0..NJ {
        assert!(lo[i] < 0.0 && hi[i] > 0.0);
        assert!((0.2..=0.5).contains(&vel[i]));
        assert!(eff[i] >= 2.0);
    }
    // exactly one base sphere, three per arm link
    assert_eq!(
        r.collision_spheres().iter().filter(|s| s.link == 0).count(),
        1
    );
    for k in 1..=NJ {
        assert_eq!(
            r.collision_spheres().iter().filter(|s| s.link == k).count(),
            3
        );
    }
    // reach: fully stretched along +x
    let kin = r.kinematics(&Vector7::zeros());
    let mount = kin.pose[1].trans;
    let reach = (r.ee_position(&kin) - mount).norm();
    assert!((1.4..=1.6).contains(&reach), "reach {reach}");
    assert!(mount.x > 0.5, "arm mounted in front of the +x face");
}

#[test]
fn stowed_configuration_is_clear_of_the_base() {
    let r = servicer();
    let th0 = Vector7::from_fn(|i, _| THETA0_DEG[i].to_radians());
    let (lo, hi, _, _) = r.joint_limit_arrays();
    for i in 0..NJ {
        assert!(
            th0[i] > lo[i] + 0.1 && th0[i] < hi[i] - 0.1,
            "θ0 inside limits"
        );
    }
    let clr = base_clearance(&r, &th0);
    eprintln!("stowed clearance to base sphere: {clr:.4} m");
    assert!(clr >= 0.08, "stowed clearance {clr}");
    let kin = r.kinematics(&th0);
    eprintln!("stowed EE at {:?}", r.ee_position(&kin).as_slice());
}

#[test]
fn reach_configuration_puts_ee_1p1_m_in_front_of_the_mount() {
    let r = servicer();
    let th =
        Vector7::from_column_slice(&[0.0, -47.0, 0.0, 94.0, 0.0, -47.0, 0.0]).map(f64::to_radians);
    let kin = r.kinematics(&th);
    let mount = kin.pose[1].trans;
    let d = r.ee_position(&kin) - mount;
    eprintln!("reach config: EE - mount = {:?}", d.as_slice());
    assert!((1.0..=1.2).contains(&d.x) && d.yz().norm() < 1e-9);
    assert!(base_clearance(&r, &th) > 0.05);
}

/// The system CoM's terms agree with `center_of_mass` and `center_of_mass_velocity` and
/// with finite differences: `J_c` along each joint, `J̇_c θ̇` along the motion.
#[test]
fn com_terms_match_the_com_and_finite_differences() {
    for (name, r) in robots() {
        let mut rng = Rng::new(23);
        for _ in 0..20 {
            let th = rng.theta(&r);
            let qd = rng.vec7(0.5);
            let kin = r.kinematics_vel(&th, &qd);
            let t = r.com_terms(&kin);
            assert_eq!(r.com_motion(&kin), (t.position, t.velocity), "{name}");
            assert!(
                (t.position - r.center_of_mass(&th)).norm() < 1e-14,
                "{name}"
            );
            let v = r.center_of_mass_velocity(&th, &qd);
            assert!((t.velocity - v).norm() < 1e-13, "{name}");
            assert!((t.jacobian * qd - v).norm() < 1e-13, "{name}");
            let h = 1e-6;
            let vel_at = |s: f64| r.center_of_mass_velocity(&(th + qd * s), &qd);
            let fd = (vel_at(h) - vel_at(-h)) / (2.0 * h);
            assert!(
                (t.jdot_qdot - fd).norm() < 1e-7,
                "{name}: {} vs {fd}",
                t.jdot_qdot
            );
        }
    }
}
