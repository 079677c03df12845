//! Filter-specific checks of the solved QPs (the properties every filter shares are in
//! `conformance.rs`): the translational filter dumps its own rows, the attitude command is
//! the minimiser of its rows with one acceleration cap, the engine's lexicographic
//! relaxation against Clarabel on random problems, the engine's and the robotic filter's
//! refusal of data they cannot solve, Clarabel's second opinion at the iteration limit, and
//! the stable fault flags.

mod common;
use common::*;
use nalgebra::{SVector, Vector3};
use sc_cbf::attitude::ACCEL_CAPS;
use sc_cbf::barrier::Row;
use sc_cbf::engine::{Engine, Kind};
use sc_cbf::robotic::Vector7;
use sc_cbf::{
    AttitudeFilter, AttitudeInput, FilterStatus, RoboticFilter, TranslationalFilter, faults,
};

// ------------------------------------------------------------------ solved QPs

/// The translational filter's dumped QP is its own: the rows `rows()` gives at the state
/// with the nominal it was given (the conformance suite checks that the command is that
/// QP's minimiser).
#[test]
fn translational_dumped_qp_is_the_filters_own() {
    let s = scenario();
    let mut f = TranslationalFilter::from_scenario(&s, mass());
    let mut solved = 0;
    for (x, un) in tr_cases(21, 200) {
        if f.filter(&x, &un).report.status != FilterStatus::Solved {
            continue;
        }
        let qp = Qp::from_dump(&f.dump_qp());
        let (rows, _, hard) = f.rows(&x).unwrap();
        let own = Qp::from_rows(&un, &rows, &hard);
        assert_eq!(qp.c, own.c);
        assert_eq!(qp.a, own.a);
        assert_eq!(qp.u_nom, own.u_nom);
        solved += 1;
    }
    assert!(solved >= 50, "only {solved} solved cases");
}

/// The six rows `cap ∓ (P τ + r)_i ≥ 0` that the attitude filter adds to its QP for an
/// acceleration cap.
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

/// The solved attitude command is the minimiser of its barrier rows with the torque box, the
/// contract and the rows of one acceleration cap — the nominal's own or one of
/// [`ACCEL_CAPS`] (the certificate's premise).
#[test]
fn attitude_solved_command_is_the_minimiser_with_one_acceleration_cap() {
    let s = scenario();
    let tmax = s.limits.torque_max_nm;
    let mut f = AttitudeFilter::from_scenario(&s, mass());
    let mut matched_caps = 0;
    for (k, (x, un)) in att_cases(33, 200).into_iter().enumerate() {
        let out = f.filter(&x, &un);
        if out.report.status != FilterStatus::Solved {
            continue;
        }
        let d = f.dump_qp();
        let u = dvec(&out.u);
        // the barrier rows and the torque box with the contract (the dump's first 20 hard
        // rows), and the acceleration cap the filter chose: the nominal's own acceleration
        // or one of ACCEL_CAPS
        let rows: Vec<Row<3>> = (0..d.rows_a.len())
            .map(|i| Row {
                a: Vector3::from_column_slice(&d.rows_a[i]),
                c: d.rows_c[i],
            })
            .collect();
        let box_and_contract: Vec<Row<3>> = (0..20)
            .map(|j| Row {
                a: -Vector3::from_column_slice(&d.bounds_g[j]),
                c: d.bounds_g_max[j],
            })
            .collect();
        let first = (x.p * un + x.r).amax();
        let matched = std::iter::once(first).chain(ACCEL_CAPS).find_map(|cap| {
            let mut hard = box_and_contract.clone();
            hard.extend(cap_rows(&x, cap));
            let qp = Qp::from_rows(&un, &rows, &hard);
            brute_force(&qp)
                .filter(|bf| near(&u, bf, 1e-9 * tmax))
                .map(|_| qp)
        });
        let qp = matched.unwrap_or_else(|| panic!("case {k}: {u} is no cap's QP minimiser"));
        check_kkt(&qp, &u, tmax, &format!("case {k}"));
        if d.bounds_g.len() > 20 {
            matched_caps += 1;
        }
    }
    println!("{matched_caps} solved commands certified by an acceleration cap");
    assert!(matched_caps >= 40, "only {matched_caps} capped solutions");
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

// ------------------------------------------------------------------ solver failure

/// Data the solver cannot take: the engine refuses non-finite rows and more rows than it
/// holds; the robotic filter at a finite joint angle so large that its rows overflow brakes
/// the arm (the conformance suite reaches the braking law of every filter through a
/// solver that may not relax).
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
    // the emergency brake: the braking law within the arm-reaction contract
    assert_eq!(o.u, f.emergency_brake(&x));
    assert_output_sane(&o, s.limits.joint_torque_max_nm);
    // the braking law opposes the joint rates through the arm's inertia
    assert!(f.brake(&x).dot(&(x.m_eff * thd)) < 0.0);
}

// ------------------------------------------------------------------ flags and the layer

#[test]
fn fault_flags_are_stable_and_the_layer_is_built_from_the_model() {
    assert_eq!(sc_cbf::names::TRANSLATIONAL.len(), 2);
    assert_eq!(sc_cbf::names::ATTITUDE.len(), 7);
    assert_eq!(sc_cbf::names::ROBOTIC.len(), 63);
    assert_eq!(sc_cbf::names::ARM_TARGET, ["base_target"]);
    assert_eq!(faults::NAMES.len(), 11);
    assert_eq!(faults::NOMINAL_MISSING, 1 << 7);
    assert_eq!(faults::QP_SECOND_OPINION, 1 << 8);
    assert_eq!(faults::MARGINS_DEGRADED, 1 << 9);
    assert_eq!(faults::SAFE_MODE, 1 << 10);
    assert_eq!(faults::ALL, (1 << faults::NAMES.len()) - 1);
    let s = scenario();
    // the safety layer: the servicer's mass, the robotic filter with the model
    let layer = sc_cbf::SafetyLayer::from_scenario(&s, robot());
    assert_eq!(layer.translational.params.mass, robot().total_mass());
    assert_eq!(layer.attitude.params.mass, robot().total_mass());
    assert_eq!(layer.robotic.params.period, s.mission.control_period_s);
    // in a multi-rate partition each filter certifies for its rate group's hold
    let hold = sc_core::PerSubsystem([0.2, 0.1, 0.02]);
    let held = sc_cbf::SafetyLayer::with_holds(&s, robot(), &hold);
    assert_eq!(held.translational.params.period, 0.2);
    assert_eq!(held.attitude.params.period, 0.1);
    assert_eq!(held.robotic.params.period, 0.02);
    // the translational dump: the two barrier rows, the tangential speed and the
    // line-of-sight contract's four rows, the force box
    let mut f = layer.translational;
    let (x, u) = tr_cases(21, 1)[0];
    f.filter(&x, &u);
    let d = f.dump_qp();
    assert_eq!(d.u_nom.len(), 3);
    assert_eq!(d.rows_a.len(), sc_cbf::translational::ROWS);
    assert_eq!(d.bounds_g.len(), 6);
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
