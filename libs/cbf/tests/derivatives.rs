//! Each constraint's value, Lie derivatives and sign convention against an independent
//! computation: the model is integrated a tiny step forward and backward with a fixed input
//! and `ḣ`, `ḧ` are compared with central differences of `h` along that trajectory.

mod common;
use common::*;
use nalgebra::{Matrix3, Vector3};
use sc_cbf::attitude::{self, AttitudeFilter};
use sc_cbf::robotic::{self, RoboticFilter, Vector7};
use sc_cbf::translational::{self, TranslationalFilter};
use sc_models::quat;

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol * (1.0 + b.abs()), "{what}: {a} vs {b}");
}

/// Fourth-order central differences of a scalar trajectory h(t): (ḣ, ḧ).
fn fd(h: impl Fn(f64) -> f64, dt: f64) -> (f64, f64) {
    let (h2, h1, h0, hm1, hm2) = (h(2.0 * dt), h(dt), h(0.0), h(-dt), h(-2.0 * dt));
    (
        (-h2 + 8.0 * h1 - 8.0 * hm1 + hm2) / (12.0 * dt),
        (-h2 + 16.0 * h1 - 30.0 * h0 + 16.0 * hm1 - hm2) / (12.0 * dt * dt),
    )
}

// ---------------------------------------------------------------- translational

/// CW + rotating corridor axis, RK4 with `steps` sub-steps to time `t`.
#[allow(clippy::too_many_arguments)]
fn tr_traj(
    n: f64,
    m: f64,
    f: Vector3<f64>,
    r0: Vector3<f64>,
    v0: Vector3<f64>,
    d0: Vector3<f64>,
    w0: Vector3<f64>,
    wd: Vector3<f64>,
    t: f64,
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let deriv = |tt: f64, r: &Vector3<f64>, v: &Vector3<f64>, d: &Vector3<f64>| {
        let a = translational::cw_drift(n, r, v) + f / m;
        let w = w0 + wd * tt;
        (*v, a, -w.cross(d))
    };
    let steps = 20;
    let h = t / steps as f64;
    let (mut r, mut v, mut d) = (r0, v0, d0);
    for k in 0..steps {
        let tt = k as f64 * h;
        let k1 = deriv(tt, &r, &v, &d);
        let k2 = deriv(
            tt + h / 2.0,
            &(r + k1.0 * h / 2.0),
            &(v + k1.1 * h / 2.0),
            &(d + k1.2 * h / 2.0),
        );
        let k3 = deriv(
            tt + h / 2.0,
            &(r + k2.0 * h / 2.0),
            &(v + k2.1 * h / 2.0),
            &(d + k2.2 * h / 2.0),
        );
        let k4 = deriv(tt + h, &(r + k3.0 * h), &(v + k3.1 * h), &(d + k3.2 * h));
        r += (k1.0 + k2.0 * 2.0 + k3.0 * 2.0 + k4.0) * (h / 6.0);
        v += (k1.1 + k2.1 * 2.0 + k3.1 * 2.0 + k4.1) * (h / 6.0);
        d += (k1.2 + k2.2 * 2.0 + k3.2 * 2.0 + k4.2) * (h / 6.0);
    }
    (r, v, d)
}

#[test]
fn translational_lie_derivatives_match_finite_differences() {
    let s = scenario();
    let mut rng = Lcg(7);
    let filt = TranslationalFilter::from_scenario(&s, MASS);
    let p = filt.params.clone();
    for case in 0..20 {
        let mut x = tr_input(
            &s,
            Vector3::new(-6.0, 0.3, -0.2) + rng.v3(1.5),
            rng.v3(0.05),
            quat::IDENTITY,
        );
        // a general (non-circular) Hill-frame motion to exercise ω̇_H too
        x.omega_h = Vector3::new(0.0, 0.0, p.mean_motion) + rng.v3(0.01);
        x.omega_dot_h = rng.v3(0.001);
        let f = rng.v3(7.0);
        let terms = filt.constraints(&x).unwrap();
        let d0 = quat::to_matrix(&x.q_hr) * p.axis_r;
        let traj = |t: f64| {
            tr_traj(
                p.mean_motion,
                p.mass,
                f,
                x.r_h,
                x.v_h,
                d0,
                x.omega_h,
                x.omega_dot_h,
                t,
            )
        };
        let h_ac = |t: f64| {
            let (r, _, d) = traj(t);
            d.dot(&r) - r.norm() * p.cos_psi
        };
        let h_caz = |t: f64| {
            let (r, _, _) = traj(t);
            r.dot(&r) - p.r_caz * p.r_caz
        };
        for (k, h) in [&h_ac as &dyn Fn(f64) -> f64, &h_caz].iter().enumerate() {
            let (hd, hdd) = fd(h, 1e-2);
            close(
                terms[k].h,
                h(0.0),
                1e-12,
                &format!("case {case} {} h", translational::NAMES[k]),
            );
            close(
                terms[k].hdot,
                hd,
                1e-7,
                &format!("case {case} {} ḣ", translational::NAMES[k]),
            );
            close(
                terms[k].hddot(&f),
                hdd,
                1e-5,
                &format!("case {case} {} ḧ", translational::NAMES[k]),
            );
        }
    }
}

