//! `safe-capture redteam`: the red-team campaign against the safety layer.

use anyhow::Context;
use sc_mission::Setup;
use sc_redteam::{Case, Target, report};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;

/// Attacks the safety layer with adversarial nominal controllers and measures the result
/// from the simulator's true state.
///
/// Every case replaces the nominal controller of one subsystem (or all three) by an
/// adversary for the whole mission: bang-bang towards each of the subsystem's barriers
/// (`toward:<barrier>`), towards whichever is nearest (`greedy`), random saturating
/// (`random:<seed>`), non-finite (`nonfinite`), 1e300 and 1000× the bound (`huge`), the
/// first command for ever (`frozen`), commands for a 10-step-old state (`stale`), or nothing
/// (`silent`). Each case runs to capture or the end of the mission; every barrier is
/// evaluated from the true state at every physics step, every applied command is checked
/// for finiteness and bounds.
///
/// Writes to OUT: cases.csv (one line per case), min_h.csv (each case's smallest value of
/// every barrier), summary.json, report.md, figures/redteam_margins.svg.
///
/// Exit codes: 0 every case safe, 1 a case unsafe, 2 bad arguments or configuration.
#[derive(clap::Args)]
pub struct Args {
    /// Scenario file.
    #[arg(long, value_name = "FILE", default_value_os_t = crate::default_scenario())]
    scenario: PathBuf,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR", default_value = "out/redteam")]
    out: PathBuf,
    /// Random strategies per target (`random:1` … `random:N`).
    #[arg(long, value_name = "N", default_value_t = 5)]
    seeds: u64,
    /// Only these targets (translational, attitude, robotic, all; comma-separated).
    #[arg(long, value_name = "T", value_delimiter = ',')]
    target: Vec<String>,
    /// Only these cases, `<target>/<strategy>` (comma-separated), e.g.
    /// `robotic/toward:theta_dot_max_7,all/random:3`.
    #[arg(long, value_name = "CASE", value_delimiter = ',')]
    cases: Vec<String>,
    /// Parallel runs (default: the machine's cores).
    #[arg(long, short, value_name = "N")]
    jobs: Option<usize>,
    /// Print nothing but the final line.
    #[arg(long, short)]
    quiet: bool,
    /// List the cases and exit.
    #[arg(long)]
    list: bool,
}

/// The cases the arguments select.
fn selected(a: &Args) -> anyhow::Result<Vec<Case>> {
    if !a.cases.is_empty() {
        return a
            .cases
            .iter()
            .map(|c| Case::parse(c).map_err(anyhow::Error::msg))
            .collect();
    }
    let targets: Vec<Target> = a
        .target
        .iter()
        .map(|t| {
            Target::parse(t).with_context(|| {
                format!("--target `{t}`: expected translational, attitude, robotic or all")
            })
        })
        .collect::<anyhow::Result<_>>()?;
    Ok(Case::all(a.seeds)
        .into_iter()
        .filter(|c| targets.is_empty() || targets.contains(&c.target))
        .collect())
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let cases = selected(&a)?;
    if a.list {
        for c in &cases {
            println!("{}", c.name());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let setup = Setup::load(&a.scenario)?;
    if let Some(j) = a.jobs {
        rayon::ThreadPoolBuilder::new()
            .num_threads(j.max(1))
            .build_global()
            .context("--jobs")?;
    }
    let started = std::time::Instant::now();
    let tty = std::io::stderr().is_terminal();
    let bar = (!a.quiet && tty).then(|| {
        let b = indicatif::ProgressBar::new(cases.len() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{elapsed_precise} [{bar:40}] {pos}/{len} cases, {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    let unsafe_count = Mutex::new(0usize);
    let results = sc_redteam::run_campaign(&setup, &cases, &|done, total, r| {
        let bad = match r {
            Ok(r) => !r.safe(),
            Err(_) => true,
        };
        let mut u = unsafe_count.lock().unwrap_or_else(|p| p.into_inner());
        if bad {
            *u += 1;
        }
        if let Some(b) = &bar {
            b.set_position(done as u64);
            b.set_message(format!("{} unsafe", *u));
        } else if !a.quiet && (done % 10 == 0 || done == total) {
            eprintln!("redteam: {done}/{total} cases, {} unsafe", *u);
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let wall = started.elapsed().as_secs_f64();
    let s = report::write(&a.out, &setup, &cases, &results, wall).map_err(anyhow::Error::msg)?;
    println!(
        "redteam: {} of {} cases safe{}; non-finite applied {}, out-of-bound applied {}; solve time geomean (worst case) {:.1} us, max {:.0} us; wall {:.1} s -> {}",
        s.safe,
        s.cases,
        if s.unsafe_cases.is_empty() {
            String::new()
        } else {
            format!(" (unsafe: {})", s.unsafe_cases.join(", "))
        },
        s.nonfinite_applied,
        s.out_of_bounds_applied,
        s.solve_time_geomean_max_us,
        s.solve_time_max_us,
        wall,
        a.out.display()
    );
    Ok(if s.safe == s.cases && s.errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
