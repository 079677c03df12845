//! Filter-level checks: KKT optimality from Clarabel's duals, an independent active-set
//! brute force for the 3-input filters, determinism and history independence, skip path ==
//! solve path, relaxed and fallback paths.

mod common;
use common::*;
use nalgebra::{DMatrix, DVector, Vector3};
use sc_cbf::robotic::Vector7;
use sc_cbf::{AttitudeFilter, FilterStatus, QpDump, RoboticFilter, TranslationalFilter, faults};
use sc_models::quat;

/// KKT conditions of `min ‖u−u_nom‖²  s.t. c + a·u ≥ 0, G u ≤ g` at the dumped solution.
fn check_kkt(d: &QpDump) {
    let m = d.u_nom.len();
    let u = DVector::from_column_slice(&d.solution);
    let un = DVector::from_column_slice(&d.u_nom);
    let mut stat = (&u - &un) * 2.0;
    let scale = 1.0 + un.norm();
    for (i, a) in d.rows_a.iter().enumerate() {
        let a = DVector::from_column_slice(a);
        let lam = d.row_duals[i];
        assert!(lam >= -1e-9, "λ_{i} = {lam}");
        let phi = d.rows_c[i] + a.dot(&u);
        let an = a.norm().max(1e-12);
        assert!(phi / an >= -1e-6, "row {i} violated: Φ = {phi}");
        assert!(
            (lam * phi).abs() <= 1e-5 * scale,
            "complementarity row {i}: λ={lam} Φ={phi}"
        );
        stat -= a * lam;
    }
    for (k, g) in d.bounds_g.iter().enumerate() {
        let g = DVector::from_column_slice(g);
        let mu = d.bound_duals[k];
        assert!(mu >= -1e-9);
        let slack = d.bounds_g_max[k] - g.dot(&u);
        assert!(slack >= -1e-9, "bound {k} violated by {slack}");
        assert!(
            (mu * slack).abs() <= 1e-5 * scale,
            "complementarity bound {k}"
        );
        stat += g * mu;
    }
    assert!(
        stat.norm() <= 1e-5 * scale,
        "stationarity residual {} (m = {m})",
        stat.norm()
    );
}

/// Exhaustive active-set solution of the same QP (inputs ≤ 3).
fn brute_force(d: &QpDump) -> DVector<f64> {
    let m = d.u_nom.len();
    let un = DVector::from_column_slice(&d.u_nom);
    // all rows as  p·u ≥ q
    let mut rows: Vec<(DVector<f64>, f64)> = Vec::new();
    for (i, a) in d.rows_a.iter().enumerate() {
        rows.push((DVector::from_column_slice(a), -d.rows_c[i]));
    }
    for (k, g) in d.bounds_g.iter().enumerate() {
        rows.push((-DVector::from_column_slice(g), -d.bounds_g_max[k]));
    }
    let n = rows.len();
    let feasible = |u: &DVector<f64>| {
        rows.iter()
            .all(|(p, q)| p.dot(u) >= q - 1e-9 * (1.0 + p.norm()))
    };
    let mut best: Option<(f64, DVector<f64>)> = None;
    let mut consider = |set: &[usize]| {
        let k = set.len();
        let mut a = DMatrix::zeros(k, m);
        let mut b = DVector::zeros(k);
        for (r, &i) in set.iter().enumerate() {
            a.row_mut(r).copy_from(&rows[i].0.transpose());
            b[r] = rows[i].1;
        }
        let u = if k == 0 {
            un.clone()
        } else {
            let aat = &a * a.transpose();
            let Some(inv) = aat.clone().try_inverse() else {
                return;
            };
            if aat.determinant().abs() < 1e-12 {
                return;
            }
            &un + a.transpose() * (inv * (&b - &a * &un))
        };
        if feasible(&u) {
            let c = (&u - &un).norm_squared();
            if best.as_ref().is_none_or(|(bc, _)| c < *bc) {
                best = Some((c, u));
            }
        }
    };
    consider(&[]);
    for i in 0..n {
        consider(&[i]);
        for j in i + 1..n {
            consider(&[i, j]);
            if m >= 3 {
                for l in j + 1..n {
                    consider(&[i, j, l]);
                }
            }
        }
    }
    best.expect("feasible problem").1
}

