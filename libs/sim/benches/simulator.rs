//! Simulator speed: a 200 s open-loop mission at the default 10 ms physics step
//! (20 000 RK4 steps of the coupled 13-DoF servicer, the target and both orbits).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use sc_multibody::{Robot, Vector7};
use sc_scenario::Scenario;
use sc_sim::{Command, Simulator};
use std::path::Path;
use std::sync::Arc;

fn mission(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scenario = Scenario::load(&root.join("config/scenario.toml")).expect("scenario");
    let robot = Arc::new(Robot::from_urdf_file(&scenario.urdf_path()).expect("urdf"));
    let cmd = Command {
        force_b: Vector3::new(1.0, 0.2, -0.1),
        torque_b: Vector3::new(0.01, -0.005, 0.002),
        tau: Vector7::zeros(), // a free arm under constant torque would spin up without bound
    };
    let steps = (200.0 / scenario.mission.control_period_s).round() as usize;
    let mut group = c.benchmark_group("simulator");
    group.sample_size(10);
    group.bench_function("mission_200s_10ms_step", |b| {
        b.iter(|| {
            let mut sim = Simulator::new(&scenario, robot.clone()).expect("sim");
            for _ in 0..steps {
                sim.step(&cmd).expect("step");
            }
            sim.observe()
        })
    });
    group.finish();
}

criterion_group!(benches, mission);
criterion_main!(benches);
