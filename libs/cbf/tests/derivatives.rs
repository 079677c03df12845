//! Every barrier's value, Lie derivatives and input gain against an independent
//! computation: the true dynamics (CW for the servicer CoM, the 13-DoF multibody model for
//! the base and the arm) are integrated a tiny time forward and backward with a fixed input
//! and `ḣ`, `ḧ` are compared with central differences of `h` along that trajectory; input
//! gains with differences over the input.

mod common;
use common::*;
use nalgebra::{Vector3, Vector6};
use sc_cbf::attitude::{self, AttitudeFilter};
use sc_cbf::robotic::{self, RoboticFilter, Vector7};
use sc_cbf::sampled::RelDeg1;
use sc_cbf::translational::{self, TranslationalFilter, TranslationalParams};
use sc_models::quat;
use sc_multibody::Vector13;

/// `|a − b| ≤ tol · scale`.
fn close(a: f64, b: f64, tol: f64, scale: f64, what: &str) {
    assert!(
        (a - b).abs() <= tol * scale,
        "{what}: {a:e} vs {b:e} (diff {:e} > {:e})",
        (a - b).abs(),
        tol * scale
    );
}

/// Fourth-order central differences of a scalar trajectory h(t): (ḣ, ḧ).
fn fd(h: impl Fn(f64) -> f64, dt: f64) -> (f64, f64) {
    let (h2, h1, h0, hm1, hm2) = (h(2.0 * dt), h(dt), h(0.0), h(-dt), h(-2.0 * dt));
    (
        (-h2 + 8.0 * h1 - 8.0 * hm1 + hm2) / (12.0 * dt),
        (-h2 + 16.0 * h1 - 30.0 * h0 + 16.0 * hm1 - hm2) / (12.0 * dt * dt),
    )
}

/// One RK4 integration to time `t` (20 steps) of `ẏ = f(τ, y)`.
fn rk4<const K: usize>(
    f: impl Fn(f64, &nalgebra::SVector<f64, K>) -> nalgebra::SVector<f64, K>,
    y0: nalgebra::SVector<f64, K>,
    t: f64,
) -> nalgebra::SVector<f64, K> {
    let steps = 20;
    let h = t / steps as f64;
    let mut y = y0;
    for k in 0..steps {
        let tt = k as f64 * h;
        let k1 = f(tt, &y);
        let k2 = f(tt + h / 2.0, &(y + k1 * (h / 2.0)));
        let k3 = f(tt + h / 2.0, &(y + k2 * (h / 2.0)));
        let k4 = f(tt + h, &(y + k3 * h));
        y += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
    }
    y
}

// ---------------------------------------------------------------- translational

/// CW motion of the CoM in F_H under a force held in F_H, and the corridor axis carried by
/// the frame's rotation `ω(t) = ω₀ + ω̇ t` (`ḋ = −ω × d`): `(r, v, d)` at `t`.
#[allow(clippy::too_many_arguments)]
fn cw_traj(
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
    let mut y0 = nalgebra::SVector::<f64, 9>::zeros();
    y0.fixed_rows_mut::<3>(0).copy_from(&r0);
    y0.fixed_rows_mut::<3>(3).copy_from(&v0);
    y0.fixed_rows_mut::<3>(6).copy_from(&d0);
    let y = rk4(
        |tt, y| {
            let r: Vector3<f64> = y.fixed_rows::<3>(0).into();
            let v: Vector3<f64> = y.fixed_rows::<3>(3).into();
            let d: Vector3<f64> = y.fixed_rows::<3>(6).into();
            let a = translational::cw_drift(n, &r, &v) + f / m;
            let w = w0 + wd * tt;
            let mut out = nalgebra::SVector::<f64, 9>::zeros();
            out.fixed_rows_mut::<3>(0).copy_from(&v);
            out.fixed_rows_mut::<3>(3).copy_from(&a);
            out.fixed_rows_mut::<3>(6).copy_from(&(-w.cross(&d)));
            out
        },
        y0,
        t,
    );
    (
        y.fixed_rows::<3>(0).into(),
        y.fixed_rows::<3>(3).into(),
        y.fixed_rows::<3>(6).into(),
    )
}

