//! The mission in one process: simulator, nominal controllers and the three safety
//! filters in causal order (translational → attitude → robotic), one control step at a
//! time; plus the telemetry record of every step and the run's summary.
//!
//! The partition (one process per module) calls the very same stage functions of
//! [`stages`], so its results are bit-for-bit those of [`Mission`].
//!
//! Every command runs its missions through an [`Executor`] ([`executor`]): in this
//! process ([`InProcess`]) or through the process partition.

pub mod build;
pub mod compare;
pub mod executor;
pub mod mission;
pub mod nominal_source;
pub mod out_dir;
pub mod record;
pub mod replay;
pub mod safe_mode_summary;
pub mod setup;
pub mod stages;
pub mod summary;

pub use executor::{
    ExecError, Executed, Execution, Executor, InProcess, Job, Place, RecordSink, Sinks,
};
pub use mission::{Mission, MissionEnd, RunOptions, all_hold, capture_check, timeout_check};
pub use nominal_source::{
    NominalCommand, NominalCommands, NominalOverride, NominalSource, PartnerProcess,
};
pub use record::{
    StepRecord, TelemetryWriter, knowledge_columns, knowledge_line, parse_telemetry,
    telemetry_columns, timing_columns,
};
pub use replay::ReplayNominals;
pub use setup::{Setup, SetupError};
pub use summary::{SafeModeSummary, Summary, UncertaintySummary, summarize};

/// Names of all 73 barriers in telemetry order: the filters' constraints (translational,
/// attitude, robotic), then the arm–target barriers only the monitor evaluates.
pub fn constraint_names() -> Vec<&'static str> {
    let mut v: Vec<&'static str> = Vec::new();
    v.extend(sc_cbf::names::TRANSLATIONAL.iter());
    v.extend(sc_cbf::names::ATTITUDE.iter());
    v.extend(sc_cbf::names::ROBOTIC.iter());
    v.extend(sc_cbf::names::ARM_TARGET.iter());
    v
}
