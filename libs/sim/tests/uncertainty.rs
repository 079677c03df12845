//! A realisation of the declared uncertainty: every draw inside its bound, a function of
//! the seed alone, the truth check flags errors outside the declared bounds, and zero
//! bounds give the truth back exactly.

use sc_multibody::Robot;
use sc_scenario::{Scenario, Uncertainty};
use sc_sim::navigation::{Estimator, PassThrough, error_of};
use sc_sim::uncertainty::NAVIGATION_ERROR_NAMES;
use sc_sim::{Command, NavigationError, NavigationGate, Realisation, Simulator};
use std::path::Path;
use std::sync::Arc;

fn setup() -> (Scenario, Arc<Robot>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let s = Scenario::load(&root.join("config/scenario.toml")).unwrap();
    let r = Arc::new(Robot::from_urdf_file(&s.urdf_path()).unwrap());
    (s, r)
}

/// The gate of `s` (its measurement age; the bounds do not matter here).
fn gate(s: &Scenario) -> NavigationGate {
    let (_, robot) = setup();
    NavigationGate::new(s, robot, Box::new(PassThrough)).unwrap()
}

fn example() -> Uncertainty {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    Uncertainty::profile("config/uncertainty/custom_example.toml", &root).unwrap()
}

/// Every bound of `u` times `k` (the measurement age kept).
fn scaled(u: &Uncertainty, k: f64) -> Uncertainty {
    let text = toml::to_string(u).unwrap();
    let mut v: toml::Value = toml::from_str(&text).unwrap();
    fn walk(v: &mut toml::Value, k: f64) {
        match v {
            toml::Value::Float(x) => *x *= k,
            toml::Value::Table(t) => {
                for (key, x) in t.iter_mut() {
                    if key != "measurement_age_s" {
                        walk(x, k);
                    }
                }
            }
            _ => {}
        }
    }
    walk(&mut v, k);
    v.try_into().unwrap()
}

/// A short run under `r`'s truth with a constant command, the estimate's errors of every
/// step.
fn navigation_errors(r: &mut Realisation, steps: usize) -> Vec<NavigationError> {
    let mut sim = Simulator::new(&r.true_scenario, Arc::new(r.true_robot.clone())).unwrap();
    let gate = gate(&r.true_scenario);
    let mut cmd = Command::zero();
    cmd.tau[1] = 0.5;
    cmd.force_b[0] = 2.0;
    (0..steps)
        .map(|_| {
            let m = gate.measure(&sim, 0);
            let e = error_of(&r.navigation.estimate(&m), &m, gate.measurement_age(&sim));
            let delivered = r.actuators.deliver(&cmd);
            sim.step(&delivered).unwrap();
            e
        })
        .collect()
}

#[test]
fn every_draw_stays_inside_its_declared_bound() {
    let (s, robot) = setup();
    let u = example();
    let bounds = NavigationError::bounds(&u.navigation);
    for seed in 0..40 {
        let mut r = Realisation::draw(&u, seed, &s, &robot).unwrap();
        assert_eq!(r.plant.outside(&u.model), Vec::<&str>::new(), "seed {seed}");
        assert_eq!(r.actuators.outside(&u.actuators), Vec::<&str>::new());
        for e in navigation_errors(&mut r, 20) {
            for ((name, v), b) in NAVIGATION_ERROR_NAMES.iter().zip(e.values()).zip(bounds) {
                assert!(v <= b, "seed {seed}: {name} = {v} > {b}");
            }
        }
    }
}

#[test]
fn a_realisation_is_a_function_of_the_seed() {
    let (s, robot) = setup();
    let u = example();
    let mut a = Realisation::draw(&u, 7, &s, &robot).unwrap();
    let mut b = Realisation::draw(&u, 7, &s, &robot).unwrap();
    let c = Realisation::draw(&u, 8, &s, &robot).unwrap();
    assert_eq!(a.plant, b.plant);
    assert_eq!(a.actuators, b.actuators);
    assert_eq!(a.navigation.bias, b.navigation.bias);
    assert_ne!(a.plant, c.plant);
    assert_eq!(navigation_errors(&mut a, 10), navigation_errors(&mut b, 10));
    // the truth differs from the model the filters use
    assert_ne!(a.true_scenario.target.inertia_kg_m2, s.target.inertia_kg_m2);
}

