//! Dynamics: mass matrix properties, C θ̇ vs Christoffel symbols of M, RNEA/CRBA/ABA
//! consistency, momentum and energy conservation (RK4, zero input), Schur-reduced arm dynamics.

mod common;

use common::{Rng, robots};
use nalgebra::{Matrix3, Vector3, Vector6};
use sc_multibody::{NJ, Robot, Vector7, Vector13};

#[test]
fn mass_matrices_are_symmetric_positive_definite() {
    for (name, r) in robots() {
        let mut rng = Rng::new(3);
        for _ in 0..50 {
            let th = rng.theta(&r);
            let m = r.mass_matrix(&th);
            assert!((m - m.transpose()).amax() < 1e-12, "{name}");
            let eig = m.symmetric_eigen().eigenvalues;
            assert!(eig.min() > 0.0, "{name} M not PD: {eig}");
            let ma = r.arm_mass_matrix(&th);
            assert!(ma.symmetric_eigen().eigenvalues.min() > 0.0);
            // base block = system mass / inertia about the base origin
            assert!((m[(0, 0)] - r.total_mass()).abs() < 1e-12);
        }
    }
}

#[test]
fn coriolis_matches_christoffel_symbols_of_m() {
    // c_i = Σ_jk (∂M_ij/∂θ_k − ½ ∂M_jk/∂θ_i) θ̇_j θ̇_k (fixed base)
    let h = 1e-6;
    for (name, r) in robots() {
        let mut rng = Rng::new(5);
        for _ in 0..10 {
            let th = rng.theta(&r);
            let qd = rng.vec7(0.8);
            let mut dm = Vec::new();
            for k in 0..NJ {
                let mut e = Vector7::zeros();
                e[k] = h;
                dm.push((r.arm_mass_matrix(&(th + e)) - r.arm_mass_matrix(&(th - e))) / (2.0 * h));
            }
            let mut c = Vector7::zeros();
            for i in 0..NJ {
                for j in 0..NJ {
                    for k in 0..NJ {
                        c[i] += (dm[k][(i, j)] - 0.5 * dm[i][(j, k)]) * qd[j] * qd[k];
                    }
                }
            }
            let rn = r.arm_coriolis(&th, &qd);
            assert!((c - rn).amax() < 1e-8, "{name}: {c} vs {rn}");
        }
    }
}

#[test]
fn rnea_crba_aba_are_consistent() {
    for (name, r) in robots() {
        let mut rng = Rng::new(9);
        for _ in 0..50 {
            let th = rng.theta(&r);
            let nu = rng.vec13(0.3);
            let nud = rng.vec13(0.5);
            let u = rng.vec13(5.0);
            let m = r.mass_matrix(&th);
            let b = r.nonlinear_effects(&th, &nu);
            let tau = r.rnea(&th, &nu, &nud);
            assert!(
                (tau - (m * nud + b)).amax() < 1e-10,
                "{name} rnea = M a + b"
            );
            let a = r.forward_dynamics(&th, &nu, &u).unwrap();
            let a_ref = m.cholesky().unwrap().solve(&(u - b));
            assert!(
                (a - a_ref).amax() < 1e-10 * a_ref.amax().max(1.0),
                "{name} aba"
            );
            // kinetic energy = ½ νᵀ M ν
            let ke = r.kinetic_energy(&th, &nu);
            assert!((ke - 0.5 * nu.dot(&(m * nu))).abs() < 1e-12 * ke.max(1.0));
            // fixed-base FD
            let qd: Vector7 = nu.fixed_rows::<7>(6).into();
            let tm: Vector7 = u.fixed_rows::<7>(6).into();
            let qdd = r.arm_forward_dynamics(&th, &qd, &tm).unwrap();
            let back = r.arm_mass_matrix(&th) * qdd + r.arm_coriolis(&th, &qd);
            assert!((back - tm).amax() < 1e-10);
        }
    }
}

#[test]
fn internal_dynamics_do_not_depend_on_base_linear_velocity() {
    for (name, r) in robots() {
        let mut rng = Rng::new(13);
        for _ in 0..20 {
            let th = rng.theta(&r);
            let mut nu = rng.vec13(0.3);
            let u = rng.vec13(5.0);
            let w = Vector3::new(nu[3], nu[4], nu[5]);
            let qd: Vector7 = nu.fixed_rows::<7>(6).into();
            let sim = r.forward_dynamics_sim(&th, &w, &qd, &u).unwrap();
            nu.fixed_rows_mut::<3>(0).copy_from(&Vector3::new(
                rng.uniform(-50.0, 50.0),
                3.0,
                -20.0,
            ));
            let v = Vector3::new(nu[0], nu[1], nu[2]);
            let a = r.forward_dynamics(&th, &nu, &u).unwrap();
            let cls = Vector3::new(a[0], a[1], a[2]) + w.cross(&v);
            assert!(
                (cls - sim.fixed_rows::<3>(0)).amax() < 1e-10,
                "{name} classical accel"
            );
            // precision degrades with |v_B| (large cancelling velocity terms): ~1e-15 |v_B| /m
            let err = (a.fixed_rows::<10>(3) - sim.fixed_rows::<10>(3)).amax();
            assert!(
                err < 1e-11 * v.norm().max(1.0),
                "{name}: {err} at |v| = {}",
                v.norm()
            );
        }
    }
}