fn tr_cases() -> Vec<(sc_cbf::TranslationalInput, Vector3<f64>)> {
    let s = scenario();
    let mut rng = Lcg(21);
    let mut v = Vec::new();
    for k in 0..60 {
        // near the corridor edge or the CAZ, moving towards the boundary
        let ang = (4.0 + rng.next()).to_radians();
        let dist = if k % 2 == 0 {
            5.0 + 3.0 * rng.next()
        } else {
            2.0 + 0.3 * rng.next()
        };
        let dir = Vector3::new(
            -ang.cos(),
            ang.sin() * rng.next().signum(),
            0.2 * rng.next() * ang.sin(),
        )
        .normalize();
        let vel = Vector3::new(
            0.03 * (1.0 + rng.next()),
            0.01 * rng.next() * dir.y.signum(),
            0.005 * rng.next(),
        );
        let x = tr_input(
            &s,
            dir * dist,
            vel,
            quat::normalized(&[1.0, 0.1 * rng.next(), 0.1 * rng.next(), 0.2 * rng.next()]).unwrap(),
        );
        v.push((x, rng.v3(9.0)));
    }
    v
}

fn att_cases() -> Vec<(sc_cbf::AttitudeInput, Vector3<f64>)> {
    let mut rng = Lcg(33);
    let mut v = Vec::new();
    for _ in 0..60 {
        let q = quat::from_axis_angle(
            &Vector3::new(0.0, rng.next(), rng.next()),
            (3.5 + rng.next()).to_radians(),
        );
        let x = att_input(
            Vector3::new(-2.5, 0.0, 0.0) + rng.v3(0.2),
            q,
            rng.v3(0.2),
            30.0 * rng.next(),
        );
        v.push((x, rng.v3(14.0)));
    }
    v
}

fn rob_cases() -> Vec<(sc_cbf::RoboticInput, Vector7)> {
    let s = scenario();
    let robot = robot();
    let mut rng = Lcg(44);
    let mut v = Vec::new();
    for _ in 0..30 {
        let mut th = theta0(&s) + rng.v7(0.3);
        let j = ((rng.next() + 1.0) * 3.5) as usize % 7;
        th[j] = s.safety.robotic.theta_max_rad[j] - 0.05 * (1.0 + rng.next());
        let mut thd = rng.v7(0.2);
        thd[j] = 0.25;
        v.push((rob_input(&robot, th, thd), rng.v7(2.5)));
    }
    v
}

#[test]
fn translational_kkt_and_brute_force() {
    let mut f = TranslationalFilter::from_scenario(&scenario(), MASS);
    let mut solved = 0;
    for (x, un) in tr_cases() {
        let out = f.filter(&x, &un);
        assert_eq!(
            out.report.faults & !faults::QP_INFEASIBLE_RELAXED,
            0,
            "{:?}",
            out.report
        );
        if out.report.status == FilterStatus::Solved {
            solved += 1;
            let d = f.dump_qp();
            check_kkt(&d);
            let bf = brute_force(&d);
            assert!(
                (DVector::from_column_slice(out.u.as_slice()) - &bf).norm()
                    < 1e-5 * (1.0 + un.norm()),
                "{} vs {bf}",
                out.u
            );
        }
    }
    assert!(solved >= 20, "only {solved} cases exercised the solver");
}

#[test]
fn attitude_kkt_and_brute_force() {
    let mut f = AttitudeFilter::from_scenario(&scenario());
    let mut solved = 0;
    for (x, un) in att_cases() {
        let out = f.filter(&x, &un);
        assert_eq!(out.report.faults & !faults::QP_INFEASIBLE_RELAXED, 0);
        if out.report.status == FilterStatus::Solved {
            solved += 1;
            let d = f.dump_qp();
            check_kkt(&d);
            let bf = brute_force(&d);
            assert!(
                (DVector::from_column_slice(out.u.as_slice()) - &bf).norm()
                    < 1e-5 * (1.0 + un.norm()),
                "{} vs {bf}",
                out.u
            );
        }
    }
    assert!(solved >= 20, "only {solved} cases exercised the solver");
}

