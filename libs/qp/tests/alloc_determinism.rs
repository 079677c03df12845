//! No heap allocation in `solve`, `least_violation` and `lexicographic` (a counting global
//! allocator, per thread), and bitwise determinism: the same inputs give the same output
//! bits, whatever the solver solved before.

// Index loops mirror the linear algebra.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use sc_qp::{ActiveSetQp, LeastViolation, Settings, Solution};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ALLOCS: Cell<u64> = const { Cell::new(0) };
}

fn bump() {
    let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        bump();
        unsafe { System.alloc(l) }
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        bump();
        unsafe { System.alloc_zeroed(l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        bump();
        unsafe { System.realloc(p, l, n) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocs() -> u64 {
    ALLOCS.with(|c| c.get())
}

/// A mix: feasible, wild scales, infeasible, degenerate, least-violation.
fn problems(m: usize, seed: u64) -> Vec<Problem> {
    let mut rng = Rng(seed);
    let mut v = Vec::new();
    for k in 0..60 {
        let mut p = random_feasible(&mut rng, m, 4 + k % 40, k % 3 == 0);
        match k % 4 {
            1 => {
                // make it infeasible: a row outside the box
                p.row(vec![1.0; m], 1e3);
            }
            2 => {
                // duplicate every row
                for i in 0..p.n().min(64 - p.n()) {
                    let (a, b) = (p.a[i].clone(), p.b[i]);
                    p.row(a, b);
                }
            }
            3 => {
                // soft rows for the least-violation solver
                for i in 0..p.n() {
                    if p.a[i].iter().filter(|x| **x != 0.0).count() > 1 {
                        p.w[i] = rng.range(0.1, 3.0);
                        p.b[i] += rng.range(0.0, 50.0);
                    }
                }
            }
            _ => {}
        }
        v.push(p);
    }
    v
}

#[derive(PartialEq, Debug)]
struct Bits(Vec<u64>);

fn sol_bits<const M: usize, const N: usize>(s: &Solution<M, N>, out: &mut Vec<u64>) {
    out.push(s.status as u64);
    out.extend(s.x.iter().map(|v| v.to_bits()));
    out.extend(s.lambda.iter().map(|v| v.to_bits()));
    out.extend(s.certificate.iter().map(|v| v.to_bits()));
    out.push(s.active as u64);
    out.push((s.active >> 64) as u64);
    out.push(s.iterations as u64);
}

fn lv_bits<const N: usize>(l: &LeastViolation<N>, out: &mut Vec<u64>) {
    out.push(l.status as u64);
    out.push(l.t.to_bits());
    out.extend(l.dual.iter().map(|v| v.to_bits()));
    out.extend(l.certificate.iter().map(|v| v.to_bits()));
    out.push(l.outer_iterations as u64);
    out.push(l.iterations as u64);
}

type Data<const M: usize> = ([f64; M], [[f64; M]; 64], [f64; 64], [f64; 64], usize);

/// Runs every entry point on every problem with one solver; returns the allocations made
/// inside the solver calls (recording the output bits afterwards is not counted).
fn run_all<const M: usize>(
    qp: &mut ActiveSetQp<M, 64>,
    data: &[Data<M>],
    bits: &mut Vec<u64>,
) -> u64 {
    let mut n_alloc = 0;
    for (x0, a, b, w, n) in data {
        let c0 = allocs();
        let s = qp.solve(x0, a, b, *n);
        let l = qp.least_violation(a, b, w, *n);
        let (l2, s2) = qp.lexicographic(x0, a, b, w, *n);
        n_alloc += allocs() - c0;
        sol_bits(&s, bits);
        sol_bits(&s2, bits);
        lv_bits(&l, bits);
        lv_bits(&l2, bits);
    }
    n_alloc
}

fn check<const M: usize>(seed: u64) {
    let data: Vec<Data<M>> = problems(M, seed)
        .iter()
        .map(|p| {
            let (x0, a, b, w) = p.arrays::<M, 64>();
            // garbage rows beyond n must not matter: fill with something finite
            let (mut a, mut b, mut w) = (a, b, w);
            for i in p.n()..64 {
                a[i] = [7.0; M];
                b[i] = 1e9;
                w[i] = 0.0;
            }
            (x0, a, b, w, p.n())
        })
        .collect();
    let mut qp = ActiveSetQp::<M, 64>::new(Settings::default());
    let mut first = Vec::with_capacity(1 << 16);
    let n1 = run_all(&mut qp, &data, &mut first);
    assert_eq!(n1, 0, "allocations inside the solver");
    // same solver again (history: it just solved everything), and a fresh one in reverse
    let mut second = Vec::with_capacity(1 << 16);
    run_all(&mut qp, &data, &mut second);
    assert!(Bits(first.clone()) == Bits(second), "repeat differs");
    let mut fresh = ActiveSetQp::<M, 64>::new(Settings::default());
    let rev: Vec<Data<M>> = data.iter().rev().cloned().collect();
    let mut third = Vec::with_capacity(1 << 16);
    run_all(&mut fresh, &rev, &mut third);
    // compare per problem: reverse the per-problem chunks of `third`
    let chunk = first.len() / data.len();
    let third_fwd: Vec<u64> = third.chunks(chunk).rev().flatten().copied().collect();
    assert!(Bits(first) == Bits(third_fwd), "history dependence");
}

#[test]
fn no_allocation_and_bitwise_determinism_m3() {
    check::<3>(40);
}

#[test]
fn no_allocation_and_bitwise_determinism_m7() {
    check::<7>(41);
}

/// The counter works (so the zero above means something).
#[test]
fn counter_counts() {
    let before = allocs();
    let v = std::hint::black_box(vec![1u8; 10]);
    assert!(allocs() > before);
    drop(v);
}

/// The solver reuses the scaling of rows equal to the previous call's: a second solve on
/// the same rows with another right-hand side — or with one row changed in one entry, or
/// a row turned NaN — gives the same bits as a fresh solver that scales everything.
fn reuse<const M: usize>(seed: u64) {
    let mut rng = Rng(seed);
    let mut warm = ActiveSetQp::<M, 64>::new(Settings::default());
    let mut hits = 0;
    for p in problems(M, seed) {
        let (x0, a, b, w) = p.arrays::<M, 64>();
        let n = p.n();
        warm.solve(&x0, &a, &b, n);
        let mut b2 = b;
        for v in b2.iter_mut().take(n) {
            *v += rng.range(-0.5, 0.5);
        }
        let mut a2 = a;
        a2[rng.below(n)][rng.below(M)] *= 1.0 + 1e-12;
        let mut a3 = a;
        a3[rng.below(n)][0] = f64::NAN;
        for (a, b) in [(&a, &b2), (&a2, &b), (&a3, &b), (&a, &b)] {
            let mut fresh = ActiveSetQp::<M, 64>::new(Settings::default());
            let (mut got, mut want) = (Vec::new(), Vec::new());
            sol_bits(&warm.solve(&x0, a, b, n), &mut got);
            sol_bits(&fresh.solve(&x0, a, b, n), &mut want);
            lv_bits(&warm.least_violation(a, b, &w, n), &mut got);
            lv_bits(&fresh.least_violation(a, b, &w, n), &mut want);
            assert!(Bits(got) == Bits(want), "reused scaling differs");
            hits += 1;
        }
    }
    assert!(hits > 0);
}

#[test]
fn reused_row_scaling_is_exact_m3() {
    reuse::<3>(42);
}

#[test]
fn reused_row_scaling_is_exact_m7() {
    reuse::<7>(43);
}
