//! The mission through the process partition, as an [`Executor`]: one
//! [`launch`] per job — the partition config's schedule, deadlines and programs, the
//! job's scenario file, lock-step (or real time), a run id of its own, output in the
//! job's folder, partner processes in place of nominal controllers — then the recorder's
//! `telemetry.csv` (bit-for-bit the in-process one in lock-step with one rate group at
//! the control period) and `timing.csv` read back into step records ([`read_run`]:
//! every tick recorded, no sample the schedule requires missing). A caller measures
//! them as it measures an in-process run.
//!
//! A launch that fails (a process crashed, hung or did not start, samples missing, files
//! left in /dev/shm) is a failed run, named in one line ([`PartitionError`]). Partner
//! processes may crash or hang (a red team's hostile ones do on purpose): then only the
//! flight side must end well, and only the partners' own services may miss samples.

use crate::launcher::{LaunchReport, ProcessExit, interrupted, last_log_line};
use crate::recorder::RecorderReport;
use crate::{ClockMode, LaunchOptions, launch};
use sc_icd::{Role, RoleKind};
use sc_mission::{
    ExecError, Executed, Execution, Executor, Job, MissionEnd, NominalSource, PartnerProcess,
    Place, StepRecord, parse_telemetry,
};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// The recorder's large outputs, removed from a run's folder once it is read back unless
/// kept ([`Partition::keep_recordings`]).
pub const RECORDINGS: [&str; 5] = [
    "telemetry.csv",
    "navigation.csv",
    "timing.csv",
    "recording.mcap",
    "latency.csv",
];

/// The simulator's program in a run with an injected failure: it does not exist, so the
/// launch fails as a real one would.
const INJECTED_MISSING_EXEC: &str = "/nonexistent/injected-failure/sc-simulator";

/// [`LaunchReport::code`] of a launch in which a process failed (or that was
/// interrupted): no mission result.
const LAUNCH_FAILED: i32 = 3;

/// How much of a log's last line a failed run's error quotes.
const QUOTED_LOG_CHARS: usize = 200;

/// Why a partition run gave no records. One line each, naming the partition.
#[derive(Debug, thiserror::Error)]
pub enum PartitionError {
    /// The launcher could not run (configuration, I/O), or reported why the run failed.
    #[error("partition: {0}")]
    Launcher(String),
    /// The launcher reported a failure of a run with partner processes.
    #[error("partition: {error} (exit code {code})")]
    LauncherCode { error: String, code: i32 },
    /// A process failed ([`failure_reason`]).
    #[error("partition failed: {0}")]
    Failed(String),
    #[error("partition: {} files left in /dev/shm: {:?}", .0.len(), .0)]
    Leftovers(Vec<PathBuf>),
    /// With partner processes: processes of the flight side did not end well.
    #[error("partition: flight-side processes failed: {}; see {}", .failed.join(", "), .logs.display())]
    FlightSide { failed: Vec<String>, logs: PathBuf },
    /// A file of the run cannot be read or makes no sense.
    #[error("partition: {}: {message}", .path.display())]
    File { path: PathBuf, message: String },
    #[error("partition: the recorder missed {missing} of the samples the schedule requires, lost or late for their step ({}): the telemetry is incomplete", .report.display())]
    SamplesMissed { missing: u64, report: PathBuf },
    #[error("partition: telemetry.csv has {rows} steps, the recorder wrote {steps} ({})", .report.display())]
    StepCount {
        rows: usize,
        steps: u64,
        report: PathBuf,
    },
    #[error("partition: the recorder wrote {steps} steps of the scheduler's {ticks} ticks ({}): the telemetry is incomplete", .log.display())]
    TicksNotRecorded {
        steps: usize,
        ticks: u64,
        log: PathBuf,
    },
    #[error("partition: telemetry.csv row {row} holds step {step} (a step is missing)")]
    StepMissing { row: usize, step: u64 },
    #[error("partition: no step recorded ({})", .telemetry.display())]
    NoStep { telemetry: PathBuf },
    #[error("partition: cannot remove {}: {message}", .path.display())]
    Remove { path: PathBuf, message: String },
}

impl From<PartitionError> for ExecError {
    fn from(e: PartitionError) -> Self {
        ExecError::Executor(Box::new(e))
    }
}

/// Runs missions through the process partition.
pub struct Partition {
    config: PathBuf,
    clock: ClockMode,
    max_ticks: u64,
    deadline_scale: Option<f64>,
    keep_recordings: bool,
    /// Unique per process: a run's id is `<job name>-<tag>`.
    tag: String,
    stopped: AtomicBool,
}

