//! Campaigns: run (all or a shard), aggregate a directory of runs, merge shards, rerun.
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
//! Everything is (re)built from the files by [`aggregate`], so an unsharded campaign and
//! the merge of its shards produce byte-identical deterministic files. A run's directory
//! gets its name `runs/K` only once its files are written, so an interrupted or killed
//! campaign leaves no run that looks complete and is not; `--resume`
//! ([`CampaignOptions::resume`]) verifies the complete runs against their re-derivation,
//! runs the others, and the result equals the uninterrupted campaign's.

use crate::config::MonteCarloConfig;
use crate::hist::LogHistogram;
use crate::host::{HostLoad, HostSample};
use crate::run::{
    self, CPU_TIMERS, CampaignBase, Execution, Executor, RunResult, RunTiming, TIMERS,
};
use crate::sample::{Dispersion, run_seed, sample};
use rayon::prelude::*;
use sc_mission::summary::TimeStats;
use sc_mission::{MissionEnd, Setup, StepRecord};
use sc_plots::{BarrierMinima, CampaignFigures, Geometry, RunPoint, RuntimeBar, TracePoint};
use sc_scenario::Scenario;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
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
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> McError + '_ {
    move |e| McError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

fn read(path: &Path) -> Result<String, McError> {
    std::fs::read_to_string(path).map_err(io(path))
}

fn write(path: &Path, text: impl AsRef<[u8]>) -> Result<(), McError> {
    std::fs::write(path, text).map_err(io(path))
}

fn json<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T, McError> {
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
}

/// Parses `i/N` (0 ≤ i < N).
pub fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| format!("shard `{s}`: expected i/N, e.g. 0/4"))?;
    let i: usize = i
        .trim()
        .parse()
        .map_err(|_| format!("shard `{s}`: `{i}` is not a number"))?;
    let n: usize = n
        .trim()
        .parse()
        .map_err(|_| format!("shard `{s}`: `{n}` is not a number"))?;
    if n == 0 || i >= n {
        return Err(format!("shard `{s}`: needs 0 <= i < N"));
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

/// Min and max of a quantity over the runs, with the runs they come from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    pub min: f64,
    pub min_run: usize,
    pub max: f64,
    pub max_run: usize,
}

#[derive(Default)]
struct SpreadAcc(Option<Spread>);

impl SpreadAcc {
    fn add(&mut self, v: Option<f64>, run: usize) {
        let Some(v) = v.filter(|v| v.is_finite()) else {
            return;
        };
        match &mut self.0 {
            None => {
                self.0 = Some(Spread {
                    min: v,
                    min_run: run,
                    max: v,
                    max_run: run,
                })
            }
            Some(s) => {
                if v < s.min {
                    s.min = v;
                    s.min_run = run;
                }
                if v > s.max {
                    s.max = v;
                    s.max_run = run;
                }
            }
        }
    }
}

/// The worst (smallest) minimum of one barrier over the runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Worst {
    pub min_h: Option<f64>,
    pub run: Option<usize>,
}

/// A failed run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    pub run: usize,
    pub error: String,
}

/// A campaign that stopped early (Ctrl-C): its summary covers the completed runs only.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Interruption {
    /// Runs completed and aggregated.
    pub completed_runs: usize,
    /// Runs of the campaign (of the shard, if it is one).
    pub planned_runs: usize,
}

/// `summary.json` of a campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignSummary {
    /// The program's version and git commit (`sc_mission::build`).
    #[serde(default)]
    pub version: String,
    #[serde(default)]
    pub git_commit: String,
    /// Runs in this directory.
    pub runs: usize,
    /// Runs of the whole campaign and the shard, if this is one.
    pub campaign_runs: usize,
    pub shard: Option<[usize; 2]>,
    pub seed: u64,
    /// Completed with every barrier ≥ 0.
    pub safe_runs: usize,
    pub captured_runs: usize,
    pub failed_runs: usize,
    /// Completed runs with at least one filter fault flag.
    pub faulted_runs: usize,
    pub unsafe_runs: Vec<usize>,
    pub not_captured_runs: Vec<usize>,
    pub failed: Vec<Failure>,
    /// Constraint → worst min_h over the runs and its run.
    pub worst: BTreeMap<String, Worst>,
    pub capture_time_s: Option<Spread>,
    /// Phase → spread of the per-run peak sync error [rad/s].
    pub sync_error_peak_rad_s: BTreeMap<String, Spread>,
    /// Phase → spread of the per-run peak joint-torque norm [N m].
    pub joint_torque_norm_peak_nm: BTreeMap<String, Spread>,
    pub joint_torque_norm_rms_grasp_nm: Option<Spread>,
    /// Result in the grasping phase → its correlation with the target's tumbling rate over
    /// the runs (the paper: synchronisation error and joint torque rise with the rate).
    #[serde(default)]
    pub trend_with_tumble_rate: BTreeMap<String, crate::trend::Trend>,
    /// Wall clock: filter → statistics over every step of every run [µs].
    pub solve_time_us: BTreeMap<String, TimeStats>,
    /// Thread CPU time: filter → statistics over every step of every run [µs].
    #[serde(default)]
    pub solve_cpu_us: BTreeMap<String, TimeStats>,
    /// Wall clock: the campaign's wall time (merged: sum over the shards; resumed: sum
    /// over the interrupted campaign and its resumes) [s].
    pub wall_time_s: f64,
    /// The host's load at the start and end of each session that ran runs (one for a
    /// campaign; one per shard of a merge; the interrupted campaign's, then each
    /// resume's). Wall-clock maxima are inflated when the load exceeds the CPUs.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub host_load: Vec<HostLoad>,
    /// Present when the campaign stopped early (Ctrl-C): completed of planned runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interrupted: Option<Interruption>,
}

