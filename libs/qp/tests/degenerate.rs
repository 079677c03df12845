//! Degenerate problems: duplicated rows, linearly dependent active rows, many rows through
//! one vertex, zero rows, opposite rows (equalities), nearly parallel rows, huge/tiny
//! scales, trivial and invalid inputs. The solution must be right, with no NaN and no
//! iteration limit.

// Index loops mirror the linear algebra.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use sc_qp::{ActiveSetQp, Settings, Solution, Status};

fn solve<const M: usize>(p: &Problem) -> Solution<M, 64> {
    let (x0, a, b, _) = p.arrays::<M, 64>();
    let s = ActiveSetQp::<M, 64>::new(Settings::default()).solve(&x0, &a, &b, p.n());
    assert!(s.x.iter().all(|v| v.is_finite()), "{s:?}");
    assert!(s.lambda.iter().all(|v| v.is_finite() && *v >= 0.0), "{s:?}");
    s
}

fn assert_x<const M: usize>(s: &Solution<M, 64>, x: &[f64], tol: f64) {
    for k in 0..M {
        assert!(
            (s.x[k] - x[k]).abs() <= tol * (1.0 + x[k].abs()),
            "x = {:?} expected {x:?}",
            s.x
        );
    }
}

/// A vertex x* in ℝ³ with `k` rows through it whose normals lie in a cone around `axis`,
/// all with positive multipliers: x* is the solution whatever the degeneracy.
fn vertex_problem(rng: &mut Rng, k: usize, dup: usize) -> (Problem, Vec<f64>) {
    let xs: Vec<f64> = (0..3).map(|_| rng.range(-3.0, 3.0)).collect();
    let axis = rng.vec(3);
    let mut x0 = xs.clone();
    let mut p = Problem::new(vec![0.0; 3]);
    for _ in 0..k {
        let mut a: Vec<f64> = rng.vec(3);
        for j in 0..3 {
            a[j] = 0.6 * a[j] + axis[j];
        }
        let sc = 10f64.powf(rng.range(-2.0, 2.0));
        a.iter_mut().for_each(|v| *v *= sc);
        let l = rng.range(0.1, 2.0) / norm(&a);
        for j in 0..3 {
            x0[j] -= l * a[j];
        }
        let b = dot(&a, &xs);
        for c in 0..=dup {
            // duplicates, also rescaled
            let f = if c == 0 { 1.0 } else { rng.range(0.1, 10.0) };
            p.row(a.iter().map(|v| v * f).collect(), b * f);
        }
    }
    p.boxed(10.0);
    p.x0 = x0;
    p.shuffle(rng);
    (p, xs)
}

#[test]
fn ten_rows_through_one_vertex() {
    let mut rng = Rng(10);
    for _ in 0..2000 {
        let (p, xs) = vertex_problem(&mut rng, 10, 0);
        let s = solve::<3>(&p);
        check_kkt(&p, &s, 1e-12).unwrap();
        assert_x(&s, &xs, 1e-12);
        assert!(s.active.count_ones() <= 3);
    }
}

#[test]
fn duplicated_rows() {
    let mut rng = Rng(11);
    for k in 0..1000 {
        let (p, xs) = vertex_problem(&mut rng, 1 + k % 4, 1 + k % 3);
        let s = solve::<3>(&p);
        check_kkt(&p, &s, 1e-12).unwrap();
        assert_x(&s, &xs, 1e-12);
    }
    // exact copies, both violated
    let mut p = Problem::new(vec![0.0, 0.0, 0.0]);
    for _ in 0..5 {
        p.row(vec![1.0, 1.0, 0.0], 2.0);
    }
    let s = solve::<3>(&p);
    check_kkt(&p, &s, 1e-15).unwrap();
    assert_x(&s, &[1.0, 1.0, 0.0], 1e-15);
    assert_eq!(s.active.count_ones(), 1);
}

#[test]
fn dependent_active_rows() {
    // a3 = a1 + a2 through the same point; all three bind.
    let mut rng = Rng(12);
    for _ in 0..1000 {
        let xs: Vec<f64> = (0..3).map(|_| rng.range(-3.0, 3.0)).collect();
        let a1 = rng.vec(3);
        let a2 = rng.vec(3);
        let a3: Vec<f64> = (0..3).map(|j| a1[j] + a2[j]).collect();
        let (l1, l2, l3) = (
            rng.range(0.1, 2.0),
            rng.range(0.1, 2.0),
            rng.range(0.0, 2.0),
        );
        let x0: Vec<f64> = (0..3)
            .map(|j| xs[j] - l1 * a1[j] - l2 * a2[j] - l3 * a3[j])
            .collect();
        let mut p = Problem::new(x0);
        for a in [&a1, &a2, &a3] {
            p.row(a.clone(), dot(a, &xs));
        }
        p.boxed(10.0);
        p.shuffle(&mut rng);
        let s = solve::<3>(&p);
        check_kkt(&p, &s, 1e-12).unwrap();
        assert_x(&s, &xs, 1e-11);
    }
}

