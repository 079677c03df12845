//! `safe-capture montecarlo --mode partition`: every run's mission through the process
//! partition (sc-ground), measured from the recorder's telemetry by the same code as
//! an in-process run.
//!
//! Per run K: `sc_ground::launch` with the user's partition config (schedule,
//! deadlines, executables), the run's `runs/K/scenario.toml`, lock-step, to the end of
//! the mission, a run id of its own, output in `runs/K/partition/`. The recorder's
//! `telemetry.csv` (bit-for-bit the in-process one in lock-step with one rate group at
//! the control period) and `timing.csv` are read back into step records
//! (`sc_mission::parse_telemetry`) and handed to the campaign, which measures them like
//! any run. A launch that fails (a process crashed, hung or did not start, samples
//! missing, files left in /dev/shm) is a failed run; the campaign goes on.

use anyhow::Context;
use sc_core::Subsystem;
use sc_ground::launcher::{LaunchReport, interrupted, last_log_line};
use sc_ground::recorder::RecorderReport;
use sc_ground::{ClockMode, LaunchOptions, PartitionConfig, launch};
use sc_mission::{MissionEnd, Setup, StepRecord, parse_telemetry};
use sc_montecarlo::campaign::PARTITION_DIR;
use sc_montecarlo::{Execution, Executor};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// The recorder's large outputs, removed from `runs/K/partition/` once the run is
/// measured unless kept (`--keep-recordings`).
pub const RECORDINGS: [&str; 4] = [
    "telemetry.csv",
    "timing.csv",
    "recording.mcap",
    "latency.csv",
];

/// The simulator executable of a run with an injected failure: it does not exist, so
/// the launch fails as a real one would.
const INJECTED_MISSING_EXEC: &str = "/nonexistent/injected-failure/sc-simulator";

/// Runs missions through the process partition.
pub struct PartitionExecutor {
    config: PathBuf,
    keep_recordings: bool,
    /// Unique per campaign process: run ids are `mc<K>-<tag>`.
    tag: String,
    stopped: AtomicBool,
}

impl PartitionExecutor {
    /// Checks the partition config and that every role's executable exists, before any
    /// run starts. Returns the executor and, when the config's schedule is not the
    /// scenario's single control period, a note that results will differ from
    /// in-process runs.
    pub fn new(
        config: &Path,
        keep_recordings: bool,
        scenario: &Path,
    ) -> anyhow::Result<(Self, Option<String>)> {
        let cfg = PartitionConfig::load(config).context("--partition-config")?;
        let schedule = cfg.schedule().context("--partition-config")?;
        // every role's program, as the launcher will find it (the scenario is the
        // campaign's, checked by the campaign)
        sc_ground::preflight::check_programs(&cfg, &None)
            .map_err(|e| anyhow::anyhow!("--partition-config {}: {e}", config.display()))?;
        let period = sc_scenario::Scenario::load(scenario)
            .map(|s| s.mission.control_period_s)
            .ok();
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
        let now = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() % 10_000_000_000)
            .unwrap_or(0);
        Ok((
            Self {
                config: config.to_path_buf(),
                keep_recordings,
                tag: format!("{}-{now}", std::process::id()),
                stopped: AtomicBool::new(false),
            },
            note,
        ))
    }

    fn stop(&self) -> String {
        self.stopped.store(true, Ordering::SeqCst);
        "interrupted".into()
    }
}

/// How much of a log's last line a failed run's error quotes.
const QUOTED_LOG_CHARS: usize = 200;

/// Why a launch failed, in one line.
fn failure(rep: &LaunchReport, out: &Path) -> String {
    match &rep.error {
        Some(e) => format!("partition: {e}"),
        None => format!("partition failed: {}", failure_reason(rep, out)),
    }
}

/// Why a launch failed, in one line: the launcher's error, or the processes that failed
/// by themselves (with the last line of their logs), then those the launcher stopped,
/// the roles never started and files left in /dev/shm.
pub fn failure_reason(rep: &LaunchReport, out: &Path) -> String {
    if let Some(e) = &rep.error {
        return e.clone();
    }
    let bad = |e: &&sc_ground::launcher::ProcessExit| !e.ended_well();
    // the processes that failed by themselves, with the last line of their log
    let mut parts: Vec<String> = rep
        .exits
        .iter()
        .filter(|e| bad(e) && !e.killed_by_launcher)
        .map(|e| {
            let how = match (e.code, e.signal) {
                (Some(c), _) => format!("exit code {c}"),
                (_, Some(s)) => format!("signal {s}"),
                _ => "unknown end".into(),
            };
            let log = last_log_line(
                &out.join("logs").join(format!("{}.log", e.role)),
                QUOTED_LOG_CHARS,
            )
            .map(|l| format!(": {l}"))
            .unwrap_or_default();
            format!("{} ({how}){log}", e.role)
        })
        .collect();
    let stopped: Vec<&str> = rep
        .exits
        .iter()
        .filter(|e| bad(e) && e.killed_by_launcher)
        .map(|e| e.role.as_str())
        .collect();
    if !stopped.is_empty() {
        parts.push(format!(
            "then stopped by the launcher: {}",
            stopped.join(", ")
        ));
    }
    let started: Vec<&str> = rep.exits.iter().map(|e| e.role.as_str()).collect();
    let missing: Vec<&str> = sc_icd::roles::names()
        .filter(|r| !started.contains(r))
        .collect();
    if !missing.is_empty() {
        parts.push(format!("not started: {}", missing.join(", ")));
    }
    if !rep.leftovers.is_empty() {
        parts.push(format!("{} files left in /dev/shm", rep.leftovers.len()));
    }
    if parts.is_empty() {
        parts.push("the launch reported a failure".into());
    }
    format!(
        "{}; see {}",
        parts.join("; ").replace('\n', " "),
        out.join("logs").display()
    )
}