#[test]
fn reduced_arm_dynamics_equal_full_forward_dynamics() {
    for (name, r) in robots() {
        let mut rng = Rng::new(17);
        for _ in 0..30 {
            let th = rng.theta(&r);
            let qd = rng.vec7(0.5);
            let w = Vector3::new(rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), 0.1);
            let wrench =
                Vector6::from_fn(|i, _| rng.uniform(-10.0, 10.0) * if i < 3 { 0.7 } else { 1.0 });
            let red = r.reduced_arm_dynamics(&th, &qd, &w, &wrench).unwrap();
            assert!((red.m_eff - red.m_eff.transpose()).amax() < 1e-14);
            assert!(red.m_eff.symmetric_eigen().eigenvalues.min() > 0.0);
            assert!((red.c_eff - red.c_free - red.xi).amax() < 1e-15);
            assert!((red.wrench_map * wrench - red.xi).amax() < 1e-15);
            let ch = red.m_eff.cholesky().unwrap();
            for _ in 0..5 {
                let tm = rng.vec7(2.0);
                let qdd = ch.solve(&(tm - red.c_eff));
                let mut u = Vector13::zeros();
                u.fixed_rows_mut::<6>(0).copy_from(&wrench);
                u.fixed_rows_mut::<7>(6).copy_from(&tm);
                let full = r.forward_dynamics_sim(&th, &w, &qd, &u).unwrap();
                let err = (full.fixed_rows::<7>(6) - qdd).amax();
                assert!(
                    err < 1e-11 * qdd.amax().max(1.0),
                    "{name}: θ̈ mismatch {err}"
                );
            }
        }
    }
}

/// Inertial state for the conservation test: base position (m), base rotation (base→inertial),
/// θ (rad), ν (Pinocchio convention).
#[derive(Clone, Copy)]
struct State {
    p: Vector3<f64>,
    rot: Matrix3<f64>,
    th: Vector7,
    nu: Vector13,
}

fn deriv(r: &Robot, s: &State) -> (Vector3<f64>, Matrix3<f64>, Vector7, Vector13) {
    let v = Vector3::new(s.nu[0], s.nu[1], s.nu[2]);
    let w = Vector3::new(s.nu[3], s.nu[4], s.nu[5]);
    let wx = Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0);
    let a = r
        .forward_dynamics(&s.th, &s.nu, &Vector13::zeros())
        .unwrap();
    (s.rot * v, s.rot * wx, s.nu.fixed_rows::<7>(6).into(), a)
}

fn step(r: &Robot, s: &State, dt: f64) -> State {
    let add = |s: &State, k: &(Vector3<f64>, Matrix3<f64>, Vector7, Vector13), h: f64| State {
        p: s.p + k.0 * h,
        rot: s.rot + k.1 * h,
        th: s.th + k.2 * h,
        nu: s.nu + k.3 * h,
    };
    let k1 = deriv(r, s);
    let k2 = deriv(r, &add(s, &k1, dt / 2.0));
    let k3 = deriv(r, &add(s, &k2, dt / 2.0));
    let k4 = deriv(r, &add(s, &k3, dt));
    let mut n = State {
        p: s.p + (k1.0 + k2.0 * 2.0 + k3.0 * 2.0 + k4.0) * (dt / 6.0),
        rot: s.rot + (k1.1 + k2.1 * 2.0 + k3.1 * 2.0 + k4.1) * (dt / 6.0),
        th: s.th + (k1.2 + k2.2 * 2.0 + k3.2 * 2.0 + k4.2) * (dt / 6.0),
        nu: s.nu + (k1.3 + k2.3 * 2.0 + k3.3 * 2.0 + k4.3) * (dt / 6.0),
    };
    // re-orthonormalize the attitude (polar decomposition via SVD)
    let svd = n.rot.svd(true, true);
    n.rot = svd.u.unwrap() * svd.v_t.unwrap();
    n
}

fn inertial_momentum(r: &Robot, s: &State) -> (Vector3<f64>, Vector3<f64>) {
    let m = r.momentum(&s.th, &s.nu);
    let p = s.rot * m.linear;
    let l = s.rot * m.angular_base + s.p.cross(&p);
    (p, l)
}

