//! Translational MPC: gain against an independent dense least-squares solution,
//! closed-loop convergence on the CW model, bad-input handling.

use nalgebra::{DMatrix, DVector, Matrix6, Matrix6x3, Rotation3, Vector3, Vector6};
use sc_models::cw::ClohessyWiltshire;
use sc_models::quat;
use sc_nominal::translational::{TranslationalMpc, TranslationalMpcParams};

const N_MEAN: f64 = 0.001_078_5; // ≈ 600 km circular orbit [rad/s]
const MASS: f64 = 269.0;

fn params(horizon: usize) -> TranslationalMpcParams {
    TranslationalMpcParams {
        mean_motion: N_MEAN,
        mass: MASS,
        dt: 0.1,
        horizon,
        gfc_point_r: Vector3::new(-2.2, 0.0, 0.0),
        weight_position: 1.0,
        weight_velocity: 40.0,
        weight_force: 0.002,
        weight_terminal: 50.0,
    }
}

/// Dense least squares of the batch problem built by impulse responses (no use of the
/// crate's batch matrices), solved by SVD. Returns the first-input gain
/// `[K_x | G_1 … G_N]` (3 × (6 + 6N)).
fn reference_gain(p: &TranslationalMpcParams) -> DMatrix<f64> {
    let n = p.horizon;
    let (ad, bd): (Matrix6<f64>, Matrix6x3<f64>) = ClohessyWiltshire {
        n: p.mean_motion,
        mass: p.mass,
    }
    .discretize(p.dt);
    // free response Φ: simulate unit initial states
    let mut phi = DMatrix::zeros(6 * n, 6);
    for j in 0..6 {
        let mut x = Vector6::zeros();
        x[j] = 1.0;
        for k in 0..n {
            x = ad * x;
            phi.view_mut((6 * k, j), (6, 1)).copy_from(&x);
        }
    }
    // forced response Γ: unit input at step i, component c
    let mut gamma = DMatrix::zeros(6 * n, 3 * n);
    for i in 0..n {
        for c in 0..3 {
            let mut x = Vector6::zeros();
            for k in 0..n {
                let mut u = Vector3::zeros();
                if k == i {
                    u[c] = 1.0;
                }
                x = ad * x + bd * u;
                gamma.view_mut((6 * k, 3 * i + c), (6, 1)).copy_from(&x);
            }
        }
    }
    // weights
    let mut w = DVector::zeros(6 * n);
    for k in 0..n {
        let s = if k + 1 == n { p.weight_terminal } else { 1.0 };
        for i in 0..3 {
            w[6 * k + i] = (s * p.weight_position).sqrt();
            w[6 * k + 3 + i] = (s * p.weight_velocity).sqrt();
        }
    }
    // min |W (Φ x0 + Γ U − X_ref)|² + w_f |U|²  ⇔  min |A U − B [x0; X_ref]|²
    let mut a = DMatrix::zeros(9 * n, 3 * n);
    let mut b = DMatrix::zeros(9 * n, 6 + 6 * n);
    for r in 0..6 * n {
        for c in 0..3 * n {
            a[(r, c)] = w[r] * gamma[(r, c)];
        }
        for c in 0..6 {
            b[(r, c)] = -w[r] * phi[(r, c)];
        }
        b[(r, 6 + r)] = w[r];
    }
    for i in 0..3 * n {
        a[(6 * n + i, i)] = p.weight_force.sqrt();
    }
    let svd = a.svd(true, true);
    let u_map = svd.solve(&b, 1e-14).expect("svd solve");
    u_map.rows(0, 3).into_owned()
}

#[test]
fn gain_equals_dense_least_squares() {
    for horizon in [1, 5, 30] {
        let p = params(horizon);
        let mpc = TranslationalMpc::new(p).unwrap();
        let g = mpc.gain();
        let g_ref = reference_gain(&p);
        let rel = (&g - &g_ref).norm() / g_ref.norm();
        assert!(rel < 1e-9, "N = {horizon}: relative gain error {rel:e}");
    }
}

