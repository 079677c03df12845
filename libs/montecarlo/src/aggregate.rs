//! A campaign's aggregate, (re)built from its run directories by [`aggregate`]:
//! `runs.csv`, `runs_timing.csv`, `summary.json` ([`CampaignSummary`]), `report.md` and
//! the figures. Everything deterministic is built from the deterministic files only, so
//! an unsharded campaign and the merge of its shards give byte-identical files.

use crate::campaign::{CampaignInfo, McError, io, json, read, run_dir, write};
use crate::hist::LogHistogram;
use crate::host::HostLoad;
use crate::run::{self, CPU_TIMERS, RunMetrics, RunResult, RunTiming, TIMERS};
use sc_mission::summary::TimeStats;
use sc_plots::{BarrierMinima, CampaignFigures, Geometry, RunPoint, RuntimeBar, TracePoint};
use sc_scenario::Scenario;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

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
    /// Completed runs with at least one filter fault flag, and which.
    pub faulted_runs: usize,
    #[serde(default)]
    pub faulted: Vec<usize>,
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
    /// The declared uncertainty profile of the runs (absent: `exact`): "safe" is then
    /// on the simulated truth, with the plant and the estimate drawn from it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<String>,
    /// The declared error sources no filter margin covers: outside the promise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_covered: Vec<String>,
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

/// One run as read back from its directory.
struct Loaded {
    result: RunResult,
    trace: Vec<TracePoint>,
    timing: Option<RunTiming>,
}

/// The runs of the campaign `dir`, in the order of their indices.
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
    ks.into_iter().map(|k| load_run(dir, k)).collect()
}

/// Run `k` of the campaign `dir`.
fn load_run(dir: &Path, k: usize) -> Result<Loaded, McError> {
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
        run::parse_trace(&read(&tp)?).map_err(|e| McError::Io {
            path: tp.display().to_string(),
            message: e.to_string(),
        })?
    } else {
        Vec::new()
    };
    let tj = d.join("timing.json");
    let timing = if tj.is_file() { Some(json(&tj)?) } else { None };
    Ok(Loaded {
        result,
        trace,
        timing,
    })
}

