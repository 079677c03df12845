//! Run time of the three filters per control step over a representative set of states
//! (free motion, near-boundary interventions, infeasible/relaxed cases): criterion timings
//! plus percentiles of the filters' own `solve_time_ns` (whole-call wall time).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use sc_cbf::robotic::Vector7;
use sc_cbf::{
    AttitudeFilter, AttitudeInput, RoboticFilter, RoboticInput, TranslationalFilter,
    TranslationalInput,
};
use sc_models::quat;
use std::hint::black_box;

struct Step {
    tr: (TranslationalInput, Vector3<f64>),
    att: (AttitudeInput, Vector3<f64>),
    rob: (RoboticInput, Vector7),
}

fn lcg(s: &mut u64) -> f64 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

fn steps() -> Vec<Step> {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let s = sc_scenario::Scenario::load(&root.join(sc_scenario::DEFAULT_SCENARIO)).unwrap();
    let robot = sc_multibody::Robot::from_urdf_file(&s.urdf_path()).unwrap();
    let a = s.orbit.earth_radius_m + s.orbit.altitude_m;
    let n = (s.orbit.earth_mu_m3_s2 / (a * a * a)).sqrt();
    let q_hr = s.reference_frame.attitude_in_hill;
    let mut seed = 99u64;
    let mut out = Vec::new();
    let th0 = Vector7::from(s.servicer.initial_theta_rad);
    for k in 0..400 {
        let mut r = || lcg(&mut seed);
        // translational: along the approach, every third step near the wall moving out
        let ang: f64 = if k % 3 == 0 {
            4.5f64.to_radians()
        } else {
            2f64.to_radians() * r()
        };
        let dist = 2.0 + 7.0 * (k as f64 / 400.0);
        let r_r = Vector3::new(-ang.cos(), ang.sin(), 0.0) * dist;
        let v_r = Vector3::new(0.02, 0.005 * r(), 0.002 * r());
        let r_hr = quat::to_matrix(&q_hr);
        let tr = TranslationalInput::circular(r_hr * r_r, r_hr * v_r, q_hr, n, quat::IDENTITY);
        let f_nom = Vector3::new(5.0 * r(), 5.0 * r(), 5.0 * r());
        // attitude: pointing error up to ~4.5°, rates up to 0.2
        let q = quat::from_axis_angle(
            &Vector3::new(0.0, r(), r()),
            4.5f64.to_radians() * r().abs(),
        );
        let wt = Vector3::new(-0.08, 0.0, 0.0);
        let rt = quat::to_matrix(&quat::from_axis_angle(&wt, 0.08 * k as f64 * 0.1));
        let p = rt * Vector3::new(-0.55, 0.12, 0.0);
        let att = AttitudeInput {
            q_rb: q,
            omega_b: Vector3::new(0.2 * r(), 0.2 * r(), 0.2 * r()),
            inertia: robot.base_inertia_com(),
            r_r,
            v_r,
            a_drift_r: Vector3::zeros(),
            grasp_r: p,
            grasp_vel_r: wt.cross(&p),
            grasp_acc_r: wt.cross(&wt.cross(&p)),
            xi_r: Vector3::new(0.02 * r(), 0.02 * r(), 0.02 * r()),
            omega_target_b: quat::to_matrix(&q).transpose() * wt,
        };
        let t_nom = Vector3::new(12.0 * r(), 12.0 * r(), 12.0 * r());
        let th = th0 + Vector7::from_fn(|_, _| 0.8 * lcg(&mut seed));
        let thd = Vector7::from_fn(|_, _| 0.3 * lcg(&mut seed));
        let rob = sc_cbf::robotic_input_from_model(
            &robot,
            &th,
            &thd,
            &Vector3::zeros(),
            &Vector3::new(3.0, 1.0, -2.0),
            &Vector3::new(1.0, 0.0, 2.0),
        )
        .unwrap();
        let tau = Vector7::from_fn(|_, _| 0.5 * lcg(&mut seed));
        out.push(Step {
            tr: (tr, f_nom),
            att: (att, t_nom),
            rob: (rob, tau),
        });
    }
    out
}

fn pct(v: &mut [u64], p: f64) -> f64 {
    v.sort_unstable();
    v[((v.len() - 1) as f64 * p).round() as usize] as f64 / 1000.0
}

fn bench(c: &mut Criterion) {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let s = sc_scenario::Scenario::load(&root.join(sc_scenario::DEFAULT_SCENARIO)).unwrap();
    let mut ft = TranslationalFilter::from_scenario(&s, 269.0);
    let mut fa = AttitudeFilter::from_scenario(&s);
    let mut fr = RoboticFilter::from_scenario(&s);
    let steps = steps();
    // percentiles of the reported whole-call times, 20 passes over the set
    let (mut tt, mut ta, mut trb, mut tot) = (vec![], vec![], vec![], vec![]);
    let mut status = [[0usize; 4]; 3];
    for _ in 0..20 {
        for st in &steps {
            let a = ft.filter(&st.tr.0, &st.tr.1).report;
            let b = fa.filter(&st.att.0, &st.att.1).report;
            let r = fr.filter(&st.rob.0, &st.rob.1).report;
            status[0][a.status as usize] += 1;
            status[1][b.status as usize] += 1;
            status[2][r.status as usize] += 1;
            tt.push(a.solve_time_ns);
            ta.push(b.solve_time_ns);
            trb.push(r.solve_time_ns);
            tot.push(a.solve_time_ns + b.solve_time_ns + r.solve_time_ns);
        }
    }
    let geo = |v: &[u64]| {
        (v.iter()
            .map(|x| (*x as f64 / 1000.0).max(1e-3).ln())
            .sum::<f64>()
            / v.len() as f64)
            .exp()
    };
    for (name, v) in [
        ("translational", &mut tt),
        ("attitude", &mut ta),
        ("robotic", &mut trb),
        ("total", &mut tot),
    ] {
        let g = geo(v);
        println!(
            "{name:14} µs: geomean {g:8.2}  p50 {:8.2}  p90 {:8.2}  p99 {:8.2}  max {:8.2}",
            pct(v, 0.5),
            pct(v, 0.9),
            pct(v, 0.99),
            pct(v, 1.0)
        );
    }
    println!(
        "status counts [skipped, solved, relaxed, fallback]: tr {:?} att {:?} rob {:?}",
        status[0], status[1], status[2]
    );
    c.bench_function("safety_layer_step_set", |b| {
        b.iter(|| {
            for st in &steps {
                black_box(ft.filter(&st.tr.0, &st.tr.1));
                black_box(fa.filter(&st.att.0, &st.att.1));
                black_box(fr.filter(&st.rob.0, &st.rob.1));
            }
        })
    });
}

criterion_group! { name = benches; config = Criterion::default().sample_size(10); targets = bench }
criterion_main!(benches);
