//! One run of a campaign: dispersed scenario → mission → metrics, trace and timing.

use crate::config::MonteCarloConfig;
use crate::hist::LogHistogram;
use crate::sample::{Dispersion, SampleError, apply, run_seed, sample};
use sc_mission::summary::TimeStats;
use sc_mission::{
    Executed, Executor, InProcess, Job, MissionEnd, Place, Setup, StepRecord, summarize,
};
use sc_plots::TracePoint;
use sc_scenario::{RoboticMode, Scenario};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Filter names of the timing statistics, in order.
pub const TIMERS: [&str; 4] = ["translational", "attitude", "robotic", "total"];

/// The same for the filters' thread CPU time (their own work, without preemption).
pub const CPU_TIMERS: [&str; 4] = [
    "translational_cpu",
    "attitude_cpu",
    "robotic_cpu",
    "total_cpu",
];

/// Deterministic result of one run (`runs/K/result.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    pub run: usize,
    pub seed: u64,
    /// "ok" or "failed" (sampling, set-up or simulation error, or a panic).
    pub status: String,
    pub error: Option<String>,
    pub dispersion: Option<Dispersion>,
    pub metrics: Option<RunMetrics>,
}

impl RunResult {
    pub fn failed(&self) -> bool {
        self.status != "ok"
    }
    /// Completed with every barrier ≥ 0 (no NaN).
    pub fn safe(&self) -> bool {
        self.metrics.as_ref().is_some_and(|m| m.safe)
    }
    pub fn captured(&self) -> bool {
        self.metrics.as_ref().is_some_and(|m| m.captured)
    }
}

/// What a completed run measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunMetrics {
    /// "captured", "timeout" or "simulator_failed" (a partition run also "stopped" or
    /// "interrupted", see `sc_mission::summary`).
    pub end: String,
    pub captured: bool,
    pub capture_time_s: Option<f64>,
    pub final_time_s: f64,
    pub steps: usize,
    /// Every barrier ≥ 0 over the whole run.
    pub safe: bool,
    pub violated: Vec<String>,
    /// Minimum of every barrier (None if it had no finite sample).
    pub min_h: BTreeMap<String, Option<f64>>,
    /// Peak ‖ω_B − R_BT ω_T‖ per phase [rad/s].
    pub sync_error_peak_rad_s: BTreeMap<String, Option<f64>>,
    /// Peak ‖τ_M‖₂ per phase [N m].
    pub joint_torque_norm_peak_nm: BTreeMap<String, Option<f64>>,
    /// RMS of ‖τ_M‖₂ over the grasping phase [N m] (None if it was not reached).
    pub joint_torque_norm_rms_grasp_nm: Option<f64>,
    pub fault_count: usize,
    /// Distinct fault flags, sorted.
    pub fault_flags: Vec<String>,
}

/// Solve times of one run (`runs/K/timing.json`), not reproducible: wall clock under
/// [`TIMERS`], thread CPU time under [`CPU_TIMERS`].
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct RunTiming {
    pub stats: BTreeMap<String, TimeStats>,
    pub histograms: BTreeMap<String, LogHistogram>,
}

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunOutput {
    pub result: RunResult,
    pub trace: Vec<TracePoint>,
    pub timing: Option<RunTiming>,
}

/// Name of the phase whose robotic mode is grasp (phase III), if any.
pub fn grasp_phase(s: &Scenario) -> Option<String> {
    s.mission
        .phases
        .iter()
        .find(|p| p.robotic == RoboticMode::Grasp)
        .map(|p| p.name.clone())
}

/// Everything a run needs that is shared by all runs of a campaign.
pub struct CampaignBase {
    pub scenario: Scenario,
    pub setup: Setup,
    pub config: MonteCarloConfig,
    pub seed: u64,
    /// File name of the URDF copy in the campaign directory.
    pub urdf_name: String,
}

/// The dispersed scenario of the run with seed `seed` as saved in `runs/K/scenario.toml`
/// (URDF path relative to that directory); a declared uncertainty gets the run's own
/// seed ([`uncertainty_seed`]), so that every run draws its own plant and errors.
pub fn run_scenario(base: &CampaignBase, d: &Dispersion, seed: u64) -> Scenario {
    let mut s = apply(&base.scenario, d);
    s.servicer.urdf = PathBuf::from("../..").join(&base.urdf_name);
    if let Some(u) = s.uncertainty.as_mut() {
        u.seed = uncertainty_seed(seed);
    }
    s
}

/// The stream of a run's uncertainty seed, apart from its dispersion's draws.
const UNCERTAINTY_STREAM: u64 = 1 << 32;

/// The seed of the uncertainty realisation of the run with seed `run_seed`: the first
/// word of ChaCha8 keyed by it on [`UNCERTAINTY_STREAM`].
pub fn uncertainty_seed(run_seed: u64) -> u64 {
    use rand_chacha::rand_core::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(run_seed);
    rng.set_stream(UNCERTAINTY_STREAM);
    rng.next_u64()
}

fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic payload".into()
    }
}

fn finite(x: Option<f64>) -> Option<f64> {
    x.filter(|v| v.is_finite())
}

fn finite_map(m: &BTreeMap<String, f64>) -> BTreeMap<String, Option<f64>> {
    m.iter()
        .map(|(k, v)| (k.clone(), finite(Some(*v))))
        .collect()
}

/// Metrics, trace and timing of a finished run.
pub fn measure(
    s: &Scenario,
    records: &[StepRecord],
    end: &MissionEnd,
    trace_every: u32,
) -> (RunMetrics, Vec<TracePoint>, RunTiming) {
    let phase_names: Vec<String> = s.mission.phases.iter().map(|p| p.name.clone()).collect();
    let mut sum = summarize(records, end, &phase_names, true);
    // a run whose true tumble left the envelope undetected is not safe
    sum.safe_mode = sc_mission::SafeModeSummary::of(records, s);
    let min_h = sum
        .constraints
        .iter()
        .map(|(n, c)| (n.clone(), c.min_h.is_finite().then_some(c.min_h)))
        .collect();
    let grasp = grasp_phase(s);
    let mut sq = 0.0;
    let mut n = 0usize;
    let mut flags = std::collections::BTreeSet::new();
    for f in &sum.faults {
        flags.extend(f.flags.iter().cloned());
    }
    for r in records {
        if grasp.as_deref() == phase_names.get(r.phase).map(|x| x.as_str()) {
            sq += r.applied.tau.norm_squared();
            n += 1;
        }
    }
    let metrics = RunMetrics {
        end: sum.end.clone(),
        captured: sum.captured,
        capture_time_s: finite(sum.capture_time_s),
        final_time_s: sum.final_time_s,
        steps: sum.steps,
        safe: sum.safe(),
        violated: sum.violated_constraints.clone(),
        min_h,
        sync_error_peak_rad_s: finite_map(&sum.sync_error_peak_rad_s),
        joint_torque_norm_peak_nm: finite_map(&sum.joint_torque_norm_peak_nm),
        joint_torque_norm_rms_grasp_nm: finite((n > 0).then(|| (sq / n as f64).sqrt())),
        fault_count: sum.fault_count,
        fault_flags: flags.into_iter().collect(),
    };
    let d_b = nalgebra::Vector3::from(s.servicer.boresight_body);
    let every = trace_every.max(1) as u64;
    let trace = records
        .iter()
        .filter(|r| r.step % every == 0)
        .map(|r| TracePoint {
            t: r.t,
            phase: r.phase,
            r_r: r.obs.r_r.into(),
            speed: r.obs.v_r.norm(),
            los_deg: sc_plots::los_angles_deg(&r.obs.grasp_b, &d_b).unwrap_or([f64::NAN; 2]),
            sync_error: r.obs.sync_error().norm(),
        })
        .collect();
    let mut timing = RunTiming::default();
    let mut h: [LogHistogram; 8] = Default::default();
    let mut v: [Vec<f64>; 8] = Default::default();
    for r in records {
        let (wall, cpu) = (r.solve_time_us(), r.solve_cpu_us());
        for (i, x) in wall.iter().chain(cpu.iter()).enumerate() {
            h[i].add(*x);
            v[i].push(*x);
        }
    }
    for (i, name) in TIMERS.iter().chain(CPU_TIMERS.iter()).enumerate() {
        timing.stats.insert(name.to_string(), TimeStats::of(&v[i]));
        timing
            .histograms
            .insert(name.to_string(), std::mem::take(&mut h[i]));
    }
    (metrics, trace, timing)
}

/// Samples, saves and runs run `k` of the campaign in this process (files under
/// `run_dir`); never panics, never fails: every problem ends up in the result as a failure.
pub fn execute(base: &CampaignBase, k: usize, run_dir: &Path, inject_panic: bool) -> RunOutput {
    execute_with(base, k, run_dir, inject_panic, &InProcess)
}

/// A run that failed with `error` (one line).
fn failed(mut result: RunResult, error: String) -> RunOutput {
    result.error = Some(error.replace('\n', " "));
    RunOutput {
        result,
        trace: Vec::new(),
        timing: None,
    }
}