/// The completed runs (with metrics), in order.
fn completed(loaded: &[Loaded]) -> impl Iterator<Item = (&Loaded, &RunMetrics)> {
    loaded
        .iter()
        .filter_map(|l| l.result.metrics.as_ref().map(|m| (l, m)))
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

/// Columns of `runs.csv` before the per-phase ones.
const RUNS_COLUMNS: [&str; 17] = [
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
];

/// The header of `runs.csv`.
fn runs_csv_header(phases: &[String], names: &[&str]) -> String {
    let mut cols: Vec<String> = RUNS_COLUMNS.iter().map(|s| s.to_string()).collect();
    for p in phases {
        cols.push(format!("sync_error_peak_{p}_rad_s"));
    }
    for p in phases {
        cols.push(format!("joint_torque_norm_peak_{p}_nm"));
    }
    cols.push("joint_torque_norm_rms_grasp_nm".into());
    cols.push("fault_count".into());
    cols.push("faults".into());
    for n in names {
        cols.push(format!("min_h_{n}"));
    }
    cols.push("error".into());
    cols.join(",") + "\n"
}

/// The dispersion's cells of a `runs.csv` row (empty when sampling failed).
fn dispersion_cells(r: &RunResult) -> Vec<String> {
    match &r.dispersion {
        Some(d) => vec![
            d.distance_m.to_string(),
            d.off_axis_deg.to_string(),
            d.azimuth_deg.to_string(),
            d.position_r_m[0].to_string(),
            d.position_r_m[1].to_string(),
            d.position_r_m[2].to_string(),
            d.initial_los_deg.to_string(),
            d.tumble_rate_rad_s.to_string(),
        ],
        None => vec![String::new(); 8],
    }
}

/// The metrics' cells of a `runs.csv` row.
fn metric_cells(m: &RunMetrics, phases: &[String], names: &[&str]) -> Vec<String> {
    let (mc, mv) = names
        .iter()
        .filter_map(|n| m.min_h.get(*n).copied().flatten().map(|h| (n, h)))
        .fold((String::new(), None::<f64>), |acc, (n, h)| match acc.1 {
            Some(b) if b <= h => acc,
            _ => (n.to_string(), Some(h)),
        });
    let mut v = vec![
        m.end.clone(),
        m.captured.to_string(),
        num(m.capture_time_s),
        m.safe.to_string(),
        mc,
        num(mv),
    ];
    for p in phases {
        v.push(num(m.sync_error_peak_rad_s.get(p).copied().flatten()));
    }
    for p in phases {
        v.push(num(m.joint_torque_norm_peak_nm.get(p).copied().flatten()));
    }
    v.push(num(m.joint_torque_norm_rms_grasp_nm));
    v.push(m.fault_count.to_string());
    v.push(m.fault_flags.join(";"));
    for n in names {
        v.push(num(m.min_h.get(*n).copied().flatten()));
    }
    v
}

/// `runs.csv` header and rows (deterministic).
fn runs_csv(loaded: &[Loaded], phases: &[String]) -> String {
    let names = sc_mission::constraint_names();
    let mut s = runs_csv_header(phases, &names);
    for l in loaded {
        let r = &l.result;
        let mut v: Vec<String> = vec![r.run.to_string(), r.seed.to_string(), r.status.clone()];
        v.extend(dispersion_cells(r));
        match &r.metrics {
            Some(m) => v.extend(metric_cells(m, phases, &names)),
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

/// The summary of no run yet: the campaign's identity and the sessions'.
fn empty_summary(info: &CampaignInfo, sessions: &Sessions, runs: usize) -> CampaignSummary {
    let build = sc_mission::build::current();
    CampaignSummary {
        version: build.version,
        git_commit: build.git_commit,
        runs,
        campaign_runs: info.runs,
        shard: info.shard,
        seed: info.seed,
        safe_runs: 0,
        captured_runs: 0,
        failed_runs: 0,
        faulted_runs: 0,
        faulted: Vec::new(),
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
            completed_runs: runs,
            planned_runs: planned,
        }),
        uncertainty: info.uncertainty.clone(),
        not_covered: info.not_covered.clone(),
    }
}

/// How many runs were safe, captured, failed, faulted, and which were not.
fn count_outcomes(s: &mut CampaignSummary, loaded: &[Loaded]) {
    for l in loaded {
        let r = &l.result;
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
            s.faulted.push(r.run);
        }
    }
}

/// Per barrier ([`sc_mission::constraint_names`]): the worst minimum over the completed
/// runs with its run, and every run's minimum (for the figure).
fn barrier_minima(loaded: &[Loaded]) -> (BTreeMap<String, Worst>, Vec<BarrierMinima>) {
    let names = sc_mission::constraint_names();
    let none = Worst {
        min_h: None,
        run: None,
    };
    let mut worst: BTreeMap<String, Worst> = names
        .iter()
        .map(|n| (n.to_string(), none.clone()))
        .collect();
    let mut minima: Vec<BarrierMinima> = names
        .iter()
        .map(|n| BarrierMinima {
            name: n.to_string(),
            values: Vec::new(),
        })
        .collect();
    for (l, m) in completed(loaded) {
        for (i, n) in names.iter().enumerate() {
            if let Some(h) = m.min_h.get(*n).copied().flatten() {
                minima[i].values.push(h);
                let w = worst.get_mut(*n).expect("constraint present");
                if w.min_h.is_none_or(|b| h < b) {
                    w.min_h = Some(h);
                    w.run = Some(l.result.run);
                }
            }
        }
    }
    (worst, minima)
}

/// The spread over the completed runs of the capture time, the per-phase peaks and the
/// grasping phase's RMS joint torque.
fn spreads(s: &mut CampaignSummary, loaded: &[Loaded]) {
    let mut sync: BTreeMap<String, SpreadAcc> = BTreeMap::new();
    let mut torque: BTreeMap<String, SpreadAcc> = BTreeMap::new();
    let mut rms = SpreadAcc::default();
    let mut capture = SpreadAcc::default();
    for (l, m) in completed(loaded) {
        let run = l.result.run;
        capture.add(m.capture_time_s, run);
        for (p, v) in &m.sync_error_peak_rad_s {
            sync.entry(p.clone()).or_default().add(*v, run);
        }
        for (p, v) in &m.joint_torque_norm_peak_nm {
            torque.entry(p.clone()).or_default().add(*v, run);
        }
        rms.add(m.joint_torque_norm_rms_grasp_nm, run);
    }
    let found = |acc: BTreeMap<String, SpreadAcc>| -> BTreeMap<String, Spread> {
        acc.into_iter()
            .filter_map(|(k, v)| v.0.map(|x| (k, x)))
            .collect()
    };
    s.capture_time_s = capture.0;
    s.sync_error_peak_rad_s = found(sync);
    s.joint_torque_norm_peak_nm = found(torque);
    s.joint_torque_norm_rms_grasp_nm = rms.0;
}

/// The grasping phase's results against the target's tumbling rate over the completed
/// runs: their correlations ([`crate::trend`]) and the points of the torque-vs-sync
/// figure.
fn tumble_rate_trends(
    loaded: &[Loaded],
    grasp: Option<&str>,
) -> (BTreeMap<String, crate::trend::Trend>, Vec<RunPoint>) {
    let mut points = Vec::new();
    let mut pairs: BTreeMap<&str, Vec<(f64, f64)>> = BTreeMap::new();
    for (l, m) in completed(loaded) {
        let (Some(d), Some(g)) = (&l.result.dispersion, grasp) else {
            continue;
        };
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
                pairs.entry(k).or_default().push((d.tumble_rate_rad_s, v));
            }
        }
        if let (Some(peak), Some(tq)) = (peak, m.joint_torque_norm_rms_grasp_nm) {
            points.push(RunPoint {
                run: l.result.run,
                tumble_rate: d.tumble_rate_rad_s,
                peak_sync_grasp: peak,
                torque_norm_grasp: tq,
            });
        }
    }
    let trends = pairs
        .into_iter()
        .map(|(k, v)| (k.to_string(), crate::trend::trend(&v)))
        .collect();
    (trends, points)
}

