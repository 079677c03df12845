//! Filter-level checks of the solved QPs: KKT optimality with multipliers computed here,
//! agreement with an exhaustive active-set solution and with the independent Clarabel
//! engine, the skip path, the relaxed (lexicographic least-violation) problem against
//! Clarabel and its independence from the nominal's magnitude, the substitute nominal for
//! a missing or invalid nominal, the solver-failure path, bounds and finiteness.

mod common;
use common::*;
use nalgebra::{DVector, SVector, Vector3};
use sc_cbf::attitude::ACCEL_CAPS;
use sc_cbf::barrier::Row;
use sc_cbf::common::NOMINAL_RANGE;
use sc_cbf::engine::{Engine, Kind};
use sc_cbf::robotic::Vector7;
use sc_cbf::{
    AttitudeFilter, AttitudeInput, FilterOutput, FilterStatus, QpDump, RoboticFilter, RoboticInput,
    TranslationalFilter, TranslationalInput, faults,
};
use sc_models::quat;

// ------------------------------------------------------------------ cases

/// States near the corridor wall or the CAZ, moving towards the boundary, with random
/// nominal forces up to 1.5 F.
fn tr_cases(seed: u64, count: usize) -> Vec<(TranslationalInput, Vector3<f64>)> {
    let s = scenario();
    let fmax = s.limits.force_max_n;
    let mut rng = Lcg(seed);
    (0..count)
        .map(|k| {
            let ang = (3.8 + 1.3 * rng.next()).to_radians();
            let phi = std::f64::consts::PI * rng.next();
            let dir = Vector3::new(-ang.cos(), ang.sin() * phi.cos(), ang.sin() * phi.sin());
            let dist = if k % 2 == 0 {
                4.5 + 3.0 * rng.next()
            } else {
                2.0 + 0.3 * rng.next()
            };
            let out = Vector3::new(0.0, phi.cos(), phi.sin());
            let v = -dir * (0.03 * (1.0 + rng.next()))
                + out * (0.004 * (1.0 + rng.next()))
                + rng.v3(0.003);
            let x = tr_input(&s, dir * dist, v, rng.unit_quat(), rng.v3(0.1));
            (x, rng.v3(1.5 * fmax))
        })
        .collect()
}

/// Pointing errors of 2–5° (the cone is 5°), body rates up to 0.06 rad/s per axis, random
/// arm states, upstream forces and nominal torques up to 1.5 T (many of these states are
/// outside the braking-safe set: relaxed).
fn att_cases(seed: u64, count: usize) -> Vec<(AttitudeInput, Vector3<f64>)> {
    let s = scenario();
    let robot = robot();
    let tmax = s.limits.torque_max_nm;
    let mut rng = Lcg(seed);
    (0..count)
        .map(|_| {
            let com = Vector3::new(-2.8, 0.0, 0.0) + rng.v3(0.3);
            let t = 40.0 * (1.0 + rng.next());
            let st = ServicerState {
                theta: theta_inside(&s, &mut rng, 0.1),
                theta_dot: rng.v7(0.1),
                omega_b: rng.v3(0.06),
                q_rb: pointing(
                    &s,
                    &com,
                    t,
                    &rng.v3(1.0),
                    (3.5 + 1.5 * rng.next()).to_radians(),
                ),
                com_r: com,
                com_v_r: rng.v3(0.02),
                t,
                f_b: rng.v3(5.0),
            };
            (att_input(&s, &robot, &st), rng.v3(1.5 * tmax))
        })
        .collect()
}

/// One joint close to a limit and moving towards it, random nominal torques.
fn rob_cases(seed: u64, count: usize) -> Vec<(RoboticInput, Vector7)> {
    let s = scenario();
    let robot = robot();
    let mut rng = Lcg(seed);
    (0..count)
        .map(|_| {
            let mut th = theta_inside(&s, &mut rng, 0.15);
            let j = ((rng.next() + 1.0) * 3.5) as usize % 7;
            let up = rng.next() > 0.0;
            let mut thd = rng.v7(0.1);
            if up {
                th[j] = s.safety.robotic.theta_max_rad[j] - 0.05 * (1.2 + rng.next());
                thd[j] = 0.2;
            } else {
                th[j] = s.safety.robotic.theta_min_rad[j] + 0.05 * (1.2 + rng.next());
                thd[j] = -0.2;
            }
            (rob_input(&robot, th, thd), rng.v7(2.5))
        })
        .collect()
}

// ------------------------------------------------------------------ helpers

fn assert_output_sane<const M: usize, const N: usize>(o: &FilterOutput<M, N>, bound: f64) {
    assert!(
        o.u.iter().chain(o.actuated.iter()).all(|x| x.is_finite()),
        "{o:?}"
    );
    assert!(
        o.actuated.amax() <= bound,
        "{} > {bound}",
        o.actuated.amax()
    );
}

/// KKT at the solution of `qp` (multipliers of our own): rows hold and the stationarity
/// residual vanishes, both relative to the input bound.
fn check_kkt(qp: &Qp, u: &DVector<f64>, bound: f64, what: &str) {
    let (viol, stat, lam) = kkt(qp, u, 1e-9 * bound);
    assert!(
        viol <= 1e-9 * bound,
        "{what}: a row is violated by {viol:e}"
    );
    assert!(
        stat <= 1e-9 * bound,
        "{what}: stationarity residual {stat:e}, λ = {lam:?}"
    );
}