#[test]
fn robotic_kkt() {
    let mut f = RoboticFilter::from_scenario(&scenario());
    let mut solved = 0;
    for (x, un) in rob_cases() {
        let out = f.filter(&x, &un);
        if out.report.status == FilterStatus::Solved {
            solved += 1;
            check_kkt(&f.dump_qp());
        }
    }
    assert!(solved >= 10, "only {solved} cases exercised the solver");
}

#[test]
fn deterministic_and_history_independent() {
    let s = scenario();
    let run = move |fresh_each: bool| {
        let mut ft = TranslationalFilter::from_scenario(&s, MASS);
        let mut fa = AttitudeFilter::from_scenario(&s);
        let mut fr = RoboticFilter::from_scenario(&s);
        let mut bits: Vec<u64> = Vec::new();
        for (x, u) in tr_cases() {
            if fresh_each {
                ft = TranslationalFilter::from_scenario(&s, MASS);
            }
            let o = ft.filter(&x, &u);
            bits.extend(o.u.iter().chain(o.actuated.iter()).map(|v| v.to_bits()));
            bits.extend(o.report.deterministic_bits());
        }
        for (x, u) in att_cases() {
            if fresh_each {
                fa = AttitudeFilter::from_scenario(&s);
            }
            let o = fa.filter(&x, &u);
            bits.extend(o.u.iter().map(|v| v.to_bits()));
            bits.extend(o.report.deterministic_bits());
        }
        for (x, u) in rob_cases() {
            if fresh_each {
                fr = RoboticFilter::from_scenario(&s);
            }
            let o = fr.filter(&x, &u);
            bits.extend(o.u.iter().map(|v| v.to_bits()));
            bits.extend(o.report.deterministic_bits());
        }
        bits
    };
    let a = run(false);
    assert_eq!(a, run(false), "same sequence, same bits");
    assert_eq!(a, run(true), "a fresh filter per call gives the same bits");
    // from another thread, too
    let b = std::thread::spawn(move || run(false)).join().unwrap();
    assert_eq!(a, b);
}

#[test]
fn skip_path_equals_solve_path_for_feasible_nominal() {
    let s = scenario();
    let mut ft = TranslationalFilter::from_scenario(&s, MASS);
    let mut ft2 = TranslationalFilter::from_scenario(&s, MASS);
    ft2.set_skip_enabled(false);
    let x = tr_input(
        &s,
        Vector3::new(-6.0, 0.1, 0.0),
        Vector3::new(0.01, 0.0, 0.0),
        quat::IDENTITY,
    );
    for un in [
        Vector3::new(0.5, -0.2, 0.1),
        Vector3::new(-1.0, 0.0, 0.3),
        Vector3::zeros(),
    ] {
        let a = ft.filter(&x, &un);
        let b = ft2.filter(&x, &un);
        assert_eq!(a.report.status, FilterStatus::Skipped);
        assert_eq!(b.report.status, FilterStatus::Solved);
        assert_eq!(a.u, un);
        assert!((a.u - b.u).norm() < 1e-6, "{} vs {}", a.u, b.u);
        assert_eq!(a.report.active, b.report.active);
    }
    let mut fa = AttitudeFilter::from_scenario(&s);
    let mut fa2 = AttitudeFilter::from_scenario(&s);
    fa2.set_skip_enabled(false);
    let x = att_input(
        Vector3::new(-3.0, 0.0, 0.0),
        quat::IDENTITY,
        Vector3::zeros(),
        0.0,
    );
    let un = Vector3::new(0.1, -0.05, 0.02);
    let (a, b) = (fa.filter(&x, &un), fa2.filter(&x, &un));
    assert_eq!(a.report.status, FilterStatus::Skipped);
    assert_eq!(b.report.status, FilterStatus::Solved);
    assert!((a.u - b.u).norm() < 1e-6);
    let robot = robot();
    let mut fr = RoboticFilter::from_scenario(&s);
    let mut fr2 = RoboticFilter::from_scenario(&s);
    fr2.set_skip_enabled(false);
    let x = rob_input(&robot, theta0(&s), Vector7::zeros());
    let un = Vector7::from_fn(|i, _| 1e-4 * (i as f64 - 3.0));
    let (a, b) = (fr.filter(&x, &un), fr2.filter(&x, &un));
    assert_eq!(a.report.status, FilterStatus::Skipped);
    assert_eq!(b.report.status, FilterStatus::Solved);
    assert!((a.u - b.u).norm() < 1e-6);
}