/// Solve-time statistics per filter over every step of every run, wall clock and thread
/// CPU time, from the runs' merged histograms.
fn solve_times(s: &mut CampaignSummary, loaded: &[Loaded]) {
    let mut hist: BTreeMap<String, LogHistogram> = BTreeMap::new();
    for t in loaded.iter().filter_map(|l| l.timing.as_ref()) {
        for (n, h) in &t.histograms {
            hist.entry(n.clone()).or_default().merge(h);
        }
    }
    let stats = |name: &str| hist.get(name).map(|h| h.stats()).unwrap_or_default();
    s.solve_time_us = TIMERS.iter().map(|n| (n.to_string(), stats(n))).collect();
    s.solve_cpu_us = TIMERS
        .iter()
        .zip(CPU_TIMERS)
        .map(|(n, c)| (n.to_string(), stats(c)))
        .collect();
}

/// The campaign's figures into `dir/figures`.
fn figures(
    dir: &Path,
    scenario: &Scenario,
    s: &CampaignSummary,
    loaded: &[Loaded],
    points: &[RunPoint],
    minima: &[BarrierMinima],
) -> Result<(), McError> {
    let traces: Vec<(usize, Vec<TracePoint>)> = completed(loaded)
        .filter(|(l, _)| !l.trace.is_empty())
        .map(|(l, _)| (l.result.run, l.trace.clone()))
        .collect();
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
        geometry: Geometry::from_scenario(scenario),
        traces: &traces,
        points,
        runtime: &runtime,
        runtime_reference: Some((
            "paper (CasADi + OSQP)".into(),
            sc_plots::paper::PAPER_TOTAL_GEOMEAN_MS * 1e3,
            sc_plots::paper::PAPER_TOTAL_MAX_MS * 1e3,
        )),
        minima,
    };
    sc_plots::campaign_figures(&dir.join("figures"), &figs)
        .map_err(|e| McError::Invalid(e.to_string()))?;
    Ok(())
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
    write(&dir.join("runs.csv"), runs_csv(&loaded, &phases))?;
    write(&dir.join("runs_timing.csv"), runs_timing_csv(&loaded))?;
    let mut s = empty_summary(&info, sessions, loaded.len());
    count_outcomes(&mut s, &loaded);
    let (worst, minima) = barrier_minima(&loaded);
    s.worst = worst;
    spreads(&mut s, &loaded);
    let (trends, points) = tumble_rate_trends(&loaded, grasp.as_deref());
    s.trend_with_tumble_rate = trends;
    solve_times(&mut s, &loaded);
    let text = serde_json::to_string_pretty(&s).map_err(|e| McError::Invalid(e.to_string()))?;
    write(&dir.join("summary.json"), text + "\n")?;
    let results: Vec<RunResult> = loaded.iter().map(|l| l.result.clone()).collect();
    let report = crate::report::report(&s, &results, grasp.as_deref(), &phases, info.execution);
    write(&dir.join("report.md"), report)?;
    figures(dir, &scenario, &s, &loaded, &points, &minima)?;
    Ok(s)
}
