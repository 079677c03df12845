//! The least-violation LP and the lexicographic problem: against Clarabel (LP and the
//! second-stage QP), LP-dual optimality certificates, known answers, independence of x0.

// Index loops mirror the linear algebra.
#![allow(clippy::needless_range_loop)]

mod common;
use clarabel::solver::SolverStatus::{AlmostSolved, Solved};
use common::*;
use proptest::prelude::{
    ProptestConfig, TestCaseError, any, prop_assert, prop_assert_eq, prop_assume, proptest,
};
use sc_qp::{ActiveSetQp, LeastViolation, Settings, Solution, Status};

fn lexi<const M: usize>(p: &Problem) -> (LeastViolation<64>, Solution<M, 64>) {
    let (x0, a, b, w) = p.arrays::<M, 64>();
    ActiveSetQp::<M, 64>::new(Settings::default()).lexicographic(&x0, &a, &b, &w, p.n())
}

fn lv_only<const M: usize>(p: &Problem) -> LeastViolation<64> {
    let (_, a, b, w) = p.arrays::<M, 64>();
    ActiveSetQp::<M, 64>::new(Settings::default()).least_violation(&a, &b, &w, p.n())
}

fn run<const M: usize>(seed: u64, soft: usize, hard: usize) -> Result<(), TestCaseError> {
    let mut rng = Rng(seed);
    let p = random_lv(&mut rng, M, soft, hard, !seed.is_multiple_of(5));
    let (lv, s) = lexi::<M>(&p);
    prop_assert_eq!(lv.status, Status::Optimal);
    let scale = p.scale();
    // exactness on our own terms: LP-dual certificate of optimality
    if let Err(e) = check_lp_dual(&p, &lv, 1e-12) {
        return Err(TestCaseError::fail(format!("LP dual: {e}\n{p:?}")));
    }
    // t* does not depend on x0: least_violation (no x0) agrees
    let lv0 = lv_only::<M>(&p);
    prop_assert!(
        (lv0.t - lv.t).abs() <= 1e-12 * lv.t.max(1.0),
        "{} vs {}",
        lv0.t,
        lv.t
    );
    // Clarabel on the LP
    let r = clarabel_lp(&p);
    // the reference must have solved it (rare degenerate cases exhaust its iterations)
    prop_assume!(matches!(r.status, Solved | AlmostSolved));
    let t_cl = r.x[M];
    // relative to the LP's own scale, which includes t* (t multiplies the weights); an
    // "almost solved" reference is only good to its reduced tolerances (one such point was
    // infeasible by 6e-9, its t below the certified optimum by 1e-8 relative)
    let scale = scale.max(lv.t);
    let tol = r.trust();
    prop_assert!(
        (lv.t - t_cl).abs() <= tol * scale,
        "t* = {} vs Clarabel {} (scale {:e})\n{:?}",
        lv.t,
        t_cl,
        scale,
        p
    );
    // second stage: KKT of the projection onto P(t*), and Clarabel on the same QP
    let q = p.relaxed(lv.t);
    if let Err(e) = check_kkt(&q, &s, 1e-12) {
        return Err(TestCaseError::fail(format!("stage 2 KKT: {e}\n{p:?}")));
    }
    let r2 = clarabel_qp(&q);
    // P(t*) has no interior (t* is the least t with P(t) ≠ ∅), where an interior-point
    // method converges only like √μ: compare x at 1e-6, and only when Clarabel reports
    // Solved (its "almost solved" points here were off by up to 5e-3).
    if r2.status == Solved {
        let dx = (0..M).fold(0.0f64, |m, k| m.max((s.x[k] - r2.x[k]).abs()));
        prop_assert!(
            dx <= 1e-6 * scale,
            "stage 2 x differs from Clarabel by {:e}",
            dx
        );
    }
    // Solved or almost solved, its point is (nearly) feasible, so the exact minimiser's
    // objective cannot be above its objective. (Clarabel may also call P(t*) infeasible:
    // it is empty up to rounding.)
    if matches!(r2.status, Solved | AlmostSolved) {
        let (f, fr) = (objective(&q, &s.x), objective(&q, &r2.x));
        prop_assert!(
            f <= fr + 1e-9 * scale * scale,
            "stage 2 objective {} > Clarabel's {}",
            f,
            fr
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), .. ProptestConfig::default() })]

    #[test]
    fn lexicographic_m3_vs_clarabel(seed in any::<u64>(), soft in 1usize..=10, hard in 0usize..=4) {
        run::<3>(seed, soft, hard)?;
    }

    #[test]
    fn lexicographic_m7_vs_clarabel(seed in any::<u64>(), soft in 1usize..=40, hard in 0usize..=4) {
        run::<7>(seed, soft, hard)?;
    }
}

