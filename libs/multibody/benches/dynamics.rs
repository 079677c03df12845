//! Timing of the hot paths: 13-DoF forward dynamics (ABA), mass matrix (CRBA), bias (RNEA),
//! kinematics + all collision-sphere Jacobians, Schur-reduced arm dynamics.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Vector3, Vector6};
use sc_multibody::{Robot, SphereState, Vector7, Vector13};

fn robot() -> Robot {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/servicer.urdf");
    Robot::from_urdf_file(&path).expect("servicer URDF")
}

fn bench(c: &mut Criterion) {
    let r = robot();
    let theta = Vector7::from_column_slice(&[0.1, -0.9, 0.3, 1.7, -0.2, -0.6, 0.4]);
    let theta_dot = Vector7::from_column_slice(&[0.05, -0.1, 0.2, 0.1, -0.3, 0.25, 0.1]);
    let mut nu = Vector13::zeros();
    nu.fixed_rows_mut::<3>(0)
        .copy_from(&Vector3::new(0.02, -0.01, 0.03));
    nu.fixed_rows_mut::<3>(3)
        .copy_from(&Vector3::new(0.05, -0.08, 0.02));
    nu.fixed_rows_mut::<7>(6).copy_from(&theta_dot);
    let u = Vector13::from_column_slice(&[
        3.0, -2.0, 1.0, 5.0, -4.0, 2.0, 1.0, -1.5, 0.5, 2.0, -0.7, 0.3, 1.1,
    ]);
    let omega = Vector3::new(0.05, -0.08, 0.02);
    c.bench_function("forward_dynamics (ABA, 13 DoF)", |b| {
        b.iter(|| r.forward_dynamics(black_box(&theta), black_box(&nu), black_box(&u)))
    });
    c.bench_function("forward_dynamics_sim (ABA, v_B = 0)", |b| {
        b.iter(|| {
            r.forward_dynamics_sim(
                black_box(&theta),
                black_box(&omega),
                black_box(&theta_dot),
                black_box(&u),
            )
        })
    });
    c.bench_function("mass_matrix (CRBA, 13x13)", |b| {
        b.iter(|| r.mass_matrix(black_box(&theta)))
    });
    c.bench_function("nonlinear_effects (RNEA)", |b| {
        b.iter(|| r.nonlinear_effects(black_box(&theta), black_box(&nu)))
    });
    c.bench_function("kinematics_vel + EE J + all sphere states", |b| {
        let mut out = [SphereState::default(); 32];
        b.iter(|| {
            let k = r.kinematics_vel(black_box(&theta), black_box(&theta_dot));
            let j = r.ee_jacobian(&k);
            let n = r.sphere_states_into(&k, &mut out);
            (j, n)
        })
    });
    let w = Vector6::new(3.0, -2.0, 1.0, 5.0, -4.0, 2.0);
    c.bench_function("reduced_arm_dynamics (Schur)", |b| {
        b.iter(|| {
            r.reduced_arm_dynamics(
                black_box(&theta),
                black_box(&theta_dot),
                black_box(&omega),
                black_box(&w),
            )
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