#[test]
fn command_uses_rotating_gfc_reference() {
    let p = params(30);
    let mpc = TranslationalMpc::new(p).unwrap();
    let g = mpc.gain();
    let q_hr = quat::from_axis_angle(&Vector3::new(0.2, -0.4, 1.0), 1.1);
    // an exaggerated Hill rate so that the rotation over the horizon matters
    let w_h = Vector3::new(0.0, 0.0, 0.05);
    let r_h = Vector3::new(1.0, -8.0, 0.3);
    let v_h = Vector3::new(0.01, 0.02, -0.003);
    let cmd = mpc.command(&r_h, &v_h, &q_hr, &w_h);
    assert!(cmd.valid);
    // independent reference: p_H(t_k) = exp(−[ω]× t_k) R_HR p_R, v = −ω × p
    let p0 = quat::to_matrix(&q_hr) * p.gfc_point_r;
    let mut z = DVector::zeros(6 + 6 * p.horizon);
    z.rows_mut(0, 3).copy_from(&r_h);
    z.rows_mut(3, 3).copy_from(&v_h);
    for k in 1..=p.horizon {
        let rot = Rotation3::from_scaled_axis(-w_h * (k as f64 * p.dt));
        let pk = rot * p0;
        let vk = -w_h.cross(&pk);
        z.rows_mut(6 * k, 3).copy_from(&pk);
        z.rows_mut(6 * k + 3, 3).copy_from(&vk);
    }
    let u = &g * z;
    assert!((cmd.f_h - Vector3::new(u[0], u[1], u[2])).norm() < 1e-9 * u.norm());
    assert!((cmd.gfc_point_h - p0).norm() < 1e-12);
}

#[test]
fn closed_loop_converges_to_gfc_point() {
    let p = params(30);
    let mpc = TranslationalMpc::new(p).unwrap();
    let (ad, bd) = (*mpc.model().0, *mpc.model().1);
    let q_hr0 = [
        std::f64::consts::FRAC_1_SQRT_2,
        0.0,
        0.0,
        std::f64::consts::FRAC_1_SQRT_2,
    ];
    let w_h = Vector3::new(0.0, 0.0, N_MEAN);
    let q_hr = |t: f64| quat::mul(&quat::from_axis_angle(&Vector3::z(), -N_MEAN * t), &q_hr0);
    // scenario start: base at [-9, 0.45, -0.35] in F_R drifting at 4 mm/s
    let r_r = Vector3::new(-9.0, 0.45, -0.35);
    let v_r = Vector3::new(0.0, 0.004, 0.0);
    let r_hr = quat::to_matrix(&q_hr(0.0));
    let r_h = r_hr * r_r;
    let v_h = r_hr * v_r - w_h.cross(&r_h);
    let mut x = Vector6::new(r_h.x, r_h.y, r_h.z, v_h.x, v_h.y, v_h.z);
    let mut f_max: f64 = 0.0;
    for k in 0..1200 {
        let t = k as f64 * p.dt;
        let c = mpc.command(
            &x.fixed_rows::<3>(0).into(),
            &x.fixed_rows::<3>(3).into(),
            &q_hr(t),
            &w_h,
        );
        assert!(c.valid);
        f_max = f_max.max(c.f_h.amax());
        x = ad * x + bd * c.f_h;
    }
    let t_end = 120.0;
    let r_hr = quat::to_matrix(&q_hr(t_end));
    let r_h: Vector3<f64> = x.fixed_rows::<3>(0).into();
    let v_h: Vector3<f64> = x.fixed_rows::<3>(3).into();
    let r_r_end = r_hr.transpose() * r_h;
    let v_r_end = r_hr.transpose() * (v_h + w_h.cross(&r_h));
    let err = (r_r_end - p.gfc_point_r).norm();
    eprintln!(
        "after {t_end} s: |r − p_gfc| = {err:.2e} m, |v_R| = {:.2e} m/s, max |f|∞ = {f_max:.1} N",
        v_r_end.norm()
    );
    assert!(err < 1e-3, "position error {err}");
    assert!(v_r_end.norm() < 1e-4);
    // unconstrained: the nominal force exceeds the 7 N actuator bound (the filter's job)
    assert!(f_max > 7.0);
}

#[test]
fn bad_inputs_give_flagged_zero() {
    let mpc = TranslationalMpc::new(params(10)).unwrap();
    let w = Vector3::new(0.0, 0.0, N_MEAN);
    let ok = Vector3::new(1.0, 2.0, 3.0);
    let nan = Vector3::new(f64::NAN, 0.0, 0.0);
    for (r, v, q, om) in [
        (nan, ok, quat::IDENTITY, w),
        (ok, nan, quat::IDENTITY, w),
        (ok, ok, [0.0; 4], w),
        (ok, ok, [f64::INFINITY, 0.0, 0.0, 0.0], w),
        (ok, ok, quat::IDENTITY, nan),
    ] {
        let c = mpc.command(&r, &v, &q, &om);
        assert!(!c.valid);
        assert_eq!(c.f_h, Vector3::zeros());
    }
}

#[test]
fn invalid_parameters_are_rejected() {
    let mut p = params(10);
    p.mass = 0.0;
    assert!(TranslationalMpc::new(p).is_err());
    let mut p = params(10);
    p.weight_force = f64::NAN;
    assert!(TranslationalMpc::new(p).is_err());
    assert!(TranslationalMpc::new(params(0)).is_err());
}
