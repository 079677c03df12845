//! Campaigns: run all runs or a shard, each run's mission through an
//! [`sc_mission::Executor`] (in this process, or through the process partition); the
//! directory is then aggregated ([`crate::aggregate`]), and can be resumed
//! ([`crate::resume`]), merged or rerun ([`crate::merge`]).
//!
//! Layout of a campaign directory:
//!
//! ```text
//! campaign.json        seed, number of runs, shard, dispersion config   (deterministic)
//! base_scenario.toml   the scenario that was dispersed                   (deterministic)
//! montecarlo.toml      the dispersion config                             (deterministic)
//! <urdf>               copy of the servicer URDF the scenarios name
//! runs/K/scenario.toml the dispersed scenario of run K                   (deterministic)
//! runs/K/result.json   seed, dispersion, metrics or failure of run K     (deterministic)
//! runs/K/trace.csv     decimated trajectory for the figures              (deterministic)
//! runs/K/timing.json   solve-time statistics and histograms             (wall clock)
//! runs/K.partial/      a run being written (renamed to runs/K once saved; ignored)
//! runs.csv             one row per run                                   (deterministic)
//! runs_timing.csv      per-run solve-time geomean and max per filter     (wall clock)
//! summary.json         counts, worst barriers, ranges; solve_time_us and wall_time_s are wall clock
//! report.md            our numbers beside the paper's                    (wall clock)
//! figures/*.svg        campaign figures; runtime.svg is wall clock
//! ```
//!
//! Everything is (re)built from the files by [`aggregate`](crate::aggregate::aggregate), so an unsharded campaign and
//! the merge of its shards produce byte-identical deterministic files. A run's directory
//! gets its name `runs/K` only once its files are written, so an interrupted or killed
//! campaign leaves no run that looks complete and is not; `--resume`
//! ([`CampaignOptions::resume`]) verifies the complete runs against their re-derivation,
//! runs the others, and the result equals the uninterrupted campaign's.