#[test]
fn rank_deficient_in_m7() {
    // 12 rows through x* spanning only a 4-dimensional subspace of ℝ⁷.
    let mut rng = Rng(13);
    for _ in 0..500 {
        let xs: Vec<f64> = (0..7).map(|_| rng.range(-3.0, 3.0)).collect();
        let basis: Vec<Vec<f64>> = (0..4).map(|_| rng.vec(7)).collect();
        let mut x0 = xs.clone();
        let mut p = Problem::new(vec![0.0; 7]);
        for _ in 0..12 {
            let c: Vec<f64> = (0..4).map(|_| rng.range(0.0, 1.0)).collect();
            let a: Vec<f64> = (0..7)
                .map(|j| (0..4).map(|k| c[k] * basis[k][j]).sum())
                .collect();
            let l = rng.range(0.0, 1.0);
            for j in 0..7 {
                x0[j] -= l * a[j];
            }
            p.row(a.clone(), dot(&a, &xs));
        }
        p.x0 = x0;
        p.boxed(20.0);
        let s = solve::<7>(&p);
        check_kkt(&p, &s, 1e-12).unwrap();
        assert_x(&s, &xs, 1e-11);
    }
}

#[test]
fn zero_rows() {
    let mut p = Problem::new(vec![3.0, -1.0, 0.5]);
    p.row(vec![0.0; 3], 0.0);
    p.row(vec![-1.0, 0.0, 0.0], -1.0); // x ≤ 1
    p.row(vec![0.0; 3], -5.0);
    p.row(vec![-0.0, 0.0, -0.0], -0.0);
    let s = solve::<3>(&p);
    check_kkt(&p, &s, 1e-15).unwrap();
    assert_eq!(s.x, [1.0, -1.0, 0.5]);
    assert_eq!(s.active, 0b10);
    assert_eq!(s.lambda[0], 0.0);

    p.row(vec![0.0; 3], 1e-300);
    let s = solve::<3>(&p);
    assert_eq!(s.status, Status::Infeasible);
    check_certificate(&p, &s.certificate, 0.0).unwrap();
}

#[test]
fn equality_from_opposite_rows() {
    // a·x ≥ b and −a·x ≥ −b: the projection onto the plane a·x = b, from either side.
    let mut rng = Rng(14);
    for _ in 0..1000 {
        let a = rng.vec(7);
        let x0 = rng.vec(7);
        let b = rng.range(-2.0, 2.0);
        let mut p = Problem::new(x0.clone());
        p.row(a.clone(), b);
        p.row(a.iter().map(|v| -v).collect(), -b);
        let s = solve::<7>(&p);
        check_kkt(&p, &s, 1e-13).unwrap();
        let t = (b - dot(&a, &x0)) / dot(&a, &a);
        let xs: Vec<f64> = (0..7).map(|j| x0[j] + t * a[j]).collect();
        assert_x(&s, &xs, 1e-13);
        assert_eq!(s.active.count_ones(), 1);
    }
}

#[test]
fn nearly_parallel_rows() {
    // Two rows at an angle of ε through the same point: well-defined, ever more
    // ill-conditioned multipliers; x must stay right and nothing may blow up.
    for e in [1e-3, 1e-6, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-14, 0.0] {
        let mut p = Problem::new(vec![-1.0, -0.3, 0.2]);
        p.row(vec![1.0, 0.0, 0.0], 0.0);
        p.row(vec![1.0, e, 0.0], 0.0);
        p.boxed(5.0);
        let s = solve::<3>(&p);
        assert_eq!(s.status, Status::Optimal, "ε = {e}");
        check_kkt(&p, &s, 1e-12).unwrap_or_else(|m| panic!("ε = {e}: {m}"));
        // x* = projection onto {x0 ≥ 0, x0 + ε x1 ≥ 0}
        assert!(
            s.x[0] >= -1e-12 && (s.x[0] + e * s.x[1]) >= -1e-12,
            "{:?}",
            s.x
        );
    }
}

#[test]
fn huge_and_tiny_scales_in_one_problem() {
    let mut rng = Rng(15);
    for _ in 0..1000 {
        let p = random_feasible(&mut rng, 3, 10, true);
        let s = solve::<3>(&p);
        check_kkt(&p, &s, 1e-12).unwrap();
    }
    // the same half-space at scales 1e-200 … 1e200
    for e in [-200, -100, -6, 0, 6, 100, 200] {
        let f = 10f64.powi(e);
        let mut p = Problem::new(vec![0.0, 0.0, 0.0]);
        p.row(vec![f, 2.0 * f, -f], 3.0 * f);
        p.row(vec![-f, 0.0, 0.0], 0.0); // x ≤ 0
        let s = solve::<3>(&p);
        check_kkt(&p, &s, 1e-14).unwrap();
        // projection of 0 onto {x + 2y − z ≥ 3, x ≤ 0}: x = 0, (y, z) = (1.2, −0.6)
        assert_x(&s, &[0.0, 1.2, -0.6], 1e-15);
    }
}