fn read(path: &Path) -> Result<String, String> {
    std::fs::read_to_string(path).map_err(|e| format!("partition: {}: {e}", path.display()))
}

/// Reads a finished partition run back from `out` into step records and the mission's
/// end, after checking that the telemetry is complete: every tick of the scheduler
/// recorded, no step missing, and no sample the schedule requires missing at the
/// recorder except on the services in `may_miss` (a hostile partner's own service).
pub fn read_run(out: &Path, may_miss: &[&str]) -> Result<(Vec<StepRecord>, MissionEnd), String> {
    let rec_path = out.join("recorder.json");
    let rec: RecorderReport = serde_json::from_str(&read(&rec_path)?)
        .map_err(|e| format!("partition: {}: {e}", rec_path.display()))?;
    let missing: u64 = rec
        .missing
        .iter()
        .filter(|(svc, _)| !may_miss.contains(&svc.as_str()))
        .map(|(_, n)| n)
        .sum();
    if missing > 0 {
        return Err(format!(
            "partition: the recorder missed {missing} of the samples the schedule requires ({}): the telemetry is incomplete",
            rec_path.display()
        ));
    }
    let records = parse_telemetry(
        &read(&out.join("telemetry.csv"))?,
        &read(&out.join("timing.csv"))?,
        true,
    )
    .map_err(|e| format!("partition: {}: {e}", out.display()))?;
    if records.len() as u64 != rec.steps {
        return Err(format!(
            "partition: telemetry.csv has {} steps, the recorder wrote {} ({})",
            records.len(),
            rec.steps,
            rec_path.display()
        ));
    }
    // a state sample the recorder never got is a step missing from the telemetry
    let sched_path = out.join("scheduler.json");
    let sched: serde_json::Value = serde_json::from_str(&read(&sched_path)?)
        .map_err(|e| format!("partition: {}: {e}", sched_path.display()))?;
    let ticks = sched["ticks"]
        .as_u64()
        .ok_or_else(|| format!("partition: {}: no `ticks`", sched_path.display()))?;
    if records.len() as u64 != ticks {
        return Err(format!(
            "partition: the recorder wrote {} steps of the scheduler's {ticks} ticks ({}): the telemetry is incomplete",
            records.len(),
            out.join("logs/recorder.log").display()
        ));
    }
    if let Some((i, r)) = records
        .iter()
        .enumerate()
        .find(|(i, r)| r.step != *i as u64)
    {
        return Err(format!(
            "partition: telemetry.csv row {i} holds step {} (a step is missing)",
            r.step
        ));
    }
    let Some(last) = records.last() else {
        return Err(format!(
            "partition: no step recorded ({})",
            out.join("telemetry.csv").display()
        ));
    };
    let end = MissionEnd::from_name(&rec.end, last.t).ok_or_else(|| {
        format!(
            "partition: {}: unknown end `{}`",
            rec_path.display(),
            rec.end
        )
    })?;
    Ok((records, end))
}

impl Executor for PartitionExecutor {
    fn execute(
        &self,
        k: usize,
        _setup: Setup,
        run_dir: &Path,
        inject_failure: bool,
    ) -> Result<(Vec<StepRecord>, MissionEnd), String> {
        if interrupted() {
            return Err(self.stop());
        }
        let out = run_dir.join(PARTITION_DIR);
        let mut opts = LaunchOptions {
            config: self.config.clone(),
            out: out.clone(),
            run_id: Some(format!("mc{k}-{}", self.tag)),
            clock: Some(ClockMode::LockStep),
            max_ticks: Some(0),
            scenario: Some(run_dir.join("scenario.toml")),
            quiet: true,
            ..Default::default()
        };
        if inject_failure {
            opts.role_override
                .push(("simulator".into(), INJECTED_MISSING_EXEC.into(), Vec::new()));
        }
        let rep = launch(&opts)
            .map_err(|e| format!("partition: {}", e.to_string().replace('\n', " ")))?;
        if rep.interrupted || interrupted() {
            return Err(self.stop());
        }
        if rep.code == 3 {
            return Err(failure(&rep, &out));
        }
        let (records, end) = read_run(&out, &[])?;
        if !self.keep_recordings {
            for f in RECORDINGS {
                let p = out.join(f);
                if p.exists() {
                    std::fs::remove_file(&p)
                        .map_err(|e| format!("partition: cannot remove {}: {e}", p.display()))?;
                }
            }
        }
        Ok((records, end))
    }

    fn stopped(&self) -> bool {
        self.stopped.load(Ordering::SeqCst)
    }

    fn execution(&self) -> Execution {
        Execution::Partition
    }
}
