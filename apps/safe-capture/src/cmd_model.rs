//! `safe-capture model`: the servicer model at one state, as JSON.

use anyhow::Context;
use sc_mission::Setup;
use sc_sim::{ModelState, evaluate_model};
use std::path::PathBuf;
use std::process::ExitCode;

/// Evaluates the servicer model (URDF of the scenario) at a state and prints JSON:
/// mass matrix, bias forces, generalised accelerations, end-effector and collision-sphere
/// positions and Jacobians.
///
/// STATE.json keys: `position` (base-frame origin, inertial frame, m), `quaternion`
/// (scalar-first [q0,q1,q2,q3], rotating base-frame vectors into the inertial frame),
/// `velocity` (base-origin velocity, inertial frame, m/s), `omega` (base frame, rad/s),
/// `theta` (7, rad), `theta_dot` (7, rad/s), and optionally `force_b`, `torque_b` (base
/// frame, about the base-frame origin, N and N m) and `tau` (7, N m).
///
/// Output basis: generalised velocity ν = [base-origin linear velocity in the base frame,
/// base angular velocity in the base frame, θ̇] — the free-flyer convention of
/// Featherstone and Pinocchio. `mass_matrix` (13×13, rows as nested arrays), `bias` (13,
/// Pinocchio's nonLinearEffects) and `nu_dot` (13, Pinocchio's aba) are in that basis.
/// No gravity acts inside the model (orbital gravity moves the whole system).
///
/// Exit codes: 0 printed, 2 bad arguments, an invalid state or scenario.
#[derive(clap::Args)]
pub struct Args {
    /// State JSON file (see above).
    #[arg(long, value_name = "STATE.json")]
    state: PathBuf,
    /// Scenario file naming the URDF.
    #[arg(long, value_name = "FILE", default_value_os_t = crate::default_scenario())]
    scenario: PathBuf,
    /// Use this URDF instead of the scenario's.
    #[arg(long, value_name = "FILE")]
    urdf: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let robot = match &a.urdf {
        Some(p) => {
            sc_multibody::Robot::from_urdf_file(p).with_context(|| p.display().to_string())?
        }
        None => (*Setup::load(&a.scenario)?.robot).clone(),
    };
    let text = std::fs::read_to_string(&a.state)
        .with_context(|| format!("cannot read {}", a.state.display()))?;
    let state: ModelState = serde_json::from_str(&text)
        .with_context(|| format!("{}: invalid state JSON", a.state.display()))?;
    let report = evaluate_model(&robot, &state).with_context(|| a.state.display().to_string())?;
    outln!("{}", serde_json::to_string_pretty(&report)?);
    Ok(ExitCode::SUCCESS)
}