#[test]
fn known_answers() {
    // box ±1; soft x ≥ 3 (w = 1): t* = 2, and the lexicographic x clamps x₀ to the box.
    let mut p = Problem::new(vec![5.0, 0.5, -7.0]);
    p.boxed(1.0);
    p.row_w(vec![1.0, 0.0, 0.0], 3.0, 1.0);
    let (lv, s) = lexi::<3>(&p);
    assert_eq!((lv.status, lv.t), (Status::Optimal, 2.0));
    assert_eq!(s.x, [1.0, 0.5, -1.0]);
    check_lp_dual(&p, &lv, 1e-15).unwrap();

    // x + t ≥ 1, −x + 2t ≥ 1: 3t ≥ 2, t* = 2/3, x = 1/3; y, z free keep x0.
    let mut p = Problem::new(vec![10.0, -4.0, 2.5]);
    p.row_w(vec![1.0, 0.0, 0.0], 1.0, 1.0);
    p.row_w(vec![-1.0, 0.0, 0.0], 1.0, 2.0);
    let (lv, s) = lexi::<3>(&p);
    assert_eq!(lv.status, Status::Optimal);
    assert!((lv.t - 2.0 / 3.0).abs() <= 2e-16, "{}", lv.t);
    assert!((s.x[0] - 1.0 / 3.0).abs() <= 2e-16 && s.x[1] == -4.0 && s.x[2] == 2.5);
    check_lp_dual(&p, &lv, 1e-15).unwrap();
    assert!((lv.dual[0] - 1.0 / 3.0).abs() < 1e-15 && (lv.dual[1] - 1.0 / 3.0).abs() < 1e-15);

    // the same rows scaled by 1e-6 and 1e6 (weights scaled along): same t*
    let mut p2 = Problem::new(vec![10.0, -4.0, 2.5]);
    p2.row_w(vec![1e-6, 0.0, 0.0], 1e-6, 1e-6);
    p2.row_w(vec![-1e6, 0.0, 0.0], 1e6, 2e6);
    let (lv2, s2) = lexi::<3>(&p2);
    assert!((lv2.t - 2.0 / 3.0).abs() <= 2e-16);
    assert!((s2.x[0] - 1.0 / 3.0).abs() <= 2e-16);

    // a soft zero row 0·x + 4t ≥ 3 dominates: t* = 3/4
    p.row_w(vec![0.0; 3], 3.0, 4.0);
    let (lv, s) = lexi::<3>(&p);
    assert_eq!(lv.t, 0.75);
    check_lp_dual(&p, &lv, 1e-15).unwrap();
    check_kkt(&p.relaxed(0.75), &s, 1e-15).unwrap();

    // hard zero row 0 ≥ −1 is harmless; 0 ≥ 1 is infeasible
    p.row(vec![0.0; 3], -1.0);
    assert_eq!(lexi::<3>(&p).0.t, 0.75);
    p.row(vec![0.0; 3], 1.0);
    let lv = lv_only::<3>(&p);
    assert_eq!(lv.status, Status::Infeasible);
    assert_eq!(lv.certificate[p.n() - 1], 1.0);
}

