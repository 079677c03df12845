//! Property tests of the fault behaviour: over random states and nominal commands —
//! including NaN, ±inf and huge values — no filter panics, every command is finite and inside
//! its input bounds, and invalid inputs are flagged.

mod common;
use common::*;
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;
use sc_cbf::robotic::{Matrix7, SphereTerms, Vector7};
use sc_cbf::{AttitudeFilter, FilterStatus, RoboticFilter, TranslationalFilter, faults};
use std::sync::OnceLock;

fn wild(scale: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => (-1.0..1.0f64).prop_map(move |x| x * scale),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(1e300),
        1 => Just(-1e300),
        1 => Just(0.0),
        1 => (-1.0..1.0f64).prop_map(|x| x * 1e8),
    ]
}
fn v3(scale: f64) -> impl Strategy<Value = Vector3<f64>> {
    [wild(scale), wild(scale), wild(scale)].prop_map(Vector3::from)
}
fn v7(scale: f64) -> impl Strategy<Value = Vector7> {
    proptest::collection::vec(wild(scale), 7).prop_map(|v| Vector7::from_column_slice(&v))
}
fn q4() -> impl Strategy<Value = [f64; 4]> {
    prop_oneof![
        4 => [(-1.0..1.0f64), (-1.0..1.0f64), (-1.0..1.0f64), (-1.0..1.0f64)]
            .prop_map(|q| sc_models::quat::normalized(&q).unwrap_or(sc_models::quat::IDENTITY)),
        1 => [wild(1.0), wild(1.0), wild(1.0), wild(1.0)],
    ]
}

fn finite<const R: usize, const C: usize>(m: &nalgebra::SMatrix<f64, R, C>) -> bool {
    m.iter().all(|x| x.is_finite())
}

static ROB: OnceLock<sc_cbf::RoboticInput> = OnceLock::new();
fn rob_base() -> sc_cbf::RoboticInput {
    *ROB.get_or_init(|| {
        let s = scenario();
        rob_input(&robot(), theta0(&s), Vector7::zeros())
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, .. ProptestConfig::default() })]

    #[test]
    fn translational_never_unsafe_output(r in v3(20.0), v in v3(0.5), w in v3(0.01), wd in v3(1e-4),
                                          qhr in q4(), qrb in q4(), fnom in v3(20.0)) {
        let s = scenario();
        let mut f = TranslationalFilter::from_scenario(&s, MASS);
        let x = sc_cbf::TranslationalInput { r_h: r, v_h: v, q_hr: qhr, omega_h: w, omega_dot_h: wd, q_rb: qrb };
        let out = f.filter(&x, &fnom);
        let fmax = s.limits.force_max_n;
        prop_assert!(finite(&out.u) && finite(&out.actuated));
        prop_assert!(out.actuated.amax() <= fmax);
        let state_ok = finite(&r) && finite(&v) && finite(&w) && finite(&wd) && qhr.iter().chain(qrb.iter()).all(|x| x.is_finite());
        if !state_ok {
            prop_assert!(out.report.faults & faults::INVALID_STATE != 0);
            prop_assert_eq!(out.u, Vector3::zeros());
        } else if out.report.faults & faults::INVALID_STATE == 0 {
            // a valid state: ‖R_BH f_H‖∞ ≤ F holds for the returned f_H too
            let r_bh = (sc_models::quat::to_matrix(&qhr) * sc_models::quat::to_matrix(&qrb)).transpose();
            prop_assert!((r_bh * out.u).amax() <= fmax * (1.0 + 1e-12));
            if !finite(&fnom) {
                prop_assert!(out.report.faults & faults::INVALID_NOMINAL != 0);
                prop_assert_eq!(out.report.status, FilterStatus::Fallback);
            }
        }
        if out.report.status == FilterStatus::Fallback {
            prop_assert!(out.report.faults != 0);
        }
        prop_assert_eq!(out.report.faults & faults::OUTPUT_CLAMPED, 0);
    }

    #[test]
    fn attitude_never_unsafe_output(r in v3(5.0), w in v3(0.5), tnom in v3(30.0), xi in v3(0.05),
                                    q in q4(), phase in 0.0..80.0f64, inertia_scale in wild(60.0),
                                    grasp_acc in v3(0.01)) {
        let s = scenario();
        let mut f = AttitudeFilter::from_scenario(&s);
        let mut x = att_input(r, q, w, phase);
        x.xi_r = xi;
        x.grasp_acc_r = grasp_acc;
        x.inertia = inertia() + Matrix3::identity() * inertia_scale;
        let out = f.filter(&x, &tnom);
        prop_assert!(finite(&out.u));
        prop_assert!(out.u.amax() <= s.limits.torque_max_nm);
        if !finite(&xi) && finite(&r) && finite(&w) && finite(&grasp_acc) && inertia_scale.is_finite()
            && q.iter().all(|c| c.is_finite()) && out.report.faults & faults::INVALID_STATE == 0 {
            prop_assert!(out.report.faults & faults::INVALID_COUPLING != 0);
        }
        if !finite(&w) || !finite(&r) {
            prop_assert!(out.report.faults & faults::INVALID_STATE != 0);
        }
        if out.report.status == FilterStatus::Fallback {
            prop_assert!(out.report.faults != 0);
        }
        prop_assert_eq!(out.report.faults & faults::OUTPUT_CLAMPED, 0);
    }

    #[test]
    fn robotic_never_unsafe_output(th in v7(3.0), thd in v7(0.5), tnom in v7(4.0), xi in v7(1.0),
                                   drift in v7(0.1), sphere in v3(1.0), a_scale in wild(2.0)) {
        let s = scenario();
        let mut f = RoboticFilter::from_scenario(&s);
        let mut x = rob_base();
        x.theta = th;
        x.theta_dot = thd;
        x.xi = xi;
        x.drift = drift;
        x.spheres[4] = SphereTerms { center: sphere, ..x.spheres[4] };
        x.a += Matrix7::identity() * a_scale;
        let out = f.filter(&x, &tnom);
        prop_assert!(finite(&out.u));
        prop_assert!(out.u.amax() <= s.limits.joint_torque_max_nm);
        if !finite(&th) || !finite(&thd) || !finite(&sphere) || !a_scale.is_finite() {
            prop_assert!(out.report.faults & faults::INVALID_STATE != 0);
        }
        if out.report.faults & faults::INVALID_STATE == 0 && !finite(&xi) {
            prop_assert!(out.report.faults & faults::INVALID_COUPLING != 0);
        }
        if out.report.faults & (faults::INVALID_STATE | faults::INVALID_COUPLING) == 0 && !finite(&tnom) {
            prop_assert!(out.report.faults & faults::INVALID_NOMINAL != 0);
        }
        if out.report.status == FilterStatus::Fallback {
            prop_assert!(out.report.faults != 0);
        }
        prop_assert_eq!(out.report.faults & faults::OUTPUT_CLAMPED, 0);
    }
}