/// The engine's barrier multipliers (`dump.row_duals`) are those of `½‖u − u_nom‖²`:
/// `u − u_nom = Σ λ_i a_i` over all active rows (note: `QpDump`'s documentation states the
/// Clarabel engine's convention `2(u − u_nom) = Σ λ_i a_i − Gᵀμ`). Compared with ours where
/// the multipliers are unique (active rows independent); returns how many positive
/// multipliers were compared.
fn check_duals(d: &QpDump, qp: &Qp, u: &DVector<f64>, bound: f64, what: &str) -> usize {
    let (_, _, lam) = kkt(qp, u, 1e-9 * bound);
    let active: Vec<usize> = (0..lam.len()).filter(|&i| lam[i] > 0.0).collect();
    if active.is_empty() {
        return 0;
    }
    let a = nalgebra::DMatrix::from_fn(qp.m(), active.len(), |r, c| qp.a[active[c]][r]);
    if active.len() > qp.m() || a.rank(1e-9) < active.len() {
        return 0;
    }
    for (i, (engine, ours)) in d.row_duals.iter().zip(&lam).enumerate().take(qp.nb) {
        assert!(
            (engine - ours).abs() <= 1e-6 * (ours.abs() + engine.abs()) + 1e-12,
            "{what}: row {i} multiplier {engine} vs KKT {ours}"
        );
    }
    (0..qp.nb).filter(|&i| lam[i] > 0.0).count()
}

fn near(a: &DVector<f64>, b: &DVector<f64>, tol: f64) -> bool {
    (a - b).amax() <= tol
}

// ------------------------------------------------------------------ solved QPs

#[test]
fn translational_solved_qps_are_kkt_points_and_match_brute_force_and_clarabel() {
    let s = scenario();
    let fmax = s.limits.force_max_n;
    let mut f = TranslationalFilter::from_scenario(&s, mass());
    let mut seen = [0usize; 4];
    let mut clarabel_err = 0.0f64;
    let mut duals = 0;
    for (k, (x, un)) in tr_cases(21, 200).into_iter().enumerate() {
        let out = f.filter(&x, &un);
        seen[out.report.status as usize] += 1;
        assert_output_sane(&out, fmax);
        assert_eq!(
            out.report.faults & !faults::QP_INFEASIBLE_RELAXED,
            0,
            "case {k}: {:?}",
            out.report
        );
        if out.report.status != FilterStatus::Solved {
            continue;
        }
        let d = f.dump_qp();
        let qp = Qp::from_dump(&d);
        // the dumped problem is the filter's own
        let (rows, _, hard) = f.rows(&x).unwrap();
        let own = Qp::from_rows(&un, &rows, &hard);
        assert_eq!(qp.c, own.c);
        let u = dvec(&out.u);
        check_kkt(&qp, &u, fmax, &format!("case {k}"));
        duals += check_duals(&d, &qp, &u, fmax, &format!("case {k}"));
        let bf = brute_force(&qp).expect("feasible");
        assert!(
            near(&u, &bf, 1e-9 * fmax),
            "case {k}: {u} vs brute force {bf}"
        );
        let cl = clarabel(&qp, 3f64.sqrt() * fmax).expect("Clarabel solves it");
        clarabel_err = clarabel_err.max((&u - &cl).amax() / fmax);
    }
    println!(
        "statuses {seen:?}; {duals} multipliers compared; max |u − u_Clarabel|∞ / F = {clarabel_err:e}"
    );
    assert!(
        clarabel_err <= 1e-6,
        "Clarabel disagrees by {clarabel_err:e} F"
    );
    assert!(seen[1] >= 50, "only {} solved cases: {seen:?}", seen[1]);
    assert!(duals >= 10, "only {duals} barrier multipliers compared");
}

/// The six rows `cap ∓ (P τ + r)_i ≥ 0` that the attitude filter adds to its QP for an
/// acceleration cap (not part of `dump_qp()`).
fn cap_rows(x: &AttitudeInput, cap: f64) -> Vec<Row<3>> {
    (0..3)
        .flat_map(|i| {
            let row: Vector3<f64> = x.p.row(i).transpose();
            [
                Row {
                    a: -row,
                    c: cap - x.r[i],
                },
                Row {
                    a: row,
                    c: cap + x.r[i],
                },
            ]
        })
        .collect()
}

