//! The ground side of the process partition: what starts, watches and records a run,
//! and measures it — never part of the flight software.
//!
//! * [`launcher`]: starts every process from the config, supervises, tears down.
//! * [`executor`]: the mission through the partition as an `sc_mission::Executor`
//!   (launch, then the recorder's telemetry read back).
//! * [`preflight`]: every role's program and the scenario checked before anything starts.
//! * [`recorder`] / [`mcap`] (also reachable as `mcap_out`): the telemetry recorder
//!   role (CSV, summary, MCAP for Foxglove).
//! * [`latency`], [`hop_cost`], [`steal`], [`pm_qos`]: the latency bench of
//!   `safe-capture bench latency` and what it needs.

pub mod error;
pub mod executor;
pub mod hop_cost;
pub mod latency;
pub mod launcher;
pub mod mcap;
pub use self::mcap as mcap_out;
pub mod pm_qos;
pub mod preflight;
pub mod recorder;
pub mod steal;

pub use launcher::{LaunchOptions, LaunchReport, launch};
pub use sc_flight::{ClockMode, PartitionConfig, Schedule, config};