#[test]
fn feasible_x0_is_returned_bitwise() {
    let mut rng = Rng(16);
    for _ in 0..200 {
        let p0 = random_feasible(&mut rng, 7, 20, false);
        let mut p = p0.clone();
        // x0 strictly inside: move it to the generator's feasible region centre by
        // projecting first, then use that point (on the boundary) as x0.
        let s = solve::<7>(&p0);
        p.x0 = s.x.to_vec();
        let s2 = solve::<7>(&p);
        assert_eq!(s2.status, Status::Optimal);
        assert_eq!(s2.x, s.x, "a solution, given as x0, is a fixed point");
        assert_eq!(s2.iterations, 0);
    }
    let p = Problem::new(vec![1.0, 2.0, 3.0]);
    let s = solve::<3>(&p);
    assert_eq!(s.x, [1.0, 2.0, 3.0]);
    assert_eq!(s.status, Status::Optimal);
}

#[test]
fn invalid_input() {
    let mut qp = ActiveSetQp::<3, 8>::new(Settings::default());
    let a = [[1.0, 0.0, 0.0]; 8];
    let b = [0.0; 8];
    let x0 = [0.0; 3];
    assert_eq!(qp.solve(&x0, &a, &b, 9).status, Status::InvalidInput);
    assert_eq!(
        qp.solve(&[f64::NAN, 0.0, 0.0], &a, &b, 1).status,
        Status::InvalidInput
    );
    let mut a2 = a;
    a2[2][1] = f64::INFINITY;
    assert_eq!(qp.solve(&x0, &a2, &b, 3).status, Status::InvalidInput);
    // rows beyond n are not looked at
    assert_eq!(qp.solve(&x0, &a2, &b, 2).status, Status::Optimal);
    let mut b2 = b;
    b2[0] = f64::NEG_INFINITY;
    assert_eq!(qp.solve(&x0, &a, &b2, 1).status, Status::InvalidInput);
    // b/‖a‖ overflows
    let mut a3 = a;
    a3[0] = [1e-300, 0.0, 0.0];
    let mut b3 = b;
    b3[0] = 1e300;
    assert_eq!(qp.solve(&x0, &a3, &b3, 1).status, Status::InvalidInput);
    // the solver is still usable afterwards
    let s = qp.solve(&[-1.0, 0.0, 0.0], &a, &b, 8);
    assert_eq!(s.status, Status::Optimal);
    assert_eq!(s.x, [0.0, 0.0, 0.0]);
}

#[test]
fn iteration_limit_is_reported() {
    let mut rng = Rng(17);
    let p = random_feasible(&mut rng, 7, 40, false);
    let (x0, a, b, _) = p.arrays::<7, 64>();
    let full = ActiveSetQp::<7, 64>::new(Settings::default()).solve(&x0, &a, &b, p.n());
    assert_eq!(full.status, Status::Optimal);
    assert!(full.iterations >= 2);
    let st = Settings {
        max_iterations: Some(full.iterations - 1),
        ..Settings::default()
    };
    let s = ActiveSetQp::<7, 64>::new(st).solve(&x0, &a, &b, p.n());
    assert_eq!(s.status, Status::IterationLimit);
    assert!(s.x.iter().all(|v| v.is_finite()));
}

/// A row that cuts the solution off by only δ = 1e-11 … 1e-6 (relative to the scale) must
/// still be enforced: the new solution satisfies it to 1e-12 and is KKT. (Without this,
/// a primal tolerance loosened to 1e-9 went unnoticed by every other test.) A few of these
/// polytopes are thinner than δ in the cut's direction: then the certificate must check.
#[test]
fn small_violations_are_not_ignored() {
    fn one<const M: usize>(rng: &mut Rng, k: usize) -> Option<bool> {
        let mut p = random_feasible(rng, M, 10, false);
        let s = solve::<M>(&p).x;
        let delta = [1e-11, 1e-10, 1e-9, 1e-6][k % 4] * p.scale();
        // x0 − x* is in the normal cone at x*, so the whole polytope lies in a·x ≥ a·x*
        // for a = x* − x0: the cut removes a slab of width δ from it.
        let a: Vec<f64> = (0..M).map(|j| s[j] - p.x0[j]).collect();
        if norm(&a) < 1e-6 * p.scale() {
            return None;
        }
        let b = dot(&a, &s) + delta * norm(&a);
        p.row(a.clone(), b);
        let s2 = solve::<M>(&p);
        if s2.status == Status::Infeasible {
            check_certificate(&p, &s2.certificate, 1e-9).unwrap();
            return Some(false);
        }
        check_kkt(&p, &s2, 1e-12).unwrap_or_else(|e| panic!("δ = {delta:e}: {e}"));
        let d = (dot(&a, &s2.x) - b) / norm(&a);
        assert!(
            d >= -1e-12 * p.scale(),
            "new row violated by {d:e} (δ = {delta:e})"
        );
        Some(true)
    }
    let mut rng = Rng(18);
    let (mut solved, mut total) = (0, 0);
    for k in 0..600 {
        let r = if k % 2 == 0 {
            one::<3>(&mut rng, k)
        } else {
            one::<7>(&mut rng, k)
        };
        if let Some(ok) = r {
            total += 1;
            solved += ok as usize;
        }
    }
    assert!(solved * 10 >= total * 9, "{solved} of {total} solved");
}