#[test]
fn attitude_solved_qps_are_kkt_points_and_match_brute_force_and_clarabel() {
    let s = scenario();
    let tmax = s.limits.torque_max_nm;
    let mut f = AttitudeFilter::from_scenario(&s, mass());
    let mut seen = [0usize; 4];
    let mut clarabel_err = 0.0f64;
    let mut dump_incomplete = 0;
    let mut duals = 0;
    for (k, (x, un)) in att_cases(33, 200).into_iter().enumerate() {
        let out = f.filter(&x, &un);
        seen[out.report.status as usize] += 1;
        assert_output_sane(&out, tmax);
        assert_eq!(
            out.report.faults & !faults::QP_INFEASIBLE_RELAXED,
            0,
            "case {k}: {:?}",
            out.report
        );
        if out.report.status != FilterStatus::Solved {
            continue;
        }
        let d = f.dump_qp();
        let dumped = Qp::from_dump(&d);
        let u = dvec(&out.u);
        if brute_force(&dumped).is_none_or(|bf| !near(&u, &bf, 1e-9 * tmax)) {
            dump_incomplete += 1;
        }
        // the solved QP = the dumped rows + the acceleration cap the filter chose: the
        // nominal's own acceleration or one of ACCEL_CAPS
        let first = (x.p * un + x.r).amax();
        let mut matched = None;
        for cap in std::iter::once(first).chain(ACCEL_CAPS) {
            let mut hard: Vec<Row<3>> = (0..d.bounds_g.len())
                .map(|j| Row {
                    a: -Vector3::from_column_slice(&d.bounds_g[j]),
                    c: d.bounds_g_max[j],
                })
                .collect();
            hard.extend(cap_rows(&x, cap));
            let rows: Vec<Row<3>> = (0..d.rows_a.len())
                .map(|i| Row {
                    a: Vector3::from_column_slice(&d.rows_a[i]),
                    c: d.rows_c[i],
                })
                .collect();
            let qp = Qp::from_rows(&un, &rows, &hard);
            if let Some(bf) = brute_force(&qp)
                && near(&u, &bf, 1e-9 * tmax)
            {
                matched = Some(qp);
                break;
            }
        }
        let qp = matched.unwrap_or_else(|| panic!("case {k}: {u} is no cap's QP minimiser"));
        check_kkt(&qp, &u, tmax, &format!("case {k}"));
        duals += check_duals(&d, &qp, &u, tmax, &format!("case {k}"));
        let cl = clarabel(&qp, tmax).expect("Clarabel solves it");
        clarabel_err = clarabel_err.max((&u - &cl).amax() / tmax);
    }
    println!(
        "statuses {seen:?}; max |u − u_Clarabel|∞ / T = {clarabel_err:e}; \
         {dump_incomplete} solved cases whose dump alone is not the solved QP; {duals} multipliers compared"
    );
    // Clarabel is an interior-point method: on the line of sight's weak rows (gains of
    // ~1e-3 per N m) it is only good to ~1e-6 T; the exact check is the brute force above
    assert!(
        clarabel_err <= 1e-5,
        "Clarabel disagrees by {clarabel_err:e} T"
    );
    assert!(seen[1] >= 40, "only {} solved cases: {seen:?}", seen[1]);
    assert!(duals >= 20, "only {duals} barrier multipliers compared");
}

/// KNOWN SRC ISSUE (reported): the attitude filter solves its QP with six extra rows that
/// cap the body's angular acceleration (`ACCEL_CAPS`, the certificate's premise), but
/// `dump_qp()` records only the barrier and hard rows, so a dumped QP does not replay the
/// solved one when a cap row is active (16 of 111 solved cases here; the test above
/// reconstructs the caps).
#[test]
fn attitude_dump_qp_is_the_solved_qp() {
    let s = scenario();
    let tmax = s.limits.torque_max_nm;
    let mut f = AttitudeFilter::from_scenario(&s, mass());
    for (k, (x, un)) in att_cases(33, 200).into_iter().enumerate() {
        let out = f.filter(&x, &un);
        if out.report.status == FilterStatus::Solved {
            check_kkt(
                &Qp::from_dump(&f.dump_qp()),
                &dvec(&out.u),
                tmax,
                &format!("case {k}"),
            );
        }
    }
}

/// Every solved robotic command holds the rows it reports (`dump_qp()`: the certified or
/// verified barrier rows, the torque box and the contract with the attitude filter), and
/// where it is the minimiser of that QP it is Clarabel's solution too.
#[test]
fn robotic_solved_commands_hold_their_dumped_certificate_and_match_clarabel() {
    let s = scenario();
    let tmax = s.limits.joint_torque_max_nm;
    let mut f = RoboticFilter::from_scenario(&s, robot());
    let mut seen = [0usize; 4];
    let mut clarabel_err = 0.0f64;
    let (mut solved, mut kkt_points) = (0, 0);
    for (k, (x, un)) in rob_cases(44, 120).into_iter().enumerate() {
        let out = f.filter(&x, &un);
        seen[out.report.status as usize] += 1;
        assert_output_sane(&out, tmax);
        if out.report.status != FilterStatus::Solved {
            continue;
        }
        solved += 1;
        let d = f.dump_qp();
        let qp = Qp::from_dump(&d);
        let u = dvec(&out.u);
        let (viol, stat, _) = kkt(&qp, &u, 1e-9 * tmax);
        assert!(
            viol <= 1e-9 * tmax,
            "case {k}: the reported rows are violated by {viol:e}"
        );
        for (i, phi) in out.report.phi.iter().enumerate() {
            assert!(*phi >= -1e-9, "case {k}: row {i} Φ = {phi}");
        }
        if stat <= 1e-9 * tmax {
            kkt_points += 1;
            let cl = clarabel(&qp, tmax).expect("Clarabel solves it");
            clarabel_err = clarabel_err.max((&u - &cl).amax() / tmax);
        }
    }
    println!(
        "statuses {seen:?}; {kkt_points} of {solved} solved commands are the minimiser of their \
         dumped QP; max |u − u_Clarabel|∞ / T_M = {clarabel_err:e}"
    );
    assert!(
        clarabel_err <= 1e-6,
        "Clarabel disagrees by {clarabel_err:e} T_M"
    );
    assert!(solved >= 30, "only {solved} solved cases: {seen:?}");
    assert!(kkt_points * 10 >= solved * 9, "{kkt_points} of {solved}");
}

