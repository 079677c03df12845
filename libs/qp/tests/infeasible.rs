//! Infeasible problems: the status must be Infeasible and the Farkas certificate must check
//! (y ≥ 0, ‖Σ y_i a_i‖ ≤ 1e-9 · Σ y_i ‖a_i‖, Σ y_i b_i > 0) in the caller's scaling.

// Index loops mirror the linear algebra.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use sc_qp::{ActiveSetQp, Settings, Status};

fn expect_infeasible<const M: usize>(p: &Problem) {
    let (x0, a, b, _) = p.arrays::<M, 64>();
    let s = ActiveSetQp::<M, 64>::new(Settings::default()).solve(&x0, &a, &b, p.n());
    assert_eq!(s.status, Status::Infeasible, "{p:?}");
    check_certificate(p, &s.certificate, 1e-9).unwrap_or_else(|e| panic!("{e}\n{p:?}"));
}

/// M+1 rows whose normals sum to zero with b_i > 0 (a simplex turned inside out), plus
/// random feasible-looking rows and the box, shuffled.
fn random_infeasible(rng: &mut Rng, m: usize, extra: usize, wild: bool) -> Problem {
    let mut p = random_feasible(rng, m, extra, wild);
    let c: Vec<f64> = (0..m).map(|_| rng.range(-3.0, 3.0)).collect();
    let mut sum = vec![0.0; m];
    for k in 0..=m {
        let a = if k < m {
            let a = rng.vec(m);
            for j in 0..m {
                sum[j] += a[j];
            }
            a
        } else {
            sum.iter().map(|v| -v).collect()
        };
        let sc = if wild {
            10f64.powf(rng.range(-6.0, 6.0))
        } else {
            1.0
        };
        let a: Vec<f64> = a.iter().map(|v| v * sc).collect();
        // a·x ≥ a·c + gap: all M+1 cannot hold (Σ a = 0 ⇒ 0 ≥ Σ gap > 0)
        let gap = rng.range(1e-3, 1.0) * norm(&a);
        p.row(a.clone(), dot(&a, &c) + gap);
    }
    p.shuffle(rng);
    p
}

#[test]
fn random_infeasible_m3() {
    let mut rng = Rng(20);
    for k in 0..2000 {
        let p = random_infeasible(&mut rng, 3, k % 20, k % 2 == 0);
        expect_infeasible::<3>(&p);
    }
}

#[test]
fn random_infeasible_m7() {
    let mut rng = Rng(21);
    for k in 0..2000 {
        let p = random_infeasible(&mut rng, 7, k % 40, k % 2 == 0);
        expect_infeasible::<7>(&p);
    }
}

#[test]
fn row_outside_the_box() {
    for e in [-6, 0, 6] {
        let f = 10f64.powi(e);
        let mut p = Problem::new(vec![0.3, 0.1, -0.2]);
        p.boxed(1.0);
        p.row(vec![f, f, f], 3.5 * f); // x+y+z ≥ 3.5 > 3
        expect_infeasible::<3>(&p);
    }
}

#[test]
fn opposite_rows_with_a_small_gap() {
    for gap in [1.0, 1e-3, 1e-6, 1e-9] {
        let mut p = Problem::new(vec![0.0; 7]);
        let a: Vec<f64> = (0..7).map(|k| (k as f64) - 2.5).collect();
        p.row(a.clone(), 1.0);
        p.row(
            a.iter().map(|v| -2.0 * v).collect(),
            -2.0 + 2.0 * gap * norm(&a),
        );
        p.boxed(100.0);
        expect_infeasible::<7>(&p);
    }
}

#[test]
fn zero_row_with_positive_b() {
    let mut p = Problem::new(vec![0.0; 3]);
    p.row(vec![1.0, 0.0, 0.0], 1.0);
    p.row(vec![0.0; 3], 1e-3);
    let (x0, a, b, _) = p.arrays::<3, 64>();
    let s = ActiveSetQp::<3, 64>::new(Settings::default()).solve(&x0, &a, &b, p.n());
    assert_eq!(s.status, Status::Infeasible);
    assert_eq!(s.certificate[1], 1.0);
    check_certificate(&p, &s.certificate, 0.0).unwrap();
}

#[test]
fn infeasible_after_many_degenerate_rows() {
    // ten rows through one point, then one more that cuts the whole cone off.
    let mut rng = Rng(22);
    for _ in 0..500 {
        let mut p = Problem::new(rng.vec(3));
        let axis = rng.vec(3);
        for _ in 0..10 {
            let a: Vec<f64> = (0..3).map(|j| 0.5 * rng.normal() + axis[j]).collect();
            p.row(a, 0.0);
        }
        // −axis·x ≥ 1 contradicts axis·x ≥ 0 only through the cone; make it certain:
        let mut a = axis.clone();
        for v in a.iter_mut() {
            *v = -*v;
        }
        p.row(axis.clone(), 0.0);
        p.row(a, 1.0);
        p.shuffle(&mut rng);
        expect_infeasible::<3>(&p);
    }
}
