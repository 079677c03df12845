//! Run time of the three filters per control step over representative states — free
//! motion, near-boundary interventions, relaxed cases — built from the servicer model the
//! way the mission builds them: criterion timings of each filter over the whole set, plus
//! percentiles of the filters' own `solve_time_ns` (whole-call wall time) and the status
//! counts, so that the timing is known to cover the solver paths.

#[path = "../tests/common/mod.rs"]
mod common;

use common::*;
use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use sc_cbf::robotic::Vector7;
use sc_cbf::{
    AttitudeFilter, AttitudeInput, FilterStatus, RoboticFilter, RoboticInput, TranslationalFilter,
    TranslationalInput,
};
use std::hint::black_box;

struct Set {
    tr: Vec<(TranslationalInput, Vector3<f64>)>,
    att: Vec<(AttitudeInput, Vector3<f64>)>,
    rob: Vec<(RoboticInput, Vector7)>,
}

fn set() -> Set {
    let s = scenario();
    let robot = robot();
    let fmax = s.limits.force_max_n;
    let tmax = s.limits.torque_max_nm;
    let mut rng = Lcg(99);
    let mut set = Set {
        tr: Vec::new(),
        att: Vec::new(),
        rob: Vec::new(),
    };
    for k in 0..400 {
        // translational: along the approach, every third step near the wall moving out
        let ang = if k % 3 == 0 {
            (4.5f64 + 0.5 * rng.next()).to_radians()
        } else {
            2f64.to_radians() * rng.next()
        };
        let phi = std::f64::consts::PI * rng.next();
        let dir = Vector3::new(-ang.cos(), ang.sin() * phi.cos(), ang.sin() * phi.sin());
        let dist = 2.0 + 7.0 * (k as f64 / 400.0);
        let v = -dir * 0.02 + rng.v3(0.005);
        let x = tr_input(&s, dir * dist, v, rng.unit_quat(), rng.v3(0.05));
        set.tr.push((x, rng.v3(fmax)));
        // attitude: pointing error up to 4.5°, rates up to 0.1 rad/s, arm anywhere
        let com = dir * dist;
        let t = 0.1 * k as f64;
        let st = ServicerState {
            theta: theta_inside(&s, &mut rng, 0.1),
            theta_dot: rng.v7(0.1),
            omega_b: rng.v3(0.1),
            q_rb: pointing(
                &s,
                &com,
                t,
                &rng.v3(1.0),
                4.5f64.to_radians() * rng.next().abs(),
            ),
            com_r: com,
            com_v_r: v,
            t,
            f_b: rng.v3(fmax),
        };
        set.att
            .push((att_input(&s, &robot, &st), rng.v3(1.2 * tmax)));
        // robotic: anywhere inside the limits, moving
        let th = theta_inside(&s, &mut rng, 0.0);
        let x = rob_input(&robot, th, rng.v7(0.2));
        set.rob
            .push((x, rng.v7(0.5 * s.limits.joint_torque_max_nm)));
    }
    set
}

fn pct(v: &mut [u64], p: f64) -> f64 {
    v.sort_unstable();
    v[((v.len() - 1) as f64 * p).round() as usize] as f64 / 1000.0
}

fn geomean(v: &[u64]) -> f64 {
    (v.iter()
        .map(|x| (*x as f64 / 1000.0).max(1e-3).ln())
        .sum::<f64>()
        / v.len() as f64)
        .exp()
}

fn bench(c: &mut Criterion) {
    let s = scenario();
    let layer = sc_cbf::SafetyLayer::from_scenario(&s, robot());
    let (mut ft, mut fa, mut fr): (TranslationalFilter, AttitudeFilter, RoboticFilter) =
        (layer.translational, layer.attitude, layer.robotic);
    let set = set();
    // percentiles of the reported whole-call times, 10 passes over the set
    let (mut tt, mut ta, mut trb) = (vec![], vec![], vec![]);
    let mut status = [[0usize; 4]; 3];
    for _ in 0..10 {
        for (x, u) in &set.tr {
            let r = ft.filter(x, u).report;
            status[0][r.status as usize] += 1;
            tt.push(r.solve_time_ns);
        }
        for (x, u) in &set.att {
            let r = fa.filter(x, u).report;
            status[1][r.status as usize] += 1;
            ta.push(r.solve_time_ns);
        }
        for (x, u) in &set.rob {
            let r = fr.filter(x, u).report;
            status[2][r.status as usize] += 1;
            trb.push(r.solve_time_ns);
        }
    }
    let mut tot: Vec<u64> = (0..tt.len()).map(|i| tt[i] + ta[i] + trb[i]).collect();
    for (name, v) in [
        ("translational", &mut tt),
        ("attitude", &mut ta),
        ("robotic", &mut trb),
        ("total", &mut tot),
    ] {
        let g = geomean(v);
        println!(
            "{name:14} µs: geomean {g:8.2}  p50 {:8.2}  p90 {:8.2}  p99 {:8.2}  max {:8.2}",
            pct(v, 0.5),
            pct(v, 0.9),
            pct(v, 0.99),
            pct(v, 1.0)
        );
    }
    let names = [
        FilterStatus::Skipped,
        FilterStatus::Solved,
        FilterStatus::Relaxed,
        FilterStatus::Fallback,
    ];
    println!(
        "status counts {names:?}: translational {:?} attitude {:?} robotic {:?}",
        status[0], status[1], status[2]
    );
    c.bench_function("translational_filter_400_states", |b| {
        b.iter(|| {
            for (x, u) in &set.tr {
                black_box(ft.filter(x, u));
            }
        })
    });
    c.bench_function("attitude_filter_400_states", |b| {
        b.iter(|| {
            for (x, u) in &set.att {
                black_box(fa.filter(x, u));
            }
        })
    });
    c.bench_function("robotic_filter_400_states", |b| {
        b.iter(|| {
            for (x, u) in &set.rob {
                black_box(fr.filter(x, u));
            }
        })
    });
}

criterion_group! { name = benches; config = Criterion::default().sample_size(10); targets = bench }
criterion_main!(benches);
