//! `safe-capture run`: the whole mission in one process.

use anyhow::Context;
use sc_mission::{
    ExecError, Executed, Executor, InProcess, Job, NominalSource, RunOptions, Setup, Sinks,
    StepRecord, TelemetryWriter, summarize,
};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Runs the three-phase mission (final approach, rate synchronisation, capture) in one
/// process: simulator, nominal controllers and the three safety filters in causal order.
///
/// Writes to OUT: telemetry.csv (deterministic, one row per control step: time, phase,
/// states, nominal and safe commands, every barrier value h, filter status and faults),
/// timing.csv (filter solve times), summary.json (captured, capture_time_s, constraints,
/// interventions, solve_time_us, faults; with --uncertainty whether the realised errors
/// stayed within the declared bounds), navigation.csv (with a declared uncertainty only:
/// the realised navigation errors and every barrier on knowledge, `hk_*`, beside the
/// truth's `h_*` in telemetry.csv), and the figures into OUT/figures (SVG): approach
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
    #[command(flatten)]
    uncertainty: crate::uncertainty_arg::UncertaintyArg,
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

    fn source(&self, setup: &Setup) -> NominalSource {
        match self {
            Nominals::Reference => NominalSource::Reference,
            Nominals::RedTeam(c) => sc_redteam::Adversary::nominals(setup, c),
            Nominals::Replay(r) => {
                NominalSource::Override(Box::new(sc_mission::ReplayNominals::new(r)))
            }
        }
    }
}

/// One mission of `run`: what runs, and where its files go.
struct MissionRun<'a> {
    setup: Setup,
    options: RunOptions,
    nominals: NominalSource,
    plant: Option<Box<dyn sc_sim::Plant + Send>>,
    /// Gets telemetry.csv and timing.csv.
    out: &'a Path,
    dump_qp: Option<&'a Path>,
    /// No progress line.
    quiet: bool,
}

/// A new buffered file at `p`.
fn create(p: &Path) -> anyhow::Result<std::io::BufWriter<std::fs::File>> {
    Ok(std::io::BufWriter::new(
        std::fs::File::create(p).with_context(|| format!("cannot create {}", p.display()))?,
    ))
}

/// Mission time between two progress lines [s].
const PROGRESS_EVERY_S: f64 = 10.0;

/// The progress line every [`PROGRESS_EVERY_S`] of mission time: on a terminal one line
/// redrawn in place, in a log one line per report. The phase is named, with its index
/// as telemetry's `phase` column counts (from 0).
/// The first step in safe mode (or outside the envelope undetected) gets a line of its
/// own, at once.
fn progress_printer(
    scenario: &sc_scenario::Scenario,
    phases: Vec<String>,
    tty: bool,
) -> impl FnMut(&StepRecord) + use<> {
    let duration = scenario.mission.duration_s;
    let watch = sc_cbf::safe_mode::EnvelopeWatch::from_scenario(scenario);
    let mut last_print = 0.0;
    let mut safe_mode_said = false;
    move |r: &StepRecord| {
        if !safe_mode_said {
            let entered = sc_mission::SafeModeSummary::with_watch(std::slice::from_ref(r), &watch)
                .filter(|m| m.entered_t_s.is_some() || m.undetected_t_s.is_some());
            if let Some(m) = entered {
                safe_mode_said = true;
                let nl = if tty { "\n" } else { "" };
                errln!("{nl}  t = {:6.1} s  SAFE MODE: {}", r.t, m.line());
            }
        }
        if r.t - last_print >= PROGRESS_EVERY_S {
            last_print = r.t;
            let line = format!(
                "  t = {:6.1} / {duration:.0} s  phase {} {:<20}  grasp distance {:7.3} m",
                r.t,
                r.phase,
                phases.get(r.phase).map(String::as_str).unwrap_or(""),
                r.obs.grasp_distance()
            );
            if tty {
                err!("\r{line}");
            } else {
                errln!("{line}");
            }
        }
    }
}

/// Runs one mission in this process ([`InProcess`]), writing its telemetry (and QPs)
/// as it goes; returns the records and how it ended.
fn run_mission(m: MissionRun<'_>) -> anyhow::Result<Executed> {
    std::fs::create_dir_all(m.out).with_context(|| format!("cannot create {}", m.out.display()))?;
    let mut writer = TelemetryWriter::new(
        create(&m.out.join("telemetry.csv"))?,
        create(&m.out.join("timing.csv"))?,
    )?;
    let mut qp_file = m.dump_qp.map(create).transpose()?;
    let tty = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let mut progress = progress_printer(&m.setup.scenario, phase_names(&m.setup.scenario), tty);
    let mut job = Job::new(m.setup);
    job.options = m.options;
    job.nominals = m.nominals;
    job.plant = m.plant;
    job.sinks = Sinks {
        telemetry: Some(&mut writer),
        dump_qp: qp_file.as_mut().map(|f| f as &mut dyn Write),
        progress: (!m.quiet).then_some(&mut progress as &mut dyn FnMut(&StepRecord)),
    };
    let executed = InProcess.execute(job);
    // the progress line ends once the mission ran (not when it could not start)
    let ran = !matches!(executed, Err(ExecError::Setup(_) | ExecError::Plant(_)));
    if !m.quiet && tty && ran {
        errln!();
    }
    let executed = executed?;
    writer.flush()?;
    if let Some(mut f) = qp_file {
        f.flush()?;
    }
    Ok(executed)
}