#[test]
fn infeasible_qp_uses_relaxed_problem_with_hard_bounds() {
    let s = scenario();
    let mut f = TranslationalFilter::from_scenario(&s, MASS);
    // 1.7 m from the target closing at 0.5 m/s: no 7 N force can keep H_CAZ ≥ 0
    let x = tr_input(
        &s,
        Vector3::new(-1.7, 0.0, 0.0),
        Vector3::new(0.5, 0.0, 0.0),
        quat::IDENTITY,
    );
    let out = f.filter(&x, &Vector3::new(0.0, 0.0, 0.0));
    assert_eq!(out.report.status, FilterStatus::Relaxed);
    assert!(out.report.faults & faults::QP_INFEASIBLE_RELAXED != 0);
    assert!(out.report.slack > 0.0);
    assert!(out.actuated.amax() <= s.limits.force_max_n);
    // it brakes as hard as the box allows along -v (away from the target)
    let f_r = quat::to_matrix(&quat::conj(&s.reference_frame.attitude_in_hill)) * out.u;
    assert!(f_r.x < -6.9, "{f_r}");
}

#[test]
fn failed_qp_uses_bounded_fallback() {
    let s = scenario();
    let mut p = sc_cbf::TranslationalParams::from_scenario(&s, MASS);
    p.solver.max_iterations = 1;
    let mut f = TranslationalFilter::new(p);
    let x = tr_input(
        &s,
        Vector3::new(-1.7, 0.0, 0.0),
        Vector3::new(0.5, 0.0, 0.0),
        quat::IDENTITY,
    );
    let out = f.filter(&x, &Vector3::zeros());
    assert_eq!(out.report.status, FilterStatus::Fallback);
    assert!(out.report.faults & faults::QP_FAILED_FALLBACK != 0);
    let (fb_h, fb_b) = f.fallback(&x);
    assert!((out.u - fb_h).norm() < 1e-12);
    assert!((out.actuated - fb_b).norm() < 1e-12);
    assert!(fb_b.amax() <= s.limits.force_max_n);
    // brake: opposes the relative velocity
    assert!(fb_h.dot(&x.v_h) < 0.0);
}

#[test]
fn report_names_and_dump_serialise() {
    assert_eq!(sc_cbf::names::TRANSLATIONAL.len(), 2);
    assert_eq!(sc_cbf::names::ATTITUDE.len(), 7);
    assert_eq!(sc_cbf::names::ROBOTIC.len(), 42);
    let mut all: Vec<&str> = sc_cbf::names::TRANSLATIONAL
        .iter()
        .chain(sc_cbf::names::ATTITUDE.iter())
        .chain(sc_cbf::names::ROBOTIC.iter())
        .copied()
        .collect();
    all.sort();
    all.dedup();
    assert_eq!(all.len(), 51, "names are unique");
    let s = scenario();
    let mut f = TranslationalFilter::from_scenario(&s, MASS);
    let (x, u) = tr_cases()[0];
    f.filter(&x, &u);
    let j = serde_json::to_string(&f.dump_qp()).unwrap();
    let back: QpDump = serde_json::from_str(&j).unwrap();
    assert_eq!(back.u_nom.len(), 3);
}