use crate::aggregate::{CampaignSummary, Sessions, aggregate};
use crate::config::MonteCarloConfig;
use crate::host::{HostLoad, HostSample};
use crate::resume::{check_resume, earlier_sessions, runs_to_resume};
use crate::run::{self, CampaignBase};
use rayon::prelude::*;
use sc_mission::{Execution, Executor, InProcess, Setup};
use sc_scenario::Scenario;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Why a campaign could not run. One line each.
#[derive(Debug, thiserror::Error)]
pub enum McError {
    #[error("{0}")]
    Config(#[from] crate::config::ConfigError),
    #[error("{0}")]
    Setup(String),
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Sample(#[from] crate::sample::SampleError),
    #[error(transparent)]
    Exec(#[from] sc_mission::ExecError),
}

pub(crate) fn io(path: &Path) -> impl Fn(std::io::Error) -> McError + '_ {
    move |e| McError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

pub(crate) fn read(path: &Path) -> Result<String, McError> {
    std::fs::read_to_string(path).map_err(io(path))
}

pub(crate) fn write(path: &Path, text: impl AsRef<[u8]>) -> Result<(), McError> {
    std::fs::write(path, text).map_err(io(path))
}

pub(crate) fn json<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T, McError> {
    serde_json::from_str(&read(path)?).map_err(|e| McError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

/// `campaign.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignInfo {
    pub seed: u64,
    /// Runs of the whole campaign.
    pub runs: usize,
    /// `[i, n]` for shard i of n (0-based), absent for a whole or merged campaign.
    pub shard: Option<[usize; 2]>,
    /// File name of the URDF copy.
    pub urdf: String,
    pub config: MonteCarloConfig,
    /// How the runs executed (absent: in-process).
    #[serde(default, skip_serializing_if = "Execution::is_in_process")]
    pub execution: Execution,
    /// The build that ran the campaign (version and git commit): `--resume` and `merge`
    /// refuse to mix runs of different builds. Absent in campaigns of earlier versions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub build: Option<sc_mission::build::BuildInfo>,
    /// The declared uncertainty profile every run drew its realisation from
    /// (docs/UNCERTAINTY.md; absent: `exact`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<String>,
    /// The declared error sources no filter margin covers (`sc_cbf::coverage`): outside
    /// the promise even within their bounds.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_covered: Vec<String>,
}

/// How a campaign is run.
#[derive(Debug, Clone)]
pub struct CampaignOptions {
    pub scenario: PathBuf,
    pub config: MonteCarloConfig,
    pub runs: usize,
    pub seed: u64,
    /// Worker threads (≥ 1).
    pub jobs: usize,
    pub shard: Option<(usize, usize)>,
    pub out: PathBuf,
    /// Runs that panic on purpose (failure-handling tests).
    pub inject_panic: Vec<usize>,
    /// Show the progress bar on stderr.
    pub progress: bool,
    /// Complete the (interrupted) campaign already in `out` instead of starting anew:
    /// its runs that are complete and verified are kept, the others run. Refused when
    /// `out` holds another campaign (seed, runs, shard, config, base scenario, URDF or
    /// execution differ).
    pub resume: bool,
    /// The declared uncertainty (`--uncertainty`), replacing the base scenario's
    /// `[uncertainty]` section; every run draws its own realisation
    /// ([`crate::run::run_scenario`]).
    pub uncertainty: Option<sc_scenario::UncertaintySpec>,
}

/// Why a shard `i/N` was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShardError {
    #[error("shard `{0}`: expected i/N, e.g. 0/4")]
    Form(String),
    #[error("shard `{shard}`: `{part}` is not a number")]
    NotANumber { shard: String, part: String },
    #[error("shard `{0}`: needs 0 <= i < N")]
    Range(String),
}

/// Parses `i/N` (0 ≤ i < N).
pub fn parse_shard(s: &str) -> Result<(usize, usize), ShardError> {
    let (i, n) = s.split_once('/').ok_or(ShardError::Form(s.into()))?;
    let number = |part: &str| {
        part.trim()
            .parse::<usize>()
            .map_err(|_| ShardError::NotANumber {
                shard: s.into(),
                part: part.into(),
            })
    };
    let (i, n) = (number(i)?, number(n)?);
    if n == 0 || i >= n {
        return Err(ShardError::Range(s.into()));
    }
    Ok((i, n))
}

/// The run indices of shard `(i, n)` of a campaign of `runs`: every n-th from i.
pub fn shard_runs(runs: usize, shard: Option<(usize, usize)>) -> Vec<usize> {
    match shard {
        None => (0..runs).collect(),
        Some((i, n)) => (0..runs).filter(|k| k % n == i).collect(),
    }
}

/// Loads the base scenario and checks the config against it.
fn load_base(opts: &CampaignOptions) -> Result<Setup, McError> {
    let mut setup = Setup::load(&opts.scenario)
        .and_then(|s| s.check_envelope_bounds(&opts.scenario).map(|()| s))
        .map_err(|e| McError::Setup(e.to_string()))?;
    if let Some(spec) = &opts.uncertainty {
        let s = &mut setup.scenario;
        s.set_uncertainty(spec.clone())
            .and_then(|()| s.validate())
            .map_err(|e| McError::Setup(format!("--uncertainty: {e}")))?;
        // the base's clearance from the target, for the mass errors now declared
        setup
            .check_target_geometry()
            .map_err(|e| McError::Setup(format!("--uncertainty: {e}")))?;
    }
    opts.config.check_against(&setup.scenario)?;
    Ok(setup)
}

/// What [`aggregate`] writes into a campaign directory besides the figures: removed with
/// an old campaign's runs, so that they never describe runs of another campaign.
const AGGREGATE_FILES: [&str; 4] = ["summary.json", "report.md", "runs.csv", "runs_timing.csv"];

/// Suffix of a run's directory while it is being written (`runs/K.partial`).
pub(crate) const PARTIAL_SUFFIX: &str = ".partial";

/// Creates `out` for a new campaign: refuses a non-empty directory that is not a campaign,
/// clears the runs, figures and aggregated files of an old one. (The command line writes
/// a new campaign into a fresh folder that holds only the marker of the output-folder
/// policy, [`sc_mission::out_dir`].)
pub(crate) fn prepare_out(out: &Path) -> Result<(), McError> {
    if out.exists() {
        let empty = std::fs::read_dir(out)
            .map_err(io(out))?
            .flatten()
            .all(|e| e.file_name() == sc_mission::out_dir::MARKER);
        if !empty && !out.join("campaign.json").is_file() {
            return Err(McError::Invalid(format!(
                "{} is not empty and holds no campaign.json; choose another --out",
                out.display()
            )));
        }
        for sub in ["runs", "figures"] {
            let p = out.join(sub);
            if p.exists() {
                std::fs::remove_dir_all(&p).map_err(io(&p))?;
            }
        }
        for f in AGGREGATE_FILES {
            let p = out.join(f);
            if p.is_file() {
                std::fs::remove_file(&p).map_err(io(&p))?;
            }
        }
    }
    std::fs::create_dir_all(out.join("runs")).map_err(io(out))
}

/// The URDF's bytes and the text of `base_scenario.toml` a campaign of `setup` saves.
fn base_files(setup: &Setup, info: &CampaignInfo) -> Result<(Vec<u8>, String), McError> {
    let urdf = setup.scenario.urdf_path();
    let urdf_bytes = std::fs::read(&urdf).map_err(io(&urdf))?;
    let mut base = setup.scenario.clone();
    base.servicer.urdf = PathBuf::from(&info.urdf);
    Ok((urdf_bytes, base.to_toml_string()))
}

/// Reads `campaign.json` of the campaign in `dir`.
pub fn campaign_info(dir: &Path) -> Result<CampaignInfo, McError> {
    let p = dir.join("campaign.json");
    if !p.is_file() {
        return Err(McError::Invalid(format!(
            "{} holds no campaign (no campaign.json)",
            dir.display()
        )));
    }
    json(&p)
}

/// Writes a campaign's base files into `out`: the URDF copy, `base_scenario.toml`,
/// `montecarlo.toml` and `campaign.json`.
pub(crate) fn write_base_files(
    out: &Path,
    info: &CampaignInfo,
    urdf_bytes: &[u8],
    text: &str,
) -> Result<(), McError> {
    write(&out.join(&info.urdf), urdf_bytes)?;
    write(&out.join("base_scenario.toml"), text)?;
    let cfg = toml::to_string(&info.config).map_err(|e| McError::Invalid(e.to_string()))?;
    write(&out.join("montecarlo.toml"), cfg)?;
    let info_json =
        serde_json::to_string_pretty(info).map_err(|e| McError::Invalid(e.to_string()))?;
    write(&out.join("campaign.json"), info_json + "\n")
}

/// Writes the campaign's base files into `out` and returns the base every run shares.
fn write_base(
    out: &Path,
    info: &CampaignInfo,
    urdf_bytes: &[u8],
    text: &str,
) -> Result<CampaignBase, McError> {
    write_base_files(out, info, urdf_bytes, text)?;
    load_campaign_base(out)
}

/// Reads the base of the campaign in `dir` (campaign.json, base_scenario.toml, URDF).
pub fn load_campaign_base(dir: &Path) -> Result<CampaignBase, McError> {
    let info: CampaignInfo = json(&dir.join("campaign.json"))?;
    info.config.validate()?;
    let text = read(&dir.join("base_scenario.toml"))?;
    let scenario = Scenario::from_toml_str(&text, dir).map_err(|e| {
        McError::Setup(format!("{}: {e}", dir.join("base_scenario.toml").display()))
    })?;
    let setup =
        Setup::from_scenario(scenario.clone()).map_err(|e| McError::Setup(e.to_string()))?;
    Ok(CampaignBase {
        scenario,
        setup,
        config: info.config,
        seed: info.seed,
        urdf_name: info.urdf,
    })
}

pub(crate) fn run_dir(dir: &Path, k: usize) -> PathBuf {
    dir.join("runs").join(k.to_string())
}

/// Where run `k` is written before it gets its name [`run_dir`].
fn partial_dir(dir: &Path, k: usize) -> PathBuf {
    dir.join("runs").join(format!("{k}{PARTIAL_SUFFIX}"))
}

/// Runs a campaign (or one shard) in this process into `opts.out` and aggregates it.
pub fn run_campaign(opts: &CampaignOptions) -> Result<CampaignSummary, McError> {
    run_campaign_with(opts, &InProcess)
}

/// `campaign.json` of the campaign `opts` describe, of `setup`, run by `executor`.
fn info_of(opts: &CampaignOptions, setup: &Setup, executor: &dyn Executor) -> CampaignInfo {
    let urdf = setup
        .scenario
        .urdf_path()
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "servicer.urdf".into());
    CampaignInfo {
        seed: opts.seed,
        runs: opts.runs,
        shard: opts.shard.map(|(i, n)| [i, n]),
        urdf,
        config: opts.config.clone(),
        execution: executor.execution(),
        build: Some(sc_mission::build::current()),
        uncertainty: setup
            .scenario
            .uncertainty
            .as_ref()
            .map(|u| u.profile.clone()),
        not_covered: sc_cbf::coverage::not_covered_in(&setup.scenario, true),
    }
}

/// A campaign about to run: its base, the runs to do, and what its earlier sessions
/// (before a resume) took.
struct Start {
    base: CampaignBase,
    todo: Vec<usize>,
    earlier_wall_s: f64,
    host_load: Vec<HostLoad>,
}

/// Writes a new campaign's base files into `opts.out`, or checks and prepares the
/// campaign there for a resume.
fn start(
    opts: &CampaignOptions,
    info: &CampaignInfo,
    setup: &Setup,
    indices: &[usize],
) -> Result<Start, McError> {
    let (urdf_bytes, base_text) = base_files(setup, info)?;
    if !opts.resume {
        prepare_out(&opts.out)?;
        return Ok(Start {
            base: write_base(&opts.out, info, &urdf_bytes, &base_text)?,
            todo: indices.to_vec(),
            earlier_wall_s: 0.0,
            host_load: Vec::new(),
        });
    }
    check_resume(&opts.out, info, &urdf_bytes, &base_text)?;
    let base = load_campaign_base(&opts.out)?;
    let todo = runs_to_resume(&opts.out, &base, indices)?;
    let (earlier_wall_s, host_load) = earlier_sessions(&opts.out);
    Ok(Start {
        base,
        todo,
        earlier_wall_s,
        host_load,
    })
}

/// The progress bar of `runs` runs on stderr (hidden without `opts.progress`).
fn progress_bar(opts: &CampaignOptions, runs: usize) -> indicatif::ProgressBar {
    let bar = if opts.progress {
        indicatif::ProgressBar::new(runs as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:30}] {pos}/{len} runs, {msg}, ETA {eta}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    bar.set_message("0 failed");
    bar
}

/// The runs of one session, on `opts.jobs` threads, counted on a progress bar.
struct Session<'a> {
    opts: &'a CampaignOptions,
    base: &'a CampaignBase,
    executor: &'a dyn Executor,
    failed: AtomicUsize,
    bar: indicatif::ProgressBar,
}

impl Session<'_> {
    /// Runs run `k` into `runs/K.partial`, saves it and names it `runs/K`; a run the
    /// executor cut short leaves no trace. The error of a run that could not be saved.
    fn run(&self, k: usize) -> Option<McError> {
        if self.executor.stopped() {
            return None;
        }
        let (dir, partial) = (run_dir(&self.opts.out, k), partial_dir(&self.opts.out, k));
        if partial.exists()
            && let Err(e) = std::fs::remove_dir_all(&partial)
        {
            return Some(io(&partial)(e));
        }
        let inject = self.opts.inject_panic.contains(&k);
        let out = run::execute_with(self.base, k, &partial, inject, self.executor);
        if out.result.failed() && self.executor.stopped() {
            // cut short, not a result of the run: leave no trace of it
            return partial
                .exists()
                .then(|| {
                    std::fs::remove_dir_all(&partial)
                        .map_err(io(&partial))
                        .err()
                })
                .flatten();
        }
        if out.result.failed() {
            self.failed.fetch_add(1, Ordering::Relaxed);
        }
        let saved = run::save(&out, &partial)
            .map_err(io(&partial))
            .and_then(|_| std::fs::rename(&partial, &dir).map_err(io(&dir)))
            .err();
        self.bar.inc(1);
        let failed = self.failed.load(Ordering::Relaxed);
        self.bar.set_message(format!("{failed} failed"));
        saved
    }

