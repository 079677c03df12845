//! One way to run a mission, whoever asks (`run`, `montecarlo`, `redteam`, `bench`): a
//! [`Job`] — the setup, the run options, where the nominal commands come from
//! ([`NominalSource`]), where every step's record goes as it is computed ([`Sinks`]) —
//! handed to an [`Executor`], which returns every step's record and how the mission
//! ended ([`Executed`]).
//!
//! * [`InProcess`]: the mission in this process ([`Mission`], the one mission loop),
//!   propagated by our simulator or by another plant ([`Job::plant`], e.g. Basilisk's
//!   `sc_sim::ProcessPlant`).
//! * The process partition (`sc_ground::executor::Partition`): one process per module,
//!   the records read back from the recorder's telemetry.
//!
//! What a caller measures from the records is the same whatever the executor, so
//! executors that reproduce the mission's records give the same results.

use crate::mission::{Mission, MissionEnd, RunOptions, StepQps};
use crate::nominal_source::NominalSource;
use crate::record::{StepRecord, TelemetryWriter};
use crate::setup::{Setup, SetupError};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::PathBuf;

/// Receives every step's record as the mission computes it (e.g. a [`TelemetryWriter`]).
pub trait RecordSink {
    fn record(&mut self, r: &StepRecord) -> std::io::Result<()>;
}

impl<W: Write> RecordSink for TelemetryWriter<W> {
    fn record(&mut self, r: &StepRecord) -> std::io::Result<()> {
        self.write(r)
    }
}

/// Where a run's records go as they are computed, besides the records returned.
#[derive(Default)]
pub struct Sinks<'a> {
    /// Every step's record (telemetry files).
    pub telemetry: Option<&'a mut dyn RecordSink>,
    /// The three QPs of every step as JSON lines (`--dump-qp`; in process only).
    pub dump_qp: Option<&'a mut dyn Write>,
    /// Called with every step's record (a progress line).
    pub progress: Option<&'a mut dyn FnMut(&StepRecord)>,
}

impl Sinks<'_> {
    /// Hands `r` (and, for `--dump-qp`, the step's QPs) to every sink; a write that fails
    /// is kept in `failed` (the first one) and the run goes on.
    fn take(
        &mut self,
        r: &StepRecord,
        qps: impl FnOnce() -> Option<StepQps>,
        failed: &mut Option<std::io::Error>,
    ) {
        if let Some(t) = self.telemetry.as_mut()
            && let Err(e) = t.record(r)
        {
            failed.get_or_insert(e);
        }
        if let (Some(f), Some(q)) = (self.dump_qp.as_mut(), qps()) {
            write_qps(&mut **f, r, &q, failed);
        }
        if let Some(p) = self.progress.as_mut() {
            p(r);
        }
    }

    /// Hands every record of a finished run to the sinks (an executor that gets the
    /// records only at the end); the first write that failed.
    pub fn take_all(&mut self, records: &[StepRecord]) -> Result<(), ExecError> {
        let mut failed = None;
        for r in records {
            self.take(r, || None, &mut failed);
        }
        failed.map_or(Ok(()), |e| Err(ExecError::Sink(e)))
    }
}

/// One JSON line per QP of the step: `{"step", "t_s", "filter", "qp"}`.
fn write_qps(f: &mut dyn Write, r: &StepRecord, q: &StepQps, failed: &mut Option<std::io::Error>) {
    for (name, d) in [
        ("translational", &q.translational),
        ("attitude", &q.attitude),
        ("robotic", &q.robotic),
    ] {
        let line = serde_json::json!({"step": r.step, "t_s": r.t, "filter": name, "qp": d});
        if let Err(e) = writeln!(f, "{line}") {
            failed.get_or_insert(e);
        }
    }
}

/// Where an executor that runs the mission outside this process finds the scenario and
/// writes its own files.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Place {
    /// The run's name, unique among the runs of one campaign (e.g. `mc7`, `rt3`).
    pub name: String,
    /// The file the setup's scenario was read from (the processes read it).
    pub scenario_file: PathBuf,
    /// The folder of the executor's files (the partition's logs, reports, telemetry).
    pub out: PathBuf,
}