impl Partition {
    /// Runs with the partition config `config`: lock-step, to the end of the mission,
    /// the config's deadlines, the recordings removed once read back, run ids
    /// `<job name>-<pid>-<time>`.
    pub fn new(config: &Path) -> Self {
        let now = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() % 10_000_000_000)
            .unwrap_or(0);
        Self {
            config: config.to_path_buf(),
            clock: ClockMode::LockStep,
            max_ticks: 0,
            deadline_scale: None,
            keep_recordings: false,
            tag: format!("{}-{now}", std::process::id()),
            stopped: AtomicBool::new(false),
        }
    }

    /// Lock-step or real time.
    pub fn clock(mut self, clock: ClockMode) -> Self {
        self.clock = clock;
        self
    }

    /// Stops every run after `n` ticks (0: the whole mission).
    pub fn max_ticks(mut self, n: u64) -> Self {
        self.max_ticks = n;
        self
    }

    /// Lock-step deadlines as this multiple of the real-time ones (`None`: the config's).
    pub fn deadline_scale(mut self, scale: Option<f64>) -> Self {
        self.deadline_scale = scale;
        self
    }

    /// Keeps the recorder's [`RECORDINGS`] in every run's folder.
    pub fn keep_recordings(mut self, keep: bool) -> Self {
        self.keep_recordings = keep;
        self
    }

    /// Run ids `<job name>-<tag>` (unique among the partitions running at once).
    pub fn run_tag(mut self, tag: String) -> Self {
        self.tag = tag;
        self
    }

    /// Records the stop: no further run starts.
    fn stop(&self) -> ExecError {
        self.stopped.store(true, Ordering::SeqCst);
        ExecError::Interrupted
    }

    /// The launch of one job's run.
    fn options(&self, place: &Place, partners: &[PartnerProcess], inject: bool) -> LaunchOptions {
        let mut role_override = partner_overrides(partners);
        if inject {
            let simulator = Role::of(RoleKind::Simulator).name;
            role_override.push((simulator.into(), INJECTED_MISSING_EXEC.into(), Vec::new()));
        }
        LaunchOptions {
            config: self.config.clone(),
            out: place.out.clone(),
            run_id: Some(format!("{}-{}", place.name, self.tag)),
            clock: Some(self.clock),
            max_ticks: Some(self.max_ticks),
            deadline_scale: match self.clock {
                ClockMode::LockStep => self.deadline_scale,
                _ => None,
            },
            scenario: Some(place.scenario_file.clone()),
            role_override,
            quiet: true,
            ..Default::default()
        }
    }

    /// Launches the run and checks how it ended ([`judge`]).
    fn run(
        &self,
        place: &Place,
        partners: &[PartnerProcess],
        inject: bool,
    ) -> Result<(), ExecError> {
        if interrupted() {
            return Err(self.stop());
        }
        // a campaign runs every process of a run itself: it cannot start another host's
        if crate::PartitionConfig::load(&self.config).is_ok_and(|c| c.across_hosts()) {
            return Err(PartitionError::Launcher(format!(
                "{}: a config across hosts ([hosts]) cannot run in a campaign (each host's side is its own launch, docs/PARTITION.md \"Across hosts\")",
                self.config.display()
            ))
            .into());
        }
        let rep = launch(&self.options(place, partners, inject))
            .map_err(|e| PartitionError::Launcher(e.to_string().replace('\n', " ")))?;
        if rep.interrupted || interrupted() {
            return Err(self.stop());
        }
        Ok(judge(&rep, &place.out, partners)?)
    }
}

/// The place and the partner processes of a job the partition can run.
fn accept(job: &mut Job<'_>) -> Result<(Place, Vec<PartnerProcess>), ExecError> {
    let refuse = ExecError::Unsupported;
    if job.options.no_filter {
        return Err(refuse("the nominal-only run needs the mission in process"));
    }
    if job.solve_every_qp || job.sinks.dump_qp.is_some() {
        return Err(refuse("the filters' QPs are only reachable in process"));
    }
    if job.plant.is_some() {
        return Err(refuse(
            "the partition's plant is its config's `[simulator] plant`",
        ));
    }
    let partners = match std::mem::take(&mut job.nominals) {
        NominalSource::Reference => Vec::new(),
        NominalSource::Partners(p) => p,
        NominalSource::Override(_) => {
            return Err(refuse("a nominal override needs the mission in process"));
        }
    };
    let place = job.place.clone().ok_or(refuse(
        "the partition needs the scenario's file and a folder for its outputs",
    ))?;
    Ok((place, partners))
}

