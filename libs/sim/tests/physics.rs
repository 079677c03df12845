//! Physics checks of the simulator: conservation laws of the free-flying servicer,
//! of a lone orbit, and agreement with the CW solution for small separations.

use nalgebra::Vector3;
use sc_models::cw::ClohessyWiltshire;
use sc_models::orbit::{TwoBody, angular_momentum};
use sc_models::quat;
use sc_multibody::{Robot, Vector7, Vector13};
use sc_scenario::Scenario;
use sc_sim::{Command, SimState, Simulator};
use std::path::Path;
use std::sync::Arc;

fn setup() -> (Scenario, Arc<Robot>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let s = Scenario::load(&root.join("config/scenario.toml")).unwrap();
    let r = Arc::new(Robot::from_urdf_file(&s.urdf_path()).unwrap());
    (s, r)
}

/// Angular momentum of the servicer about its CoM and its internal kinetic energy
/// (relative to the CoM), both in inertial axes.
fn internal_momentum(sim: &Simulator) -> (Vector3<f64>, f64) {
    let s = sim.state();
    let robot = sim.robot();
    let r_ib = quat::to_matrix(&s.q_ib);
    let mut nu = Vector13::zeros();
    nu.fixed_rows_mut::<3>(0)
        .copy_from(&(r_ib.transpose() * s.dv));
    nu.fixed_rows_mut::<3>(3).copy_from(&s.w_b);
    nu.fixed_rows_mut::<7>(6).copy_from(&s.theta_dot);
    let m = robot.momentum(&s.theta, &nu);
    let e =
        robot.kinetic_energy(&s.theta, &nu) - 0.5 * m.linear.norm_squared() / robot.total_mass();
    (r_ib * m.angular_com, e)
}

/// Servicer CoM relative to the target CoM (inertial) and its velocity.
fn com_relative(sim: &Simulator) -> (Vector3<f64>, Vector3<f64>) {
    let s = sim.state();
    let robot = sim.robot();
    let r_ib = quat::to_matrix(&s.q_ib);
    let mut nu = Vector13::zeros();
    nu.fixed_rows_mut::<3>(0)
        .copy_from(&(r_ib.transpose() * s.dv));
    nu.fixed_rows_mut::<3>(3).copy_from(&s.w_b);
    nu.fixed_rows_mut::<7>(6).copy_from(&s.theta_dot);
    let m = robot.momentum(&s.theta, &nu);
    (s.dr + r_ib * m.com, r_ib * m.linear / robot.total_mass())
}