/// KNOWN SRC ISSUE (reported): in the robotic filter's a-posteriori certificate, when the
/// second round's check passes (`rows = Certified(accel(res.u))`), `res.u` is the
/// minimiser of the *previous* rows (`Certified(grown)`), but the rows recorded for
/// `dump_qp()` and `report.phi` are the new ones: the command holds them but is not their
/// QP's minimiser (more invasive than needed; the dump does not replay). 5 of 109 solved
/// cases here, stationarity residuals 1.3–4.4 N m.
#[test]
fn robotic_solved_commands_are_minimisers_of_their_dumped_qp() {
    let s = scenario();
    let tmax = s.limits.joint_torque_max_nm;
    let mut f = RoboticFilter::from_scenario(&s, robot());
    for (k, (x, un)) in rob_cases(44, 120).into_iter().enumerate() {
        let out = f.filter(&x, &un);
        if out.report.status == FilterStatus::Solved {
            check_kkt(
                &Qp::from_dump(&f.dump_qp()),
                &dvec(&out.u),
                tmax,
                &format!("case {k}"),
            );
        }
    }
}

// ------------------------------------------------------------------ skip path

#[test]
fn feasible_nominal_is_returned_unchanged_and_equals_the_solved_qp() {
    let s = scenario();
    let id = quat::IDENTITY;
    let z = Vector3::zeros();
    // translational: on the axis, far from the CAZ, slow
    let mut ft = TranslationalFilter::from_scenario(&s, mass());
    let mut ft2 = TranslationalFilter::from_scenario(&s, mass());
    ft2.set_skip_enabled(false);
    let x = tr_input(
        &s,
        Vector3::new(-6.0, 0.05, 0.0),
        Vector3::new(0.01, 0.0, 0.0),
        id,
        z,
    );
    for un in [
        Vector3::new(0.5, -0.2, 0.1),
        Vector3::new(-1.0, 0.0, 0.3),
        Vector3::zeros(),
    ] {
        let (a, b) = (ft.filter(&x, &un), ft2.filter(&x, &un));
        assert_eq!(a.report.status, FilterStatus::Skipped);
        assert_eq!(b.report.status, FilterStatus::Solved);
        assert_eq!(a.u, un, "bit for bit");
        assert!(
            (a.u - b.u).amax() <= 1e-12 * s.limits.force_max_n,
            "{} vs {}",
            a.u,
            b.u
        );
        assert_eq!(a.report.active, b.report.active);
        assert_eq!(a.report.faults, 0);
    }
    // attitude: pointing at the grasping point, at rest
    let robot = robot();
    let mut fa = AttitudeFilter::from_scenario(&s, mass());
    let mut fa2 = AttitudeFilter::from_scenario(&s, mass());
    fa2.set_skip_enabled(false);
    let com = Vector3::new(-3.0, 0.0, 0.0);
    let x = att_input(
        &s,
        &robot,
        &ServicerState::rest(&s, com, pointing(&s, &com, 0.0, &Vector3::z(), 0.0)),
    );
    let un = Vector3::new(0.1, -0.05, 0.02);
    let (a, b) = (fa.filter(&x, &un), fa2.filter(&x, &un));
    assert_eq!(a.report.status, FilterStatus::Skipped);
    assert_eq!(b.report.status, FilterStatus::Solved);
    assert_eq!(a.u, un);
    assert!((a.u - b.u).amax() <= 1e-12 * s.limits.torque_max_nm);
    // robotic: the stowed arm at rest
    let mut fr = RoboticFilter::from_scenario(&s, robot.clone());
    let mut fr2 = RoboticFilter::from_scenario(&s, robot.clone());
    fr2.set_skip_enabled(false);
    let x = rob_input(&robot, theta0(&s), Vector7::zeros());
    let hold = -(x.m_eff * (x.drift + x.xi));
    let un = hold + Vector7::from_fn(|i, _| 1e-4 * (i as f64 - 3.0));
    let (a, b) = (fr.filter(&x, &un), fr2.filter(&x, &un));
    assert_eq!(a.report.status, FilterStatus::Skipped, "{:?}", a.report);
    assert_eq!(b.report.status, FilterStatus::Solved);
    assert_eq!(a.u, un);
    assert!((a.u - b.u).amax() <= 1e-12 * s.limits.joint_torque_max_nm);
}

// ------------------------------------------------------------------ relaxed problem

/// Scales of the nominal along one direction: from a tenth of the bound to the largest
/// nominal still accepted (`NOMINAL_RANGE × bound`).
const SCALES: [f64; 5] = [0.1, 1.0, 10.0, 100.0, 0.999 * NOMINAL_RANGE];

/// What the relaxed checks found, for the report line.
#[derive(Default, Debug)]
struct RelaxedStats {
    cases: usize,
    /// Commands compared with Clarabel's projection, and the largest distance to it
    /// relative to `bound + ‖u_nom‖∞`.
    compared: usize,
    worst: f64,
    /// Largest relative deviation of Clarabel's LP values from the exact ones.
    lp_deviation: f64,
}