#[test]
fn corridor_and_caz_terms_match_finite_differences_along_cw_motion_of_the_com() {
    let s = scenario();
    let mut rng = Lcg(7);
    let filt = TranslationalFilter::from_scenario(&s, mass());
    let p = filt.params.clone();
    for case in 0..40 {
        let mut x = tr_input(
            &s,
            Vector3::new(-6.0, 0.3, -0.2) + rng.v3(1.5),
            rng.v3(0.05),
            rng.unit_quat(),
            rng.v3(0.1),
        );
        if case % 2 == 1 {
            // a general (non-circular) frame motion exercises the ω_H and ω̇_H terms
            x.omega_h = Vector3::new(0.0, 0.0, p.mean_motion) + rng.v3(0.01);
            x.omega_dot_h = rng.v3(0.001);
        }
        let f = rng.v3(7.0);
        let terms = filt.constraints(&x).unwrap();
        let d0 = quat::to_matrix(&x.q_hr) * p.axis_r;
        let traj = |t: f64| {
            cw_traj(
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
            let name = translational::NAMES[k];
            let (hd, hdd) = fd(h, 1e-2);
            let sc = 1.0 + h(0.0).abs();
            close(
                terms[k].h,
                h(0.0),
                1e-14,
                sc,
                &format!("case {case} {name} h"),
            );
            close(
                terms[k].hdot,
                hd,
                1e-10,
                sc,
                &format!("case {case} {name} ḣ"),
            );
            close(
                terms[k].hddot(&f),
                hdd,
                1e-9,
                sc,
                &format!("case {case} {name} ḧ"),
            );
            // the input gain: ḧ is affine in f, difference over a 1 N step per axis
            for j in 0..3 {
                let mut f2 = f;
                f2[j] += 1.0;
                let traj2 = |t: f64| {
                    cw_traj(
                        p.mean_motion,
                        p.mass,
                        f2,
                        x.r_h,
                        x.v_h,
                        d0,
                        x.omega_h,
                        x.omega_dot_h,
                        t,
                    )
                };
                let h2 = |t: f64| {
                    let (r, _, d) = traj2(t);
                    if k == 0 {
                        d.dot(&r) - r.norm() * p.cos_psi
                    } else {
                        r.dot(&r) - p.r_caz * p.r_caz
                    }
                };
                let gain = fd(h2, 1e-2).1 - hdd;
                close(
                    terms[k].hddot_u[j],
                    gain,
                    1e-9,
                    sc,
                    &format!("case {case} {name} ∂ḧ/∂f_{j}"),
                );
            }
        }
    }
}

/// The tangential-speed row (`h_t = c_t ‖r‖ − ‖v_⊥‖²` in the inertially fixed F_R): the CW
/// motion is integrated in F_H, mapped to F_R with the frame's true rotation
/// `R_RH(t)` (position `R_RH r_H`, inertial velocity `R_RH (v_H + ω_H × r_H)`), and `h_t`
/// differenced there. Also with a mean motion 45× the scenario's, so that a frame error
/// (a missing `ω × r`, a drift in the wrong frame) would show.
#[test]
fn tangential_speed_row_matches_frame_consistent_finite_differences_in_f_r() {
    let s = scenario();
    let mut rng = Lcg(17);
    for n in [mean_motion(&s), 0.05] {
        let mut params = TranslationalParams::from_scenario(&s, mass());
        params.mean_motion = n;
        let filt = TranslationalFilter::new(params.clone());
        let p = &filt.params;
        let c_t = translational::tangential_coefficient(p);
        assert!(c_t > 0.0, "c_t = {c_t}");
        for case in 0..30 {
            let r_r = Vector3::new(-5.0, 0.2, -0.1) + rng.v3(2.0);
            let v_r = rng.v3(0.05);
            let q_hr0 = s.reference_frame.attitude_in_hill;
            let r_hr0 = quat::to_matrix(&q_hr0);
            let w = Vector3::new(0.0, 0.0, n);
            let r_h0 = r_hr0 * r_r;
            let v_h0 = r_hr0 * v_r - w.cross(&r_h0);
            let q_rb = rng.unit_quat();
            let mut x = sc_cbf::TranslationalInput::circular(r_h0, v_h0, q_hr0, n, q_rb);
            x.omega_b = rng.v3(0.1);
            let f_h = rng.v3(7.0);
            // the state in F_R along the true motion
            let state_r = |t: f64, f: &Vector3<f64>| {
                let (r_h, v_h, _) = cw_traj(
                    n,
                    p.mass,
                    *f,
                    r_h0,
                    v_h0,
                    Vector3::x(),
                    w,
                    Vector3::zeros(),
                    t,
                );
                let r_rh = quat::to_matrix(&q_hr_at(&s, n, t)).transpose();
                (r_rh * r_h, r_rh * (v_h + w.cross(&r_h)))
            };
            let h_t = |t: f64, f: &Vector3<f64>| {
                let (r, v) = state_r(t, f);
                let rhat = r.normalize();
                let vp = v - rhat * rhat.dot(&v);
                c_t * r.norm() - vp.norm_squared()
            };
            // the fixture's frame is consistent: the F_R velocity is the derivative of the
            // F_R position
            let (r_p, _) = state_r(1e-3, &f_h);
            let (r_m, _) = state_r(-1e-3, &f_h);
            let (r0, v0) = state_r(0.0, &f_h);
            assert!(((r_p - r_m) / 2e-3 - v0).norm() < 1e-8 * (1.0 + v0.norm()));
            assert!((r0 - r_r).norm() < 1e-12 * r_r.norm());
            // the terms from the independent F_R quantities
            let radial = r_hr0.transpose() * Vector3::x();
            let tidal = (radial * (3.0 * radial.dot(&r_r)) - r_r) * (n * n);
            let terms = translational::tangential_speed(&r_r, &v_r, &tidal, &r_hr0, p.mass, c_t);
            let sc = 1.0 + terms.h.abs();
            close(
                terms.h,
                h_t(0.0, &f_h),
                1e-13,
                sc,
                &format!("n {n} case {case} h_t"),
            );
            let (hd, _) = fd(|t| h_t(t, &f_h), 1e-2);
            close(
                terms.hdot(&f_h),
                hd,
                1e-10,
                sc,
                &format!("n {n} case {case} ḣ_t"),
            );
            for j in 0..3 {
                let mut f2 = f_h;
                f2[j] += 1.0;
                let gain = fd(|t| h_t(t, &f2), 1e-2).0 - hd;
                close(
                    terms.hdot_u[j],
                    gain,
                    1e-10,
                    1.0 + terms.hdot_u.norm(),
                    &format!("n {n} case {case} ∂ḣ_t/∂f_{j}"),
                );
            }
            // the filter builds its third row from exactly these terms
            let (rows, weights, _) = filt.rows(&x).unwrap();
            assert_eq!(rows.len(), translational::ROWS);
            assert_eq!(weights.len(), translational::ROWS);
            let axis = translational::corridor_axis(&r_hr0, &p.axis_r, &x.omega_h, &x.omega_dot_h);
            let (_, bt) = filt.sample_bounds(&x.r_h, &x.v_h, &x.omega_b, &axis);
            let row = RelDeg1::from(terms).row(&bt, p.gamma, 0.0);
            let scale = 1.0 + row.a.norm() + row.c.abs();
            assert!(
                (rows[2].a - row.a).norm() <= 1e-12 * scale
                    && (rows[2].c - row.c).abs() <= 1e-12 * scale,
                "n {n} case {case}: filter row {:?} vs independent {:?}",
                rows[2],
                row
            );
        }
    }
}

#[test]
fn translational_sign_convention() {
    let s = scenario();
    let filt = TranslationalFilter::from_scenario(&s, mass());
    let z = Vector3::zeros();
    let id = quat::IDENTITY;
    // on the corridor axis, outside the CAZ: both safe
    let t = filt
        .constraints(&tr_input(&s, Vector3::new(-5.0, 0.0, 0.0), z, id, z))
        .unwrap();
    assert!(t[0].h > 0.0 && t[1].h > 0.0);
    // 10° off the axis: outside the 5° cone
    let a = 10f64.to_radians();
    let t = filt
        .constraints(&tr_input(
            &s,
            Vector3::new(-5.0 * a.cos(), 5.0 * a.sin(), 0.0),
            z,
            id,
            z,
        ))
        .unwrap();
    assert!(t[0].h < 0.0 && t[1].h > 0.0);
    // inside the CAZ (on the axis): corridor fine, CAZ violated
    let t = filt
        .constraints(&tr_input(&s, Vector3::new(-1.0, 0.0, 0.0), z, id, z))
        .unwrap();
    assert!(t[0].h > 0.0 && t[1].h < 0.0);
    // approaching the CAZ: ḣ_CAZ < 0; thrust away from the target raises ḧ_CAZ
    let x = tr_input(
        &s,
        Vector3::new(-3.0, 0.0, 0.0),
        Vector3::new(0.05, 0.0, 0.0),
        id,
        z,
    );
    let t = filt.constraints(&x).unwrap();
    assert!(t[1].hdot < 0.0);
    assert!(t[1].hddot_u.dot(&x.r_h) > 0.0);
    // the third row exists and limits the speed across the line of sight: at rest it is
    // slack, moving fast sideways it binds against any force
    let (rows, _, _) = filt
        .rows(&tr_input(&s, Vector3::new(-3.0, 0.0, 0.0), z, id, z))
        .unwrap();
    assert!(rows[2].c > 0.0);
    let (rows, _, _) = filt
        .rows(&tr_input(
            &s,
            Vector3::new(-3.0, 0.0, 0.0),
            Vector3::new(0.0, 0.5, 0.0),
            id,
            z,
        ))
        .unwrap();
    assert!(rows[2].c < 0.0, "{:?}", rows[2]);
}

// ---------------------------------------------------------------- attitude

/// `ω̇_B` and `θ̈` of the 13-DoF model with the base wrench `[f; τ_B]` and the arm held by
/// `τ_hold = c_eff` (the torque that keeps the joint rates).
fn held_arm_acceleration(x: &ServicerState, tau_b: &Vector3<f64>) -> (Vector3<f64>, Vector7) {
    let robot = robot();
    let wrench = Vector6::new(x.f_b.x, x.f_b.y, x.f_b.z, tau_b.x, tau_b.y, tau_b.z);
    let red = robot
        .reduced_arm_dynamics(&x.theta, &x.theta_dot, &x.omega_b, &wrench)
        .unwrap();
    let mut u = Vector13::zeros();
    u.fixed_rows_mut::<3>(0).copy_from(&x.f_b);
    u.fixed_rows_mut::<3>(3).copy_from(tau_b);
    u.fixed_rows_mut::<7>(6).copy_from(&red.c_eff);
    let a = robot
        .forward_dynamics_sim(&x.theta, &x.omega_b, &x.theta_dot, &u)
        .unwrap();
    (a.fixed_rows::<3>(3).into(), a.fixed_rows::<7>(6).into())
}

/// The line-of-sight barrier along the true motion: the base turns with `ω(t) = ω₀ + ω̇ t`
/// (RK4 on the quaternion), the CoM moves with its drift and the upstream force's
/// acceleration, the grasping point with the tumbling target.
fn los_along(
    s: &sc_scenario::Scenario,
    x: &ServicerState,
    a_com: &Vector3<f64>,
    wdot: &Vector3<f64>,
    t: f64,
) -> f64 {
    let d_b = Vector3::from(s.servicer.boresight_body).normalize();
    let cos_beta = s.safety.attitude.los_half_angle_deg.to_radians().cos();
    let mut y0 = nalgebra::SVector::<f64, 4>::zeros();
    y0.copy_from_slice(&x.q_rb);
    let y = rk4(
        |tt, y| {
            let q = [y[0], y[1], y[2], y[3]];
            let w = x.omega_b + wdot * tt;
            nalgebra::SVector::<f64, 4>::from(quat::kinematics(&q, &w))
        },
        y0,
        t,
    );
    let q = quat::normalized(&[y[0], y[1], y[2], y[3]]).unwrap();
    let r = x.com_r + x.com_v_r * t + a_com * (0.5 * t * t);
    let g = grasp_at(s, x.t + t).0;
    d_b.dot(&(quat::to_matrix(&q).transpose() * (g - r).normalize())) - cos_beta
}

fn random_servicer_state(s: &sc_scenario::Scenario, rng: &mut Lcg) -> ServicerState {
    let com_r = Vector3::new(-3.0, 0.1, -0.1) + rng.v3(0.5);
    let t = 40.0 * (1.0 + rng.next());
    ServicerState {
        theta: theta_inside(s, rng, 0.05),
        theta_dot: rng.v7(0.2),
        omega_b: rng.v3(0.15),
        q_rb: pointing(s, &com_r, t, &rng.v3(1.0), 4f64.to_radians() * rng.next()),
        com_r,
        com_v_r: rng.v3(0.03),
        t,
        f_b: rng.v3(7.0),
    }
}

/// `ω̇ = P τ + r` of the attitude input (the base with the arm locked, from the model) is
/// the multibody forward dynamics when the arm holds its rates with `τ_hold = c_eff`, and
/// the line-of-sight and rate rows' `ḣ`, `ḧ`, `∂ḧ/∂τ` match finite differences along it.
#[test]
fn attitude_terms_match_the_multibody_model_with_the_arm_held() {
    let s = scenario();
    let robot = robot();
    let filt = AttitudeFilter::from_scenario(&s, mass());
    let p = filt.params.clone();
    let mut rng = Lcg(11);
    for case in 0..30 {
        let st = random_servicer_state(&s, &mut rng);
        let x = att_input(&s, &robot, &st);
        let tau = rng.v3(10.0);
        let terms = filt.constraints(&x).unwrap();
        let (wdot, qdd) = held_arm_acceleration(&st, &tau);
        // the arm is held: its joint rates do not change
        assert!(
            qdd.amax() < 1e-9 * (1.0 + st.theta_dot.amax()),
            "case {case}: θ̈ = {qdd}"
        );
        let model = x.p * tau + x.r;
        assert!(
            (model - wdot).norm() <= 1e-9 * ((x.p * tau).norm() + x.r.norm()),
            "case {case}: P τ + r = {model} vs multibody {wdot}"
        );
        // rate rows: h = ω_max − ω, ω − ω_min, ḣ = ∓ω̇
        for i in 0..3 {
            let sc = 1e-9 * (1.0 + wdot.norm());
            close(
                terms.omega[i].h,
                p.omega_max[i] - st.omega_b[i],
                1e-15,
                1.0,
                "omega_max h",
            );
            close(
                terms.omega[3 + i].h,
                st.omega_b[i] - p.omega_min[i],
                1e-15,
                1.0,
                "omega_min h",
            );
            close(terms.omega[i].hdot(&tau), -wdot[i], 1.0, sc, "omega_max ḣ");
            close(
                terms.omega[3 + i].hdot(&tau),
                wdot[i],
                1.0,
                sc,
                "omega_min ḣ",
            );
        }
        // line of sight along the true motion (the CoM is accelerated by drift + force)
        let a_com = x.a_drift_r + x.xi_r;
        let h = |t: f64| los_along(&s, &st, &a_com, &wdot, t);
        let (hd, hdd) = fd(h, 1e-2);
        close(
            terms.los.h,
            h(0.0),
            1e-14,
            1.0,
            &format!("case {case} los h"),
        );
        close(
            terms.los.hdot,
            hd,
            1e-10,
            1.0,
            &format!("case {case} los ḣ"),
        );
        close(
            terms.los.hddot(&tau),
            hdd,
            1e-9,
            1.0,
            &format!("case {case} los ḧ"),
        );
        // ∂ḧ/∂τ_B: ḧ is affine in τ_B (the held arm's torque is affine in it too)
        for k in 0..3 {
            let mut tau2 = tau;
            tau2[k] += 1.0;
            let (wdot2, _) = held_arm_acceleration(&st, &tau2);
            let gain = fd(|t| los_along(&s, &st, &a_com, &wdot2, t), 1e-2).1 - hdd;
            close(
                terms.los.hddot_u[k],
                gain,
                1e-9,
                1.0,
                &format!("case {case} los ∂ḧ/∂τ_{k}"),
            );
        }
    }
}

/// `sc_multibody::BaseAngularDynamics`: `ω̇ = P τ_B + Q τ_M + r = P_L τ_B + r_L + Q (τ_M −
/// τ_hold(τ_B))` with `τ_hold = c_eff` of the reduced arm dynamics for the same wrench,
/// against the simulator's forward dynamics at random states.
#[test]
fn base_angular_dynamics_identity_matches_forward_dynamics() {
    let s = scenario();
    let robot = robot();
    let mut rng = Lcg(23);
    for case in 0..200 {
        let th = theta_inside(&s, &mut rng, 0.0) + rng.v7(0.3);
        let thd = rng.v7(0.4);
        let w = rng.v3(0.3);
        let f = rng.v3(7.0);
        let tb = rng.v3(10.0);
        let tm = rng.v7(2.0);
        let mut u = Vector13::zeros();
        u.fixed_rows_mut::<3>(0).copy_from(&f);
        u.fixed_rows_mut::<3>(3).copy_from(&tb);
        u.fixed_rows_mut::<7>(6).copy_from(&tm);
        let truth: Vector3<f64> = robot
            .forward_dynamics_sim(&th, &w, &thd, &u)
            .unwrap()
            .fixed_rows::<3>(3)
            .into();
        let bd = robot.base_angular_dynamics(&th, &thd, &w, &f).unwrap();
        let red = robot
            .reduced_arm_dynamics(
                &th,
                &thd,
                &w,
                &Vector6::new(f.x, f.y, f.z, tb.x, tb.y, tb.z),
            )
            .unwrap();
        let free = bd.p * tb + bd.q * tm + bd.r;
        let locked = bd.p_locked * tb + bd.r_locked + bd.q * (tm - red.c_eff);
        let scale =
            (bd.p * tb).norm() + (bd.q * tm).norm() + bd.r.norm() + (bd.q * red.c_eff).norm();
        assert!(
            (free - truth).norm() <= 1e-9 * scale,
            "case {case}: P τ_B + Q τ_M + r = {free} vs {truth}"
        );
        assert!(
            (locked - truth).norm() <= 1e-9 * scale,
            "case {case}: P_L τ_B + r_L + Q (τ_M − τ_hold) = {locked} vs {truth}"
        );
        // P and P_L are symmetric positive definite
        for pm in [bd.p, bd.p_locked] {
            assert!((pm - pm.transpose()).norm() <= 1e-12 * pm.norm());
            assert!(pm.symmetric_eigenvalues().min() > 0.0);
        }
    }
}

#[test]
fn attitude_sign_convention() {
    let s = scenario();
    let robot = robot();
    let filt = AttitudeFilter::from_scenario(&s, mass());
    let com = Vector3::new(-3.0, 0.0, 0.0);
    // boresight exactly at the grasping point: inside the cone, rates inside the limits
    let st = ServicerState::rest(&s, com, pointing(&s, &com, 0.0, &Vector3::z(), 0.0));
    let t = filt.constraints(&att_input(&s, &robot, &st)).unwrap();
    assert!((t.los.h - (1.0 - filt.params.cos_beta)).abs() < 1e-12);
    assert!(t.omega.iter().all(|o| o.h > 0.0));
    // turned by 20° about z: the grasping point leaves the 5° cone
    let mut st2 = st;
    st2.q_rb = pointing(&s, &com, 0.0, &Vector3::z(), 20f64.to_radians());
    st2.omega_b = Vector3::new(0.3, 0.0, -0.25);
    let t = filt.constraints(&att_input(&s, &robot, &st2)).unwrap();
    assert!(t.los.h < 0.0);
    assert!(t.omega[0].h < 0.0 && t.omega[5].h < 0.0 && t.omega[3].h > 0.0);
    // turning the boresight further out (positive rate about z) lowers h: ḣ < 0
    st2.omega_b = Vector3::new(0.0, 0.0, 0.05);
    let t = filt.constraints(&att_input(&s, &robot, &st2)).unwrap();
    assert!(t.los.hdot < 0.0, "{}", t.los.hdot);
    assert_eq!(attitude::NAMES[0], "line_of_sight");
}

// ---------------------------------------------------------------- robotic

/// `θ̈ = A τ + b + ξ`, the reaction `Q` and the holding torque `τ_hold = −M_eff (b + ξ)`
/// of the robotic input against the 13-DoF forward dynamics; the spheres' Jacobians and
/// `J̇θ̇` against differences of the kinematics.
#[test]
fn robotic_input_reproduces_the_free_flying_dynamics() {
    let s = scenario();
    let robot = robot();
    let mut rng = Lcg(3);
    for case in 0..30 {
        let th = theta_inside(&s, &mut rng, 0.0);
        let thd = rng.v7(0.3);
        let w = rng.v3(0.1);
        let f = rng.v3(7.0);
        let tb = rng.v3(10.0);
        let tau = rng.v7(2.0);
        let x = sc_cbf::robotic_input_from_model(&robot, &th, &thd, &w, &f, &tb).unwrap();
        let fd_at = |tau: &Vector7| {
            let mut u = Vector13::zeros();
            u.fixed_rows_mut::<3>(0).copy_from(&f);
            u.fixed_rows_mut::<3>(3).copy_from(&tb);
            u.fixed_rows_mut::<7>(6).copy_from(tau);
            robot.forward_dynamics_sim(&th, &w, &thd, &u).unwrap()
        };
        let full = fd_at(&tau);
        let qdd: Vector7 = full.fixed_rows::<7>(6).into();
        let ours = x.a * tau + x.drift + x.xi;
        assert!(
            (qdd - ours).norm() < 1e-9 * (1.0 + qdd.norm()),
            "case {case}: θ̈ {qdd} vs {ours}"
        );
        // the reaction on the base per joint torque
        let w0: Vector3<f64> = fd_at(&Vector7::zeros()).fixed_rows::<3>(3).into();
        let w1: Vector3<f64> = full.fixed_rows::<3>(3).into();
        assert!(
            ((w1 - w0) - x.reaction * tau).norm() < 1e-9 * (1.0 + (w1 - w0).norm()),
            "case {case}: Q"
        );
        // the holding torque of the contract rows keeps the joint rates
        let hold = -(x.m_eff * (x.drift + x.xi));
        let held: Vector7 = fd_at(&hold).fixed_rows::<7>(6).into();
        assert!(
            held.amax() < 1e-9 * (1.0 + qdd.amax()),
            "case {case}: held θ̈ = {held}"
        );
        assert!((x.a * x.m_eff - sc_cbf::robotic::Matrix7::identity()).amax() < 1e-9);
        // spheres: J = ∂p/∂θ, J̇θ̇ = d/dt (J θ̇) along θ̇
        let e = 1e-6;
        for (k, sp) in x.spheres.iter().enumerate() {
            let center = |t: &Vector7| {
                let idx = robot.arm_spheres().nth(k).unwrap().0;
                robot.sphere_state(&robot.kinematics(t), idx).unwrap()
            };
            for j in 0..7 {
                let mut tp = th;
                tp[j] += e;
                let mut tm = th;
                tm[j] -= e;
                let col = (center(&tp).center - center(&tm).center) / (2.0 * e);
                assert!(
                    (col - sp.jacobian.column(j)).norm() < 1e-8,
                    "sphere {k} J col {j}"
                );
            }
            let jv = |t: f64| center(&(th + thd * t)).jacobian * thd;
            let jd = (jv(e) - jv(-e)) / (2.0 * e);
            assert!(
                (jd - sp.jdot_qdot).norm() < 1e-8,
                "sphere {k} J̇θ̇: {jd} vs {}",
                sp.jdot_qdot
            );
        }
    }
}

#[test]
fn robotic_barrier_terms_match_finite_differences() {
    let s = scenario();
    let robot = robot();
    let filt = RoboticFilter::from_scenario(&s, robot.clone());
    let p = filt.params.clone();
    let base = robot.base_sphere().unwrap().clone();
    let mut rng = Lcg(5);
    for case in 0..15 {
        let th = theta_inside(&s, &mut rng, 0.0);
        let thd = rng.v7(0.3);
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
            let (hd, hdd) = (fd(h, 1e-4).0, fd(h, 1e-3).1);
            let name = robotic::NAMES[i];
            close(terms.theta[i].h, h(0.0), 1e-14, 1.0, name);
            close(terms.theta[i].hdot, hd, 1e-10, 1.0, name);
            close(
                terms.theta[i].hddot(&tau),
                hdd,
                1e-7,
                1.0 + hdd.abs(),
                &format!("case {case} {name} ḧ"),
            );
            close(
                terms.theta_dot_max[i].h,
                p.theta_dot_max[i] - thd[i],
                1e-15,
                1.0,
                "rate h",
            );
            close(
                terms.theta_dot_min[i].h,
                thd[i] + p.theta_dot_max[i],
                1e-15,
                1.0,
                "rate h",
            );
            close(
                terms.theta_dot_max[i].hdot(&tau),
                -thdd[i],
                1e-12,
                1.0 + thdd[i].abs(),
                "θ̇_max ḣ",
            );
            close(
                terms.theta_dot_min[i].hdot(&tau),
                thdd[i],
                1e-12,
                1.0 + thdd[i].abs(),
                "θ̇_min ḣ",
            );
        }
        for (k, &idx) in arm.iter().enumerate() {
            let h = |t: f64| {
                let kin = robot.kinematics(&theta_at(t));
                let st = robot.sphere_state(&kin, idx).unwrap();
                let d = st.center - base.center;
                d.dot(&d) - (st.radius + base.radius).powi(2)
            };
            // ḣ from a shorter step: the light distal links' θ̈ of hundreds of rad/s² make
            // the trajectory's higher derivatives large
            let (hd, hdd) = (fd(h, 1e-4).0, fd(h, 1e-3).1);
            let name = robotic::NAMES[21 + k];
            close(terms.link_base[k].h, h(0.0), 1e-14, 1.0, name);
            close(terms.link_base[k].hdot, hd, 1e-10, 1.0, name);
            close(
                terms.link_base[k].hddot(&tau),
                hdd,
                1e-7,
                1.0 + hdd.abs(),
                &format!("case {case} {name} ḧ"),
            );
        }
    }
}

