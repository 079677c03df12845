//! Per-step cost of the nominal controllers on the default scenario.

use criterion::{Criterion, criterion_group, criterion_main};
use sc_models::{Vec3, quat};
use sc_multibody::{Robot, Vector7};
use sc_nominal::{NominalControllers, NominalInput};
use sc_scenario::Scenario;
use std::hint::black_box;
use std::path::Path;

fn bench(c: &mut Criterion) {
    let s =
        Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml"))
            .unwrap();
    let robot = Robot::from_urdf_file(&s.urdf_path()).unwrap();
    let ctl = NominalControllers::new(&s, robot).unwrap();
    let x = NominalInput {
        t: 0.0,
        q_hr: s.reference_frame.attitude_in_hill,
        omega_h: Vec3::new(0.0, 0.0, 1.08e-3),
        r_r: Vec3::new(-4.0, 0.2, -0.1),
        v_r: Vec3::new(0.05, -0.01, 0.0),
        q_rb: quat::from_axis_angle(&Vec3::new(0.0, 0.3, 1.0), 0.05),
        omega_b: Vec3::new(-0.05, 0.002, 0.001),
        q_rt: quat::from_axis_angle(&Vec3::x(), -1.0),
        omega_t: Vec3::new(-0.08, 0.0, 0.0),
        theta: Vector7::from(s.servicer.initial_theta_rad),
        theta_dot: Vector7::zeros(),
    };
    let r_h = Vec3::new(4.0, 0.1, -0.1);
    let v_h = Vec3::new(-0.01, 0.02, 0.0);
    c.bench_function("translational_mpc_step", |b| {
        b.iter(|| {
            ctl.translational()
                .command(black_box(&r_h), &v_h, &x.q_hr, &x.omega_h)
        })
    });
    c.bench_function("nominal_hold_phase", |b| {
        b.iter(|| ctl.command(black_box(&x)))
    });
    let mut xg = x;
    xg.t = 130.0;
    xg.r_r = Vec3::new(-2.2, 0.0, 0.0);
    c.bench_function("nominal_grasp_phase_with_ik", |b| {
        b.iter(|| ctl.command(black_box(&xg)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