/// The relaxed command against the lexicographic LPs (Clarabel; exact vertices for ≤ 3
/// inputs) + Clarabel's projection, for nominals of every magnitude along `dir`: `t*` is
/// the same bits for all of them and equals the reference's; the command is the
/// projection of the nominal onto the rows with the reference's allowances (KKT with
/// multipliers of our own, and Clarabel's own solution where it resolves it).
#[allow(clippy::too_many_arguments)] // a test helper: each argument is one axis of the check
fn check_relaxed<const M: usize>(
    what: &str,
    bound: f64,
    u_inf: f64,
    rows: &(Vec<Row<M>>, Vec<f64>, Vec<Row<M>>),
    tiers: &[u8],
    dir: &SVector<f64, M>,
    stats: &mut RelaxedStats,
    mut run: impl FnMut(&SVector<f64, M>) -> (SVector<f64, M>, FilterStatus, f64, u32),
) {
    let (barrier, w, hard) = rows;
    let mut t_ref = None;
    stats.cases += 1;
    // the allowances do not depend on the nominal (that is the point): computed once
    let lex = lexicographic_tiered(&Qp::from_rows(dir, barrier, hard), w, tiers)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    stats.lp_deviation = stats.lp_deviation.max(lex.clarabel_lp_deviation);
    for k in SCALES {
        let un = dir * (k * bound / dir.amax());
        let (u, status, t, flags) = run(&un);
        assert_eq!(status, FilterStatus::Relaxed, "{what}: scale {k}");
        assert_ne!(flags & faults::QP_INFEASIBLE_RELAXED, 0);
        assert!(t > 0.0);
        // the allowance cannot be bought: t* is the same for every nominal, bit for bit
        match t_ref {
            None => t_ref = Some(t),
            Some(t0) => assert_eq!(
                t.to_bits(),
                f64::to_bits(t0),
                "{what}: t* {t} at scale {k} vs {t0}"
            ),
        }
        let qp = Qp::from_rows(&un, barrier, hard);
        let t_tol = if M <= 3 { 1e-9 } else { 1e-6 };
        assert!(
            (t - lex.t1).abs() <= t_tol * lex.t1,
            "{what}: t* {t} vs reference {}",
            lex.t1
        );
        // the projection onto the relaxed rows, to 1e-7 of the problem's scale (the rows'
        // gains differ by orders of magnitude: the allowances of later rounds are only as
        // exact as the earlier rows' positions)
        let u = dvec(&u);
        let scale = bound + un.amax();
        let (viol, stat, _) = kkt(&qp.relaxed(&lex.allowance), &u, 1e-7 * scale);
        assert!(
            viol <= 1e-7 * scale && stat <= 1e-7 * scale,
            "{what} scale {k}: KKT violation {viol:e}, stationarity {stat:e}"
        );
        let relaxed = qp.relaxed(&lex.allowance);
        let resolved = clarabel(&relaxed, u_inf).filter(|u_cl| {
            // a reference that breaks the rows itself (interior-point tolerance on an
            // ill-conditioned problem) is not one
            let (v, st, _) = kkt(&relaxed, u_cl, 1e-7 * scale);
            v <= 1e-9 * scale && st <= 1e-7 * scale
        });
        if let Some(u_cl) = resolved {
            stats.compared += 1;
            let err = (&u - &u_cl).amax() / scale;
            stats.worst = stats.worst.max(err);
            assert!(err <= 1e-6, "{what} scale {k}: {u} vs Clarabel {u_cl}");
        }
        // no barrier row is violated by more than t* of its weight, every hard row holds
        let us = SVector::<f64, M>::from_column_slice(u.as_slice());
        for (i, r) in barrier.iter().enumerate() {
            assert!(
                r.phi(&us) >= -w[i] * t * (1.0 + 1e-6) - 1e-9 * bound,
                "{what}: row {i}"
            );
        }
        for r in hard {
            assert!(r.phi(&us) >= -1e-12 * scale);
        }
    }
}

#[test]
fn translational_relaxed_command_is_the_lexicographic_least_violation_and_ignores_the_nominal_size()
{
    let s = scenario();
    let fmax = s.limits.force_max_n;
    let mut f = TranslationalFilter::from_scenario(&s, mass());
    let mut rng = Lcg(5);
    let mut stats = RelaxedStats::default();
    for k in 0..40 {
        // inside or at the CAZ closing fast, or at the corridor wall moving out fast
        let (r, v) = if k % 2 == 0 {
            (
                Vector3::new(-1.7, 0.0, 0.0) + rng.v3(0.1),
                Vector3::new(0.3 + 0.2 * rng.next(), 0.0, 0.0) + rng.v3(0.05),
            )
        } else {
            let a = (4.9f64 + 0.3 * rng.next()).to_radians();
            (
                Vector3::new(-5.0 * a.cos(), 5.0 * a.sin(), 0.0),
                Vector3::new(0.0, 0.1 + 0.05 * rng.next(), 0.0) + rng.v3(0.02),
            )
        };
        let x = tr_input(&s, r, v, rng.unit_quat(), rng.v3(0.1));
        let rows = f.rows(&x).unwrap();
        let dir = rng.v3(1.0);
        if f.filter(&x, &dir).report.status != FilterStatus::Relaxed {
            continue;
        }
        check_relaxed(
            &format!("case {k}"),
            fmax,
            3f64.sqrt() * fmax,
            &rows,
            &[],
            &dir,
            &mut stats,
            |un| {
                let o = f.filter(&x, un);
                assert_output_sane(&o, fmax);
                (o.u, o.report.status, o.report.violation, o.report.faults)
            },
        );
    }
    println!("{stats:?}");
    assert!(stats.cases >= 20, "{stats:?}");
    assert!(
        stats.compared >= 3 * stats.cases,
        "Clarabel resolved too few: {stats:?}"
    );
}