/// What a summary records beside the runs: the wall time and host load of the sessions
/// that ran them, and whether the campaign stopped early.
#[derive(Debug, Clone, Default)]
pub struct Sessions {
    /// Wall time of every session together [s].
    pub wall_time_s: f64,
    pub host_load: Vec<HostLoad>,
    /// `Some(planned runs)` when the campaign stopped before completing them.
    pub interrupted_of: Option<usize>,
}

/// Keys of [`CampaignSummary::trend_with_tumble_rate`]: the grasping phase's peak
/// synchronisation error [rad/s], RMS and peak joint-torque norm [N m].
pub const TREND_SYNC_PEAK: &str = "sync_error_peak_grasp_rad_s";
pub const TREND_TORQUE_RMS: &str = "joint_torque_norm_rms_grasp_nm";
pub const TREND_TORQUE_PEAK: &str = "joint_torque_norm_peak_grasp_nm";

/// Keys of [`CampaignSummary`] that depend on the wall clock.
pub const WALL_CLOCK_KEYS: [&str; 4] =
    ["solve_time_us", "solve_cpu_us", "wall_time_s", "host_load"];

/// Files of a campaign directory that depend on the wall clock (everything else is
/// byte-identical between a campaign and the merge of its shards; in `summary.json` only
/// [`WALL_CLOCK_KEYS`] differ).
/// (With `--figure-format`, the runtime figure's PNG and PDF too.)
pub const WALL_CLOCK_FILES: [&str; 5] = [
    "runs_timing.csv",
    "report.md",
    "figures/runtime.svg",
    "figures/runtime.png",
    "figures/runtime.pdf",
];

/// Loads the base scenario and checks the config against it.
fn load_base(scenario: &Path, config: &MonteCarloConfig) -> Result<Setup, McError> {
    let setup = Setup::load(scenario).map_err(|e| McError::Setup(e.to_string()))?;
    config.check_against(&setup.scenario)?;
    Ok(setup)
}

/// What [`aggregate`] writes into a campaign directory besides the figures: removed with
/// an old campaign's runs, so that they never describe runs of another campaign.
const AGGREGATE_FILES: [&str; 4] = ["summary.json", "report.md", "runs.csv", "runs_timing.csv"];

/// Suffix of a run's directory while it is being written (`runs/K.partial`).
const PARTIAL_SUFFIX: &str = ".partial";