#[test]
fn translational_sign_convention() {
    let s = scenario();
    let filt = TranslationalFilter::from_scenario(&s, MASS);
    let z = Vector3::zeros();
    // on the corridor axis, outside the CAZ: both safe
    let t = filt
        .constraints(&tr_input(
            &s,
            Vector3::new(-5.0, 0.0, 0.0),
            z,
            quat::IDENTITY,
        ))
        .unwrap();
    assert!(t[0].h > 0.0 && t[1].h > 0.0);
    // 10° off the axis: outside the 5° cone
    let a = 10f64.to_radians();
    let t = filt
        .constraints(&tr_input(
            &s,
            Vector3::new(-5.0 * a.cos(), 5.0 * a.sin(), 0.0),
            z,
            quat::IDENTITY,
        ))
        .unwrap();
    assert!(t[0].h < 0.0 && t[1].h > 0.0);
    // inside the CAZ (on the axis): corridor fine, CAZ violated
    let t = filt
        .constraints(&tr_input(
            &s,
            Vector3::new(-1.0, 0.0, 0.0),
            z,
            quat::IDENTITY,
        ))
        .unwrap();
    assert!(t[0].h > 0.0 && t[1].h < 0.0);
    // approaching the CAZ: ḣ_CAZ < 0; thrust away from the target raises ḧ_CAZ
    let x = tr_input(
        &s,
        Vector3::new(-3.0, 0.0, 0.0),
        Vector3::new(0.05, 0.0, 0.0),
        quat::IDENTITY,
    );
    let t = filt.constraints(&x).unwrap();
    assert!(t[1].hdot < 0.0);
    assert!(t[1].hddot_u.dot(&x.r_h) > 0.0);
}

// ---------------------------------------------------------------- attitude

