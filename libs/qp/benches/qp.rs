//! Run time of the projection solve at the filters' sizes (3×8 and 3×13 with the 2M box
//! rows, 7×56 with them) on random problems where several rows are active, and of the
//! least-violation and lexicographic solves: criterion timings over a pool of problems,
//! then per-call percentiles (each call timed on its own).

#[path = "../tests/common/mod.rs"]
mod common;

use common::{Problem, Rng, random_feasible, random_lv};
use criterion::{Criterion, criterion_group, criterion_main};
use sc_qp::{ActiveSetQp, Settings, Status};
use std::hint::black_box;
use std::time::{Duration, Instant};

const POOL: usize = 256;

type Data<const M: usize> = ([f64; M], [[f64; M]; 64], [f64; 64], [f64; 64], usize);

fn pool<const M: usize>(make: impl Fn(&mut Rng) -> Problem) -> Vec<Data<M>> {
    let mut rng = Rng(2024);
    (0..POOL)
        .map(|_| {
            let p = make(&mut rng);
            let (x0, a, b, w) = p.arrays::<M, 64>();
            (x0, a, b, w, p.n())
        })
        .collect()
}

/// Projection problems of `M` variables with `rows` rows in total (2M of them the box).
fn projection<const M: usize>(rows: usize) -> Vec<Data<M>> {
    pool::<M>(|rng| random_feasible(rng, M, rows - 2 * M, false))
}

/// Least-violation problems: the box (hard), two hard rows, the rest soft and contradictory.
fn violation<const M: usize>(rows: usize) -> Vec<Data<M>> {
    pool::<M>(|rng| random_lv(rng, M, rows - 2 * M - 2, 2, true))
}

#[derive(Clone, Copy)]
enum Call {
    Solve,
    LeastViolation,
    Lexicographic,
}

fn call<const M: usize>(qp: &mut ActiveSetQp<M, 64>, d: &Data<M>, c: Call) -> f64 {
    let (x0, a, b, w, n) = d;
    match c {
        Call::Solve => qp.solve(x0, a, b, *n).x[0],
        Call::LeastViolation => qp.least_violation(a, b, w, *n).t,
        Call::Lexicographic => qp.lexicographic(x0, a, b, w, *n).1.x[0],
    }
}

fn percentiles<const M: usize>(name: &str, data: &[Data<M>], c: Call) {
    let mut qp = ActiveSetQp::<M, 64>::new(Settings::default());
    // statistics of the pool itself
    let (mut act, mut it, mut outer) = (0u64, 0u64, 0u64);
    let (mut it_max, mut outer_max) = (0u32, 0u32);
    for d in data {
        let (x0, a, b, w, n) = d;
        if matches!(c, Call::Solve) {
            let s = qp.solve(x0, a, b, *n);
            assert_eq!(s.status, Status::Optimal);
            act += s.active.count_ones() as u64;
            it += s.iterations as u64;
            it_max = it_max.max(s.iterations);
        } else {
            let (l, s) = qp.lexicographic(x0, a, b, w, *n);
            assert_eq!(l.status, Status::Optimal);
            act += s.active.count_ones() as u64;
            it += l.iterations as u64;
            outer += l.outer_iterations as u64;
            it_max = it_max.max(l.iterations);
            outer_max = outer_max.max(l.outer_iterations);
        }
    }
    let reps = 80;
    let mut ns: Vec<u64> = Vec::with_capacity(reps * data.len());
    for _ in 0..reps {
        for d in data {
            let t0 = Instant::now();
            black_box(call(&mut qp, black_box(d), c));
            ns.push(t0.elapsed().as_nanos() as u64);
        }
    }
    ns.sort_unstable();
    let q = |p: f64| ns[((ns.len() - 1) as f64 * p).round() as usize] as f64 / 1000.0;
    let k = data.len() as f64;
    println!(
        "{name:<22} p50 {:7.2} µs  p90 {:7.2}  p99 {:7.2}  p99.9 {:7.2}  max {:7.2}   \
         (mean active rows {:.1}, active-set changes mean {:.1} max {}{})",
        q(0.5),
        q(0.9),
        q(0.99),
        q(0.999),
        q(1.0),
        act as f64 / k,
        it as f64 / k,
        it_max,
        if matches!(c, Call::Solve) {
            String::new()
        } else {
            format!(
                ", projections per lexicographic mean {:.1} max {outer_max}",
                outer as f64 / k
            )
        }
    );
}

fn bench_one<const M: usize>(cr: &mut Criterion, name: &str, data: &[Data<M>], c: Call) {
    let mut qp = ActiveSetQp::<M, 64>::new(Settings::default());
    let mut i = 0;
    cr.bench_function(name, |bn| {
        bn.iter(|| {
            i = (i + 1) % data.len();
            black_box(call(&mut qp, black_box(&data[i]), c))
        })
    });
}

fn benches(cr: &mut Criterion) {
    let p3x8 = projection::<3>(8);
    let p3x13 = projection::<3>(13);
    let p7x56 = projection::<7>(56);
    let v3x13 = violation::<3>(13);
    let v7x56 = violation::<7>(56);
    bench_one(cr, "solve 3x8", &p3x8, Call::Solve);
    bench_one(cr, "solve 3x13", &p3x13, Call::Solve);
    bench_one(cr, "solve 7x56", &p7x56, Call::Solve);
    bench_one(cr, "least_violation 3x13", &v3x13, Call::LeastViolation);
    bench_one(cr, "least_violation 7x56", &v7x56, Call::LeastViolation);
    bench_one(cr, "lexicographic 7x56", &v7x56, Call::Lexicographic);
    println!("\nper-call percentiles ({POOL} problems × 80 repetitions each):");
    percentiles("solve 3x8", &p3x8, Call::Solve);
    percentiles("solve 3x13", &p3x13, Call::Solve);
    percentiles("solve 7x56", &p7x56, Call::Solve);
    percentiles("least_violation 3x13", &v3x13, Call::LeastViolation);
    percentiles("least_violation 7x56", &v7x56, Call::LeastViolation);
    percentiles("lexicographic 3x13", &v3x13, Call::Lexicographic);
    percentiles("lexicographic 7x56", &v7x56, Call::Lexicographic);
}

criterion_group! {
    name = group;
    config = Criterion::default()
        .sample_size(30)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    targets = benches
}
criterion_main!(group);