#[test]
fn free_servicer_conserves_momentum_and_energy_over_200s() {
    let (scenario, robot) = setup();
    let mut sim = Simulator::new(&scenario, robot).unwrap();
    // give the arm and the base some motion, then let the system coast for 200 s
    let mut s: SimState = *sim.state();
    s.w_b = Vector3::new(0.02, -0.03, 0.015);
    s.theta_dot = Vector7::from_column_slice(&[0.05, -0.04, 0.03, 0.06, -0.05, 0.04, 0.08]);
    s.dv += Vector3::new(0.01, -0.02, 0.005);
    sim.set_state(s);
    let (l0, e0) = internal_momentum(&sim);
    let (c0, cv0) = com_relative(&sim);
    // a point mass started at the servicer's CoM, propagated by the same two-body law
    let g = TwoBody {
        mu: scenario.orbit.earth_mu_m3_s2,
    };
    let (mut rt, mut vt) = (sim.state().r_t, sim.state().v_t);
    let (mut pc, mut pv) = (rt + c0, vt + cv0);
    let h = scenario.mission.physics_step_s;
    let rk4 = |r: &mut Vector3<f64>, v: &mut Vector3<f64>| {
        let f = |r: &Vector3<f64>| g.gravity(r);
        let (k1r, k1v) = (*v, f(r));
        let (k2r, k2v) = (*v + k1v * h / 2.0, f(&(*r + k1r * h / 2.0)));
        let (k3r, k3v) = (*v + k2v * h / 2.0, f(&(*r + k2r * h / 2.0)));
        let (k4r, k4v) = (*v + k3v * h, f(&(*r + k3r * h)));
        *r += (k1r + 2.0 * k2r + 2.0 * k3r + k4r) * h / 6.0;
        *v += (k1v + 2.0 * k2v + 2.0 * k3v + k4v) * h / 6.0;
    };
    for _ in 0..2000 {
        sim.step(&Command::zero()).unwrap();
        for _ in 0..scenario.physics_substeps() {
            rk4(&mut rt, &mut vt);
            rk4(&mut pc, &mut pv);
        }
    }
    let (l1, e1) = internal_momentum(&sim);
    let (c1, _) = com_relative(&sim);
    assert!(
        (l1 - l0).norm() < 1e-9 * l0.norm(),
        "angular momentum about CoM: {l0} -> {l1}"
    );
    assert!(
        (e1 - e0).abs() < 1e-9 * e0,
        "internal kinetic energy: {e0} -> {e1}"
    );
    // the CoM moves exactly like a point mass under two-body gravity (linear momentum
    // changes only through gravity); compare relative to the target (differences of
    // 7000 km positions carry ~1e-9 m rounding)
    let point_rel = (pc - rt) - (Vector3::zeros());
    assert!(
        (c1 - point_rel).norm() < 1e-6,
        "CoM drift {}",
        (c1 - point_rel).norm()
    );
}

#[test]
fn lone_orbit_conserves_energy_and_angular_momentum() {
    let (scenario, robot) = setup();
    let mut sim = Simulator::new(&scenario, robot).unwrap();
    let g = TwoBody {
        mu: scenario.orbit.earth_mu_m3_s2,
    };
    let s0 = *sim.state();
    let e0 = g.specific_energy(&s0.r_t, &s0.v_t);
    let h0 = angular_momentum(&s0.r_t, &s0.v_t);
    for _ in 0..2000 {
        sim.step(&Command::zero()).unwrap();
    }
    let s1 = *sim.state();
    let e1 = g.specific_energy(&s1.r_t, &s1.v_t);
    let h1 = angular_momentum(&s1.r_t, &s1.v_t);
    assert!((e1 - e0).abs() < 1e-12 * e0.abs(), "energy {e0} -> {e1}");
    assert!(
        (h1 - h0).norm() < 1e-12 * h0.norm(),
        "angular momentum {h0} -> {h1}"
    );
    // the target's tumbling: torque-free, so its rotational energy and inertial angular
    // momentum are conserved too
    let i = nalgebra::Matrix3::from_fn(|r, c| scenario.target.inertia_kg_m2[r][c]);
    let l0 = quat::to_matrix(&s0.q_it) * (i * s0.w_t);
    let l1 = quat::to_matrix(&s1.q_it) * (i * s1.w_t);
    assert!((l1 - l0).norm() < 1e-10 * l0.norm());
}