impl Executor for Partition {
    fn execute(&self, mut job: Job<'_>) -> Result<Executed, ExecError> {
        let (place, partners) = accept(&mut job)?;
        self.run(&place, &partners, job.inject_failure)?;
        let services = partner_services(&partners);
        let executed = read_run(&place.out, &services)?;
        if !self.keep_recordings {
            remove_recordings(&place.out)?;
        }
        job.sinks.take_all(&executed.records)?;
        Ok(executed)
    }

    fn stopped(&self) -> bool {
        self.stopped.load(Ordering::SeqCst)
    }

    fn execution(&self) -> Execution {
        Execution::Partition
    }
}

/// The role of the nominal controller a partner replaces.
fn partner_role(p: &PartnerProcess) -> &'static Role {
    Role::of(RoleKind::Nominal(p.subsystem))
}

/// The launcher's role overrides `(role, program, args)` that put the partner processes
/// in place of their nominal controllers.
pub fn partner_overrides(partners: &[PartnerProcess]) -> Vec<(String, String, Vec<String>)> {
    partners
        .iter()
        .map(|p| {
            (
                partner_role(p).name.to_string(),
                p.program.display().to_string(),
                p.args.clone(),
            )
        })
        .collect()
}

/// The services the partners publish on (they may miss samples: the partners' own).
fn partner_services(partners: &[PartnerProcess]) -> Vec<&'static str> {
    partners
        .iter()
        .flat_map(|p| partner_role(p).publishes.iter().map(|s| s.as_str()))
        .collect()
}

/// How the launch ended, judged: without partners any failed process (exit code 3)
/// fails the run; with partners, which may crash or hang, the launcher's error, files
/// left in /dev/shm or a flight-side process that did not end well do.
fn judge(
    rep: &LaunchReport,
    out: &Path,
    partners: &[PartnerProcess],
) -> Result<(), PartitionError> {
    if partners.is_empty() {
        return match (rep.code == LAUNCH_FAILED, &rep.error) {
            (false, _) => Ok(()),
            (true, Some(e)) => Err(PartitionError::Launcher(e.clone())),
            (true, None) => Err(PartitionError::Failed(failure_reason(rep, out))),
        };
    }
    if let Some(e) = &rep.error {
        return Err(PartitionError::LauncherCode {
            error: e.clone(),
            code: rep.code,
        });
    }
    if !rep.leftovers.is_empty() {
        return Err(PartitionError::Leftovers(rep.leftovers.clone()));
    }
    let partner_roles: Vec<&str> = partners.iter().map(|p| partner_role(p).name).collect();
    let failed: Vec<String> = rep
        .exits
        .iter()
        .filter(|e| !partner_roles.contains(&e.role.as_str()) && !e.ended_well())
        .map(|e| format!("{} ({:?}/{:?})", e.role, e.code, e.signal))
        .collect();
    if !failed.is_empty() {
        return Err(PartitionError::FlightSide {
            failed,
            logs: out.join("logs"),
        });
    }
    Ok(())
}

/// How a process that failed by itself ended, with the last line of its log.
fn failed_process(e: &ProcessExit, out: &Path) -> String {
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
}

