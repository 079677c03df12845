//! `Simulator::step_with_plant`: a plant that integrates exactly as our RK4 does gives the
//! same run bit for bit, and a plant that answers wrongly is refused, never used.

use sc_multibody::Robot;
use sc_scenario::Scenario;
use sc_sim::{BarrierState, Command, Plant, PlantError, SimError, SimState, Simulator};
use std::path::Path;
use std::sync::Arc;

fn setup() -> (Scenario, Arc<Robot>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let s = Scenario::load(&root.join("config/scenario.toml")).unwrap();
    let r = Arc::new(Robot::from_urdf_file(&s.urdf_path()).unwrap());
    (s, r)
}

/// Our own simulator, one physics step per inner step, as a plant.
struct OwnRk4(Simulator);

impl Plant for OwnRk4 {
    fn start(&mut self, state: &SimState) -> Result<(), PlantError> {
        self.0.set_state(*state);
        Ok(())
    }
    fn propagate(&mut self, cmd: &Command, _h: f64, n: usize) -> Result<Vec<SimState>, PlantError> {
        (0..n)
            .map(|_| {
                self.0.step(cmd).map_err(|e| PlantError(e.to_string()))?;
                Ok(*self.0.state())
            })
            .collect()
    }
}

/// Spoils the states a plant should give.
type Spoil = fn(&mut Vec<SimState>);

/// A plant that answers with its states spoiled.
struct Faulty(OwnRk4, Spoil);

impl Plant for Faulty {
    fn start(&mut self, s: &SimState) -> Result<(), PlantError> {
        self.0.start(s)
    }
    fn propagate(&mut self, c: &Command, h: f64, n: usize) -> Result<Vec<SimState>, PlantError> {
        let mut v = self.0.propagate(c, h, n)?;
        (self.1)(&mut v);
        Ok(v)
    }
}

fn inner(s: &Scenario, r: &Arc<Robot>) -> OwnRk4 {
    let mut one = s.clone();
    one.mission.control_period_s = s.mission.physics_step_s;
    OwnRk4(Simulator::new(&one, r.clone()).unwrap())
}

fn command(k: usize) -> Command {
    let mut c = Command::zero();
    let x = k as f64;
    c.force_b = nalgebra::Vector3::new(2.0 * (0.3 * x).sin(), 1.0, -0.5 * (0.1 * x).cos());
    c.torque_b = nalgebra::Vector3::new(0.4, -0.3 * (0.2 * x).sin(), 0.2);
    for j in 0..7 {
        c.tau[j] = 0.05 * ((0.5 + 0.1 * j as f64) * x).sin();
    }
    c
}

#[test]
fn a_plant_that_integrates_like_ours_gives_the_same_run_bit_for_bit() {
    let (s, r) = setup();
    let mut own = Simulator::new(&s, r.clone()).unwrap();
    let mut via = Simulator::new(&s, r.clone()).unwrap();
    let mut plant = inner(&s, &r);
    plant.start(via.state()).unwrap();
    for k in 0..50 {
        let (mut a, mut b): (Vec<BarrierState>, Vec<BarrierState>) = (vec![], vec![]);
        own.step_with(&command(k), |x| a.push(*x)).unwrap();
        via.step_with_plant(&mut plant, &command(k), |x| b.push(*x))
            .unwrap();
        assert_eq!(a, b, "physics steps of control step {k}");
        assert_eq!(own.state(), via.state(), "state after control step {k}");
    }
    assert_eq!(via.step_count(), 50);
}

#[test]
fn a_plant_that_answers_wrongly_is_refused() {
    let (s, r) = setup();
    let cases: [(Spoil, &str); 4] = [
        (
            |v| {
                v.pop();
            },
            "states for",
        ),
        (|v| v[3].theta[2] = f64::NAN, "non-finite"),
        (|v| v[0].q_ib = [0.9, 0.0, 0.0, 0.0], "non-finite"),
        (|v| v.push(v[0]), "states for"),
    ];
    for (bad, what) in cases {
        let mut sim = Simulator::new(&s, r.clone()).unwrap();
        let before = *sim.state();
        let mut plant = Faulty(inner(&s, &r), bad);
        plant.start(sim.state()).unwrap();
        let e = sim
            .step_with_plant(&mut plant, &command(0), |_| {})
            .unwrap_err();
        assert!(e.to_string().contains(what), "{e}");
        assert!(matches!(
            e,
            SimError::Plant { .. } | SimError::Diverged { .. }
        ));
        assert_eq!(*sim.state(), before, "a refused answer is not used");
        assert_eq!(sim.step_count(), 0);
    }
}
