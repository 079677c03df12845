//! `safe-capture run`: the whole mission in one process.

use anyhow::Context;
use sc_mission::{Mission, MissionEnd, RunOptions, Setup, StepRecord, TelemetryWriter, summarize};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Runs the three-phase mission (final approach, rate synchronisation, capture) in one
/// process: simulator, nominal controllers and the three safety filters in causal order.
///
/// Writes to OUT: telemetry.csv (deterministic, one row per control step: time, phase,
/// states, nominal and safe commands, every barrier value h, filter status and faults),
/// timing.csv (filter solve times), summary.json (captured, capture_time_s, constraints,
/// interventions, solve_time_us, faults), and the figures into OUT/figures (SVG): approach
/// trajectory with corridor and sphere, every barrier over time, range rate, sync error,
/// joint torques, line of sight. The figures compare with a nominal-only run (dashed),
/// which is run too and written to OUT/nominal (skip with --no-compare).
///
/// Exit code 0 when the run was safe (every barrier ≥ 0, no fault) and captured, 1
/// otherwise, 2 bad arguments or configuration (nothing was run).
#[derive(clap::Args)]
pub struct Args {
    /// Scenario file.
    #[arg(long, value_name = "FILE", default_value_os_t = crate::default_scenario())]
    scenario: PathBuf,
    #[arg(long, value_name = "DIR", default_value = "out/run", help = crate::out_help!())]
    out: PathBuf,
    #[arg(long, help = crate::out_folder::FORCE_HELP)]
    force: bool,
    /// Apply the nominal commands alone (saturated to the actuator bounds); the filters
    /// still evaluate every barrier so the summary shows what the nominal violates.
    #[arg(long)]
    no_filter: bool,
    /// Write every QP (P, q, A, b, bounds, solution) as JSON lines to FILE.
    #[arg(long, value_name = "FILE")]
    dump_qp: Option<PathBuf>,
    /// Print nothing but the final line.
    #[arg(long, short)]
    quiet: bool,
    /// Do not run the nominal-only comparison (figures then show the run alone).
    #[arg(long)]
    no_compare: bool,
    /// Write no figures.
    #[arg(long)]
    no_figures: bool,
    #[command(flatten)]
    figures: crate::figure_format::FigureFormatArg,
    /// Replace nominal controllers by a red-team adversary, `<target>/<strategy>`
    /// (`safe-capture redteam --list` lists them), e.g. `all/random:3` or
    /// `robotic/toward:theta_dot_max_7`.
    #[arg(long, value_name = "CASE", conflicts_with = "replay_nominals")]
    redteam: Option<String>,
    /// Feed the filters the nominal commands a recorded run's filters received (DIR holds
    /// its telemetry.csv and timing.csv, e.g. a partition run or a red-team case's
    /// `cases/<case>/`): with the same scenario the run is recomputed exactly, in one
    /// process.
    #[arg(long, value_name = "DIR")]
    replay_nominals: Option<PathBuf>,
    /// Basilisk propagates the true state instead of our simulator (a child process,
    /// scripts/basilisk_plant.py; needs `scripts/setup.sh --with-basilisk`): everything
    /// else — filters, nominal controllers, barrier monitor, outputs — is this process's.
    /// Implies --no-compare. docs/SIMULATOR.md, "Basilisk in the loop".
    #[arg(long)]
    basilisk: bool,
    /// --basilisk: the Python interpreter with Basilisk (default: $SC_PYTHON, else
    /// scripts/.venv/bin/python).
    #[arg(long, value_name = "PY", default_value_os_t = crate::redteam_partition::default_python())]
    python: PathBuf,
}

/// Where the run's nominal commands come from.
#[derive(Clone)]
enum Nominals {
    Reference,
    RedTeam(sc_redteam::Case),
    Replay(std::sync::Arc<Vec<StepRecord>>),
}

