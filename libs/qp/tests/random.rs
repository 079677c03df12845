//! Random feasible projection problems (M ∈ {3, 7}, up to 60 rows including the box rows)
//! against Clarabel at tight tolerances, plus our own KKT check of every solution.

// Index loops mirror the linear algebra.
#![allow(clippy::needless_range_loop)]

mod common;
use clarabel::solver::SolverStatus::{AlmostSolved, Solved};
use common::*;
use proptest::prelude::*;
use sc_qp::{ActiveSetQp, Settings, Status};

fn run<const M: usize>(seed: u64, extra: usize, wild: bool) -> Result<(), TestCaseError> {
    let mut rng = Rng(seed);
    let p = random_feasible(&mut rng, M, extra, wild);
    prop_assert!(p.n() <= 60);
    let (x0, a, b, _) = p.arrays::<M, 64>();
    let mut qp = ActiveSetQp::<M, 64>::new(Settings::default());
    let s = qp.solve(&x0, &a, &b, p.n());
    prop_assert_eq!(s.status, Status::Optimal, "{:?}", p);
    if let Err(e) = check_kkt(&p, &s, 1e-12) {
        return Err(TestCaseError::fail(format!("KKT: {e}\n{p:?}")));
    }
    let r = clarabel_qp(&p);
    // the reference must have solved it (rare degenerate cases exhaust its iterations)
    prop_assume!(matches!(r.status, Solved | AlmostSolved));
    let scale = p.scale();
    let dx = (0..M).fold(0.0f64, |m, k| m.max((s.x[k] - r.x[k]).abs()));
    // An interior-point method leaves a weakly active row (tiny λ̂ = λ‖a‖) at a slack of
    // about μ/λ̂: seen as 8e-8 for λ̂ = 4e-5 with μ ≈ 1e-15·scale² at Clarabel's 1e-14.
    // The x comparison allows that term (10× margin); the objectives must agree anyway.
    let lam_min = (0..p.n())
        .map(|i| s.lambda[i] * p.row_norm(i))
        .filter(|&l| l > 0.0)
        .fold(f64::INFINITY, f64::min);
    // an "almost solved" reference is only good to its reduced tolerances
    let tol = r.trust();
    prop_assert!(
        dx <= tol * scale + 1e-13 * scale * scale / lam_min,
        "x differs from Clarabel by {:e} (scale {:e}); active {:b}\n{:?}",
        dx,
        scale,
        s.active,
        p
    );
    let (f, fr) = (objective(&p, &s.x), objective(&p, &r.x));
    // ours is exact: it can only be lower than Clarabel's up to Clarabel's infeasibility
    prop_assert!(
        (f - fr).abs() <= tol * scale * scale,
        "objective {f} vs Clarabel {fr}"
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), .. ProptestConfig::default() })]

    #[test]
    fn random_m3_vs_clarabel(seed in any::<u64>(), extra in 0usize..=54, wild in any::<bool>()) {
        run::<3>(seed, extra, wild)?;
    }

    #[test]
    fn random_m7_vs_clarabel(seed in any::<u64>(), extra in 0usize..=46, wild in any::<bool>()) {
        run::<7>(seed, extra, wild)?;
    }
}

/// The filters' sizes (3×8, 3×13, 7×56 with the box): several rows must be active, and the
/// active-set sizes actually exercised are reported.
#[test]
fn filter_sizes_have_active_rows() {
    let mut hist = [0usize; 9];
    for seed in 0..300u64 {
        let mut rng = Rng(seed);
        for (m, extra) in [(3usize, 2usize), (3, 7), (7, 42)] {
            let q = if m == 3 {
                let p = random_feasible(&mut rng, 3, extra, false);
                let (x0, a, b, _) = p.arrays::<3, 64>();
                let s = ActiveSetQp::<3, 64>::new(Settings::default()).solve(&x0, &a, &b, p.n());
                check_kkt(&p, &s, 1e-12).unwrap();
                s.active.count_ones()
            } else {
                let p = random_feasible(&mut rng, 7, extra, false);
                let (x0, a, b, _) = p.arrays::<7, 64>();
                let s = ActiveSetQp::<7, 64>::new(Settings::default()).solve(&x0, &a, &b, p.n());
                check_kkt(&p, &s, 1e-12).unwrap();
                s.active.count_ones()
            };
            hist[q as usize] += 1;
        }
    }
    eprintln!("active-set sizes 0..=8: {hist:?}");
    assert!(hist[2..].iter().sum::<usize>() > 600, "{hist:?}");
}