#[test]
fn attitude_relaxed_command_is_the_lexicographic_least_violation_and_ignores_the_nominal_size() {
    let s = scenario();
    let robot = robot();
    let tmax = s.limits.torque_max_nm;
    let mut f = AttitudeFilter::from_scenario(&s, mass());
    let mut rng = Lcg(6);
    let mut stats = RelaxedStats::default();
    for k in 0..30 {
        // at the cone's edge turning out fast, or beyond a rate limit
        let com = Vector3::new(-2.8, 0.0, 0.0) + rng.v3(0.2);
        let axis = Vector3::new(0.0, rng.next(), rng.next()).normalize();
        let mut st = ServicerState::rest(
            &s,
            com,
            pointing(&s, &com, 10.0, &axis, (4.8 + 0.3 * rng.next()).to_radians()),
        );
        st.t = 10.0;
        st.omega_b = if k % 2 == 0 {
            axis * (0.05 + 0.1 * rng.next().abs())
        } else {
            rng.v3(0.1) + Vector3::new(0.0, 0.0, 0.21)
        };
        st.theta = theta_inside(&s, &mut rng, 0.2);
        let x = att_input(&s, &robot, &st);
        let rows = f.rows(&x).unwrap();
        let dir = rng.v3(1.0);
        if f.filter(&x, &dir).report.status != FilterStatus::Relaxed {
            continue;
        }
        check_relaxed(
            &format!("case {k}"),
            tmax,
            tmax,
            &rows,
            &sc_cbf::attitude::TIERS,
            &dir,
            &mut stats,
            |un| {
                let o = f.filter(&x, un);
                assert_output_sane(&o, tmax);
                (o.u, o.report.status, o.report.violation, o.report.faults)
            },
        );
    }
    println!("{stats:?}");
    assert!(stats.cases >= 15, "{stats:?}");
    assert!(
        stats.compared >= 3 * stats.cases,
        "Clarabel resolved too few: {stats:?}"
    );
}

/// The engine alone on random infeasible problems in 3 and 7 inputs: the relaxed command
/// is Clarabel's lexicographic LP + QP solution, `t*` does not depend on the nominal, and
/// one infeasible row does not license violating the others.
#[test]
fn engine_relaxation_matches_clarabel_on_random_infeasible_problems() {
    fn run<const M: usize, const N: usize>(seed: u64) -> RelaxedStats {
        let mut rng = Lcg(seed);
        let mut eng = Engine::<M, N>::new();
        let mut stats = RelaxedStats::default();
        for _ in 0..150 {
            let nb = 2 + (rng.next().abs() * 5.0) as usize;
            let barrier: Vec<Row<M>> = (0..nb)
                .map(|_| Row {
                    a: SVector::from_fn(|_, _| rng.next()) * 10f64.powf(rng.next()),
                    c: rng.next() * 3.0 - 1.0,
                })
                .collect();
            let w: Vec<f64> = (0..nb).map(|_| 10f64.powf(rng.next())).collect();
            let hard: Vec<Row<M>> = (0..2 * M)
                .map(|k| {
                    let mut a = SVector::<f64, M>::zeros();
                    a[k / 2] = if k % 2 == 0 { -1.0 } else { 1.0 };
                    Row { a, c: 1.0 }
                })
                .collect();
            let dir = SVector::<f64, M>::from_fn(|_, _| rng.next());
            // every third problem with two priority tiers
            let tiers: Vec<u8> = if stats.cases % 3 == 2 {
                (0..nb).map(|i| (i % 2) as u8).collect()
            } else {
                Vec::new()
            };
            let first = eng.solve_tiered(&dir, &barrier, &w, &tiers, &hard);
            // the hard problem alone: the same command where it has one, none otherwise
            match (first.kind, eng.solve_hard(&dir, &barrier, &hard)) {
                (Kind::Skipped | Kind::Solved, Some(h)) => assert_eq!(h, first),
                (Kind::Relaxed | Kind::Failed, None) => {}
                (k, h) => panic!("solve_hard {h:?} against {k:?}"),
            }
            if first.kind != Kind::Relaxed {
                continue;
            }
            check_relaxed(
                "engine",
                1.0,
                1.0,
                &(barrier.clone(), w.clone(), hard.clone()),
                &tiers,
                &dir,
                &mut stats,
                |un| {
                    let o = eng.solve_tiered(un, &barrier, &w, &tiers, &hard);
                    let st = if o.kind == Kind::Relaxed {
                        FilterStatus::Relaxed
                    } else {
                        FilterStatus::Fallback
                    };
                    (o.u, st, o.violation, faults::QP_INFEASIBLE_RELAXED)
                },
            );
        }
        stats
    }
    let s3 = run::<3, 16>(1);
    let s7 = run::<7, 24>(2);
    println!("M = 3: {s3:?}\nM = 7: {s7:?}");
    for st in [&s3, &s7] {
        assert!(st.cases >= 30, "{st:?}");
        assert!(
            st.compared >= 3 * st.cases,
            "Clarabel resolved too few: {st:?}"
        );
    }
}