/// Why run `k`'s dispersed scenario could not be made (the run fails).
#[derive(Debug, thiserror::Error)]
enum DispersionError {
    #[error(transparent)]
    Sample(#[from] SampleError),
    #[error("cannot write {}: {error}", .dir.display())]
    Write { dir: PathBuf, error: std::io::Error },
    #[error("dispersed scenario rejected: {0}")]
    Rejected(sc_scenario::ScenarioError),
}

/// Samples run `k`'s dispersion, saves its scenario into `run_dir/scenario.toml` and
/// reads it back: a run executes exactly what was saved.
fn dispersed_scenario(
    base: &CampaignBase,
    run_dir: &Path,
    result: &mut RunResult,
) -> Result<Scenario, DispersionError> {
    let d = sample(&base.config, &base.scenario, result.seed)?;
    result.dispersion = Some(d);
    let text = run_scenario(base, &d, result.seed).to_toml_string();
    std::fs::create_dir_all(run_dir)
        .and_then(|_| std::fs::write(run_dir.join("scenario.toml"), &text))
        .map_err(|error| DispersionError::Write {
            dir: run_dir.to_path_buf(),
            error,
        })?;
    Scenario::from_toml_str(&text, run_dir).map_err(DispersionError::Rejected)
}

/// The job of run `k`: its scenario, read back from `run_dir`, with the campaign's
/// servicer model; an executor outside this process reads `run_dir/scenario.toml` and
/// writes into `run_dir/partition/`.
fn job(base: &CampaignBase, k: usize, run_dir: &Path, scenario: Scenario) -> Job<'static> {
    let mut job = Job::new(Setup {
        scenario,
        robot: base.setup.robot.clone(),
    });
    job.place = Some(Place {
        name: format!("mc{k}"),
        scenario_file: run_dir.join("scenario.toml"),
        out: run_dir.join(crate::campaign::PARTITION_DIR),
    });
    job
}

/// [`execute`] with the mission executed by `executor`.
pub fn execute_with(
    base: &CampaignBase,
    k: usize,
    run_dir: &Path,
    inject_failure: bool,
    executor: &dyn Executor,
) -> RunOutput {
    let mut result = RunResult {
        run: k,
        seed: run_seed(base.seed, k),
        status: "failed".into(),
        error: None,
        dispersion: None,
        metrics: None,
    };
    let scenario = match dispersed_scenario(base, run_dir, &mut result) {
        Ok(s) => s,
        Err(e) => return failed(result, e.to_string()),
    };
    let mut job = job(base, k, run_dir, scenario.clone());
    job.inject_failure = inject_failure;
    let executed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        executor.execute(job).map_err(|e| e.to_string())
    }))
    .unwrap_or_else(|p| Err(format!("panicked: {}", panic_message(p))));
    let Executed { records, end } = match executed {
        Ok(x) => x,
        Err(e) => return failed(result, e),
    };
    let (metrics, trace, timing) = measure(
        &scenario,
        &records,
        &end,
        base.config.output.trace_every_steps,
    );
    result.status = "ok".into();
    result.metrics = Some(metrics);
    RunOutput {
        result,
        trace,
        timing: Some(timing),
    }
}

/// Columns of `runs/K/trace.csv`.
pub const TRACE_COLUMNS: &str =
    "t_s,phase,x_r_m,y_r_m,z_r_m,speed_m_s,los_e1_deg,los_e2_deg,sync_error_rad_s";

/// The trace as CSV text (floats in shortest round-trip form).
pub fn trace_csv(trace: &[TracePoint]) -> String {
    let mut s = String::from(TRACE_COLUMNS);
    s.push('\n');
    for p in trace {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{}\n",
            p.t,
            p.phase,
            p.r_r[0],
            p.r_r[1],
            p.r_r[2],
            p.speed,
            p.los_deg[0],
            p.los_deg[1],
            p.sync_error
        ));
    }
    s
}

/// Why a `trace.csv` does not read back (line numbers from 1, the header's included).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TraceError {
    #[error("line {line}: expected 9 fields, found {found}")]
    Fields { line: usize, found: usize },
    #[error("line {line}: `{field}` is not a number")]
    NotANumber { line: usize, field: String },
    #[error("line {line}: `{field}` is not a phase index")]
    NotAPhase { line: usize, field: String },
}

/// Parses [`trace_csv`] output.
pub fn parse_trace(text: &str) -> Result<Vec<TracePoint>, TraceError> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 9 {
            return Err(TraceError::Fields {
                line: i + 1,
                found: f.len(),
            });
        }
        let num = |j: usize| {
            f[j].parse::<f64>().map_err(|_| TraceError::NotANumber {
                line: i + 1,
                field: f[j].into(),
            })
        };
        out.push(TracePoint {
            t: num(0)?,
            phase: f[1].parse().map_err(|_| TraceError::NotAPhase {
                line: i + 1,
                field: f[1].into(),
            })?,
            r_r: [num(2)?, num(3)?, num(4)?],
            speed: num(5)?,
            los_deg: [num(6)?, num(7)?],
            sync_error: num(8)?,
        });
    }
    Ok(out)
}

/// Writes a run's `result.json`, `trace.csv` and `timing.json` into `run_dir`.
pub fn save(out: &RunOutput, run_dir: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(run_dir)?;
    let json = serde_json::to_string_pretty(&out.result).map_err(std::io::Error::other)? + "\n";
    std::fs::write(run_dir.join("result.json"), json)?;
    if !out.trace.is_empty() {
        std::fs::write(run_dir.join("trace.csv"), trace_csv(&out.trace))?;
    }
    if let Some(t) = &out.timing {
        let json = serde_json::to_string(t).map_err(std::io::Error::other)? + "\n";
        std::fs::write(run_dir.join("timing.json"), json)?;
    }
    Ok(())
}