/// Basilisk as the plant, a child process (`scripts/basilisk_plant.py`).
fn basilisk(a: &Args) -> anyhow::Result<Box<dyn sc_sim::Plant + Send>> {
    let script = crate::home::shipped("scripts/basilisk_plant.py");
    let args = vec![
        script.display().to_string(),
        "--scenario".to_string(),
        a.scenario.display().to_string(),
    ];
    Ok(Box::new(sc_sim::ProcessPlant::spawn(&a.python, &args)?))
}

/// The names of the scenario's phases.
fn phase_names(scenario: &sc_scenario::Scenario) -> Vec<String> {
    scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect()
}

/// Writes `summary` as `path` (pretty JSON).
fn write_summary(path: &Path, summary: &sc_mission::Summary) -> anyhow::Result<()> {
    std::fs::write(path, serde_json::to_string_pretty(summary)? + "\n")
        .with_context(|| format!("cannot write {}", path.display()))
}

/// What ran, for the final line: "Basilisk plant, red team all/greedy, filtered".
fn what_ran(a: &Args) -> String {
    format!(
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
    )
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let mut setup = Setup::load(&a.scenario)?;
    setup
        .check_before_run(&a.scenario)
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.scenario.display()))?;
    a.uncertainty.apply(&mut setup.scenario)?;
    // the base's clearance from the target, for the mass errors now declared
    setup.check_target_geometry()?;
    if a.basilisk && setup.scenario.uncertainty.is_some() {
        // Basilisk propagates the scenario file's model, not the drawn plant
        anyhow::bail!(
            "--basilisk: the Basilisk plant runs the declared model only; a declared uncertainty (--uncertainty or the scenario's [uncertainty]) runs with the built-in simulator"
        );
    }
    let options = RunOptions {
        no_filter: a.no_filter,
    };
    let started = std::time::Instant::now();
    let scenario = setup.scenario.clone();
    let robot = setup.robot.clone();
    let compare_setup = setup.clone();
    let nominals = Nominals::from_args(&a)?;
    let source = nominals.source(&setup);
    // a new folder replaces an earlier run's as a whole (no stale nominal/ comparison)
    a.figures.check()?;
    let staged = crate::out_folder::stage(&a.out, "run", a.force)?;
    let out = staged.path().to_path_buf();
    let plant = if a.basilisk {
        Some(basilisk(&a)?)
    } else {
        None
    };
    let Executed { records, end } = run_mission(MissionRun {
        setup,
        options,
        nominals: source,
        plant,
        out: &out,
        dump_qp: a.dump_qp.as_deref(),
        quiet: a.quiet,
    })?;
    let knowledge = out.join("navigation.csv");
    sc_mission::record::write_knowledge(&knowledge, &records)
        .with_context(|| format!("cannot write {}", knowledge.display()))?;
    let mut summary = summarize(&records, &end, &phase_names(&scenario), !a.no_filter);
    summary.uncertainty =
        sc_mission::UncertaintySummary::of(&records, &scenario, &robot, !a.no_filter);
    // (without the filters nothing acted on the safe mode: the nominals did)
    summary.safe_mode = (!a.no_filter)
        .then(|| sc_mission::SafeModeSummary::of(&records, &scenario))
        .flatten();
    write_summary(&out.join("summary.json"), &summary)?;
    if !a.no_figures {
        let alone = a.no_filter || a.no_compare || a.basilisk;
        write_figures(&out, &scenario, &records, compare_setup, alone, &nominals)?;
        a.figures.export_dir(&out.join("figures"))?;
    }
    staged.commit()?;
    if let Some(u) = &summary.uncertainty {
        outln!("{}", u.line());
    }
    outln!(
        "{}: {}; total solve time geomean {:.1} us, max {:.1} us; wall {:.2} s -> {}",
        what_ran(&a),
        summary.verdict(),
        summary.solve_time_us["total"].geomean,
        summary.solve_time_us["total"].max,
        started.elapsed().as_secs_f64(),
        a.out.display()
    );
    Ok(if summary.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
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
        // the same nominal (or adversary) without the filters
        let source = nominals.source(&setup);
        let Executed { records, end } = run_mission(MissionRun {
            setup,
            options: RunOptions { no_filter: true },
            nominals: source,
            plant: None,
            out: &dir,
            dump_qp: None,
            quiet: true,
        })?;
        let summary = summarize(&records, &end, &phase_names(scenario), false);
        write_summary(&dir.join("summary.json"), &summary)?;
        Some(records)
    };
    sc_plots::run_figures(&out.join("figures"), scenario, records, nominal.as_deref())?;
    Ok(())
}