#[test]
fn errors_beyond_the_declared_bounds_are_named() {
    let (s, robot) = setup();
    let u = example();
    let wide = scaled(&u, 3.0);
    let mut named = std::collections::BTreeSet::new();
    let mut drawn = 0;
    for seed in 0..40 {
        // 3x the inertia bounds can break an inertia's triangle inequality: such a
        // plant is refused (NotPhysical), not simulated
        let Ok(r) = Realisation::draw(&wide, seed, &s, &robot) else {
            continue;
        };
        drawn += 1;
        named.extend(r.plant.outside(&u.model));
        named.extend(r.actuators.outside(&u.actuators));
    }
    assert!(drawn >= 10, "only {drawn} of 40 plants physical");
    for key in [
        "model.servicer_mass_rel",
        "model.servicer_com_m",
        "model.link_mass_rel",
        "model.target_inertia_rel",
        "actuators.thruster_force_scale_rel",
        "actuators.thruster_misalignment_rad",
        "actuators.joint_torque_bias_nm",
        "actuators.joint_torque_ripple_rel",
    ] {
        assert!(named.contains(key), "{key} never flagged: {named:?}");
    }
}

#[test]
fn zero_bounds_give_the_truth_back() {
    let (s, robot) = setup();
    let mut r = Realisation::draw(&Uncertainty::default(), 3, &s, &robot).unwrap();
    // the same model, to the last bit (Robot has no PartialEq: its Debug form is complete)
    assert_eq!(format!("{:?}", r.true_robot), format!("{robot:?}"));
    let sim = Simulator::new(&s, robot.clone()).unwrap();
    let mut gate = NavigationGate::new(&s, robot.clone(), Box::new(PassThrough)).unwrap();
    let m = gate.measure(&sim, 0);
    let estimate = r.navigation.estimate(&m);
    assert_eq!(estimate, m);
    let (k, rejected) = gate.admit(Some(&estimate), &m, &sim, &sim.observe());
    assert_eq!((k.observation, rejected), (sim.observe(), None));
    assert_eq!(k.error, NavigationError::default());
    let mut cmd = Command::zero();
    cmd.tau[3] = 1.0;
    assert_eq!(r.actuators.deliver(&cmd), cmd);
}

/// A Monte Carlo of 1000 runs draws 1000 plants from `realistic`: every one must be a
/// physical body (an inertia refused as NotPhysical would be a failed run).
#[test]
fn every_realistic_plant_of_a_campaign_is_physical() {
    let (s, robot) = setup();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let u = Uncertainty::profile("realistic", &root).unwrap();
    let refused: Vec<u64> = (0..1000)
        .filter(|&seed| Realisation::draw(&u, seed, &s, &robot).is_err())
        .collect();
    assert!(refused.is_empty(), "seeds refused: {refused:?}");
}

/// The simulator's substitute for a refused estimate stays within the **declared**
/// navigation bounds also when the truth is drawn from bounds three times as wide
/// (`[uncertainty.truth]`): its bias is held to the declared one, its noise truncated
/// at the declared noise — what the filters' margins are derived for.
#[test]
fn the_substitute_keeps_the_declared_bounds_under_a_wider_truth() {
    let (s, robot) = setup();
    let declared = example();
    let wide = scaled(&declared, 3.0);
    let bounds = NavigationError::bounds(&declared.navigation);
    let mut outside_truth = 0;
    for seed in 0..20 {
        let mut r = Realisation::draw(&wide, seed, &s, &robot).unwrap();
        let sim = Simulator::new(&r.true_scenario, Arc::new(r.true_robot.clone())).unwrap();
        let m = gate(&r.true_scenario).measure(&sim, 0);
        let mut sub = r.navigation.substitute(&declared.navigation);
        for _ in 0..20 {
            let e = error_of(&sub.estimate(&m), &m, 0.0);
            for ((name, v), b) in NAVIGATION_ERROR_NAMES.iter().zip(e.values()).zip(bounds) {
                assert!(
                    v <= b * (1.0 + 1e-12),
                    "seed {seed}: substitute {name} = {v} > {b}"
                );
            }
            let t = error_of(&r.navigation.estimate(&m), &m, 0.0);
            outside_truth += t
                .values()
                .iter()
                .zip(bounds)
                .filter(|(v, b)| **v > *b)
                .count();
        }
    }
    assert!(
        outside_truth > 0,
        "the wide truth never left the declared bounds: no test"
    );
}
