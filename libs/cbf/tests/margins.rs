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

/// Number of tracked quantities: 7 joint rates, 7 angles, 21 sphere centres and 21
/// sphere velocities (3 components each).
const Q: usize = 14 + 2 * 3 * robotic::NS;

/// One sample (10 physics steps) of the arm under the held torque `tau` and the base
/// wrench `(f, tb)`: the joint rates and angles and the spheres' centres and velocities
/// (F_B) after every physics step.
fn sample(
    robot: &sc_multibody::Robot,
    f: &RoboticFilter,
    x0: (&Vector7, &Vector7, &Vector3<f64>),
    wrench: (&Vector3<f64>, &Vector3<f64>),
    tau: &Vector7,
) -> Vec<[f64; Q]> {
    let p = &f.params;
    let mut u = Vector13::zeros();
    u.fixed_rows_mut::<3>(0).copy_from(wrench.0);
    u.fixed_rows_mut::<3>(3).copy_from(wrench.1);
    u.fixed_rows_mut::<7>(6).copy_from(tau);
    let spheres: Vec<usize> = robot.arm_spheres().map(|(i, _)| i).collect();
    let (mut a, mut b, mut c) = (*x0.0, *x0.1, *x0.2);
    (0..10)
        .map(|_| {
            (a, b, c) = rk4_internal(robot, &a, &b, &c, &u, p.physics_step).expect("finite");
            let kin = robot.kinematics_vel(&a, &b);
            let mut q = [0.0; Q];
            for i in 0..7 {
                q[i] = b[i];
                q[7 + i] = a[i];
            }
            for (k, idx) in spheres.iter().enumerate() {
                let st = robot.sphere_state(&kin, *idx).expect("sphere");
                let v = st.jacobian * b;
                for d in 0..3 {
                    q[14 + 3 * k + d] = st.center[d];
                    q[14 + 3 * robotic::NS + 3 * k + d] = v[d];
                }
            }
            q
        })
        .collect()
}

/// The filter's first-order estimate of quantity group `g` (a joint's rate or angle: one
/// component; a sphere's centre or velocity: its three, as a Euclidean norm) after `step`,
/// and the plant's change under a corner: `(Σ_k ‖x_k − x‖, ‖x_corner − x‖)`.
fn estimate_and_change(
    single: &[Vec<[f64; Q]>],
    nominal: &[[f64; Q]],
    corner: &[[f64; Q]],
    comps: &[usize],
    step: usize,
) -> (f64, f64) {
    let norm = |a: &[f64; Q], b: &[f64; Q]| {
        comps
            .iter()
            .map(|&c| (a[c] - b[c]).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let estimate = single.iter().map(|s| norm(&s[step], &nominal[step])).sum();
    (estimate, norm(&corner[step], &nominal[step]))
}

/// Over random envelope states (joint rates within their limits), base wrenches in their
/// boxes, torques whose joint accelerations the rate rows admit, and the corners of the
/// `realistic` torque error that the first-order estimate finds worst for each tracked
/// component, the plant's change exceeds the estimate by less than
/// `(VERIFY_SECOND_ORDER − 1) / SAFETY_FACTOR` of it at every physics step — for the
/// joints' rates and angles and the spheres' centres and velocities: the constant covers
/// the higher orders with that factor.
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
    let (mut joints, mut spheres) = (0.0f64, 0.0f64);
    for _ in 0..40 {
        let th = theta_inside(&s, &mut rng, 0.0);
        let thd = Vector7::from_fn(|i, _| p.theta_dot_max[i] * rng.next());
        let w = rng.v3(0.05);
        let (fb, tb) = (rng.v3(s.limits.force_max_n), rng.v3(s.limits.torque_max_nm));
        let x = robotic::robotic_input_from_model(&robot, &th, &thd, &w, &fb, &tb).unwrap();
        // joint accelerations the rate rows admit, |θ̈_i| ≤ 2 θ̇_max,i / T, in the box
        let qdd = Vector7::from_fn(|i, _| 2.0 * p.theta_dot_max[i] / p.period * rng.next());
        let tau = (x.m_eff * (qdd - x.drift - x.xi)).map(|v| v.clamp(-p.torque_max, p.torque_max));
        let e = te.at(&tau);
        let (x0, wr) = ((&th, &thd, &w), (&fb, &tb));
        let nominal = sample(&robot, &f, x0, wr, &tau);
        let single: Vec<Vec<[f64; Q]>> = (0..7)
            .map(|k| {
                let mut t = tau;
                t[k] += e[k];
                sample(&robot, &f, x0, wr, &t)
            })
            .collect();
        // groups: each joint's rate and angle, each sphere's centre and velocity
        let groups: Vec<Vec<usize>> = (0..14)
            .map(|c| vec![c])
            .chain((0..2 * robotic::NS).map(|g| (14 + 3 * g..17 + 3 * g).collect()))
            .collect();
        for (gi, comps) in groups.iter().enumerate() {
            // the corner the first-order estimate finds worst for each component
            for &c in comps {
                for sign in [-1.0, 1.0] {
                    let dtau = Vector7::from_fn(|k, _| {
                        sign * (single[k][9][c] - nominal[9][c]).signum() * e[k]
                    });
                    let corner = sample(&robot, &f, x0, wr, &(tau + dtau));
                    for step in 0..10 {
                        let (est, change) =
                            estimate_and_change(&single, &nominal, &corner, comps, step);
                        if est > 1e-12 {
                            let worst = if gi < 14 { &mut joints } else { &mut spheres };
                            *worst = worst.max(change / est);
                        }
                    }
                }
            }
        }
    }
    println!(
        "plant's change / first-order estimate: joints max {joints:.4}, spheres max {spheres:.4} (VERIFY_SECOND_ORDER {VERIFY_SECOND_ORDER})"
    );
    for (what, worst) in [("joints", joints), ("spheres", spheres)] {
        assert!(
            (worst - 1.0) * SAFETY_FACTOR <= VERIFY_SECOND_ORDER - 1.0,
            "{what}: the remainder {} × {SAFETY_FACTOR} exceeds {}",
            worst - 1.0,
            VERIFY_SECOND_ORDER - 1.0
        );
        // the corners must move what they are estimated to move (the spheres' norm sum
        // over-estimates by the triangle inequality: ~0.9 measured)
        assert!(
            worst > 0.5,
            "{what}: the corners must move as estimated: {worst}"
        );
    }
}
