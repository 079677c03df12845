//! `safe-capture bench filters`: per-filter and total safety-layer solve time over whole
//! default missions, as geometric mean and percentiles, in wall and thread CPU time.

use sc_cbf::FilterStatus;
use sc_core::{PerSubsystem, Subsystem};
use sc_mission::summary::TimeStats;
use sc_mission::{Executor, InProcess, Job, Setup, StepRecord};
use sc_montecarlo::host::{HostLoad, HostSample};
use sc_plots::paper::{PAPER_TOTAL_GEOMEAN_MS, PAPER_TOTAL_MAX_MS};
use std::path::PathBuf;
use std::process::ExitCode;

/// Runs the mission REPEAT times in one process and reports the solve time of each filter
/// and of the whole safety layer per control step (µs): N, geomean, p50, p90, p99, p99.9,
/// max — as wall time (what a deadline sees, preemption included), as the thread's CPU
/// time (the filter's own work), and as the wall time inside the QP solver alone (`qp`:
/// every solve of the step, without building the rows or certifying the command) — and,
/// over the steps where a QP was solved, the solver's iterations and the number of active
/// barrier rows. Also the wall time per mission.
///
/// With --solve-all the filters' skip path is off: every step solves its QP although the
/// nominal command may already be safe (the worst case a flight processor must budget for).
/// --scenario may be given several times (e.g. every `runs/*/scenario.toml` of a Monte
/// Carlo campaign: each is run REPEAT times), and --redteam CASE replaces the nominal
/// controllers by an in-process adversary (`safe-capture redteam --list`), so the same
/// figures cover the campaigns the filters work hardest in.
///
/// --json FILE writes {"total"|"translational"|"attitude"|"robotic": {"n", "geomean_us",
/// "p50_us", "p90_us", "p99_us", "p999_us", "max_us", "cpu": {same keys}, "qp": {same
/// keys}, "solved_steps", "iterations": {"mean", "max"}, "active_rows": {"mean", "max"}},
/// "host_load": {"start"|"end": {"load_avg_1min", "cpus"}}, "solve_all", "uncertainty", "mission_wall_s"}.
///
/// Wall-clock tails depend on what else runs: the host's 1-minute load average at the
/// start and the end is printed (and in the JSON); with a load above the CPU count the
/// wall maxima include waiting for a CPU (compare the cpu lines).
///
/// Exit codes: 0 done, 2 bad arguments or configuration.
#[derive(clap::Args)]
pub struct Args {
    /// Scenario file; several: each one's missions are pooled.
    #[arg(long, value_name = "FILE", num_args = 1.., default_values_os_t = [crate::default_scenario()])]
    scenario: Vec<PathBuf>,
    /// Red team: an in-process adversary in place of the nominal controller(s), e.g.
    /// `all/random:1` (`safe-capture redteam --list` lists the cases).
    #[arg(long, value_name = "CASE")]
    redteam: Option<String>,
    /// Number of missions.
    #[arg(long, default_value_t = 5)]
    repeat: usize,
    /// Solve every QP (the skip path for an already safe nominal off).
    #[arg(long)]
    solve_all: bool,
    /// Write the report as JSON to FILE as well.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Every mission under a declared uncertainty (its realisation from the seed): what
    /// the margins for the declared errors cost.
    #[command(flatten)]
    uncertainty: crate::uncertainty_arg::UncertaintyArg,
}