#[test]
fn attitude_lie_derivatives_match_finite_differences() {
    let filt = AttitudeFilter::from_scenario(&scenario());
    let p = filt.params.clone();
    let mut rng = Lcg(11);
    for case in 0..20 {
        let q0 = quat::normalized(&[1.0, rng.next() * 0.05, rng.next() * 0.05, rng.next() * 0.05])
            .unwrap();
        let x = att_input(
            Vector3::new(-3.0, 0.1, -0.1) + rng.v3(0.5),
            q0,
            rng.v3(0.1),
            rng.next() * 40.0,
        );
        let tau = rng.v3(10.0);
        let terms = filt.constraints(&x).unwrap();
        let ii = x.inertia.try_inverse().unwrap();
        let wt_r = x.grasp_vel_r.cross(&x.grasp_r) / 1.0; // not used; grasp motion below
        let _ = wt_r;
        let wt = Vector3::new(-0.08, 0.0, 0.0);
        let acc = x.a_drift_r + x.xi_r;
        // independent trajectory: rigid body (RK4 on q, ω), servicer with constant acceleration,
        // grasp point rotating at ω_T about the target CoM
        let traj_h = |t: f64| {
            let steps = 20;
            let h = t / steps as f64;
            let (mut q, mut w) = (x.q_rb, x.omega_b);
            let f = |q: &quat::Quat, w: &Vector3<f64>| {
                (
                    quat::kinematics(q, w),
                    ii * (tau - w.cross(&(x.inertia * w))),
                )
            };
            let add = |q: &quat::Quat, d: &quat::Quat, s: f64| {
                [
                    q[0] + d[0] * s,
                    q[1] + d[1] * s,
                    q[2] + d[2] * s,
                    q[3] + d[3] * s,
                ]
            };
            for _ in 0..steps {
                let (k1q, k1w) = f(&q, &w);
                let (k2q, k2w) = f(&add(&q, &k1q, h / 2.0), &(w + k1w * h / 2.0));
                let (k3q, k3w) = f(&add(&q, &k2q, h / 2.0), &(w + k2w * h / 2.0));
                let (k4q, k4w) = f(&add(&q, &k3q, h), &(w + k3w * h));
                for k in 0..4 {
                    q[k] += h / 6.0 * (k1q[k] + 2.0 * k2q[k] + 2.0 * k3q[k] + k4q[k]);
                }
                w += (k1w + 2.0 * k2w + 2.0 * k3w + k4w) * (h / 6.0);
            }
            let r = x.r_r + x.v_r * t + acc * (0.5 * t * t);
            let g = quat::to_matrix(&quat::from_axis_angle(&wt, wt.norm() * t)) * x.grasp_r;
            let s_r = (g - r).normalize();
            let q = quat::normalized(&q).unwrap();
            p.boresight_b.dot(&(quat::to_matrix(&q).transpose() * s_r)) - p.cos_beta
        };
        let (hd, hdd) = fd(traj_h, 1e-3);
        close(
            terms.los.h,
            traj_h(0.0),
            1e-12,
            &format!("case {case} los h"),
        );
        close(terms.los.hdot, hd, 1e-7, &format!("case {case} los ḣ"));
        close(
            terms.los.hddot(&tau),
            hdd,
            1e-5,
            &format!("case {case} los ḧ"),
        );
        // rate limits: ḣ = ∓ω̇_i
        let wdot = ii * (tau - x.omega_b.cross(&(x.inertia * x.omega_b)));
        for i in 0..3 {
            close(terms.omega[i].hdot(&tau), -wdot[i], 1e-12, "omega_max ḣ");
            close(terms.omega[3 + i].hdot(&tau), wdot[i], 1e-12, "omega_min ḣ");
            close(
                terms.omega[i].h,
                p.omega_max[i] - x.omega_b[i],
                1e-15,
                "omega_max h",
            );
        }
    }
}

#[test]
fn attitude_sign_convention() {
    let filt = AttitudeFilter::from_scenario(&scenario());
    // boresight +x_B along the LOS (servicer on -x_R): inside the cone
    let x = att_input(
        Vector3::new(-3.0, 0.0, 0.0),
        quat::IDENTITY,
        Vector3::zeros(),
        0.0,
    );
    let t = filt.constraints(&x).unwrap();
    assert!(t.los.h > 0.0);
    assert!(t.omega.iter().all(|o| o.h > 0.0));
    // rotated by 20° about z: the grasping point leaves the 5° cone
    let q = quat::from_axis_angle(&Vector3::z(), 20f64.to_radians());
    let t = filt
        .constraints(&att_input(
            Vector3::new(-3.0, 0.0, 0.0),
            q,
            Vector3::new(0.3, 0.0, -0.25),
            0.0,
        ))
        .unwrap();
    assert!(t.los.h < 0.0);
    assert!(t.omega[0].h < 0.0 && t.omega[5].h < 0.0 && t.omega[3].h > 0.0);
    // unused import guard
    let _ = attitude::NAMES;
    let _ = Matrix3::<f64>::identity();
}

// ---------------------------------------------------------------- robotic

#[test]
fn robotic_model_terms_reproduce_free_flying_dynamics() {
    let s = scenario();
    let robot = robot();
    let mut rng = Lcg(3);
    for _ in 0..10 {
        let th = theta0(&s) + rng.v7(0.5);
        let thd = rng.v7(0.2);
        let w = rng.v3(0.05);
        let f = rng.v3(7.0);
        let tb = rng.v3(10.0);
        let tau = rng.v7(2.0);
        let x = sc_cbf::robotic_input_from_model(&robot, &th, &thd, &w, &f, &tb).unwrap();
        let mut nu = sc_multibody::Vector13::zeros();
        nu.fixed_rows_mut::<3>(0).copy_from(&rng.v3(0.1));
        nu.fixed_rows_mut::<3>(3).copy_from(&w);
        nu.fixed_rows_mut::<7>(6).copy_from(&thd);
        let mut u = sc_multibody::Vector13::zeros();
        u.fixed_rows_mut::<3>(0).copy_from(&f);
        u.fixed_rows_mut::<3>(3).copy_from(&tb);
        u.fixed_rows_mut::<7>(6).copy_from(&tau);
        let full: Vector7 = robot
            .forward_dynamics(&th, &nu, &u)
            .unwrap()
            .fixed_rows::<7>(6)
            .into();
        let ours = x.a * tau + x.drift + x.xi;
        assert!(
            (full - ours).norm() < 1e-8 * (1.0 + full.norm()),
            "{full} vs {ours}"
        );
    }
}

