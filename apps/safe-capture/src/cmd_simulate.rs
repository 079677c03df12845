//! `safe-capture simulate`: open-loop run of a command profile.

use anyhow::Context;
use sc_mission::Setup;
use sc_sim::{CommandProfile, Simulator, TRAJECTORY_COLUMNS};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Open-loop simulation: applies a command profile (zero-order hold at the control
/// period) to the high-fidelity simulator and writes the trajectory.
///
/// PROFILE.csv columns (header required): t_s, f_b_x_n, f_b_y_n, f_b_z_n, tau_b_x_nm,
/// tau_b_y_nm, tau_b_z_nm, tau_m_1_nm … tau_m_7_nm. Forces/torques in the servicer base
/// frame; a row holds from its time until the next row. At least one row; every row's
/// time a multiple of the scenario's control period (to rounding: docs/SIMULATOR.md),
/// increasing.
///
/// TRAJ.csv: one row per control step with the inertial states of both spacecraft
/// (servicer base origin position/velocity, quaternion base→inertial scalar-first, body
/// rate; target likewise), θ, θ̇, Hill-frame relative position/velocity, grasp distance,
/// end-effector and grasping point in the base frame. SI units; see docs/SIMULATOR.md.
///
/// TRAJ.csv is written as TRAJ.csv.incomplete and renamed once complete (a simulation
/// that fails leaves TRAJ.csv.incomplete, never a TRAJ.csv that looks whole).
///
/// Exit codes: 0 the trajectory was written, 2 bad arguments, an unreadable or invalid
/// profile or scenario, or a simulation that failed.
#[derive(clap::Args)]
pub struct Args {
    /// Command profile CSV.
    #[arg(long, value_name = "PROFILE.csv")]
    commands: PathBuf,
    /// Output trajectory CSV.
    #[arg(long, value_name = "TRAJ.csv")]
    out: PathBuf,
    /// Scenario file (initial state, orbit, timing).
    #[arg(long, value_name = "FILE", default_value_os_t = crate::default_scenario())]
    scenario: PathBuf,
    /// Duration [s]; default: the scenario's mission.duration_s.
    #[arg(long)]
    duration: Option<f64>,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let setup = Setup::load(&a.scenario)?;
    let text = std::fs::read_to_string(&a.commands)
        .with_context(|| format!("cannot read {}", a.commands.display()))?;
    let period = setup.scenario.mission.control_period_s;
    let profile = CommandProfile::parse(&text, period)
        .with_context(|| format!("{}", a.commands.display()))?;
    let duration = a.duration.unwrap_or(setup.scenario.mission.duration_s);
    if !(duration.is_finite() && duration >= 0.0) {
        anyhow::bail!("--duration {duration}: must be a finite number >= 0");
    }
    let steps = (duration / period).round() as usize;
    let mut sim = Simulator::new(&setup.scenario, setup.robot.clone())?;
    // written beside it and renamed once complete: a failed simulation never leaves a
    // trajectory that looks whole (the output-folder policy, for one file)
    let mut partial = a.out.clone().into_os_string();
    partial.push(sc_mission::out_dir::INCOMPLETE_SUFFIX);
    let partial = PathBuf::from(partial);
    let file = std::fs::File::create(&partial)
        .with_context(|| format!("cannot create {}", partial.display()))?;
    let mut w = std::io::BufWriter::new(file);
    writeln!(w, "{}", TRAJECTORY_COLUMNS.join(","))?;
    let started = std::time::Instant::now();
    for k in 0..=steps {
        let o = sim.observe();
        let row = sim.trajectory_row();
        let line: Vec<String> = row.values(&o).iter().map(|x| x.to_string()).collect();
        writeln!(w, "{}", line.join(","))?;
        if k == steps {
            break;
        }
        let cmd = profile.at(o.t);
        sim.step(&cmd)
            .with_context(|| format!("simulation failed at t = {} s", o.t))?;
    }
    w.flush()?;
    drop(w);
    std::fs::rename(&partial, &a.out)
        .with_context(|| format!("cannot rename {} to {}", partial.display(), a.out.display()))?;
    errln!(
        "simulated {duration} s ({steps} control steps) in {:.3} s -> {}",
        started.elapsed().as_secs_f64(),
        a.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