#[test]
fn free_flyer_conserves_momentum_and_energy_under_zero_input() {
    for (name, r) in robots() {
        let mut rng = Rng::new(23);
        let mut s = State {
            p: Vector3::new(1.0, -2.0, 0.5),
            rot: Matrix3::identity(),
            th: rng.theta(&r) * 0.5,
            nu: rng.vec13(0.3),
        };
        let (p0, l0) = inertial_momentum(&r, &s);
        let e0 = r.kinetic_energy(&s.th, &s.nu);
        let dt = 0.005;
        for _ in 0..2000 {
            s = step(&r, &s, dt);
        }
        let (p1, l1) = inertial_momentum(&r, &s);
        let e1 = r.kinetic_energy(&s.th, &s.nu);
        eprintln!(
            "{name}: 10 s RK4, |ΔP| = {:.2e}, |ΔL| = {:.2e}, ΔE/E = {:.2e}",
            (p1 - p0).norm(),
            (l1 - l0).norm(),
            (e1 - e0) / e0
        );
        assert!(
            (p1 - p0).norm() < 1e-9 * p0.norm().max(1.0),
            "{name} linear momentum"
        );
        assert!(
            (l1 - l0).norm() < 1e-8 * l0.norm().max(1.0),
            "{name} angular momentum"
        );
        assert!(((e1 - e0) / e0).abs() < 1e-8, "{name} energy");
        // CoM moves uniformly: m ċ = P (checked on the momentum struct at the end state)
        let mo = r.momentum(&s.th, &s.nu);
        assert!((mo.angular_com - (mo.angular_base - mo.com.cross(&mo.linear))).amax() < 1e-14);
        assert!((r.center_of_mass(&s.th) - mo.com).amax() < 1e-14);
    }
}

/// `body_com_distance_bounds` bounds the system CoM's distance from a base-fixed point at
/// every joint state (the weighted sum of the bodies' bounds), and is not loose beyond
/// the chain's length.
#[test]
fn the_com_distance_bounds_hold_at_every_joint_state() {
    for (name, r) in robots() {
        let q = Vector3::new(0.1, -0.2, 0.05);
        let b = r.body_com_distance_bounds(&q);
        let weighted: f64 = (0..=NJ).map(|k| r.body_mass(k) * b[k]).sum::<f64>() / r.total_mass();
        let mut rng = Rng::new(17);
        let mut largest: f64 = 0.0;
        for _ in 0..2000 {
            let th = rng.theta(&r);
            let d = (q - r.center_of_mass(&th)).norm();
            assert!(d <= weighted + 1e-12, "{name}: {d} > {weighted}");
            largest = largest.max(d);
        }
        assert!(
            b.iter().all(|v| v.is_finite() && *v >= 0.0),
            "{name}: {b:?}"
        );
        assert!(
            weighted < 3.0 * largest + 0.5,
            "{name}: {weighted} vs {largest}"
        );
    }
}

/// The plant's CoM lies within `com_shift_bound` of the model's for plants anywhere in the
/// box (the ends of every scale and the CoM's whole offset half the time); without errors
/// the bound is 0, and mass scales that can take every body's mass give none.
#[test]
fn the_com_shift_bound_covers_every_plant_in_the_box() {
    let (base_rel, com_m, link_rel) = (0.05, 0.02, 0.2);
    for (name, r) in robots() {
        let mut rng = Rng::new(11);
        let th = rng.theta(&r);
        assert_eq!(r.com_shift_bound(&th, 0.0, 0.0, 0.0), Some(0.0), "{name}");
        assert_eq!(r.com_shift_bound(&th, 1.0, 0.0, 1.0), None, "{name}");
        let mut widest = 0.0f64;
        for _ in 0..300 {
            let th = rng.theta(&r);
            let mut end = |e: f64| {
                if rng.next_f64() < 0.5 {
                    if rng.next_f64() < 0.5 { -e } else { e }
                } else {
                    rng.uniform(-e, e)
                }
            };
            let offset = Vector3::new(end(1.0), end(1.0), end(1.0)).normalize() * com_m;
            let mut p = r
                .with_body_mass_properties(0, 1.0 + end(base_rel), 1.0, offset)
                .unwrap();
            for k in 1..=NJ {
                p = p
                    .with_body_mass_properties(k, 1.0 + end(link_rel), 1.0, Vector3::zeros())
                    .unwrap();
            }
            let bound = r.com_shift_bound(&th, base_rel, com_m, link_rel).unwrap();
            let shift = (p.center_of_mass(&th) - r.center_of_mass(&th)).norm();
            assert!(shift <= bound, "{name}: {shift} > {bound}");
            widest = widest.max(shift / bound);
        }
        // not loose by orders of magnitude
        assert!(widest > 0.2, "{name}: {widest}");
    }
}