/// Why a launch failed, in one line: the launcher's error, or the processes that failed
/// by themselves (with the last line of their logs), then those the launcher stopped,
/// the roles never started and files left in /dev/shm.
pub fn failure_reason(rep: &LaunchReport, out: &Path) -> String {
    if let Some(e) = &rep.error {
        return e.clone();
    }
    let bad = |e: &&ProcessExit| !e.ended_well();
    let mut parts: Vec<String> = rep
        .exits
        .iter()
        .filter(|e| bad(e) && !e.killed_by_launcher)
        .map(|e| failed_process(e, out))
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
    if let Some(link) = rep
        .link
        .as_ref()
        .filter(|l| bad(l) && !l.killed_by_launcher)
    {
        parts.push(format!(
            "the link to the other host ended ({}: {})",
            link.code.map_or_else(
                || format!("signal {:?}", link.signal),
                |c| format!("exit {c}")
            ),
            super::launcher::last_log_line(&out.join("logs/link.log"), QUOTED_LOG_CHARS)
                .unwrap_or_default()
        ));
    }
    let started: Vec<&str> = rep.exits.iter().map(|e| e.role.as_str()).collect();
    // across hosts the other hosts' roles are not this launch's
    let missing: Vec<&str> = sc_icd::roles::names()
        .filter(|r| !started.contains(r) && rep.host.is_none())
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

fn read(path: &Path) -> Result<String, PartitionError> {
    std::fs::read_to_string(path).map_err(|e| PartitionError::File {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, PartitionError> {
    serde_json::from_str(&read(path)?).map_err(|e| PartitionError::File {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Reads a finished partition run back from `out` into step records and the mission's
/// end, after checking that the telemetry is complete: every tick of the scheduler
/// recorded, no step missing, and no sample the schedule requires missing at the
/// recorder except on the services in `may_miss` (a partner's own), and none of the
/// simulator's own there only after its step was written (a late truth leaves its step's
/// barriers unevaluated).
pub fn read_run(out: &Path, may_miss: &[&str]) -> Result<Executed, PartitionError> {
    let report = out.join("recorder.json");
    let rec: RecorderReport = read_json(&report)?;
    // the simulator's own samples are late only in transport (the commands may be late
    // by a process's fault, which the run's faults and fallbacks already tell)
    let simulator = [
        sc_icd::services::TRUTH.as_str(),
        sc_icd::services::SIM_STATE.as_str(),
        sc_icd::services::NAVIGATION_ERROR.as_str(),
    ];
    let late = rec
        .late
        .iter()
        .filter(|(svc, _)| simulator.contains(&svc.as_str()));
    let missing: u64 = rec
        .missing
        .iter()
        .filter(|(svc, _)| !may_miss.contains(&svc.as_str()))
        .chain(late)
        .map(|(_, n)| n)
        .sum();
    if missing > 0 {
        return Err(PartitionError::SamplesMissed { missing, report });
    }
    let file_error = |e: sc_mission::record::TelemetryError| PartitionError::File {
        path: out.to_path_buf(),
        message: e.to_string(),
    };
    let mut records = parse_telemetry(
        &read(&out.join("telemetry.csv"))?,
        &read(&out.join("timing.csv"))?,
        true,
    )
    .map_err(file_error)?;
    // a declared uncertainty: the navigation errors and the barriers on knowledge
    let knowledge = out.join("navigation.csv");
    if knowledge.exists() {
        sc_mission::record::read_knowledge(&read(&knowledge)?, &mut records).map_err(file_error)?;
    }
    if records.len() as u64 != rec.steps {
        return Err(PartitionError::StepCount {
            rows: records.len(),
            steps: rec.steps,
            report,
        });
    }
    check_every_tick(out, &records)?;
    let end = mission_end(out, &rec, &records)?;
    Ok(Executed { records, end })
}

/// Every tick of the scheduler is a step of the telemetry, in order (a state sample the
/// recorder never got is a step missing from it).
fn check_every_tick(out: &Path, records: &[StepRecord]) -> Result<(), PartitionError> {
    let path = out.join("scheduler.json");
    let sched: serde_json::Value = read_json(&path)?;
    let ticks = sched["ticks"].as_u64().ok_or(PartitionError::File {
        path,
        message: "no `ticks`".into(),
    })?;
    if records.len() as u64 != ticks {
        return Err(PartitionError::TicksNotRecorded {
            steps: records.len(),
            ticks,
            log: out.join("logs/recorder.log"),
        });
    }
    match records
        .iter()
        .enumerate()
        .find(|(i, r)| r.step != *i as u64)
    {
        Some((row, r)) => Err(PartitionError::StepMissing { row, step: r.step }),
        None => Ok(()),
    }
}

/// How the mission ended, as the recorder names it, at the last step.
fn mission_end(
    out: &Path,
    rec: &RecorderReport,
    records: &[StepRecord],
) -> Result<MissionEnd, PartitionError> {
    let Some(last) = records.last() else {
        return Err(PartitionError::NoStep {
            telemetry: out.join("telemetry.csv"),
        });
    };
    MissionEnd::from_name(&rec.end, last.t).ok_or_else(|| PartitionError::File {
        path: out.join("recorder.json"),
        message: format!("unknown end `{}`", rec.end),
    })
}

/// Removes the recorder's [`RECORDINGS`] from `out`.
fn remove_recordings(out: &Path) -> Result<(), PartitionError> {
    for f in RECORDINGS {
        let p = out.join(f);
        if p.exists() {
            std::fs::remove_file(&p).map_err(|e| PartitionError::Remove {
                path: p.clone(),
                message: e.to_string(),
            })?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use sc_core::Subsystem;

    fn partner(s: Subsystem) -> PartnerProcess {
        PartnerProcess {
            subsystem: s,
            program: PathBuf::from("/usr/bin/python3"),
            args: vec!["hostile.py".into(), "--role".into(), s.name().into()],
        }
    }

    fn exit(role: &str, code: Option<i32>) -> ProcessExit {
        ProcessExit {
            role: role.into(),
            pid: 1,
            code,
            signal: None,
            killed_by_launcher: false,
        }
    }

    fn report(exits: Vec<ProcessExit>, code: i32) -> LaunchReport {
        LaunchReport {
            run_id: "t".into(),
            exits,
            host: None,
            link: None,
            code,
            interrupted: false,
            leftovers: Vec::new(),
            stale_removed: 0,
            cpu_wakeup_latency: String::new(),
            wall_s: 0.0,
            error: None,
        }
    }

    /// Partners replace their subsystems' nominal roles and may miss on their own
    /// services only.
    #[test]
    fn partners_are_their_nominal_roles() {
        let p = [partner(Subsystem::Attitude), partner(Subsystem::Robotic)];
        let o = partner_overrides(&p);
        assert_eq!(o[0].0, "nominal_attitude");
        assert_eq!(o[1].0, "nominal_robotic");
        assert_eq!(o[1].1, "/usr/bin/python3");
        assert_eq!(
            partner_services(&p),
            vec![
                "safe_capture/nominal/attitude",
                "safe_capture/nominal/robotic"
            ]
        );
    }

    /// A crashed partner is no failure of the run; a crashed flight-side process is;
    /// without partners any failed launch is.
    #[test]
    fn only_the_flight_side_must_end_well() {
        let out = Path::new("/tmp/x");
        let p = [partner(Subsystem::Attitude)];
        let crashed_partner = report(vec![exit("nominal_attitude", Some(1))], LAUNCH_FAILED);
        assert!(judge(&crashed_partner, out, &p).is_ok());
        let crashed_filter = report(vec![exit("filter_attitude", Some(1))], LAUNCH_FAILED);
        let e = judge(&crashed_filter, out, &p).unwrap_err().to_string();
        assert_eq!(
            e,
            "partition: flight-side processes failed: filter_attitude (Some(1)/None); see /tmp/x/logs"
        );
        let e = judge(&crashed_partner, out, &[]).unwrap_err().to_string();
        assert!(
            e.starts_with("partition failed: nominal_attitude (exit code 1)"),
            "{e}"
        );
        assert!(judge(&report(Vec::new(), 1), out, &[]).is_ok());
    }

    /// What the partition cannot do is refused before anything starts.
    #[test]
    fn in_process_only_jobs_are_refused() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let setup = sc_mission::Setup::load(&root.join("config/scenario.toml")).unwrap();
        let mut job = Job::new(setup.clone());
        assert!(matches!(accept(&mut job), Err(ExecError::Unsupported(_))));
        let mut job = Job::new(setup);
        job.options.no_filter = true;
        let e = Partition::new(Path::new("x.toml"))
            .execute(job)
            .unwrap_err();
        assert!(matches!(e, ExecError::Unsupported(_)), "{e}");
    }

    /// A late sample of the simulator's own (its step's truth unevaluated) makes the run
    /// unreadable, like a lost one; a late partner command does not.
    #[test]
    fn a_late_truth_is_refused_a_late_partner_command_is_not() {
        let dir = std::env::temp_dir().join(format!("sc-late-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let write = |late: &str| {
            let rep = RecorderReport {
                late: [(late.to_string(), 1)].into_iter().collect(),
                ..Default::default()
            };
            std::fs::write(
                dir.join("recorder.json"),
                serde_json::to_string(&rep).unwrap(),
            )
            .unwrap();
            read_run(&dir, &[])
        };
        let truth = write("safe_capture/sim/truth");
        assert!(
            matches!(truth, Err(PartitionError::SamplesMissed { missing: 1, .. })),
            "{truth:?}"
        );
        // past the check, to the missing telemetry
        let partner = write("safe_capture/nominal/robotic");
        assert!(
            matches!(partner, Err(PartitionError::File { .. })),
            "{partner:?}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
