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
    // a joint rate's change over `Σ_k |A_ik| e_k · s`, the first-order bound at the sample
    let mut at_sample = 0.0f64;
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
                        if gi < 7 {
                            let delta = x.a.row(gi).abs().transpose().dot(&e);
                            let sec = (step + 1) as f64 * p.physics_step;
                            at_sample = at_sample.max(change / (delta * sec));
                        }
                    }
                }
            }
        }
    }
    println!(
        "plant's change / first-order estimate: joints max {joints:.4}, spheres max {spheres:.4} (VERIFY_SECOND_ORDER {VERIFY_SECOND_ORDER}); a joint rate's change / the bound at the sample alone: max {at_sample:.2}"
    );
    // why the verification integrates each joint's error: the bound at the sample alone
    // misses what the joints' coupling adds inside the sample
    assert!(at_sample > VERIFY_SECOND_ORDER, "{at_sample}");
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

/// A plant drawn at the edge of the `realistic` model bounds: every body's mass and
/// rotational inertia scaled at random within its declared relative bound, the base CoM
/// moved within its declared ball.
fn realistic_plant(robot: &sc_multibody::Robot, rng: &mut Lcg) -> sc_multibody::Robot {
    let m = sc_scenario::Uncertainty::profile("realistic", std::path::Path::new("."))
        .unwrap()
        .model;
    let mut plant = robot.clone();
    for k in 0..8 {
        let (mass, inertia) = if k == 0 {
            (m.servicer_mass_rel, m.servicer_inertia_rel)
        } else {
            (m.link_mass_rel, m.link_inertia_rel)
        };
        let offset = if k == 0 {
            let v = rng.v3(1.0);
            v * (m.servicer_com_m * rng.next().abs() / v.norm().max(1e-12))
        } else {
            Vector3::zeros()
        };
        plant = plant
            .with_body_mass_properties(
                k,
                1.0 + mass * rng.next(),
                1.0 + inertia * rng.next(),
                offset,
            )
            .unwrap();
    }
    plant
}

/// Why the mass-property error has no margin yet (docs/SAFETY.md, "Model error"): the
/// torque the model misses, `Δτ = (M − M_t) θ̈_t + (c − c_t)`, against the bound
/// `ε (κ_M (|M| |θ̈_t|)_i + κ_c (|c_free| + |K||w|)_i)` with `ε` the largest declared
/// relative error and `κ_M = 4.2`, `κ_c = 6.2`: over `realistic` plants, envelope states,
/// base wrenches in their boxes and slow commands (|θ̈| ≤ 0.1 rad/s², the mission's), the
/// bound holds for every joint — and for the wrist it is many times the realised error.
/// Prints the measured ratios.
#[test]
fn the_mass_property_bound_holds_but_is_loose_for_the_wrist() {
    const KAPPA_M: f64 = 4.2;
    const KAPPA_C: f64 = 6.2;
    let s = scenario();
    let robot = robot();
    let p = RoboticFilter::from_scenario(&s, robot.clone()).params;
    let mb = sc_scenario::Uncertainty::profile("realistic", std::path::Path::new("."))
        .unwrap()
        .model;
    let eps = [
        mb.servicer_mass_rel,
        mb.servicer_inertia_rel,
        mb.link_mass_rel,
        mb.link_inertia_rel,
    ]
    .into_iter()
    .fold(0.0, f64::max);
    let mut rng = Lcg(5);
    let (mut inertia, mut bias) = (0.0f64, 0.0f64);
    // the wrist (joint 7): largest realised and largest bound of each part [N m]
    let (mut real_c, mut bound_c, mut real_m, mut bound_m) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..1500 {
        let plant = realistic_plant(&robot, &mut rng);
        let th = theta_inside(&s, &mut rng, 0.0);
        let thd = Vector7::from_fn(|i, _| p.theta_dot_max[i] * rng.next());
        let w = rng.v3(0.05);
        let (f, tb) = (rng.v3(s.limits.force_max_n), rng.v3(s.limits.torque_max_nm));
        let wrench = nalgebra::Vector6::new(f.x, f.y, f.z, tb.x, tb.y, tb.z);
        let m = robot.reduced_arm_dynamics(&th, &thd, &w, &wrench).unwrap();
        let t = plant.reduced_arm_dynamics(&th, &thd, &w, &wrench).unwrap();
        let qdd = Vector7::from_fn(|_, _| 0.1 * rng.next());
        let tau = m.m_eff * qdd + m.c_eff;
        let qdd_t = t.m_eff.cholesky().unwrap().solve(&(tau - t.c_eff));
        let d_inertia = (m.m_eff - t.m_eff) * qdd_t;
        let d_bias = m.c_eff - t.c_eff;
        let scale_inertia = m.m_eff.abs() * qdd_t.abs() * eps;
        let scale_bias = (m.c_free.abs() + m.wrench_map.abs() * wrench.abs()) * eps;
        for i in 0..7 {
            inertia = inertia.max(d_inertia[i].abs() / scale_inertia[i].max(1e-300));
            bias = bias.max(d_bias[i].abs() / scale_bias[i].max(1e-300));
        }
        real_m = real_m.max(d_inertia[6].abs());
        bound_m = bound_m.max(KAPPA_M * scale_inertia[6]);
        real_c = real_c.max(d_bias[6].abs());
        bound_c = bound_c.max(KAPPA_C * scale_bias[6]);
    }
    println!(
        "mass-property error: inertia part / ε(|M||θ̈|) max {inertia:.2}, bias part / ε(|c_free|+|K||w|) max {bias:.2}; wrist: inertia part {real_m:.2e} realised, {bound_m:.2e} bound; bias part {real_c:.2e} realised, {bound_c:.2e} bound"
    );
    assert!(inertia <= KAPPA_M && bias <= KAPPA_C, "{inertia}, {bias}");
    assert!(bound_m > 5.0 * real_m && bound_c > 5.0 * real_c);
}
