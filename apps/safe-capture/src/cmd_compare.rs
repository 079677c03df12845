//! `safe-capture compare A B`: how far two runs of the same mission part.

use anyhow::Context;
use sc_mission::compare::{LargestDifference, differences, largest};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Compare two runs of the same mission step by step (e.g. `run --basilisk` against
/// `run`, or a partition run against either): the Hill position of the servicer's base,
/// its attitude, the joint angles and the target's attitude at every control step.
///
/// Reads A/telemetry.csv, A/timing.csv and the same in B. Prints the largest differences
/// over the first --window seconds and over the whole run; writes OUT/compare.csv (every
/// step), OUT/compare.json (the largest differences) and OUT/compare.svg (log scale).
///
/// Exit codes: 0 compared (and within --tolerance if given), 1 a difference in the window
/// above --tolerance, 2 unreadable runs or bad arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The first run's directory.
    a: PathBuf,
    /// The second run's directory.
    b: PathBuf,
    /// The window of the first comparison [s].
    #[arg(long, value_name = "S", default_value_t = 60.0)]
    window: f64,
    /// Exit 1 when a difference in the window exceeds this (in m or rad).
    #[arg(long, value_name = "X")]
    tolerance: Option<f64>,
    #[arg(long, value_name = "DIR", help = crate::out_help!(" (default: B/compare)"))]
    out: Option<PathBuf>,
    #[arg(long, help = crate::out_folder::FORCE_HELP)]
    force: bool,
    #[command(flatten)]
    figures: crate::figure_format::FigureFormatArg,
}

fn records(dir: &Path) -> anyhow::Result<Vec<sc_mission::StepRecord>> {
    let read = |name: &str| {
        let p = dir.join(name);
        std::fs::read_to_string(&p).with_context(|| format!("cannot read {}", p.display()))
    };
    sc_mission::parse_telemetry(&read("telemetry.csv")?, &read("timing.csv")?, true)
        .map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))
}

fn line(l: &LargestDifference) -> String {
    format!(
        "Hill position {:.2e} m, attitude {:.2e} rad, joints {:.2e} rad, target attitude {:.2e} rad",
        l.hill_position_m, l.attitude_rad, l.joint_angle_rad, l.target_attitude_rad
    )
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        a.window.is_finite() && a.window > 0.0,
        "--window {}: must be > 0",
        a.window
    );
    let target = a.out.clone().unwrap_or_else(|| a.b.join("compare"));
    a.figures.check()?;
    let staged = crate::out_folder::stage_reading(&target, "compare", a.force, &[&a.a, &a.b])?;
    let out = staged.path().to_path_buf();
    let (ra, rb) = (records(&a.a)?, records(&a.b)?);
    let d = differences(&ra, &rb).map_err(anyhow::Error::msg)?;
    anyhow::ensure!(!d.is_empty(), "no step to compare");
    let (w, all) = (largest(&d, a.window), largest(&d, f64::INFINITY));
    let mut csv =
        String::from("t_s,hill_position_m,attitude_rad,joint_angle_rad,target_attitude_rad\n");
    for x in &d {
        csv += &format!(
            "{:?},{:?},{:?},{:?},{:?}\n",
            x.t, x.hill_position_m, x.attitude_rad, x.joint_angle_rad, x.target_attitude_rad
        );
    }
    std::fs::write(out.join("compare.csv"), csv)?;
    let json = serde_json::json!({
        "a": a.a, "b": a.b, "steps_a": ra.len(), "steps_b": rb.len(),
        "window": w, "whole": all,
    });
    std::fs::write(
        out.join("compare.json"),
        serde_json::to_string_pretty(&json)? + "\n",
    )?;
    sc_plots::difference_figure(
        &out.join("compare.svg"),
        &d,
        &format!("{} against {}", a.b.display(), a.a.display()),
    )?;
    a.figures.export_file(&out.join("compare.svg"))?;
    staged.commit()?;
    let out = target;
    outln!(
        "compare: first {:.1} s ({} steps): {}",
        w.until_s,
        w.steps,
        line(&w)
    );
    outln!(
        "compare: whole run ({} steps of {} and {}): {} -> {}",
        all.steps,
        ra.len(),
        rb.len(),
        line(&all),
        out.display()
    );
    if let Some(tol) = a.tolerance {
        let worst = w
            .hill_position_m
            .max(w.attitude_rad)
            .max(w.joint_angle_rad)
            .max(w.target_attitude_rad);
        // a NaN difference fails too
        let within = matches!(
            worst.partial_cmp(&tol),
            Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
        );
        if !within {
            outln!(
                "compare: {worst:.2e} > tolerance {tol:.2e} in the first {:.1} s",
                w.until_s
            );
            return Ok(ExitCode::from(1));
        }
    }
    Ok(ExitCode::SUCCESS)
}