#[test]
fn robotic_sign_convention_and_sphere_order() {
    let s = scenario();
    let robot = robot();
    let filt = RoboticFilter::from_scenario(&s, robot.clone());
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
    // the pitch joints' limits exclude ±0.5 rad around 0
    for i in [1, 3, 5] {
        let (lo, hi) = (
            s.safety.robotic.theta_min_rad[i],
            s.safety.robotic.theta_max_rad[i],
        );
        assert!(hi <= -0.5 || lo >= 0.5, "joint {}: [{lo}, {hi}]", i + 1);
    }
}

// ---------------------------------------------------------------- monitor

/// The safety monitor (barriers from the true state, written independently of the filters)
/// and the filters' own barrier values agree at random consistent states, in
/// `sc_cbf::names` order (the paper's 51; the link–target rows in `sc_cbf::link_target`'s
/// tests: against the monitor, and against finite differences along the verification's
/// motion).
#[test]
fn monitor_barriers_equal_the_filters_barriers() {
    use sc_cbf::monitor::{Monitor, N_FILTERED as N_ALL};
    use sc_core::BarrierState;
    let s = scenario();
    let robot = robot();
    let monitor = Monitor::from_scenario(&s, robot.clone());
    let ft = TranslationalFilter::from_scenario(&s, mass());
    let fa = AttitudeFilter::from_scenario(&s, mass());
    let fr = RoboticFilter::from_scenario(&s, robot.clone());
    let mut rng = Lcg(31);
    for case in 0..50 {
        let st = random_servicer_state(&s, &mut rng);
        let h = monitor.evaluate(&BarrierState {
            t: 0.0,
            com_r: st.com_r,
            q_rb: st.q_rb,
            omega_b: st.omega_b,
            grasp_r: grasp_at(&s, st.t).0,
            theta: st.theta,
            theta_dot: st.theta_dot,
            base_r: st.com_r,
            q_rt: [1.0, 0.0, 0.0, 0.0],
        });
        let mut ours = Vec::with_capacity(N_ALL);
        let tr = ft
            .constraints(&tr_input(&s, st.com_r, st.com_v_r, st.q_rb, st.omega_b))
            .unwrap();
        ours.extend(tr.iter().map(|t| t.h));
        let at = fa.constraints(&att_input(&s, &robot, &st)).unwrap();
        ours.push(at.los.h);
        ours.extend(at.omega.iter().map(|o| o.h));
        let rb = fr
            .constraints(&rob_input(&robot, st.theta, st.theta_dot))
            .unwrap();
        ours.extend(rb.h());
        assert_eq!(ours.len(), N_ALL);
        // the link–target rows of an input from the model alone know no target
        ours.truncate(sc_cbf::robotic::LINK_TARGET + 9);
        for (i, (a, b)) in h.iter().zip(&ours).enumerate() {
            assert!(
                (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                "case {case} {}: monitor {a} vs filter {b}",
                [
                    &sc_cbf::names::TRANSLATIONAL[..],
                    &sc_cbf::names::ATTITUDE[..],
                    &sc_cbf::names::ROBOTIC[..]
                ]
                .concat()[i]
            );
        }
    }
}

/// The certified set's boresight-rate rows (`attitude::boresight_rate`): the two axes
/// are orthonormal and across the boresight, and `ḣ = hdot_drift + hdot_u·τ` matches the
/// finite difference of `h = w̄ ∓ e_kᵀω` along `ω̇ = Pτ + r`, for random states.
#[test]
fn boresight_rate_rows_match_finite_differences() {
    let mut rng = 0x5eedu64;
    let mut r = || {
        rng = rng
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((rng >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    for _ in 0..200 {
        let d = Vector3::new(r(), r(), r()).normalize();
        let [e1, e2] = attitude::across_boresight(&d);
        assert!((e1.norm() - 1.0).abs() < 1e-12 && (e2.norm() - 1.0).abs() < 1e-12);
        assert!(e1.dot(&d).abs() < 1e-12 && e2.dot(&d).abs() < 1e-12 && e1.dot(&e2).abs() < 1e-12);
        let omega = Vector3::new(r(), r(), r()) * 0.1;
        let p = nalgebra::Matrix3::from_fn(|_, _| r() * 0.02);
        let drift = Vector3::new(r(), r(), r()) * 0.01;
        let tau = Vector3::new(r(), r(), r()) * 10.0;
        let w_max = 0.06;
        let rows = attitude::boresight_rate(&omega, &p, &drift, &d, w_max);
        let dt = 1e-6;
        let omega_next = omega + (p * tau + drift) * dt;
        let next = attitude::boresight_rate(&omega_next, &p, &drift, &d, w_max);
        for k in 0..4 {
            let fd = (next[k].h - rows[k].h) / dt;
            let analytic = rows[k].hdot_drift + rows[k].hdot_u.dot(&tau);
            assert!(
                (fd - analytic).abs() <= 1e-8 * (1.0 + analytic.abs()),
                "row {k}: finite difference {fd}, analytic {analytic}"
            );
        }
        // the four rows are ± the two axes: h sums to 2 w̄ per axis
        assert!((rows[0].h + rows[2].h - 2.0 * w_max).abs() < 1e-12);
        assert!((rows[1].h + rows[3].h - 2.0 * w_max).abs() < 1e-12);
    }
}