/// Final Hill-frame position error of the full simulation w.r.t. the CW solution after
/// `t` seconds, starting at `scale` × a fixed relative state.
fn cw_error(scale: f64, steps: usize) -> f64 {
    let (mut scenario, robot) = setup();
    scenario.servicer.initial_theta_dot_rad_s = [0.0; 7];
    scenario.servicer.initial_omega_rad_s = [0.0; 3];
    let mut sim = Simulator::new(&scenario, robot).unwrap();
    let o = sim.observe();
    // put the servicer's CoM (not its base origin) at the chosen Hill state
    let com_b = sim.robot().center_of_mass(&o.theta);
    let mut s = *sim.state();
    let hill = sc_models::hill::HillFrame::from_inertial(&s.r_t, &s.v_t);
    let r_h0 = Vector3::new(4.0, -10.0, 3.0) * scale;
    let v_h0 = Vector3::new(0.002, 0.001, -0.003) * scale;
    let (dr_com, dv) = hill.hill_to_relative(&r_h0, &v_h0);
    s.dr = dr_com - quat::to_matrix(&s.q_ib) * com_b;
    s.dv = dv;
    sim.set_state(s);
    for _ in 0..steps {
        sim.step(&Command::zero()).unwrap();
    }
    let o = sim.observe();
    let st = sim.state();
    let hill = sc_models::hill::HillFrame::from_inertial(&st.r_t, &st.v_t);
    let com_h = hill.c_hi * (st.dr + quat::to_matrix(&st.q_ib) * com_b);
    let cw = ClohessyWiltshire {
        n: o.mean_motion,
        mass: 1.0,
    };
    let x0 = nalgebra::Vector6::new(r_h0.x, r_h0.y, r_h0.z, v_h0.x, v_h0.y, v_h0.z);
    let x = cw.transition(o.t) * x0;
    (com_h - Vector3::new(x[0], x[1], x[2])).norm()
}

#[test]
fn small_separations_follow_clohessy_wiltshire_to_second_order() {
    let steps = 3000; // 300 s
    let e1 = cw_error(1.0, steps);
    let e2 = cw_error(2.0, steps);
    // the CW model drops O(|r|^2 / a) terms: the error is tiny and grows quadratically
    assert!(
        e1 < 1e-4,
        "CW error at ~11 m separation after 300 s: {e1} m"
    );
    let ratio = e2 / e1;
    assert!(
        (3.5..4.5).contains(&ratio),
        "error ratio for 2x separation: {ratio} ({e1} m, {e2} m)"
    );
}

#[test]
fn body_fixed_force_rotates_with_the_base() {
    // a constant body-x force while the base spins about body z: the inertial force
    // direction turns with the base, so the net velocity change is much smaller than
    // F t / m (it would be exactly F t / m for an inertially fixed force)
    let (mut scenario, robot) = setup();
    scenario.servicer.initial_omega_rad_s = [0.0, 0.0, 0.2];
    let mut sim = Simulator::new(&scenario, robot).unwrap();
    let m = sim.robot().total_mass();
    let (_, v0) = com_relative(&sim);
    let force_b = Vector3::new(5.0, 0.0, 0.0);
    let cmd = Command {
        force_b,
        torque_b: Vector3::zeros(),
        tau: Vector7::zeros(),
    };
    let steps = (2.0 * std::f64::consts::PI / 0.2 / 0.1).round() as usize; // ~ one revolution
    // the CoM's velocity change is the integral of R_IB(t) f_B / m (trapezoid over control steps)
    let mut predicted = Vector3::zeros();
    let mut prev = quat::to_matrix(&sim.state().q_ib) * force_b / m;
    for _ in 0..steps {
        sim.step(&cmd).unwrap();
        let now = quat::to_matrix(&sim.state().q_ib) * force_b / m;
        predicted += (prev + now) * 0.05;
        prev = now;
    }
    let (_, v1) = com_relative(&sim);
    let fixed = 5.0 * steps as f64 * 0.1 / m;
    // differential gravity over 6 m/s... is tiny at this separation; allow for it
    assert!(
        (v1 - v0 - predicted).norm() < 2e-3 * fixed,
        "{} vs {}",
        v1 - v0,
        predicted
    );
    // and that is far from what an inertially fixed force would give
    assert!(
        predicted.norm() < 0.5 * fixed,
        "{} vs {fixed}",
        predicted.norm()
    );
}

#[test]
fn non_finite_command_is_an_error_not_a_panic() {
    let (scenario, robot) = setup();
    let mut sim = Simulator::new(&scenario, robot).unwrap();
    let mut cmd = Command::zero();
    cmd.tau[3] = f64::NAN;
    assert!(sim.step(&cmd).is_err());
    assert_eq!(sim.step_count(), 0);
}