// ------------------------------------------------------------------ substitute nominal

/// `filter_with(None)` and an invalid nominal run the QP on the substitute (the braking
/// law): same command as filtering the braking law itself, never the fallback.
fn check_substitute<const M: usize, const N: usize>(
    what: &str,
    bound: f64,
    brake: SVector<f64, M>,
    mut run: impl FnMut(Option<&SVector<f64, M>>) -> FilterOutput<M, N>,
) -> FilterStatus {
    let reference = run(Some(&brake));
    assert_eq!(
        reference.report.faults & (faults::NOMINAL_MISSING | faults::INVALID_NOMINAL),
        0
    );
    let missing = run(None);
    assert_ne!(missing.report.faults & faults::NOMINAL_MISSING, 0, "{what}");
    assert_eq!(missing.report.faults & faults::INVALID_NOMINAL, 0, "{what}");
    assert_ne!(missing.report.status, FilterStatus::Fallback, "{what}");
    assert_eq!(missing.u, reference.u, "{what}: missing nominal");
    assert_eq!(missing.report.status, reference.report.status);
    let mut over = SVector::<f64, M>::zeros();
    over[0] = NOMINAL_RANGE * bound * 1.001;
    let mut nan = SVector::<f64, M>::zeros();
    nan[M - 1] = f64::NAN;
    let mut inf = SVector::<f64, M>::repeat(0.1);
    inf[0] = f64::NEG_INFINITY;
    for bad in [nan, inf, SVector::repeat(1e300), over] {
        let o = run(Some(&bad));
        assert_ne!(
            o.report.faults & faults::INVALID_NOMINAL,
            0,
            "{what}: {bad}"
        );
        assert_eq!(o.report.faults & faults::NOMINAL_MISSING, 0);
        assert_ne!(
            o.report.status,
            FilterStatus::Fallback,
            "{what}: the QP must still run"
        );
        assert_eq!(o.u, reference.u, "{what}: invalid nominal {bad}");
        assert_output_sane(&o, bound);
    }
    // the largest accepted nominal is used as given
    let mut big = SVector::<f64, M>::zeros();
    big[0] = NOMINAL_RANGE * bound * 0.999;
    let o = run(Some(&big));
    assert_eq!(o.report.faults & faults::INVALID_NOMINAL, 0, "{what}");
    assert_output_sane(&o, bound);
    missing.report.status
}

#[test]
fn missing_or_invalid_nominal_runs_the_qp_on_the_substitute() {
    let s = scenario();
    let robot = robot();
    let mut statuses = Vec::new();
    let mut ft = TranslationalFilter::from_scenario(&s, mass());
    for (x, _) in tr_cases(8, 30) {
        let brake = ft.brake(&x).0;
        statuses.push(check_substitute(
            "translational",
            s.limits.force_max_n,
            brake,
            |u| ft.filter_with(&x, u),
        ));
        // the backup is the same call
        assert_eq!(ft.backup(&x).u, ft.filter_with(&x, None).u);
    }
    let mut fa = AttitudeFilter::from_scenario(&s, mass());
    for (x, _) in att_cases(9, 30) {
        let brake = fa.brake(&x);
        statuses.push(check_substitute(
            "attitude",
            s.limits.torque_max_nm,
            brake,
            |u| fa.filter_with(&x, u),
        ));
        assert_eq!(fa.backup(&x).u, fa.filter_with(&x, None).u);
    }
    let mut fr = RoboticFilter::from_scenario(&s, robot.clone());
    for (x, _) in rob_cases(10, 20) {
        let brake = fr.brake(&x);
        statuses.push(check_substitute(
            "robotic",
            s.limits.joint_torque_max_nm,
            brake,
            |u| fr.filter_with(&x, u),
        ));
        assert_eq!(fr.backup(&x).u, fr.filter_with(&x, None).u);
    }
    // the substitute is not always feasible as it is: the QP really ran
    assert!(
        statuses.iter().any(|s| *s != FilterStatus::Skipped),
        "{statuses:?}"
    );
}

// ------------------------------------------------------------------ solver failure