#[test]
fn feasible_means_zero_violation_and_plain_projection() {
    let mut rng = Rng(30);
    for _ in 0..300 {
        let mut p = random_feasible(&mut rng, 7, 20, false);
        for i in 0..p.n() {
            if p.a[i].iter().filter(|v| **v != 0.0).count() > 1 {
                p.w[i] = rng.range(0.1, 10.0);
            }
        }
        let (lv, s) = lexi::<7>(&p);
        assert_eq!((lv.status, lv.t), (Status::Optimal, 0.0));
        assert!(lv.dual.iter().all(|v| *v == 0.0));
        let (x0, a, b, _) = p.arrays::<7, 64>();
        let plain = ActiveSetQp::<7, 64>::new(Settings::default()).solve(&x0, &a, &b, p.n());
        assert_eq!(s.x, plain.x);
        assert_eq!(s.lambda, plain.lambda);
    }
}

#[test]
fn hard_rows_infeasible() {
    let mut rng = Rng(31);
    for _ in 0..300 {
        let mut p = random_lv(&mut rng, 3, 6, 0, true);
        p.row(vec![1.0, 1.0, 1.0], 1e3); // outside the box: hard rows infeasible
        let (lv, s) = lexi::<3>(&p);
        assert_eq!(lv.status, Status::Infeasible);
        assert_eq!(s.status, Status::Infeasible);
        // the certificate uses hard rows only and proves them infeasible
        for i in 0..p.n() {
            assert!(p.w[i] == 0.0 || lv.certificate[i] == 0.0);
        }
        check_certificate(&p, &lv.certificate, 1e-12).unwrap();
        assert_eq!(s.certificate, lv.certificate);
    }
}

/// A large x0 cannot buy violation: t* is the same for x0 scaled by 1 … 1e9 (it does not
/// even take x0), and the lexicographic x stays put when x0 moves away along a direction of
/// the normal cone at the solution.
#[test]
fn large_x0_buys_nothing() {
    let mut rng = Rng(32);
    let mut worst = 0.0f64;
    for _ in 0..300 {
        let p = random_lv(&mut rng, 7, 12, 2, true);
        let lv0 = lv_only::<7>(&p);
        let (lv1, s1) = lexi::<7>(&p);
        assert_eq!(lv1.status, Status::Optimal);
        // the direction from the solution back to x0 is in the normal cone of P(t*) there
        let d: Vec<f64> = (0..7).map(|k| p.x0[k] - s1.x[k]).collect();
        for f in [1.0, 1e3, 1e6, 1e9] {
            let mut q = p.clone();
            q.x0 = p.x0.iter().map(|v| v * f).collect();
            let (lv, _) = lexi::<7>(&q);
            assert_eq!(lv.status, Status::Optimal);
            assert!(
                (lv.t - lv0.t).abs() <= 1e-12 * lv0.t.max(1.0),
                "t* = {} for x0·{f:e}, {} without x0",
                lv.t,
                lv0.t
            );
            let mut q = p.clone();
            q.x0 = (0..7).map(|k| s1.x[k] + f * d[k]).collect();
            let (lv, s) = lexi::<7>(&q);
            assert!((lv.t - lv0.t).abs() <= 1e-12 * lv0.t.max(1.0));
            let dx = (0..7).fold(0.0f64, |m, k| m.max((s.x[k] - s1.x[k]).abs()));
            let x0n = inf(&q.x0);
            worst = worst.max(dx / x0n);
            assert!(
                dx <= 1e-13 * x0n.max(1.0),
                "x moved by {dx:e} for x0 at distance ·{f:e} (‖x0‖ {x0n:e})"
            );
        }
    }
    eprintln!("worst |Δx| / ‖x0‖∞ = {worst:e}");
}

#[test]
fn invalid_weights() {
    let mut p = Problem::new(vec![0.0; 3]);
    p.row_w(vec![1.0, 0.0, 0.0], 1.0, -1.0);
    assert_eq!(lv_only::<3>(&p).status, Status::InvalidInput);
    p.w[0] = f64::NAN;
    assert_eq!(lv_only::<3>(&p).status, Status::InvalidInput);
    p.w[0] = 1.0;
    let mut q = p.clone();
    q.x0[1] = f64::INFINITY;
    assert_eq!(lexi::<3>(&q).0.status, Status::InvalidInput);
    // alone, the soft row x ≥ 1 can be met: t* = 0
    assert_eq!(lexi::<3>(&p).0.t, 0.0);
}