/// Everything one mission run needs.
pub struct Job<'a> {
    pub setup: Setup,
    pub options: RunOptions,
    pub nominals: NominalSource,
    /// Every filter solves its QP at every step, also for a nominal that is already
    /// safe (the skip path off: the worst case a flight processor budgets for).
    pub solve_every_qp: bool,
    /// Propagates the true state instead of our simulator (in process only).
    pub plant: Option<Box<dyn sc_sim::Plant + Send>>,
    pub sinks: Sinks<'a>,
    /// Needed by an executor that runs the mission outside this process.
    pub place: Option<Place>,
    /// Test hook: the run fails (in process: a panic at [`INJECTED_FAILURE_STEP`];
    /// through the partition: the simulator's program is missing).
    pub inject_failure: bool,
}

impl Job<'_> {
    /// The mission of `setup` with the reference controllers, default options, no sink.
    pub fn new(setup: Setup) -> Self {
        Self {
            setup,
            options: RunOptions::default(),
            nominals: NominalSource::Reference,
            solve_every_qp: false,
            plant: None,
            sinks: Sinks::default(),
            place: None,
            inject_failure: false,
        }
    }
}

/// The step at which an in-process run with [`Job::inject_failure`] panics.
pub const INJECTED_FAILURE_STEP: u64 = 10;

/// What a mission run produced.
#[derive(Debug, Clone)]
pub struct Executed {
    /// Every control step's record, in order.
    pub records: Vec<StepRecord>,
    pub end: MissionEnd,
}

/// Where the missions of an executor run (recorded in a campaign's `campaign.json`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Execution {
    /// Simulator, nominal controllers and filters in this process ([`InProcess`]).
    #[default]
    InProcess,
    /// Through the process partition, one process per module.
    Partition,
}

impl Execution {
    pub fn is_in_process(&self) -> bool {
        *self == Execution::InProcess
    }
}