fn pct(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    sorted[((p / 100.0 * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1]
}

/// geomean, p50, p90, p99, p99.9, max of `v` (sorted in place).
fn stats(v: &mut [f64]) -> [f64; 6] {
    v.sort_by(f64::total_cmp);
    [
        TimeStats::of(v).geomean,
        pct(v, 50.0),
        pct(v, 90.0),
        pct(v, 99.0),
        pct(v, 99.9),
        pct(v, 100.0),
    ]
}

fn json_stats(s: &[f64; 6], n: usize) -> serde_json::Value {
    serde_json::json!({"n": n, "geomean_us": s[0], "p50_us": s[1], "p90_us": s[2], "p99_us": s[3], "p999_us": s[4], "max_us": s[5]})
}

/// Per filter: (iterations, active rows) of the steps that solved a QP.
#[derive(Default)]
struct SolverWork {
    iterations: Vec<u32>,
    active_rows: Vec<u32>,
}

impl SolverWork {
    fn push(&mut self, status: FilterStatus, iterations: u32, active: u64) {
        if matches!(status, FilterStatus::Solved | FilterStatus::Relaxed) {
            self.iterations.push(iterations);
            self.active_rows.push(active.count_ones());
        }
    }

    fn mean_max(v: &[u32]) -> (f64, u32) {
        if v.is_empty() {
            return (0.0, 0);
        }
        let sum: u64 = v.iter().map(|&x| x as u64).sum();
        (
            sum as f64 / v.len() as f64,
            v.iter().copied().max().unwrap_or(0),
        )
    }
}

/// The names of the four timings of a step: the three filters, then the whole layer.
const TIMINGS: [&str; 4] = ["translational", "attitude", "robotic", "total"];

/// Every step's timings and solver work over all missions, and each mission's wall time.
#[derive(Default)]
struct Samples {
    /// Per [`TIMINGS`]: wall time, thread CPU time, time in the QP solver [µs].
    wall: [Vec<f64>; 4],
    cpu: [Vec<f64>; 4],
    qp: [Vec<f64>; 4],
    work: PerSubsystem<SolverWork>,
    mission_wall: Vec<f64>,
}

impl Samples {
    fn add(&mut self, r: &StepRecord) {
        let (t, c, q) = (r.solve_time_us(), r.solve_cpu_us(), r.qp_time_us());
        for i in 0..4 {
            self.wall[i].push(t[i]);
            self.cpu[i].push(c[i]);
            self.qp[i].push(q[i]);
        }
        let (t, a, ro) = (
            &r.translational.report,
            &r.attitude.report,
            &r.robotic.report,
        );
        let w = &mut self.work;
        w[Subsystem::Translational].push(t.status, t.iterations, t.active);
        w[Subsystem::Attitude].push(a.status, a.iterations, a.active);
        w[Subsystem::Robotic].push(ro.status, ro.iterations, ro.active);
    }
}

/// Runs every mission in this process, `--repeat` times each scenario, collecting the
/// timings; one progress line per mission on stderr.
fn run_missions(
    a: &Args,
    setups: &[Setup],
    case: Option<sc_redteam::Case>,
) -> anyhow::Result<Samples> {
    let mut samples = Samples::default();
    let tty = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let missions = a.repeat.max(1) * setups.len();
    for k in 0..missions {
        let setup = &setups[k % setups.len()];
        let started = std::time::Instant::now();
        let mut job = Job::new(setup.clone());
        if let Some(c) = &case {
            job.nominals = sc_redteam::Adversary::nominals(setup, c);
        }
        job.solve_every_qp = a.solve_all;
        let executed = InProcess.execute(job)?;
        executed.records.iter().for_each(|r| samples.add(r));
        samples.mission_wall.push(started.elapsed().as_secs_f64());
        if tty {
            err!("\r  mission {}/{missions}", k + 1);
        } else {
            errln!("  mission {}/{missions}", k + 1);
        }
    }
    if tty {
        errln!();
    }
    Ok(samples)
}

/// Prints the table of every timing (wall, cpu, qp) and returns each one's JSON entry.
fn timing_table(samples: &mut Samples) -> serde_json::Map<String, serde_json::Value> {
    outln!(
        "{:<14} {:<5} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "filter",
        "clock",
        "N",
        "geomean",
        "p50",
        "p90",
        "p99",
        "p99.9",
        "max"
    );
    let mut report = serde_json::Map::new();
    for (i, n) in TIMINGS.iter().enumerate() {
        let w = stats(&mut samples.wall[i]);
        let c = stats(&mut samples.cpu[i]);
        let q = stats(&mut samples.qp[i]);
        for (clock, s) in [("wall", &w), ("cpu", &c), ("qp", &q)] {
            outln!(
                "{:<14} {:<5} {:>7} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2}",
                n,
                clock,
                samples.wall[i].len(),
                s[0],
                s[1],
                s[2],
                s[3],
                s[4],
                s[5]
            );
        }
        let mut entry = json_stats(&w, samples.wall[i].len());
        entry["cpu"] = json_stats(&c, samples.cpu[i].len());
        entry["qp"] = json_stats(&q, samples.qp[i].len());
        if let Some(s) = Subsystem::parse(n) {
            let work = &samples.work[s];
            let (im, ix) = SolverWork::mean_max(&work.iterations);
            let (am, ax) = SolverWork::mean_max(&work.active_rows);
            entry["solved_steps"] = serde_json::json!(work.iterations.len());
            entry["iterations"] = serde_json::json!({"mean": im, "max": ix});
            entry["active_rows"] = serde_json::json!({"mean": am, "max": ax});
        }
        report.insert(n.to_string(), entry);
    }
    report
}

/// Prints each filter's solved QPs, solver iterations and active rows.
fn solver_work_table(work: &PerSubsystem<SolverWork>) {
    outln!("QPs solved (steps), solver iterations and active barrier rows per solved QP:");
    for (s, w) in work.iter() {
        let (im, ix) = SolverWork::mean_max(&w.iterations);
        let (am, ax) = SolverWork::mean_max(&w.active_rows);
        outln!(
            "{:<14} solved {:>7}  iterations mean {:>5.2} max {:>3}  active rows mean {:>5.2} max {:>3}",
            s.name(),
            w.iterations.len(),
            im,
            ix,
            am,
            ax
        );
    }
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let case = a
        .redteam
        .as_deref()
        .map(sc_redteam::Case::parse)
        .transpose()
        .map_err(|e| anyhow::anyhow!("--redteam: {e}"))?;
    a.uncertainty.refuse_truth("bench filters")?;
    let mut setups = a
        .scenario
        .iter()
        .map(|p| {
            let s = Setup::load(p)?;
            s.check_before_run(p)
                .map_err(|e| anyhow::anyhow!("{}: {e}", p.display()))?;
            Ok(s)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    for s in &mut setups {
        a.uncertainty.apply(&mut s.scenario)?;
        s.check_target_geometry()?;
    }
    let load_start = HostSample::now();
    let mut samples = run_missions(&a, &setups, case)?;
    let missions = samples.mission_wall.len();
    outln!(
        "safety-layer solve time per control step [us] ({missions} missions{}{}, {})",
        a.redteam
            .as_deref()
            .map(|c| format!(" under red-team case {c}"))
            .unwrap_or_default(),
        a.uncertainty
            .uncertainty
            .as_deref()
            .map(|u| format!(", uncertainty {u}"))
            .unwrap_or_default(),
        if a.solve_all {
            "every QP solved"
        } else {
            "skip path on"
        }
    );
    let mut report = timing_table(&mut samples);
    solver_work_table(&samples.work);
    let mission_wall = &samples.mission_wall;
    let mean_wall = mission_wall.iter().sum::<f64>() / mission_wall.len() as f64;
    outln!("whole mission (simulator + nominal + filters) wall time: mean {mean_wall:.3} s");
    let load = HostLoad {
        start: load_start,
        end: HostSample::now(),
    };
    outln!("{}", load_line(&load));
    outln!(
        "paper (CasADi + OSQP from Python, whole safety layer per step): geomean {PAPER_TOTAL_GEOMEAN_MS} ms, max {PAPER_TOTAL_MAX_MS} ms"
    );
    report.insert("host_load".into(), serde_json::to_value(load)?);
    report.insert("solve_all".into(), serde_json::json!(a.solve_all));
    report.insert(
        "uncertainty".into(),
        serde_json::json!(a.uncertainty.uncertainty.as_deref().unwrap_or("exact")),
    );
    report.insert("mission_wall_s".into(), serde_json::json!(mission_wall));
    if let Some(p) = a.json {
        std::fs::write(&p, serde_json::to_string_pretty(&report)?)?;
    }
    Ok(ExitCode::SUCCESS)
}

/// The host's load during the benchmark, and what it means for the wall-clock tails.
fn load_line(l: &HostLoad) -> String {
    let f = |v: Option<f64>| v.map_or("unknown".to_string(), |v| format!("{v:.2}"));
    let busy = [l.start, l.end]
        .iter()
        .any(|s| s.load_avg_1min.is_some_and(|v| v > s.cpus as f64));
    format!(
        "host load (1-min average) {} at start, {} at end, on {} CPUs{}",
        f(l.start.load_avg_1min),
        f(l.end.load_avg_1min),
        l.end.cpus,
        if busy {
            ": busier than its CPUs - the wall tails (p99.9, max) include waiting for a CPU; compare the cpu lines"
        } else {
            ""
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(load: Option<f64>) -> HostSample {
        HostSample {
            load_avg_1min: load,
            cpus: 2,
        }
    }

    #[test]
    fn a_busy_host_is_named_in_the_load_line() {
        let quiet = HostLoad {
            start: sample(Some(0.5)),
            end: sample(Some(1.0)),
        };
        assert_eq!(
            load_line(&quiet),
            "host load (1-min average) 0.50 at start, 1.00 at end, on 2 CPUs"
        );
        let busy = HostLoad {
            start: sample(Some(0.5)),
            end: sample(Some(3.5)),
        };
        assert!(load_line(&busy).contains("busier than its CPUs"));
        let unknown = HostLoad {
            start: sample(None),
            end: sample(None),
        };
        assert!(load_line(&unknown).contains("unknown at start"));
    }
}