    /// Runs `todo` in parallel; the first run that could not be saved.
    fn run_all(&self, todo: &[usize]) -> Result<(), McError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.opts.jobs)
            .build()
            .map_err(|e| {
                McError::Invalid(format!("cannot start {} threads: {e}", self.opts.jobs))
            })?;
        let save_errors: Vec<McError> =
            pool.install(|| todo.par_iter().filter_map(|&k| self.run(k)).collect());
        self.bar.finish_and_clear();
        save_errors.into_iter().next().map_or(Ok(()), Err)
    }
}

/// [`run_campaign`] with every run's mission executed by `executor` (on `opts.jobs`
/// threads). If the executor stops (Ctrl-C), no further run starts, the runs in flight
/// finish (a run the executor cut short leaves no trace), and the completed runs are
/// aggregated into a summary that says the campaign was interrupted
/// ([`CampaignSummary::interrupted`]). Every run is written into `runs/K.partial` and
/// renamed to `runs/K` once saved.
pub fn run_campaign_with(
    opts: &CampaignOptions,
    executor: &dyn Executor,
) -> Result<CampaignSummary, McError> {
    let started = std::time::Instant::now();
    let host_start = HostSample::now();
    let setup = load_base(opts)?;
    if opts.jobs == 0 {
        return Err(McError::Invalid(
            "--jobs 0: need at least one thread".into(),
        ));
    }
    let info = info_of(opts, &setup, executor);
    let indices = shard_runs(opts.runs, opts.shard);
    let Start {
        base,
        todo,
        earlier_wall_s,
        mut host_load,
    } = start(opts, &info, &setup, &indices)?;
    let session = Session {
        opts,
        base: &base,
        executor,
        failed: AtomicUsize::new(0),
        bar: progress_bar(opts, todo.len()),
    };
    session.run_all(&todo)?;
    let stopped = executor.stopped();
    let wall = if todo.is_empty() {
        // nothing ran: the campaign's time and load stay those of its earlier sessions
        earlier_wall_s
    } else {
        host_load.push(HostLoad {
            start: host_start,
            end: HostSample::now(),
        });
        earlier_wall_s + started.elapsed().as_secs_f64()
    };
    let complete = count_runs(&opts.out, &indices);
    let interrupted_of = (stopped && complete < indices.len()).then_some(indices.len());
    aggregate(
        &opts.out,
        &Sessions {
            wall_time_s: wall,
            host_load,
            interrupted_of,
        },
    )
}

/// How many of the runs `indices` have their directory in the campaign `dir`.
fn count_runs(dir: &Path, indices: &[usize]) -> usize {
    indices
        .iter()
        .filter(|k| run_dir(dir, **k).is_dir())
        .count()
}

/// Sub-directory of a run with the reports of its partition launch (`--mode partition`).
pub const PARTITION_DIR: &str = "partition";