/// Why a mission run produced no result. One line each.
#[derive(Debug, thiserror::Error)]
pub enum ExecError {
    /// The mission could not be built from its setup.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// The plant in the loop failed to start.
    #[error(transparent)]
    Plant(#[from] sc_sim::PlantError),
    /// A sink could not be written.
    #[error("writing telemetry")]
    Sink(#[source] std::io::Error),
    /// The job asks for what this executor cannot do.
    #[error("{0}")]
    Unsupported(&'static str),
    /// The run was cut short by a stop request (SIGINT/SIGTERM): no result.
    #[error("interrupted")]
    Interrupted,
    /// The executor's own failure (e.g. a partition launch that failed), in its words.
    #[error(transparent)]
    Executor(Box<dyn std::error::Error + Send + Sync>),
}

/// Runs missions.
pub trait Executor: Sync {
    /// Runs `job`'s mission to its end.
    fn execute(&self, job: Job<'_>) -> Result<Executed, ExecError>;

    /// True once no further mission may start (e.g. after Ctrl-C); a run that failed by
    /// then was cut short, it is no result.
    fn stopped(&self) -> bool {
        false
    }

    /// Where its missions run.
    fn execution(&self) -> Execution;
}

/// The mission in this process: [`Mission`] stepped to its end.
#[derive(Debug, Clone, Copy, Default)]
pub struct InProcess;

impl Executor for InProcess {
    fn execute(&self, job: Job<'_>) -> Result<Executed, ExecError> {
        let Job {
            setup,
            options,
            nominals,
            solve_every_qp,
            plant,
            mut sinks,
            place: _,
            inject_failure,
        } = job;
        let nominal_override = match nominals {
            NominalSource::Reference => None,
            NominalSource::Override(o) => Some(o),
            NominalSource::Partners(_) => {
                return Err(ExecError::Unsupported(
                    "partner processes need the process partition",
                ));
            }
        };
        let mut mission = Mission::new(setup, options)?;
        mission.nominal_override = nominal_override;
        if let Some(p) = plant {
            mission.set_plant(p)?;
        }
        if solve_every_qp {
            mission.safety.translational.set_skip_enabled(false);
            mission.safety.attitude.set_skip_enabled(false);
            mission.safety.robotic.set_skip_enabled(false);
        }
        let mut records = Vec::with_capacity(mission.setup.scenario.control_steps() + 1);
        let mut failed = None;
        let end = mission.run(|m, r| {
            if inject_failure && r.step == INJECTED_FAILURE_STEP {
                panic!("injected failure");
            }
            sinks.take(r, || Some(m.last_qps()), &mut failed);
            records.push(*r);
        });
        match failed {
            Some(e) => Err(ExecError::Sink(e)),
            None => Ok(Executed { records, end }),
        }
    }

    fn execution(&self) -> Execution {
        Execution::InProcess
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nominal_source::{NominalCommand, NominalCommands, NominalOverride};
    use std::path::Path;

    /// A short mission of the default scenario (`duration_s` seconds).
    fn short_setup(duration_s: f64) -> Setup {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let mut setup = Setup::load(&root.join("config/scenario.toml")).unwrap();
        setup.scenario.mission.duration_s = duration_s;
        setup
    }

    /// Sinks see exactly the records returned, in order; the QP dump has three lines a
    /// step.
    #[test]
    fn every_sink_sees_every_record() {
        let setup = short_setup(2.0);
        let (mut tel, mut tim, mut qps) = (Vec::new(), Vec::new(), Vec::new());
        let mut steps = Vec::new();
        let mut progress = |r: &StepRecord| steps.push(r.step);
        let executed = {
            let mut w = TelemetryWriter::new(&mut tel, &mut tim).unwrap();
            let mut job = Job::new(setup);
            job.sinks = Sinks {
                telemetry: Some(&mut w),
                dump_qp: Some(&mut qps),
                progress: Some(&mut progress),
            };
            let executed = InProcess.execute(job).unwrap();
            w.flush().unwrap();
            executed
        };
        let n = executed.records.len();
        assert!(n > 10, "{n} steps");
        assert_eq!(steps, (0..n as u64).collect::<Vec<_>>());
        let parsed = crate::parse_telemetry(
            std::str::from_utf8(&tel).unwrap(),
            std::str::from_utf8(&tim).unwrap(),
            true,
        )
        .unwrap();
        assert_eq!(parsed.len(), n);
        assert_eq!(String::from_utf8(qps).unwrap().lines().count(), 3 * n);
        assert!(matches!(executed.end, MissionEnd::Timeout { .. }));
    }

    /// Silences the attitude controller.
    struct Silent;
    impl NominalOverride for Silent {
        fn commands(
            &mut self,
            _: &sc_sim::Observation,
            _: &sc_nominal::NominalOutput,
        ) -> NominalCommands {
            NominalCommands {
                attitude: NominalCommand::Missing,
                ..NominalCommands::REFERENCE
            }
        }
    }

    /// The job's nominal source reaches the filters; partner processes are refused in
    /// process; an injected failure panics at its step.
    #[test]
    fn nominal_sources_and_what_in_process_refuses() {
        let mut job = Job::new(short_setup(1.0));
        job.nominals = NominalSource::Override(Box::new(Silent));
        let r = InProcess.execute(job).unwrap().records;
        assert!(
            r.iter()
                .all(|r| r.tau_b_nom[0].is_nan() && r.f_h_nom[0].is_finite())
        );
        let mut job = Job::new(short_setup(1.0));
        job.nominals = NominalSource::Partners(Vec::new());
        assert!(matches!(
            InProcess.execute(job),
            Err(ExecError::Unsupported(_))
        ));
        let mut job = Job::new(short_setup(2.0));
        job.inject_failure = true;
        let panicked =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| InProcess.execute(job)));
        assert!(panicked.is_err());
    }
}
