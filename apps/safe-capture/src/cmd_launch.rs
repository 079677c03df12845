//! `safe-capture launch`: the mission as a process partition (logic in sc-partition).

use sc_partition::launcher::configured;
use sc_partition::preflight::preflight;
use sc_partition::{ClockMode, LaunchOptions, launch};
use std::path::PathBuf;
use std::process::ExitCode;

/// Runs the mission with every module in its own process (iceoryx2), from
/// config/partition.toml: starts every process, waits for all to be ready, runs
/// the mission, tears everything down. Writes the same telemetry.csv, timing.csv and
/// summary.json as `run`, plus recording.mcap, latency.csv, logs/<role>.log.
///
/// Before anything starts, the config, the scenario it names, every role's program,
/// partner scripts and the simulator's plant program are checked as `safe-capture
/// check` does: a problem is one line naming the role or key, the cause and the fix.
///
/// Exit codes, the mission's verdict: 0 captured safely, 1 the mission ended but not
/// captured safely. The infrastructure's (no mission result): 2 bad configuration or
/// arguments (nothing was started), 3 a process failed (did not start, crashed, was
/// killed or hung) or the run was interrupted, 4 every process ended well but
/// flight-side samples were lost in transport.
#[derive(clap::Args)]
pub struct Args {
    /// Partition config.
    #[arg(long, value_name = "FILE", default_value = "config/partition.toml")]
    config: PathBuf,
    /// Output directory.
    #[arg(long, value_name = "DIR", default_value = "out/partition")]
    out: PathBuf,
    /// Pace ticks on the wall clock instead of lock-step.
    #[arg(long)]
    real_time: bool,
    /// Stop after N ticks (0 = to the end of the mission).
    #[arg(long, value_name = "N")]
    max_ticks: Option<u64>,
    /// Red team: a hostile partner process (scripts/python/hostile_nominal.py) in place
    /// of the nominal controller(s) of a target, `<target>/<strategy>`, e.g.
    /// `attitude/spin:-y+burst:40` or `all/random:1+hang:300` (`safe-capture redteam
    /// --partition --list` lists the campaign's cases).
    #[arg(long, value_name = "CASE")]
    hostile: Option<String>,
    /// --hostile: Python interpreter with the iceoryx2 package (default: $SC_PYTHON,
    /// else scripts/.venv/bin/python).
    #[arg(long, value_name = "PY", default_value_os_t = crate::redteam_partition::default_python())]
    python: PathBuf,
    /// --hostile: the hostile partner script.
    #[arg(
        long,
        value_name = "FILE",
        default_value = "scripts/python/hostile_nominal.py"
    )]
    partner: PathBuf,
}

/// The launcher's codes from this one on are the infrastructure's (a process failed,
/// samples lost): the run is no mission result.
const INFRASTRUCTURE_FAILURE: i32 = 3;

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let mut opts = LaunchOptions {
        config: a.config.clone(),
        out: a.out.clone(),
        clock: a.real_time.then_some(ClockMode::RealTime),
        max_ticks: a.max_ticks,
        ..Default::default()
    };
    let mut partners = None;
    if let Some(h) = &a.hostile {
        let case = crate::redteam_partition::parse_hostile(h)?;
        let cfg = sc_partition::PartitionConfig::load(&a.config)?;
        let p = crate::redteam_partition::Partners::new(
            &a.python,
            &a.partner,
            &a.config,
            &cfg.base_dir.join(&cfg.scenario),
            0,
            None,
            opts.clock.unwrap_or(ClockMode::LockStep),
        )?;
        opts.role_override = p.overrides(&case);
        partners = Some((p, case));
    }
    // nothing starts unless the scenario and every program are there
    let cfg = configured(&opts)?;
    preflight(&cfg, &opts.bin_dir).map_err(|e| anyhow::anyhow!("{}: {e}", a.config.display()))?;
    if let Some((p, case)) = &partners {
        p.check(case)?;
    }
    let rep = launch(&opts)?;
    if rep.code >= INFRASTRUCTURE_FAILURE {
        // no mission result: say why, in one line
        println!(
            "partition: infrastructure failure (exit {}), no mission result: {}; wall {:.2} s -> {}",
            rep.code,
            crate::montecarlo_partition::failure_reason(&rep, &a.out),
            rep.wall_s,
            a.out.display()
        );
        return Ok(ExitCode::from(rep.code.clamp(0, 255) as u8));
    }
    let failed: Vec<String> = rep
        .exits
        .iter()
        .filter(|e| !e.ended_well())
        .map(|e| e.role.clone())
        .collect();
    let summary = std::fs::read_to_string(a.out.join("summary.json"))
        .ok()
        .and_then(|s| serde_json::from_str::<serde_json::Value>(&s).ok());
    println!(
        "partition: {} at t = {} s; {} processes, failed: [{}]; shm leftovers: {}; wall {:.2} s -> {}",
        summary
            .as_ref()
            .and_then(|s| s["end"].as_str().map(String::from))
            .unwrap_or_else(|| "no summary".into()),
        summary
            .as_ref()
            .map(|s| s["final_time_s"].to_string())
            .unwrap_or_default(),
        rep.exits.len(),
        failed.join(", "),
        rep.leftovers.len(),
        rep.wall_s,
        a.out.display()
    );
    Ok(ExitCode::from(rep.code.clamp(0, 255) as u8))
}