#[test]
fn solver_failure_falls_back_to_the_braking_law() {
    // the engine: non-finite rows are refused, the command is not touched
    let mut eng = Engine::<3, 8>::new();
    let un = Vector3::new(1.0, 2.0, 3.0);
    let bad = [Row {
        a: Vector3::new(f64::NAN, 0.0, 0.0),
        c: -1.0,
    }];
    let o = eng.solve(&un, &bad, &[1.0], &[]);
    assert_eq!(o.kind, Kind::Failed);
    assert_eq!(o.u, un);
    // too many rows for the engine
    let many = [Row {
        a: Vector3::x(),
        c: -1.0,
    }; 9];
    assert_eq!(eng.solve(&un, &many, &[1.0; 9], &[]).kind, Kind::Failed);
    // the robotic filter at a finite joint angle so large that its rows overflow: the
    // solver refuses them and the filter brakes the arm (bounded, finite)
    let s = scenario();
    let robot = robot();
    let mut f = RoboticFilter::from_scenario(&s, robot.clone());
    let mut th = theta0(&s);
    th[2] = 1e200;
    let thd = Vector7::from_fn(|i, _| 0.1 * (i as f64 - 3.0));
    let x = rob_input(&robot, th, thd);
    let o = f.filter(&x, &Vector7::repeat(0.5));
    assert_eq!(o.report.status, FilterStatus::Fallback, "{:?}", o.report);
    assert_ne!(o.report.faults & faults::QP_FAILED_FALLBACK, 0);
    assert_eq!(o.u, f.brake(&x));
    assert_output_sane(&o, s.limits.joint_torque_max_nm);
    // the braking law opposes the joint rates through the arm's inertia
    assert!(f.brake(&x).dot(&(x.m_eff * thd)) < 0.0);
    // translational and attitude braking laws: bounded, opposing the relative motion
    let ft = TranslationalFilter::from_scenario(&s, mass());
    let (xt, _) = tr_cases(3, 1)[0];
    let (fh, fb) = ft.brake(&xt);
    assert!(fb.amax() <= s.limits.force_max_n && fh.dot(&xt.v_h) < 0.0);
    let fa = AttitudeFilter::from_scenario(&s, mass());
    let (xa, _) = att_cases(3, 1)[0];
    let tb = fa.brake(&xa);
    assert!(tb.amax() <= s.limits.torque_max_nm);
    assert!(tb.dot(&(xa.p.try_inverse().unwrap() * (xa.omega_b - xa.omega_target_b))) < 0.0);
}

// ------------------------------------------------------------------ names and dumps

#[test]
fn report_names_are_unique_and_dumps_serialise() {
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
    assert_eq!(faults::NAMES.len(), 9);
    assert_eq!(faults::NOMINAL_MISSING, 1 << 7);
    assert_eq!(faults::QP_SECOND_OPINION, 1 << 8);
    assert_eq!(faults::ALL, (1 << faults::NAMES.len()) - 1);
    let s = scenario();
    // the safety layer: the servicer's mass, the robotic filter with the model
    let layer = sc_cbf::SafetyLayer::from_scenario(&s, robot());
    assert_eq!(layer.translational.params.mass, robot().total_mass());
    assert_eq!(layer.attitude.params.mass, robot().total_mass());
    assert_eq!(layer.robotic.params.period, s.mission.control_period_s);
    let mut f = layer.translational;
    let (x, u) = tr_cases(21, 1)[0];
    f.filter(&x, &u);
    let j = serde_json::to_string(&f.dump_qp()).unwrap();
    let back: QpDump = serde_json::from_str(&j).unwrap();
    assert_eq!(back, f.dump_qp());
    assert_eq!(back.u_nom.len(), 3);
    assert_eq!(back.rows_a.len(), 3);
    assert_eq!(back.bounds_g.len(), 6);
}

/// When the active-set solver stops at its iteration limit, Clarabel's solution of the
/// same hard problem is the command, flagged; it agrees with the exact solution.
#[test]
fn iteration_limit_takes_clarabels_second_opinion() {
    let mut rng = Lcg(7);
    let mut used = 0;
    for _ in 0..50 {
        // a random box-bounded problem whose nominal violates several rows
        let barrier: Vec<Row<3>> = (0..6)
            .map(|_| Row {
                a: Vector3::new(rng.next(), rng.next(), rng.next()),
                c: -0.5 * rng.next().abs(),
            })
            .collect();
        let hard: Vec<Row<3>> = (0..6)
            .map(|k| {
                let mut a = Vector3::zeros();
                a[k / 2] = if k % 2 == 0 { -1.0 } else { 1.0 };
                Row { a, c: 2.0 }
            })
            .collect();
        let u_nom = Vector3::new(rng.next(), rng.next(), rng.next()) * 1.5;
        let w = vec![1.0; barrier.len()];
        let mut exact = Engine::<3, 16>::new();
        let want = exact.solve(&u_nom, &barrier, &w, &hard);
        if want.kind != Kind::Solved || want.iterations < 2 {
            continue;
        }
        let settings = sc_qp::Settings {
            max_iterations: Some(1),
            ..Default::default()
        };
        let mut limited = Engine::<3, 16>::with_settings(settings);
        let got = limited.solve(&u_nom, &barrier, &w, &hard);
        assert_eq!(got.kind, Kind::Solved, "{got:?}");
        // one second opinion per filter step: a second limited solve before the reset
        // gets none (the filter's braking law then)
        let again = limited.solve(&u_nom, &barrier, &w, &hard);
        assert_eq!(again.kind, Kind::Failed, "{again:?}");
        assert!(got.second_opinion && limited.take_second_opinion());
        assert!(!limited.take_second_opinion(), "the flag resets");
        assert!(limited.solve(&u_nom, &barrier, &w, &hard).second_opinion);
        assert!(
            (got.u - want.u).amax() < 1e-7,
            "{:?} vs {:?}",
            got.u,
            want.u
        );
        assert!(!want.second_opinion);
        used += 1;
    }
    assert!(
        used >= 5,
        "only {used} problems needed two or more iterations"
    );
}