/// Creates `out` for a new campaign: refuses a non-empty directory that is not a campaign,
/// clears the runs, figures and aggregated files of an old one. (The command line writes
/// a new campaign into a fresh folder that holds only the marker of the output-folder
/// policy, [`sc_mission::out_dir`].)
fn prepare_out(out: &Path) -> Result<(), McError> {
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

/// Refuses to resume the campaign in `out` with another campaign's parameters; one line
/// naming every difference.
fn check_resume(
    out: &Path,
    info: &CampaignInfo,
    urdf: &[u8],
    base_text: &str,
) -> Result<(), McError> {
    let saved = campaign_info(out).map_err(|e| McError::Invalid(format!("--resume: {e}")))?;
    let shard = |s: Option<[usize; 2]>| s.map_or("none".into(), |[i, n]| format!("{i}/{n}"));
    let mut diff = Vec::new();
    if saved.seed != info.seed {
        diff.push(format!("seed {} (not {})", saved.seed, info.seed));
    }
    if saved.runs != info.runs {
        diff.push(format!("{} runs (not {})", saved.runs, info.runs));
    }
    if saved.shard != info.shard {
        diff.push(format!(
            "shard {} (not {})",
            shard(saved.shard),
            shard(info.shard)
        ));
    }
    if saved.config != info.config {
        diff.push("another dispersion config".into());
    }
    if saved.execution != info.execution {
        diff.push(format!(
            "execution {:?} (not {:?})",
            saved.execution, info.execution
        ));
    }
    if saved.build != info.build {
        let name = |b: &Option<sc_mission::build::BuildInfo>| {
            b.as_ref().map_or("an unrecorded build".into(), |b| {
                format!("build {} ({})", b.version, b.git_commit)
            })
        };
        diff.push(format!(
            "runs of {} (this is {})",
            name(&saved.build),
            name(&info.build)
        ));
    }
    let saved_urdf = std::fs::read(out.join(&saved.urdf)).ok();
    if saved.urdf != info.urdf || saved_urdf.as_deref() != Some(urdf) {
        diff.push("another servicer URDF".into());
    }
    if std::fs::read_to_string(out.join("base_scenario.toml"))
        .ok()
        .as_deref()
        != Some(base_text)
    {
        diff.push("another base scenario".into());
    }
    if diff.is_empty() {
        return Ok(());
    }
    Err(McError::Invalid(format!(
        "--resume: {} holds another campaign: {}; resume it with its own parameters (omitted ones are taken from its campaign.json) or choose another --out",
        out.display(),
        diff.join(", ")
    )))
}

/// Writes the campaign's base files into `out` and returns the base every run shares.
fn write_base(
    out: &Path,
    info: &CampaignInfo,
    urdf_bytes: &[u8],
    text: &str,
) -> Result<CampaignBase, McError> {
    write(&out.join(&info.urdf), urdf_bytes)?;
    write(&out.join("base_scenario.toml"), text)?;
    let cfg = toml::to_string(&info.config).map_err(|e| McError::Invalid(e.to_string()))?;
    write(&out.join("montecarlo.toml"), cfg)?;
    let info_json =
        serde_json::to_string_pretty(info).map_err(|e| McError::Invalid(e.to_string()))?;
    write(&out.join("campaign.json"), info_json + "\n")?;
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

fn run_dir(dir: &Path, k: usize) -> PathBuf {
    dir.join("runs").join(k.to_string())
}

/// Where run `k` is written before it gets its name [`run_dir`].
fn partial_dir(dir: &Path, k: usize) -> PathBuf {
    dir.join("runs").join(format!("{k}{PARTIAL_SUFFIX}"))
}

/// Run `k`'s seed and, unless sampling fails, its dispersion and the text of its
/// dispersed scenario, re-derived from the campaign.
fn derive_run(base: &CampaignBase, k: usize) -> (u64, Result<(Dispersion, String), String>) {
    let seed = run_seed(base.seed, k);
    let derived = sample(&base.config, &base.scenario, seed)
        .map(|d| (d, run::run_scenario(base, &d).to_toml_string()));
    (seed, derived)
}

/// Checks the saved run `k` of the campaign in `dir` without running it: `result.json`
/// names run k with its derived seed, the dispersion and `scenario.toml` are the
/// re-derived ones, and the trace and the timing of a completed run read back.
fn verify_saved_run(base: &CampaignBase, dir: &Path, k: usize) -> Result<(), String> {
    let d = run_dir(dir, k);
    let result: RunResult = json(&d.join("result.json")).map_err(|e| e.to_string())?;
    let (seed, derived) = derive_run(base, k);
    if result.run != k || result.seed != seed {
        return Err(format!(
            "result.json holds run {} with seed {}, not run {k} with seed {seed}",
            result.run, result.seed
        ));
    }
    match derived {
        Ok((disp, text)) => {
            if result.dispersion != Some(disp) {
                return Err("the saved dispersion differs from the re-derived one".into());
            }
            if read(&d.join("scenario.toml")).map_err(|e| e.to_string())? != text {
                return Err("scenario.toml differs from the re-derived dispersed scenario".into());
            }
        }
        Err(e) => {
            if !result.failed() || result.dispersion.is_some() {
                return Err(format!(
                    "sampling fails ({e}) but the saved run has a dispersion"
                ));
            }
        }
    }
    let tp = d.join("trace.csv");
    if tp.is_file() {
        run::parse_trace(&read(&tp).map_err(|e| e.to_string())?)
            .map_err(|e| format!("{}: {e}", tp.display()))?;
    }
    if !result.failed() {
        json::<RunTiming>(&d.join("timing.json")).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Prepares a resume of the campaign in `out`: removes the runs being written when it
/// stopped, keeps the complete runs of `indices` that verify ([`verify_saved_run`]; the
/// others are removed, with a note on stderr) and returns the runs still to do.
fn runs_to_resume(
    out: &Path,
    base: &CampaignBase,
    indices: &[usize],
) -> Result<Vec<usize>, McError> {
    let runs = out.join("runs");
    std::fs::create_dir_all(&runs).map_err(io(&runs))?;
    for e in std::fs::read_dir(&runs).map_err(io(&runs))? {
        let p = e.map_err(io(&runs))?.path();
        if p.is_dir()
            && p.file_name()
                .is_some_and(|n| n.to_string_lossy().ends_with(PARTIAL_SUFFIX))
        {
            std::fs::remove_dir_all(&p).map_err(io(&p))?;
        }
    }
    let mut todo = Vec::new();
    for &k in indices {
        let d = run_dir(out, k);
        if !d.exists() {
            todo.push(k);
            continue;
        }
        if let Err(why) = verify_saved_run(base, out, k) {
            // not `eprintln!`: a closed stderr must not stop the campaign
            use std::io::Write as _;
            let _ = writeln!(
                std::io::stderr().lock(),
                "resume: run {k} in {} does not verify ({why}); running it again",
                d.display()
            );
            std::fs::remove_dir_all(&d).map_err(io(&d))?;
            todo.push(k);
        }
    }
    Ok(todo)
}

/// Wall time and host load of the earlier sessions of the campaign in `dir`, from its
/// `summary.json` (none if it has none).
fn earlier_sessions(dir: &Path) -> (f64, Vec<HostLoad>) {
    let Ok(v) = json::<serde_json::Value>(&dir.join("summary.json")) else {
        return (0.0, Vec::new());
    };
    let wall = v.get("wall_time_s").and_then(|w| w.as_f64()).unwrap_or(0.0);
    let load = v
        .get("host_load")
        .cloned()
        .and_then(|l| serde_json::from_value(l).ok())
        .unwrap_or_default();
    (wall, load)
}

/// Runs a campaign (or one shard) in this process into `opts.out` and aggregates it.
pub fn run_campaign(opts: &CampaignOptions) -> Result<CampaignSummary, McError> {
    run_campaign_with(opts, &run::InProcess)
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
    let setup = load_base(&opts.scenario, &opts.config)?;
    if opts.jobs == 0 {
        return Err(McError::Invalid(
            "--jobs 0: need at least one thread".into(),
        ));
    }
    let urdf = setup
        .scenario
        .urdf_path()
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "servicer.urdf".into());
    let info = CampaignInfo {
        seed: opts.seed,
        runs: opts.runs,
        shard: opts.shard.map(|(i, n)| [i, n]),
        urdf,
        config: opts.config.clone(),
        execution: executor.execution(),
        build: Some(sc_mission::build::current()),
    };
    let (urdf_bytes, base_text) = base_files(&setup, &info)?;
    let indices = shard_runs(opts.runs, opts.shard);
    let (base, todo, (earlier_wall, mut host_load)) = if opts.resume {
        check_resume(&opts.out, &info, &urdf_bytes, &base_text)?;
        let base = load_campaign_base(&opts.out)?;
        let todo = runs_to_resume(&opts.out, &base, &indices)?;
        (base, todo, earlier_sessions(&opts.out))
    } else {
        prepare_out(&opts.out)?;
        let base = write_base(&opts.out, &info, &urdf_bytes, &base_text)?;
        (base, indices.clone(), (0.0, Vec::new()))
    };
    let bar = if opts.progress {
        indicatif::ProgressBar::new(todo.len() as u64)
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
    let failed = AtomicUsize::new(0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| McError::Invalid(format!("cannot start {} threads: {e}", opts.jobs)))?;
    let save_errors: Vec<McError> = pool.install(|| {
        todo.par_iter()
            .filter_map(|&k| {
                if executor.stopped() {
                    return None;
                }
                let (dir, partial) = (run_dir(&opts.out, k), partial_dir(&opts.out, k));
                if partial.exists()
                    && let Err(e) = std::fs::remove_dir_all(&partial)
                {
                    return Some(io(&partial)(e));
                }
                let inject = opts.inject_panic.contains(&k);
                let out = run::execute_with(&base, k, &partial, inject, executor);
                if out.result.failed() && executor.stopped() {
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
                    failed.fetch_add(1, Ordering::Relaxed);
                }
                let saved = run::save(&out, &partial)
                    .map_err(io(&partial))
                    .and_then(|_| std::fs::rename(&partial, &dir).map_err(io(&dir)))
                    .err();
                bar.inc(1);
                bar.set_message(format!("{} failed", failed.load(Ordering::Relaxed)));
                saved
            })
            .collect()
    });
    bar.finish_and_clear();
    if let Some(e) = save_errors.into_iter().next() {
        return Err(e);
    }
    let stopped = executor.stopped();
    let wall = if todo.is_empty() {
        // nothing ran: the campaign's time and load stay those of its earlier sessions
        earlier_wall
    } else {
        host_load.push(HostLoad {
            start: host_start,
            end: HostSample::now(),
        });
        earlier_wall + started.elapsed().as_secs_f64()
    };
    let complete = count_runs(&opts.out, &indices);
    aggregate(
        &opts.out,
        &Sessions {
            wall_time_s: wall,
            host_load,
            interrupted_of: (stopped && complete < indices.len()).then_some(indices.len()),
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

/// One run as read back from its directory.
struct Loaded {
    result: RunResult,
    trace: Vec<TracePoint>,
    timing: Option<RunTiming>,
}

fn load_runs(dir: &Path) -> Result<Vec<Loaded>, McError> {
    let runs = dir.join("runs");
    let mut ks: Vec<usize> = Vec::new();
    for e in std::fs::read_dir(&runs).map_err(io(&runs))? {
        let e = e.map_err(io(&runs))?;
        if let Some(k) = e.file_name().to_str().and_then(|n| n.parse::<usize>().ok()) {
            ks.push(k);
        }
    }
    ks.sort_unstable();
    let mut out = Vec::with_capacity(ks.len());
    for k in ks {
        let d = run_dir(dir, k);
        let result: RunResult = json(&d.join("result.json"))?;
        if result.run != k {
            return Err(McError::Invalid(format!(
                "{}: holds run {} instead of {k}",
                d.join("result.json").display(),
                result.run
            )));
        }
        let tp = d.join("trace.csv");
        let trace = if tp.is_file() {
            run::parse_trace(&read(&tp)?).map_err(|m| McError::Io {
                path: tp.display().to_string(),
                message: m,
            })?
        } else {
            Vec::new()
        };
        let tj = d.join("timing.json");
        let timing = if tj.is_file() { Some(json(&tj)?) } else { None };
        out.push(Loaded {
            result,
            trace,
            timing,
        });
    }
    Ok(out)
}

fn num(x: Option<f64>) -> String {
    x.map(|v| v.to_string()).unwrap_or_default()
}

fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\"").replace('\n', " "))
    } else {
        s.to_string()
    }
}

/// `runs.csv` header and rows (deterministic).
fn runs_csv(loaded: &[Loaded], phases: &[String], grasp: Option<&str>) -> String {
    let names = sc_mission::constraint_names();
    let mut cols: Vec<String> = [
        "run",
        "seed",
        "status",
        "distance_m",
        "off_axis_deg",
        "azimuth_deg",
        "x0_r_m",
        "y0_r_m",
        "z0_r_m",
        "initial_los_deg",
        "tumble_rate_rad_s",
        "end",
        "captured",
        "capture_time_s",
        "safe",
        "min_margin_constraint",
        "min_margin",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for p in phases {
        cols.push(format!("sync_error_peak_{p}_rad_s"));
    }
    for p in phases {
        cols.push(format!("joint_torque_norm_peak_{p}_nm"));
    }
    cols.push("joint_torque_norm_rms_grasp_nm".into());
    cols.push("fault_count".into());
    cols.push("faults".into());
    for n in &names {
        cols.push(format!("min_h_{n}"));
    }
    cols.push("error".into());
    let mut s = cols.join(",") + "\n";
    let _ = grasp;
    for l in loaded {
        let r = &l.result;
        let mut v: Vec<String> = vec![r.run.to_string(), r.seed.to_string(), r.status.clone()];
        match &r.dispersion {
            Some(d) => v.extend([
                d.distance_m.to_string(),
                d.off_axis_deg.to_string(),
                d.azimuth_deg.to_string(),
                d.position_r_m[0].to_string(),
                d.position_r_m[1].to_string(),
                d.position_r_m[2].to_string(),
                d.initial_los_deg.to_string(),
                d.tumble_rate_rad_s.to_string(),
            ]),
            None => v.extend(std::iter::repeat_n(String::new(), 8)),
        }
        match &r.metrics {
            Some(m) => {
                let (mc, mv) = names
                    .iter()
                    .filter_map(|n| m.min_h.get(*n).copied().flatten().map(|h| (n, h)))
                    .fold((String::new(), None::<f64>), |acc, (n, h)| match acc.1 {
                        Some(b) if b <= h => acc,
                        _ => (n.to_string(), Some(h)),
                    });
                v.extend([
                    m.end.clone(),
                    m.captured.to_string(),
                    num(m.capture_time_s),
                    m.safe.to_string(),
                    mc,
                    num(mv),
                ]);
                for p in phases {
                    v.push(num(m.sync_error_peak_rad_s.get(p).copied().flatten()));
                }
                for p in phases {
                    v.push(num(m.joint_torque_norm_peak_nm.get(p).copied().flatten()));
                }
                v.push(num(m.joint_torque_norm_rms_grasp_nm));
                v.push(m.fault_count.to_string());
                v.push(m.fault_flags.join(";"));
                for n in &names {
                    v.push(num(m.min_h.get(*n).copied().flatten()));
                }
            }
            None => v.extend(std::iter::repeat_n(
                String::new(),
                6 + 2 * phases.len() + 3 + names.len(),
            )),
        }
        v.push(quote(r.error.as_deref().unwrap_or("")));
        s += &(v.join(",") + "\n");
    }
    s
}

fn runs_timing_csv(loaded: &[Loaded]) -> String {
    let mut cols = vec!["run".to_string()];
    for t in TIMERS.iter().chain(CPU_TIMERS.iter()) {
        cols.push(format!("{t}_geomean_us"));
        cols.push(format!("{t}_max_us"));
    }
    let mut s = cols.join(",") + "\n";
    for l in loaded {
        let Some(t) = &l.timing else { continue };
        let mut v = vec![l.result.run.to_string()];
        for n in TIMERS.iter().chain(CPU_TIMERS.iter()) {
            let st = t.stats.get(*n).copied().unwrap_or_default();
            v.push(format!("{:.3}", st.geomean));
            v.push(format!("{:.3}", st.max));
        }
        s += &(v.join(",") + "\n");
    }
    s
}

/// (Re)builds runs.csv, runs_timing.csv, summary.json, report.md and the figures of the
/// campaign directory `dir` from its run directories; `sessions` gives what the summary
/// records beside the runs.
pub fn aggregate(dir: &Path, sessions: &Sessions) -> Result<CampaignSummary, McError> {
    let info: CampaignInfo = json(&dir.join("campaign.json"))?;
    let base = read(&dir.join("base_scenario.toml"))?;
    let scenario = Scenario::from_toml_str(&base, dir).map_err(|e| {
        McError::Setup(format!("{}: {e}", dir.join("base_scenario.toml").display()))
    })?;
    let phases: Vec<String> = scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let grasp = run::grasp_phase(&scenario);
    let loaded = load_runs(dir)?;
    write(
        &dir.join("runs.csv"),
        runs_csv(&loaded, &phases, grasp.as_deref()),
    )?;
    write(&dir.join("runs_timing.csv"), runs_timing_csv(&loaded))?;

    let names = sc_mission::constraint_names();
    let mut worst: BTreeMap<String, Worst> = names
        .iter()
        .map(|n| {
            (
                n.to_string(),
                Worst {
                    min_h: None,
                    run: None,
                },
            )
        })
        .collect();
    let mut minima: Vec<BarrierMinima> = names
        .iter()
        .map(|n| BarrierMinima {
            name: n.to_string(),
            values: Vec::new(),
        })
        .collect();
    let mut sync: BTreeMap<String, SpreadAcc> = BTreeMap::new();
    let mut torque: BTreeMap<String, SpreadAcc> = BTreeMap::new();
    let mut rms = SpreadAcc::default();
    let mut capture = SpreadAcc::default();
    let mut hist: BTreeMap<String, LogHistogram> = BTreeMap::new();
    let build = sc_mission::build::current();
    let mut s = CampaignSummary {
        version: build.version,
        git_commit: build.git_commit,
        runs: loaded.len(),
        campaign_runs: info.runs,
        shard: info.shard,
        seed: info.seed,
        safe_runs: 0,
        captured_runs: 0,
        failed_runs: 0,
        faulted_runs: 0,
        unsafe_runs: Vec::new(),
        not_captured_runs: Vec::new(),
        failed: Vec::new(),
        worst: BTreeMap::new(),
        capture_time_s: None,
        sync_error_peak_rad_s: BTreeMap::new(),
        joint_torque_norm_peak_nm: BTreeMap::new(),
        joint_torque_norm_rms_grasp_nm: None,
        trend_with_tumble_rate: BTreeMap::new(),
        solve_time_us: BTreeMap::new(),
        solve_cpu_us: BTreeMap::new(),
        wall_time_s: sessions.wall_time_s,
        host_load: sessions.host_load.clone(),
        interrupted: sessions.interrupted_of.map(|planned| Interruption {
            completed_runs: loaded.len(),
            planned_runs: planned,
        }),
    };
    let mut traces = Vec::new();
    let mut points = Vec::new();
    let mut trend_pairs: BTreeMap<&str, Vec<(f64, f64)>> = BTreeMap::new();
    for l in &loaded {
        let r = &l.result;
        if let Some(t) = &l.timing {
            for (n, h) in &t.histograms {
                hist.entry(n.clone()).or_default().merge(h);
            }
        }
        let Some(m) = &r.metrics else {
            s.failed_runs += 1;
            s.failed.push(Failure {
                run: r.run,
                error: r.error.clone().unwrap_or_default(),
            });
            continue;
        };
        if m.safe {
            s.safe_runs += 1;
        } else {
            s.unsafe_runs.push(r.run);
        }
        if m.captured {
            s.captured_runs += 1;
        } else {
            s.not_captured_runs.push(r.run);
        }
        if m.fault_count > 0 {
            s.faulted_runs += 1;
        }
        capture.add(m.capture_time_s, r.run);
        for (i, n) in names.iter().enumerate() {
            if let Some(h) = m.min_h.get(*n).copied().flatten() {
                minima[i].values.push(h);
                let w = worst.get_mut(*n).expect("constraint present");
                if w.min_h.is_none_or(|b| h < b) {
                    w.min_h = Some(h);
                    w.run = Some(r.run);
                }
            }
        }
        for (p, v) in &m.sync_error_peak_rad_s {
            sync.entry(p.clone()).or_default().add(*v, r.run);
        }
        for (p, v) in &m.joint_torque_norm_peak_nm {
            torque.entry(p.clone()).or_default().add(*v, r.run);
        }
        rms.add(m.joint_torque_norm_rms_grasp_nm, r.run);
        if !l.trace.is_empty() {
            traces.push((r.run, l.trace.clone()));
        }
        if let (Some(d), Some(g)) = (&r.dispersion, &grasp) {
            let peak = m.sync_error_peak_rad_s.get(g).copied().flatten();
            let results = [
                (TREND_SYNC_PEAK, peak),
                (TREND_TORQUE_RMS, m.joint_torque_norm_rms_grasp_nm),
                (
                    TREND_TORQUE_PEAK,
                    m.joint_torque_norm_peak_nm.get(g).copied().flatten(),
                ),
            ];
            for (k, v) in results {
                if let Some(v) = v {
                    trend_pairs
                        .entry(k)
                        .or_default()
                        .push((d.tumble_rate_rad_s, v));
                }
            }
            if let (Some(peak), Some(tq)) = (peak, m.joint_torque_norm_rms_grasp_nm) {
                points.push(RunPoint {
                    run: r.run,
                    tumble_rate: d.tumble_rate_rad_s,
                    peak_sync_grasp: peak,
                    torque_norm_grasp: tq,
                });
            }
        }
    }
    s.worst = worst;
    s.capture_time_s = capture.0;
    s.sync_error_peak_rad_s = sync
        .into_iter()
        .filter_map(|(k, v)| v.0.map(|x| (k, x)))
        .collect();
    s.joint_torque_norm_peak_nm = torque
        .into_iter()
        .filter_map(|(k, v)| v.0.map(|x| (k, x)))
        .collect();
    s.joint_torque_norm_rms_grasp_nm = rms.0;
    s.trend_with_tumble_rate = trend_pairs
        .into_iter()
        .map(|(k, v)| (k.to_string(), crate::trend::trend(&v)))
        .collect();
    s.solve_time_us = TIMERS
        .iter()
        .map(|n| {
            (
                n.to_string(),
                hist.get(*n).map(|h| h.stats()).unwrap_or_default(),
            )
        })
        .collect();
    s.solve_cpu_us = TIMERS
        .iter()
        .zip(CPU_TIMERS)
        .map(|(n, c)| {
            (
                n.to_string(),
                hist.get(c).map(|h| h.stats()).unwrap_or_default(),
            )
        })
        .collect();
    let text = serde_json::to_string_pretty(&s).map_err(|e| McError::Invalid(e.to_string()))?;
    write(&dir.join("summary.json"), text + "\n")?;
    write(
        &dir.join("report.md"),
        crate::report::report(
            &s,
            &loaded_results(&loaded),
            grasp.as_deref(),
            &phases,
            info.execution,
        ),
    )?;

    let runtime: Vec<RuntimeBar> = ["total", "translational", "attitude", "robotic"]
        .iter()
        .map(|n| {
            let st = s.solve_time_us.get(*n).copied().unwrap_or_default();
            let cpu = s.solve_cpu_us.get(*n).copied().unwrap_or_default();
            RuntimeBar {
                name: n.to_string(),
                geomean_us: st.geomean,
                max_us: st.max,
                cpu_geomean_us: cpu.geomean,
                cpu_max_us: cpu.max,
            }
        })
        .collect();
    let figs = CampaignFigures {
        geometry: Geometry::from_scenario(&scenario),
        traces: &traces,
        points: &points,
        runtime: &runtime,
        runtime_reference: Some((
            "paper (CasADi + OSQP)".into(),
            sc_plots::paper::PAPER_TOTAL_GEOMEAN_MS * 1e3,
            sc_plots::paper::PAPER_TOTAL_MAX_MS * 1e3,
        )),
        minima: &minima,
    };
    sc_plots::campaign_figures(&dir.join("figures"), &figs)
        .map_err(|e| McError::Invalid(e.to_string()))?;
    Ok(s)
}

fn loaded_results(l: &[Loaded]) -> Vec<RunResult> {
    l.iter().map(|x| x.result.clone()).collect()
}

/// Sub-directory of a run with the reports of its partition launch (`--mode partition`).
pub const PARTITION_DIR: &str = "partition";

/// Copies the files of a directory; of its sub-directories every one with `all`, else
/// only the partition reports of a run (not, e.g., a rerun's output).
fn copy_dir(from: &Path, to: &Path, all: bool) -> Result<(), McError> {
    std::fs::create_dir_all(to).map_err(io(to))?;
    for e in std::fs::read_dir(from).map_err(io(from))? {
        let e = e.map_err(io(from))?;
        let p = e.path();
        if p.is_file() {
            std::fs::copy(&p, to.join(e.file_name())).map_err(io(&p))?;
        } else if p.is_dir() && (all || e.file_name() == PARTITION_DIR) {
            copy_dir(&p, &to.join(e.file_name()), true)?;
        }
    }
    Ok(())
}

/// Merges shard directories into `out`: checks that they belong to the same campaign and
/// cover every run exactly once, copies the runs and aggregates. `wall_time_s` of the
/// result is the sum of the shards'.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<CampaignSummary, McError> {
    let first = dirs
        .first()
        .ok_or_else(|| McError::Invalid("merge: no shard directories given".into()))?;
    let info0: CampaignInfo = json(&first.join("campaign.json"))?;
    let base0 = read(&first.join("base_scenario.toml"))?;
    let urdf0 = std::fs::read(first.join(&info0.urdf)).map_err(io(&first.join(&info0.urdf)))?;
    let out_abs = std::path::absolute(out).unwrap_or(out.to_path_buf());
    for d in dirs {
        if std::path::absolute(d).unwrap_or(d.clone()) == out_abs {
            return Err(McError::Invalid(format!(
                "merge: --out {} is one of the inputs",
                out.display()
            )));
        }
        let info: CampaignInfo = json(&d.join("campaign.json"))?;
        let same = info.seed == info0.seed
            && info.runs == info0.runs
            && info.config == info0.config
            && info.urdf == info0.urdf
            && info.execution == info0.execution
            && info.build == info0.build
            && read(&d.join("base_scenario.toml"))? == base0
            && std::fs::read(d.join(&info.urdf)).map_err(io(&d.join(&info.urdf)))? == urdf0;
        if !same {
            return Err(McError::Invalid(format!(
                "merge: {} belongs to a different campaign than {} (seed, runs, config, scenario, execution mode or build differ)",
                d.display(),
                first.display()
            )));
        }
    }
    prepare_out(out)?;
    let info = CampaignInfo {
        shard: None,
        ..info0.clone()
    };
    write(&out.join(&info.urdf), &urdf0)?;
    write(&out.join("base_scenario.toml"), &base0)?;
    let cfg = toml::to_string(&info.config).map_err(|e| McError::Invalid(e.to_string()))?;
    write(&out.join("montecarlo.toml"), cfg)?;
    let text = serde_json::to_string_pretty(&info).map_err(|e| McError::Invalid(e.to_string()))?;
    write(&out.join("campaign.json"), text + "\n")?;
    let mut seen: BTreeMap<usize, PathBuf> = BTreeMap::new();
    let mut sessions = Sessions::default();
    for d in dirs {
        let runs = d.join("runs");
        for e in std::fs::read_dir(&runs).map_err(io(&runs))? {
            let e = e.map_err(io(&runs))?;
            let Some(k) = e.file_name().to_str().and_then(|n| n.parse::<usize>().ok()) else {
                continue;
            };
            if let Some(prev) = seen.get(&k) {
                return Err(McError::Invalid(format!(
                    "merge: run {k} is in both {} and {}",
                    prev.display(),
                    d.display()
                )));
            }
            if k >= info.runs {
                return Err(McError::Invalid(format!(
                    "merge: {} holds run {k} outside the campaign's {} runs",
                    d.display(),
                    info.runs
                )));
            }
            copy_dir(&e.path(), &run_dir(out, k), false)?;
            seen.insert(k, d.clone());
        }
        let (wall, load) = earlier_sessions(d);
        sessions.wall_time_s += wall;
        sessions.host_load.extend(load);
    }
    let missing: Vec<String> = (0..info.runs)
        .filter(|k| !seen.contains_key(k))
        .map(|k| k.to_string())
        .collect();
    if !missing.is_empty() {
        let shown: Vec<String> = missing.iter().take(10).cloned().collect();
        return Err(McError::Invalid(format!(
            "merge: {} of {} runs missing (e.g. {}); merge every shard",
            missing.len(),
            info.runs,
            shown.join(", ")
        )));
    }
    aggregate(out, &sessions)
}

/// A rerun of one run and how it compares with the saved one.
pub struct Rerun {
    pub scenario: Scenario,
    pub records: Vec<StepRecord>,
    pub end: MissionEnd,
    pub result: RunResult,
    pub timing: RunTiming,
    /// Empty when the rerun reproduced the saved dispersion, scenario and result exactly.
    pub differences: Vec<String>,
}

/// Reruns run `k` of the campaign in `dir` from its saved scenario and compares the
/// re-derived seed and dispersion, the scenario text and the result with the saved ones.
pub fn rerun(dir: &Path, k: usize) -> Result<Rerun, McError> {
    let base = load_campaign_base(dir)?;
    let info: CampaignInfo = json(&dir.join("campaign.json"))?;
    if k >= info.runs {
        return Err(McError::Invalid(format!(
            "--run {k}: the campaign has runs 0..{}",
            info.runs
        )));
    }
    let rd = run_dir(dir, k);
    let saved_path = rd.join("result.json");
    if !saved_path.is_file() {
        return Err(McError::Invalid(format!(
            "run {k} is not in {} (another shard?)",
            dir.display()
        )));
    }
    let saved_text = read(&saved_path)?;
    let saved: RunResult = json(&saved_path)?;
    let mut differences = Vec::new();
    let (seed, derived) = derive_run(&base, k);
    if seed != saved.seed {
        differences.push(format!("seed: saved {}, derived {seed}", saved.seed));
    }
    let (d, text) = derived.map_err(McError::Invalid)?;
    let saved_scenario = read(&rd.join("scenario.toml"))?;
    if text != saved_scenario {
        differences
            .push("scenario.toml: re-derived dispersed scenario differs from the saved one".into());
    }
    let scenario = Scenario::from_toml_str(&saved_scenario, &rd)
        .map_err(|e| McError::Setup(format!("{}: {e}", rd.join("scenario.toml").display())))?;
    let setup =
        Setup::from_scenario(scenario.clone()).map_err(|e| McError::Setup(e.to_string()))?;
    let (records, end) = run::simulate(setup, false).map_err(McError::Invalid)?;
    let (metrics, _trace, timing) = run::measure(
        &scenario,
        &records,
        &end,
        base.config.output.trace_every_steps,
    );
    let result = RunResult {
        run: k,
        seed,
        status: "ok".into(),
        error: None,
        dispersion: Some(d),
        metrics: Some(metrics),
    };
    let new_text =
        serde_json::to_string_pretty(&result).map_err(|e| McError::Invalid(e.to_string()))? + "\n";
    if new_text != saved_text {
        if saved.failed() {
            differences.push(format!(
                "result: the saved run failed ({}), the rerun completed",
                saved.error.as_deref().unwrap_or("")
            ));
        } else {
            differences.push("result.json: rerun result differs from the saved one".into());
        }
    }
    Ok(Rerun {
        scenario,
        records,
        end,
        result,
        timing,
        differences,
    })
}
