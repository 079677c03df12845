//! Problems with a known solution: choose x*, an active set with multipliers λ > 0 and
//! rows through x*, set x0 = x* − Σ λ_i a_i, add rows strictly satisfied at x* (and the
//! input box), shuffle. The solver must return x* and λ.

// Index loops mirror the linear algebra.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use sc_qp::{ActiveSetQp, Settings, Status};

pub struct Known {
    pub p: Problem,
    pub x: Vec<f64>,
    /// λ per row in the caller's scaling (0 for inactive rows).
    pub lambda: Vec<f64>,
}

/// `k` active rows (random normals, independent with overwhelming probability, row scales
/// 10^U(−e, e)), `extra` strictly inactive rows, and the box.
pub fn known(rng: &mut Rng, m: usize, k: usize, extra: usize, e: f64) -> Known {
    let limit = 10.0;
    let xs: Vec<f64> = (0..m).map(|_| rng.range(-5.0, 5.0)).collect();
    let mut p = Problem::new(vec![0.0; m]);
    let mut lam = Vec::new();
    let mut x0 = xs.clone();
    for _ in 0..k {
        let sc = 10f64.powf(rng.range(-e, e));
        let a: Vec<f64> = rng.vec(m).iter().map(|v| v * sc).collect();
        let nu = norm(&a);
        let l = rng.range(0.1, 3.0) / nu; // λ̂ = λ‖a‖ ∈ [0.1, 3) (a distance)
        for j in 0..m {
            x0[j] -= l * a[j];
        }
        p.row(a.clone(), dot(&a, &xs));
        lam.push(l);
    }
    for _ in 0..extra {
        let sc = 10f64.powf(rng.range(-e, e));
        let a: Vec<f64> = rng.vec(m).iter().map(|v| v * sc).collect();
        let slack = rng.range(0.05, 3.0) * norm(&a);
        p.row(a.clone(), dot(&a, &xs) - slack);
    }
    p.boxed(limit);
    lam.resize(p.n(), 0.0); // inactive and box rows
    p.x0 = x0;
    // shuffle rows and multipliers together
    let mut idx: Vec<usize> = (0..p.n()).collect();
    rng.shuffle(&mut idx);
    let q = p.clone();
    for (to, &from) in idx.iter().enumerate() {
        p.a[to] = q.a[from].clone();
        p.b[to] = q.b[from];
    }
    let lambda = idx.iter().map(|&i| lam[i]).collect();
    Known { p, x: xs, lambda }
}

fn check<const M: usize>(kn: &Known, tol_x: f64, tol_l: f64) {
    let p = &kn.p;
    let (x0, a, b, _) = p.arrays::<M, 64>();
    let s = ActiveSetQp::<M, 64>::new(Settings::default()).solve(&x0, &a, &b, p.n());
    assert_eq!(s.status, Status::Optimal, "{p:?}");
    let scale = p.scale();
    for k in 0..M {
        assert!(
            (s.x[k] - kn.x[k]).abs() <= tol_x * scale,
            "x[{k}] = {} vs x* = {} (scale {scale:e})\n{p:?}",
            s.x[k],
            kn.x[k]
        );
    }
    // λ's sensitivity to the rounding of the data grows with cond(ÂÂᵀ) of the active rows
    let act: Vec<usize> = (0..p.n()).filter(|&i| kn.lambda[i] > 0.0).collect();
    let cond = gram_cond(p, &act);
    let tol_l = tol_l * cond.max(1.0);
    for i in 0..p.n() {
        // compare λ̂ = λ‖a‖ (distance units)
        let nu = p.row_norm(i);
        let (l, lk) = (s.lambda[i] * nu, kn.lambda[i] * nu);
        assert!(
            (l - lk).abs() <= tol_l * scale,
            "λ̂_{i} = {l} vs {lk} (cond {cond:e})\n{p:?}"
        );
        assert_eq!(s.active >> i & 1 == 1, lk > 0.0, "active bit of row {i}");
    }
    check_kkt(p, &s, 1e-12).unwrap();
}

#[test]
fn known_solutions_m3() {
    let mut rng = Rng(1);
    for case in 0..2000 {
        let k = case % 4; // 0..=3 active rows
        let extra = rng.below(8);
        let kn = known(&mut rng, 3, k, extra, 0.5);
        check::<3>(&kn, 1e-12, 1e-14);
    }
}

#[test]
fn known_solutions_m7() {
    let mut rng = Rng(2);
    for case in 0..2000 {
        let k = case % 8; // 0..=7 active rows
        let extra = rng.below(40);
        let kn = known(&mut rng, 7, k, extra, 0.5);
        check::<7>(&kn, 1e-12, 1e-14);
    }
}

/// Row scales 1e-6 … 1e6 within one problem.
#[test]
fn known_solutions_wild_scales() {
    let mut rng = Rng(3);
    for case in 0..1000 {
        let kn = known(&mut rng, 3, case % 4, 6, 6.0);
        check::<3>(&kn, 1e-12, 1e-14);
        let kn = known(&mut rng, 7, case % 8, 30, 6.0);
        check::<7>(&kn, 1e-12, 1e-14);
    }
}

/// Row scales 1e-150 … 1e150: the normalisation must neither overflow nor underflow.
#[test]
fn known_solutions_extreme_scales() {
    let mut rng = Rng(4);
    for case in 0..300 {
        let kn = known(&mut rng, 3, case % 4, 6, 150.0);
        check::<3>(&kn, 1e-12, 1e-14);
    }
}

/// The other sizes the solver is generic over: M = 1, 2 and 8 (the largest the filters
/// may use), with up to N = 64 rows.
#[test]
fn known_solutions_other_sizes() {
    let mut rng = Rng(5);
    for case in 0..500 {
        let kn = known(&mut rng, 1, case % 2, 3, 0.5);
        check::<1>(&kn, 1e-12, 1e-14);
        let kn = known(&mut rng, 2, case % 3, 6, 0.5);
        check::<2>(&kn, 1e-12, 1e-14);
        let extra = case % 40;
        let kn = known(&mut rng, 8, case % 9, extra, 0.5);
        check::<8>(&kn, 1e-12, 1e-14);
    }
}
