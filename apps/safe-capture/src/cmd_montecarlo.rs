//! `safe-capture montecarlo`: dispersed campaigns, in parallel, sharded, merged, rerun.

use anyhow::Context;
use sc_core::Subsystem;
use sc_ground::PartitionConfig;
use sc_ground::executor::Partition;
use sc_mission::{Execution, Executor, InProcess, RunOptions, TelemetryWriter, summarize};
use sc_montecarlo::interrupt::{EXIT_FORCED, StopOnSignal};
use sc_montecarlo::{CampaignOptions, CampaignSummary, MonteCarloConfig};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Partition config of --mode partition unless --partition-config is given (in the
/// installation).
const DEFAULT_PARTITION_CONFIG: &str = "config/partition.toml";

/// Runs of a new campaign unless --runs is given.
const DEFAULT_RUNS: usize = 100;

/// Seed of a new campaign unless --seed is given.
const DEFAULT_SEED: u64 = 1;

/// Exit code of a campaign stopped by SIGINT/SIGTERM (the completed runs aggregated).
const EXIT_INTERRUPTED: u8 = 3;

// the exit-code table of `--help` (the doc comment of `Args`) names the code of a second
// signal as 130
const _: () = assert!(EXIT_FORCED == 130);

/// Monte Carlo campaign over dispersed initial positions (inside the approach corridor)
/// and target tumbling rates (config/montecarlo.toml). Runs in parallel in one process,
/// or with --mode partition each run through the process partition (one process per
/// module, lock-step; same results as in-process except the solve times); every run's
/// seed derives from (--seed, run index), so shards and reruns reproduce exactly.
///
/// Writes to OUT: runs/K/ (scenario.toml, result.json, trace.csv, timing.json per run),
/// runs.csv, runs_timing.csv, summary.json, report.md, figures/*.svg.
///
/// Ctrl-C (SIGINT) or SIGTERM stops the campaign gracefully: no further run starts, the
/// runs in flight finish (with --mode partition: are torn down and left out), the
/// completed runs are aggregated and summary.json, report.md and the last line say
/// "interrupted after K of N runs"; `--resume --out DIR` then runs the rest (a second
/// signal quits at once; a run is only named runs/K once saved).
/// Every report records the host's load at the start and end (1-minute load average,
/// CPUs).
///
/// Exit codes (a campaign, and `merge`): 0 every run passed as `run` judges one (safe,
/// captured, no fault: README, "Verdicts and exit codes"), 1 a run unsafe, not captured,
/// with faults or failed (a partition run that could not be launched is a failed run), 2 bad arguments or configuration (checked before any run starts; with
/// --resume also a DIR that holds another campaign), 3 interrupted by SIGINT/SIGTERM
/// (the completed runs aggregated; --resume completes the campaign), 130 a second
/// SIGINT/SIGTERM quit at once (in-process; the runs in flight abandoned).
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Args {
    #[command(subcommand)]
    action: Option<Action>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(clap::Subcommand)]
enum Action {
    /// Rerun one run of a campaign from its saved scenario and check that it reproduces
    /// the saved result exactly; writes its telemetry, summary and figures.
    ///
    /// Exit codes: 0 reproduced exactly, 1 it differs from the saved run, 2 bad
    /// arguments or an unreadable campaign.
    Rerun(RerunArgs),
    /// Merge shard directories into one campaign (same outputs as an unsharded run).
    ///
    /// Exit codes: 0 every run safe, captured and without faults, 1 a run unsafe, not
    /// captured, with faults or failed, 2 bad arguments or shards that do not fit together.
    Merge(MergeArgs),
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Mode {
    /// Simulator, nominal controllers and filters in one process.
    InProcess,
    /// Each run through the process partition (one process per module, iceoryx2,
    /// lock-step): the deployed configuration. Results equal in-process runs except the
    /// solve times (with a partition config of one rate group at the control period).
    Partition,
}

#[derive(clap::Args)]
struct RunArgs {
    /// Runs in the whole campaign, at least 1 [default: 100; with --resume the
    /// campaign's].
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    runs: Option<usize>,
    /// Campaign seed [default: 1; with --resume the campaign's].
    #[arg(long)]
    seed: Option<u64>,
    /// Runs at a time (default: all cores in-process; 1 with --mode partition, where a
    /// run is nine processes).
    #[arg(long, short)]
    jobs: Option<usize>,
    #[arg(long, value_name = "DIR", default_value = "out/montecarlo", help = crate::out_help!(" (with --resume: the campaign, completed in place; a campaign stopped by Ctrl-C/SIGTERM is the exception to what follows: its completed runs, aggregated, replace DIR so that --resume completes them there)"))]
    out: PathBuf,
    #[arg(long, conflicts_with = "resume", help = crate::out_folder::FORCE_HELP)]
    force: bool,
    /// Run only shard i of N (0-based): runs k with k mod N = i [with --resume default:
    /// the campaign's].
    #[arg(long, value_name = "i/N")]
    shard: Option<String>,
    /// Base scenario to disperse [default: config/scenario.toml; with --resume the
    /// campaign's base_scenario.toml].
    #[arg(long, value_name = "FILE")]
    scenario: Option<PathBuf>,
    /// Dispersion configuration [default: config/montecarlo.toml; with --resume the
    /// campaign's].
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Where the runs execute [default: in-process; with --resume the campaign's].
    #[arg(long, value_enum)]
    mode: Option<Mode>,
    /// Complete the interrupted campaign in --out: its complete runs that verify against
    /// their re-derivation (seed, dispersion, scenario) are kept, the others run, and the
    /// outputs cover the whole campaign. Options not given are the campaign's; one that
    /// differs from it is refused (exit 2).
    #[arg(long)]
    resume: bool,
    /// With --mode partition: the partition config (schedule, deadlines, executables;
    /// default config/partition.toml). Each run replaces its scenario and runs lock-step
    /// to the end of the mission.
    #[arg(long, value_name = "FILE")]
    partition_config: Option<PathBuf>,
    /// With --mode partition: keep every run's telemetry.csv, timing.csv, recording.mcap
    /// and latency.csv in runs/K/partition/ (several MB per run; removed otherwise).
    #[arg(long)]
    keep_recordings: bool,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
    #[command(flatten)]
    figures: crate::figure_format::FigureFormatArg,
    /// Each run draws its own realisation of the profile, seeded from the run's seed and
    /// saved in its scenario.toml.
    #[command(flatten)]
    uncertainty: crate::uncertainty_arg::UncertaintyArg,

    /// Test hook: make these runs panic (also SC_MONTECARLO_INJECT_PANIC=K,K,...).
    #[arg(long, value_name = "K", value_delimiter = ',', hide = true)]
    inject_panic: Vec<usize>,
}

#[derive(clap::Args)]
struct RerunArgs {
    /// Campaign directory.
    dir: PathBuf,
    /// Run index.
    #[arg(long)]
    run: usize,
    #[arg(long, value_name = "DIR", help = crate::out_help!(" for telemetry, summary and figures (default: DIR/runs/K/rerun)"))]
    out: Option<PathBuf>,
    #[arg(long, help = crate::out_folder::FORCE_HELP)]
    force: bool,
    /// Write no figures.
    #[arg(long)]
    no_figures: bool,
    #[command(flatten)]
    figures: crate::figure_format::FigureFormatArg,
}

/// The arguments of `montecarlo merge` and `redteam merge`.
#[derive(clap::Args)]
pub(crate) struct MergeArgs {
    /// Shard directories.
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    #[arg(long, value_name = "DIR", help = crate::out_help!())]
    pub out: PathBuf,
    #[arg(long, help = crate::out_folder::FORCE_HELP)]
    pub force: bool,
    #[command(flatten)]
    pub figures: crate::figure_format::FigureFormatArg,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    match a.action {
        Some(Action::Rerun(r)) => rerun(r),
        Some(Action::Merge(m)) => {
            let inputs: Vec<&std::path::Path> = m.dirs.iter().map(|d| d.as_path()).collect();
            m.figures.check()?;
            let staged =
                crate::out_folder::stage_reading(&m.out, "montecarlo merge", m.force, &inputs)?;
            let s = sc_montecarlo::merge(&m.dirs, staged.path())?;
            m.figures.export_dir(&staged.path().join("figures"))?;
            staged.commit()?;
            Ok(report(&s, &m.out))
        }
        None => campaign(a.run),
    }
}

/// The campaign's parameters: given, else with --resume those of the campaign in --out,
/// else the defaults.
struct Params {
    runs: usize,
    seed: u64,
    shard: Option<(usize, usize)>,
    scenario: PathBuf,
    config: MonteCarloConfig,
    mode: Mode,
}

fn params(a: &RunArgs) -> anyhow::Result<Params> {
    let shard = a
        .shard
        .as_deref()
        .map(sc_montecarlo::parse_shard)
        .transpose()?;
    let config = a
        .config
        .as_deref()
        .map(MonteCarloConfig::load)
        .transpose()?;
    if !a.resume {
        return Ok(Params {
            runs: a.runs.unwrap_or(DEFAULT_RUNS),
            seed: a.seed.unwrap_or(DEFAULT_SEED),
            shard,
            scenario: a.scenario.clone().unwrap_or_else(crate::default_scenario),
            config: match config {
                Some(c) => c,
                None => {
                    MonteCarloConfig::load(&crate::home::shipped(sc_montecarlo::DEFAULT_CONFIG))?
                }
            },
            mode: a.mode.unwrap_or(Mode::InProcess),
        });
    }
    crate::out_folder::adopt_staging(&a.out, "montecarlo")?;
    let info = sc_montecarlo::campaign_info(&a.out).context("--resume")?;
    Ok(Params {
        runs: a.runs.unwrap_or(info.runs),
        seed: a.seed.unwrap_or(info.seed),
        shard: shard.or(info.shard.map(|[i, n]| (i, n))),
        scenario: a
            .scenario
            .clone()
            .unwrap_or_else(|| a.out.join("base_scenario.toml")),
        config: config.unwrap_or(info.config),
        mode: a.mode.unwrap_or(match info.execution {
            Execution::InProcess => Mode::InProcess,
            Execution::Partition => Mode::Partition,
        }),
    })
}

/// `--mode partition`: the partition's executor, after checking the partition config and
/// that every role's executable exists, before any run starts; and, when the config's
/// schedule is not the scenario's single control period, a note that results will
/// differ from in-process runs.
fn partition_executor(
    config: &Path,
    keep_recordings: bool,
    scenario: &Path,
) -> anyhow::Result<(Partition, Option<String>)> {
    let cfg = PartitionConfig::load(config).context("--partition-config")?;
    let schedule = cfg.schedule().context("--partition-config")?;
    // every role's program, as the launcher will find it (the scenario is the
    // campaign's, checked by the campaign)
    sc_ground::preflight::check_programs(&cfg, &None)
        .map_err(|e| anyhow::anyhow!("--partition-config {}: {e}", config.display()))?;
    let base = sc_scenario::Scenario::load(scenario).ok();
    // the base scenario's tumble inside the envelope at the attitude group's hold, as
    // `launch` checks (each draw's tumble is checked at the control period by the campaign)
    if let Some(s) = &base {
        sc_ground::preflight::held_envelope(&cfg, s)
            .map_err(|e| anyhow::anyhow!("--partition-config {}: {e}", config.display()))?;
    }
    let period = base.map(|s| s.mission.control_period_s);
    let note = match period {
        Some(p) if schedule.period_s.iter().all(|(_, x)| *x == p) => None,
        Some(p) => Some(format!(
            "note: the schedule of {} (periods translational {} s, attitude {} s, robotic {} s) is not the scenario's control period {p} s: results will differ from --mode in-process",
            config.display(),
            schedule.period_s[Subsystem::Translational],
            schedule.period_s[Subsystem::Attitude],
            schedule.period_s[Subsystem::Robotic]
        )),
        None => None, // the campaign reports the scenario's problem
    };
    let executor = Partition::new(config).keep_recordings(keep_recordings);
    Ok((executor, note))
}

fn campaign(a: RunArgs) -> anyhow::Result<ExitCode> {
    a.figures.check()?;
    let p = params(&a)?;
    if p.mode == Mode::InProcess {
        if a.partition_config.is_some() {
            anyhow::bail!("--partition-config needs --mode partition");
        }
        if a.keep_recordings {
            anyhow::bail!("--keep-recordings needs --mode partition");
        }
    }
    let mut inject = a.inject_panic.clone();
    if let Ok(v) = std::env::var("SC_MONTECARLO_INJECT_PANIC") {
        for k in v.split(',').filter(|s| !s.trim().is_empty()) {
            inject.push(k.trim().parse().with_context(|| {
                format!("SC_MONTECARLO_INJECT_PANIC: `{k}` is not a run index")
            })?);
        }
    }
    if !inject.is_empty() {
        // keep the injected panics' messages off the progress bar; they are recorded
        std::panic::set_hook(Box::new(|_| {}));
    }
    let jobs = a.jobs.unwrap_or_else(|| match p.mode {
        Mode::InProcess => std::thread::available_parallelism().map_or(1, |n| n.get()),
        Mode::Partition => 1,
    });
    let executor: Box<dyn Executor> = match p.mode {
        Mode::InProcess => {
            // the partition's launcher handles the signals of --mode partition itself
            sc_montecarlo::interrupt::install()?;
            Box::new(StopOnSignal(InProcess))
        }
        Mode::Partition => {
            let config = a
                .partition_config
                .clone()
                .unwrap_or_else(|| crate::home::shipped(DEFAULT_PARTITION_CONFIG));
            let (executor, note) = partition_executor(&config, a.keep_recordings, &p.scenario)?;
            if let Some(n) = note {
                errln!("{n}");
            }
            Box::new(executor)
        }
    };
    // a new campaign is written apart and replaces --out once aggregated (also when
    // interrupted: --resume then completes it there); --resume completes it in place
    let staged = if a.resume {
        None
    } else {
        Some(crate::out_folder::stage(&a.out, "montecarlo", a.force)?)
    };
    let opts = CampaignOptions {
        scenario: p.scenario,
        config: p.config,
        runs: p.runs,
        seed: p.seed,
        jobs,
        shard: p.shard,
        out: staged
            .as_ref()
            .map_or(a.out.clone(), |s| s.path().to_path_buf()),
        inject_panic: inject,
        progress: !a.quiet,
        resume: a.resume,
        uncertainty: a.uncertainty.spec_per_run()?,
    };
    let s = sc_montecarlo::run_campaign_with(&opts, executor.as_ref())?;
    a.figures.export_dir(&opts.out.join("figures"))?;
    if let Some(staged) = staged {
        staged.commit()?;
    }
    Ok(report(&s, &a.out))
}

fn report(s: &CampaignSummary, out: &std::path::Path) -> ExitCode {
    let worst = s
        .worst
        .iter()
        .filter_map(|(n, w)| w.min_h.map(|h| (n, h, w.run)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    let t = s.solve_time_us.get("total").copied().unwrap_or_default();
    if !s.not_covered.is_empty() {
        outln!(
            "montecarlo: the filters' margins do not cover the declared [{}]: outside the promise, the truth's margins below are measured (docs/SAFETY.md)",
            s.not_covered.join(", ")
        );
    }
    outln!(
        "montecarlo: {} runs{} (seed {}{}): {} safe, {} captured, {} with faults, {} failed; worst margin {}; total solve time geomean {:.1} us, max {:.1} us; wall {:.1} s -> {}",
        s.runs,
        s.shard
            .map(|[i, n]| format!(" of shard {i}/{n}"))
            .unwrap_or_default(),
        s.seed,
        s.uncertainty
            .as_ref()
            .map(|u| format!(", uncertainty {u}: safe on the simulated truth"))
            .unwrap_or_default(),
        s.safe_runs,
        s.captured_runs,
        s.faulted_runs,
        s.failed_runs,
        worst
            .map(|(n, h, r)| format!(
                "{n} = {h:.3e} (run {})",
                r.map_or("-".into(), |r| r.to_string())
            ))
            .unwrap_or_else(|| "-".into()),
        t.geomean,
        t.max,
        s.wall_time_s,
        out.display()
    );
    for f in &s.failed {
        outln!("  run {} failed: {}", f.run, f.error);
    }
    if !s.unsafe_runs.is_empty() {
        outln!("  unsafe runs: {:?}", s.unsafe_runs);
    }
    if !s.not_captured_runs.is_empty() {
        outln!("  runs without capture: {:?}", s.not_captured_runs);
    }
    if !s.faulted.is_empty() {
        outln!(
            "  runs with faults: {:?} (`montecarlo rerun DIR --run K` writes their telemetry)",
            s.faulted
        );
    }
    if let Some(i) = &s.interrupted {
        outln!(
            "  interrupted after {} of {} runs: only those are aggregated; `safe-capture montecarlo --resume --out {}` runs the rest",
            i.completed_runs,
            i.planned_runs,
            out.display()
        );
        return ExitCode::from(EXIT_INTERRUPTED);
    }
    if s.failed_runs == 0
        && s.safe_runs == s.runs
        && s.captured_runs == s.runs
        && s.faulted_runs == 0
    {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

fn rerun(a: RerunArgs) -> anyhow::Result<ExitCode> {
    // a campaign to rerun, and a folder to write, before the run
    sc_montecarlo::campaign_info(&a.dir)?;
    let target = a
        .out
        .clone()
        .unwrap_or_else(|| a.dir.join("runs").join(a.run.to_string()).join("rerun"));
    a.figures.check()?;
    let staged = crate::out_folder::stage_reading(&target, "montecarlo rerun", a.force, &[&a.dir])?;
    let out = staged.path().to_path_buf();
    let r = sc_montecarlo::rerun(&a.dir, a.run)?;
    let open = |name: &str| -> anyhow::Result<std::io::BufWriter<std::fs::File>> {
        let p = out.join(name);
        Ok(std::io::BufWriter::new(
            std::fs::File::create(&p).with_context(|| format!("cannot create {}", p.display()))?,
        ))
    };
    let mut w = TelemetryWriter::new(open("telemetry.csv")?, open("timing.csv")?)?;
    for rec in &r.records {
        w.write(rec)?;
    }
    w.flush()?;
    let phases: Vec<String> = r
        .scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let mut summary = summarize(
        &r.records,
        &r.end,
        &phases,
        !RunOptions::default().no_filter,
    );
    summary.safe_mode = sc_mission::SafeModeSummary::of(&r.records, &r.scenario);
    std::fs::write(
        out.join("summary.json"),
        serde_json::to_string_pretty(&summary)? + "\n",
    )?;
    let mut f = std::fs::File::create(out.join("result.json"))?;
    writeln!(f, "{}", serde_json::to_string_pretty(&r.result)?)?;
    if !a.no_figures {
        sc_plots::run_figures(&out.join("figures"), &r.scenario, &r.records, None)?;
        a.figures.export_dir(&out.join("figures"))?;
    }
    staged.commit()?;
    let out = target;
    let m = r.result.metrics.as_ref();
    outln!(
        "rerun of run {}: {} at t = {:.1} s, safe: {}, -> {}",
        a.run,
        m.map_or("-", |m| m.end.as_str()),
        m.map_or(0.0, |m| m.final_time_s),
        m.is_some_and(|m| m.safe),
        out.display()
    );
    if r.differences.is_empty() {
        outln!("reproduced exactly: seed, dispersion, scenario and result match the saved run");
        Ok(ExitCode::SUCCESS)
    } else {
        for d in &r.differences {
            outln!("  differs: {d}");
        }
        Ok(ExitCode::from(1))
    }
}