/// Scaling a row (a_i, b_i, w_i) by any positive factor gives the same problem: with
/// factors 1e-6 … 1e6, t* and the lexicographic x must not change (beyond rounding), and
/// the scaled problem's own LP-dual certificate and KKT conditions must hold.
#[test]
fn row_scaling_invariance() {
    let mut rng = Rng(33);
    for k in 0..400 {
        let m7 = k % 2 == 1;
        let p = random_lv(
            &mut rng,
            if m7 { 7 } else { 3 },
            if m7 { 30 } else { 8 },
            2,
            true,
        );
        let mut q = p.clone();
        for i in 0..q.n() {
            let f = 10f64.powf(rng.range(-6.0, 6.0));
            q.a[i].iter_mut().for_each(|v| *v *= f);
            q.b[i] *= f;
            q.w[i] *= f;
        }
        let ((l1, x1), (l2, x2)) = if m7 {
            let (l1, s1) = lexi::<7>(&p);
            let (l2, s2) = lexi::<7>(&q);
            check_kkt(&q.relaxed(l2.t), &s2, 1e-12).unwrap();
            ((l1, s1.x.to_vec()), (l2, s2.x.to_vec()))
        } else {
            let (l1, s1) = lexi::<3>(&p);
            let (l2, s2) = lexi::<3>(&q);
            check_kkt(&q.relaxed(l2.t), &s2, 1e-12).unwrap();
            ((l1, s1.x.to_vec()), (l2, s2.x.to_vec()))
        };
        check_lp_dual(&q, &l2, 1e-12).unwrap();
        assert!(
            (l1.t - l2.t).abs() <= 1e-12 * l1.t.max(1.0),
            "t* {} vs {} after row scaling",
            l1.t,
            l2.t
        );
        let dx = x1
            .iter()
            .zip(&x2)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            dx <= 1e-12 * p.scale(),
            "x moved by {dx:e} after row scaling"
        );
    }
}

/// Hard rows contradictory by a pair `a·x ≥ g`, `−a·x ≥ 0` (g > 0), found while soft rows
/// are active: the status must be Infeasible — never a huge "optimal" t from rounding
/// noise on a soft row in the certificate — and the certificate must use hard rows only.
#[test]
fn hard_contradiction_among_active_soft_rows() {
    let mut rng = Rng(34);
    for k in 0..2000 {
        let m7 = k % 2 == 1;
        let m = if m7 { 7 } else { 3 };
        let mut p = random_lv(&mut rng, m, if m7 { 30 } else { 8 }, 0, true);
        // every other case: parallel to a soft row (whose coefficient in the dependence
        // r is then exactly zero in exact arithmetic, rounding noise in floating point)
        let a = if k % 4 < 2 {
            let soft: Vec<usize> = (0..p.n()).filter(|&i| p.w[i] > 0.0).collect();
            p.a[soft[rng.below(soft.len())]].clone()
        } else {
            rng.vec(m)
        };
        let gap = [1e-6, 1e-3, 1.0][k % 3];
        p.row(a.clone(), gap);
        p.row(a.iter().map(|v| -v).collect(), 0.0);
        p.shuffle(&mut rng);
        let lv = if m7 {
            lv_only::<7>(&p)
        } else {
            lv_only::<3>(&p)
        };
        assert_eq!(lv.status, Status::Infeasible, "t = {} (gap {gap})", lv.t);
        for i in 0..p.n() {
            assert!(
                p.w[i] == 0.0 || lv.certificate[i] == 0.0,
                "soft row {i} in certificate"
            );
        }
        check_certificate(&p, &lv.certificate, 1e-12).unwrap();
    }
}