#[test]
fn robotic_lie_derivatives_match_finite_differences() {
    let s = scenario();
    let robot = robot();
    let filt = RoboticFilter::from_scenario(&s);
    let p = filt.params.clone();
    let base = robot.base_sphere().unwrap().clone();
    let mut rng = Lcg(5);
    for case in 0..10 {
        let th = theta0(&s) + rng.v7(0.6);
        let thd = rng.v7(0.25);
        let tau = rng.v7(2.0);
        let x = rob_input(&robot, th, thd);
        let terms = filt.constraints(&x).unwrap();
        let thdd = x.a * tau + x.drift + x.xi;
        // θ(t) with the true θ̈(0): exact up to second order in t
        let theta_at = |t: f64| th + thd * t + thdd * (0.5 * t * t);
        let arm: Vec<usize> = robot.arm_spheres().map(|(i, _)| i).collect();
        for i in 0..7 {
            let h = |t: f64| {
                let q = theta_at(t)[i];
                (q - p.theta_min[i]) * (p.theta_max[i] - q)
            };
            let (hd, hdd) = fd(h, 1e-3);
            close(terms.theta[i].h, h(0.0), 1e-12, "theta h");
            close(terms.theta[i].hdot, hd, 1e-7, "theta ḣ");
            close(
                terms.theta[i].hddot(&tau),
                hdd,
                1e-5,
                &format!("case {case} theta_{} ḧ", i + 1),
            );
            close(
                terms.theta_dot_max[i].hdot(&tau),
                -thdd[i],
                1e-12,
                "theta_dot_max ḣ",
            );
            close(
                terms.theta_dot_min[i].hdot(&tau),
                thdd[i],
                1e-12,
                "theta_dot_min ḣ",
            );
        }
        for (k, &idx) in arm.iter().enumerate() {
            let h = |t: f64| {
                let kin = robot.kinematics(&theta_at(t));
                let st = robot.sphere_state(&kin, idx).unwrap();
                let d = st.center - base.center;
                d.dot(&d) - (st.radius + base.radius).powi(2)
            };
            let (hd, hdd) = fd(h, 1e-3);
            let name = robotic::NAMES[21 + k];
            close(terms.link_base[k].h, h(0.0), 1e-12, name);
            close(terms.link_base[k].hdot, hd, 1e-7, name);
            close(
                terms.link_base[k].hddot(&tau),
                hdd,
                1e-5,
                &format!("case {case} {name} ḧ"),
            );
        }
    }
}

#[test]
fn robotic_sign_convention_and_sphere_order() {
    let s = scenario();
    let robot = robot();
    let filt = RoboticFilter::from_scenario(&s);
    let x = rob_input(&robot, theta0(&s), Vector7::zeros());
    let t = filt.constraints(&x).unwrap();
    assert!(
        t.h().iter().all(|h| *h > 0.0),
        "initial configuration is safe: {:?}",
        t.h()
    );
    // the spheres are link-major, three per link, matching the names
    let links: Vec<usize> = robot.arm_spheres().map(|(_, sp)| sp.link).collect();
    assert_eq!(links.len(), 21);
    for (k, l) in links.iter().enumerate() {
        assert_eq!(*l, k / 3 + 1);
        assert_eq!(
            robotic::NAMES[21 + k],
            format!("link_base_{}_{}", k / 3 + 1, k % 3 + 1)
        );
    }
    // beyond a joint limit / a rate limit: negative
    let mut th = theta0(&s);
    th[3] = s.safety.robotic.theta_max_rad[3] + 0.1;
    let mut thd = Vector7::zeros();
    thd[0] = 0.5;
    let t = filt.constraints(&rob_input(&robot, th, thd)).unwrap();
    assert!(t.theta[3].h < 0.0 && t.theta_dot_max[0].h < 0.0 && t.theta_dot_min[0].h > 0.0);
}
