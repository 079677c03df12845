//! The verification path's margin for the declared joint-torque error (docs/SAFETY.md,
//! "Margins for the declared errors") against the plant it stands for: the arm integrated
//! over one sample under `τ`, under `τ + e_k 1_k` for each joint (the filter's first-order
//! estimate) and under the corners of the box `|Δτ_k| ≤ e_k`, at random states and torques
//! of the certified envelope.

mod common;
use common::*;
use nalgebra::Vector3;
use sc_cbf::robotic::{
    self, RoboticFilter, TorqueError, VERIFY_SECOND_ORDER, Vector7, rk4_internal,
};
use sc_multibody::Vector13;

/// Factor the configured constant keeps over the sampled maximum (as the envelope's bounds).
const SAFETY_FACTOR: f64 = 1.5;

/// One sample (10 physics steps) of the arm under the held torque `tau`: the joint rates
/// and angles `(θ̇, θ)` after every physics step.
fn sample(
    robot: &sc_multibody::Robot,
    f: &RoboticFilter,
    x0: (&Vector7, &Vector7, &Vector3<f64>),
    tau: &Vector7,
) -> Vec<[f64; 14]> {
    let p = &f.params;
    let mut u = Vector13::zeros();
    u.fixed_rows_mut::<7>(6).copy_from(tau);
    let (mut a, mut b, mut c) = (*x0.0, *x0.1, *x0.2);
    (0..10)
        .map(|_| {
            (a, b, c) = rk4_internal(robot, &a, &b, &c, &u, p.physics_step).expect("finite");
            std::array::from_fn(|j| if j < 7 { b[j] } else { a[j - 7] })
        })
        .collect()
}

/// Over random envelope states (joint rates within their limits), torques whose joint
/// accelerations the rate rows admit, and the corners of the `realistic` torque error
/// that the first-order estimate finds worst for each joint's rate and angle, the plant's
/// change exceeds the estimate by less than `(VERIFY_SECOND_ORDER − 1) / SAFETY_FACTOR`
/// of it at every physics step: the constant covers the higher orders with that factor.
#[test]
fn the_verification_margin_bounds_the_torque_errors_effect() {
    let s = scenario();
    let robot = robot();
    let f = RoboticFilter::from_scenario(&s, robot.clone());
    let p = &f.params;
    let a = sc_scenario::Uncertainty::profile("realistic", std::path::Path::new("."))
        .unwrap()
        .actuators;
    let te = TorqueError::from_actuators(&a);
    let mut rng = Lcg(11);
    let mut worst: f64 = 0.0;
    for _ in 0..150 {
        let th = theta_inside(&s, &mut rng, 0.0);
        let thd = Vector7::from_fn(|i, _| p.theta_dot_max[i] * rng.next());
        let w = rng.v3(0.05);
        let zero = Vector3::zeros();
        let x = robotic::robotic_input_from_model(&robot, &th, &thd, &w, &zero, &zero).unwrap();
        // joint accelerations the rate rows admit, |θ̈_i| ≤ 2 θ̇_max,i / T, in the box
        let qdd = Vector7::from_fn(|i, _| 2.0 * p.theta_dot_max[i] / p.period * rng.next());
        let tau = (x.m_eff * (qdd - x.drift - x.xi)).map(|v| v.clamp(-p.torque_max, p.torque_max));
        let e = te.at(&tau);
        let x0 = (&th, &thd, &w);
        let nominal = sample(&robot, &f, x0, &tau);
        let single: Vec<Vec<[f64; 14]>> = (0..7)
            .map(|k| {
                let mut t = tau;
                t[k] += e[k];
                sample(&robot, &f, x0, &t)
            })
            .collect();
        for j in 0..14 {
            // the corner the first-order estimate finds worst at the end of the sample
            for sign in [-1.0, 1.0] {
                let dtau = Vector7::from_fn(|k, _| {
                    sign * (single[k][9][j] - nominal[9][j]).signum() * e[k]
                });
                let corner = sample(&robot, &f, x0, &(tau + dtau));
                for (step, got) in corner.iter().enumerate() {
                    let estimate: f64 = (0..7)
                        .map(|k| (single[k][step][j] - nominal[step][j]).abs())
                        .sum();
                    let change = (got[j] - nominal[step][j]).abs();
                    if estimate > 1e-12 {
                        worst = worst.max(change / estimate);
                    }
                }
            }
        }
    }
    println!(
        "plant's change / first-order estimate: max {worst:.4} (VERIFY_SECOND_ORDER {VERIFY_SECOND_ORDER})"
    );
    assert!(
        (worst - 1.0) * SAFETY_FACTOR <= VERIFY_SECOND_ORDER - 1.0,
        "the remainder {} × {SAFETY_FACTOR} exceeds {}",
        worst - 1.0,
        VERIFY_SECOND_ORDER - 1.0
    );
    assert!(
        worst > 0.9,
        "the corners must move the joints as estimated: {worst}"
    );
}