impl Nominals {
    fn from_args(a: &Args) -> anyhow::Result<Self> {
        if let Some(c) = &a.redteam {
            return sc_redteam::Case::parse(c)
                .map(Nominals::RedTeam)
                .map_err(|e| anyhow::anyhow!("--redteam: {e}"));
        }
        if let Some(dir) = &a.replay_nominals {
            let read = |name: &str| {
                let p = dir.join(name);
                std::fs::read_to_string(&p)
                    .with_context(|| format!("--replay-nominals: cannot read {}", p.display()))
            };
            let records =
                sc_mission::parse_telemetry(&read("telemetry.csv")?, &read("timing.csv")?, true)
                    .map_err(|e| anyhow::anyhow!("--replay-nominals {}: {e}", dir.display()))?;
            return Ok(Nominals::Replay(std::sync::Arc::new(records)));
        }
        Ok(Nominals::Reference)
    }

    fn source(&self, setup: &Setup) -> Option<Box<dyn sc_mission::NominalOverride>> {
        match self {
            Nominals::Reference => None,
            Nominals::RedTeam(c) => Some(adversary(setup, *c)),
            Nominals::Replay(r) => Some(Box::new(sc_mission::ReplayNominals::new(r))),
        }
    }
}

/// Runs one mission, writing telemetry into `out`; returns the records and how it ended.
pub fn run_mission(
    setup: Setup,
    options: RunOptions,
    out: &Path,
    dump_qp: Option<&Path>,
    quiet: bool,
    nominal_override: Option<Box<dyn sc_mission::NominalOverride>>,
    plant: Option<Box<dyn sc_sim::Plant + Send>>,
) -> anyhow::Result<(Vec<StepRecord>, MissionEnd)> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let open = |name: &str| -> anyhow::Result<std::io::BufWriter<std::fs::File>> {
        let p = out.join(name);
        Ok(std::io::BufWriter::new(
            std::fs::File::create(&p).with_context(|| format!("cannot create {}", p.display()))?,
        ))
    };
    let mut writer = TelemetryWriter::new(open("telemetry.csv")?, open("timing.csv")?)?;
    let mut qp_file = match dump_qp {
        Some(p) => Some(std::io::BufWriter::new(
            std::fs::File::create(p).with_context(|| format!("cannot create {}", p.display()))?,
        )),
        None => None,
    };
    let duration = setup.scenario.mission.duration_s;
    let mut mission = Mission::new(setup, options)?;
    mission.nominal_override = nominal_override;
    if let Some(p) = plant {
        mission.set_plant(p).map_err(anyhow::Error::msg)?;
    }
    let mut records = Vec::new();
    let mut io_err: Option<std::io::Error> = None;
    let mut last_print = 0.0;
    // a terminal gets one line redrawn in place; a log gets one line per report
    let tty = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let end = mission.run(|m, r| {
        if let Err(e) = writer.write(r) {
            io_err.get_or_insert(e);
        }
        if let Some(f) = qp_file.as_mut() {
            let q = m.last_qps();
            for (name, d) in [
                ("translational", &q.translational),
                ("attitude", &q.attitude),
                ("robotic", &q.robotic),
            ] {
                let line = serde_json::json!({"step": r.step, "t_s": r.t, "filter": name, "qp": d});
                if let Err(e) = writeln!(f, "{line}") {
                    io_err.get_or_insert(e);
                }
            }
        }
        if !quiet && r.t - last_print >= 10.0 {
            last_print = r.t;
            let line = format!(
                "  t = {:6.1} / {duration:.0} s  phase {}  grasp distance {:7.3} m",
                r.t,
                r.phase + 1,
                r.obs.grasp_distance()
            );
            if tty {
                err!("\r{line}");
            } else {
                errln!("{line}");
            }
        }
        records.push(*r);
    });
    if !quiet && tty {
        errln!();
    }
    if let Some(e) = io_err {
        return Err(e).context("writing telemetry");
    }
    writer.flush()?;
    if let Some(mut f) = qp_file {
        f.flush()?;
    }
    Ok((records, end))
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let setup = Setup::load(&a.scenario)?;
    let phase_names: Vec<String> = setup
        .scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let options = RunOptions {
        no_filter: a.no_filter,
    };
    let started = std::time::Instant::now();
    let scenario = setup.scenario.clone();
    let compare_setup = setup.clone();
    let nominals = Nominals::from_args(&a)?;
    let source = nominals.source(&setup);
    // a new folder replaces an earlier run's as a whole (no stale nominal/ comparison)
    a.figures.check()?;
    let staged = crate::out_folder::stage(&a.out, "run", a.force)?;
    let out = staged.path().to_path_buf();
    let plant: Option<Box<dyn sc_sim::Plant + Send>> = if a.basilisk {
        let script = crate::home::shipped("scripts/basilisk_plant.py");
        let args = vec![
            script.display().to_string(),
            "--scenario".to_string(),
            a.scenario.display().to_string(),
        ];
        Some(Box::new(sc_sim::ProcessPlant::spawn(&a.python, &args)?))
    } else {
        None
    };
    let (records, end) = run_mission(
        setup,
        options,
        &out,
        a.dump_qp.as_deref(),
        a.quiet,
        source,
        plant,
    )?;
    let summary = summarize(&records, &end, &phase_names, !a.no_filter);
    let path = out.join("summary.json");
    std::fs::write(&path, serde_json::to_string_pretty(&summary)? + "\n")
        .with_context(|| format!("cannot write {}", path.display()))?;
    if !a.no_figures {
        write_figures(
            &out,
            &scenario,
            &records,
            compare_setup,
            a.no_filter || a.no_compare || a.basilisk,
            &nominals,
        )?;
        a.figures.export_dir(&out.join("figures"))?;
    }
    staged.commit()?;
    let safe = summary.violated_constraints.is_empty() && summary.fault_count == 0;
    let what = format!(
        "{}{}{}",
        if a.basilisk { "Basilisk plant, " } else { "" },
        match (&a.redteam, &a.replay_nominals) {
            (Some(c), _) => format!("red team {c}, "),
            (None, Some(d)) => format!("replay of {}, ", d.display()),
            _ => String::new(),
        },
        if a.no_filter {
            "nominal only"
        } else {
            "filtered"
        }
    );
    outln!(
        "{what}: {} at t = {:.1} s; min margin {} = {:.3e}; violated: [{}]; faults: {}; total solve time geomean {:.1} us, max {:.1} us; wall {:.2} s -> {}",
        summary.end,
        summary.final_time_s,
        summary.min_margin.0,
        summary.min_margin.1,
        summary.violated_constraints.join(", "),
        summary.fault_count,
        summary.solve_time_us["total"].geomean,
        summary.solve_time_us["total"].max,
        started.elapsed().as_secs_f64(),
        a.out.display()
    );
    Ok(if safe && summary.captured {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// A red-team adversary for `case` in `setup`'s scenario.
pub(crate) fn adversary(
    setup: &Setup,
    case: sc_redteam::Case,
) -> Box<dyn sc_mission::NominalOverride> {
    Box::new(sc_redteam::Adversary::new(
        &setup.scenario,
        setup.robot.clone(),
        case.target,
        case.strategy,
    ))
}

/// Writes the run's figures into `out/figures`; unless `alone`, first runs the nominal
/// controllers alone into `out/nominal` and draws that run dashed.
fn write_figures(
    out: &Path,
    scenario: &sc_scenario::Scenario,
    records: &[StepRecord],
    setup: Setup,
    alone: bool,
    nominals: &Nominals,
) -> anyhow::Result<()> {
    let nominal = if alone {
        None
    } else {
        let dir = out.join("nominal");
        let phase_names: Vec<String> = scenario
            .mission
            .phases
            .iter()
            .map(|p| p.name.clone())
            .collect();
        // the same nominal (or adversary) without the filters
        let source = nominals.source(&setup);
        let (recs, end) = run_mission(
            setup,
            RunOptions { no_filter: true },
            &dir,
            None,
            true,
            source,
            None,
        )?;
        let summary = summarize(&recs, &end, &phase_names, false);
        let path = dir.join("summary.json");
        std::fs::write(&path, serde_json::to_string_pretty(&summary)? + "\n")
            .with_context(|| format!("cannot write {}", path.display()))?;
        Some(recs)
    };
    sc_plots::run_figures(&out.join("figures"), scenario, records, nominal.as_deref())?;
    Ok(())
}
