//! `safe-capture bench filters`: per-filter and total safety-layer solve time over whole
//! default missions, as geometric mean and percentiles.

use sc_mission::summary::TimeStats;
use sc_mission::{Mission, RunOptions, Setup};
use std::path::PathBuf;
use std::process::ExitCode;

/// Runs the mission REPEAT times in one process and reports the solve time of each filter
/// and of the whole safety layer per control step (µs): N, geomean, p50, p90, p99, p99.9, max.
/// Also the simulator's wall time per mission.
#[derive(clap::Args)]
pub struct Args {
    /// Scenario file.
    #[arg(long, value_name = "FILE", default_value_os_t = crate::default_scenario())]
    scenario: PathBuf,
    /// Number of missions.
    #[arg(long, default_value_t = 5)]
    repeat: usize,
    /// Write the report as JSON to FILE as well.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

fn pct(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    sorted[((p / 100.0 * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1]
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let setup = Setup::load(&a.scenario)?;
    let mut times: [Vec<f64>; 4] = Default::default();
    let mut mission_wall = Vec::new();
    for k in 0..a.repeat.max(1) {
        let started = std::time::Instant::now();
        let mut m = Mission::new(setup.clone(), RunOptions::default())?;
        m.run(|_, r| {
            let t = r.solve_time_us();
            for i in 0..4 {
                times[i].push(t[i]);
            }
        });
        mission_wall.push(started.elapsed().as_secs_f64());
        eprint!("\r  mission {}/{}", k + 1, a.repeat.max(1));
    }
    eprintln!();
    let names = ["translational", "attitude", "robotic", "total"];
    let mut report = serde_json::Map::new();
    println!(
        "safety-layer solve time per control step [us] ({} missions)",
        a.repeat.max(1)
    );
    println!(
        "{:<14} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "filter", "N", "geomean", "p50", "p90", "p99", "p99.9", "max"
    );
    for (i, n) in names.iter().enumerate() {
        let mut v = times[i].clone();
        v.sort_by(f64::total_cmp);
        let g = TimeStats::of(&v).geomean;
        let row = [
            g,
            pct(&v, 50.0),
            pct(&v, 90.0),
            pct(&v, 99.0),
            pct(&v, 99.9),
            pct(&v, 100.0),
        ];
        println!(
            "{:<14} {:>7} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2}",
            n,
            v.len(),
            row[0],
            row[1],
            row[2],
            row[3],
            row[4],
            row[5]
        );
        report.insert(
            n.to_string(),
            serde_json::json!({"n": v.len(), "geomean": row[0], "p50": row[1], "p90": row[2], "p99": row[3], "p99_9": row[4], "max": row[5]}),
        );
    }
    let mean_wall = mission_wall.iter().sum::<f64>() / mission_wall.len() as f64;
    println!("whole mission (simulator + nominal + filters) wall time: mean {mean_wall:.3} s");
    report.insert("mission_wall_s".into(), serde_json::json!(mission_wall));
    if let Some(p) = a.json {
        std::fs::write(&p, serde_json::to_string_pretty(&report)?)?;
    }
    Ok(ExitCode::SUCCESS)
}
