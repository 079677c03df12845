//! The flight side of the process partition: each module of the mission (simulator,
//! three nominal controllers, three safety filters, scheduler) in its own process,
//! talking only through iceoryx2 zero-copy messages (sc-bus, sc-icd).
//!
//! * [`config`]: `config/partition.toml` — rate groups, deadlines, clock, roles.
//! * [`component`]: a role as a transport-free component (events in, actions out);
//!   [`roles`]: the scheduler, simulator, nominal controller and filter components;
//!   [`runner`]: the one iceoryx2 runner that drives any of them (each executable is one
//!   line calling [`runner::main`]).
//! * [`admission`], [`convert`]: what the simulator applies, messages ↔ the libraries'
//!   types. The backups are the safety layer's (`sc_cbf::chain`).
//!
//! Nothing here plots, runs campaigns, writes MCAP or draws progress bars: the ground
//! tools (launcher, preflight, recorder, latency bench) are `sc-ground`.
//!
//! In lock-step mode with one rate group the partition runs exactly the safety layer's
//! causal chain (`sc_cbf::chain::SafetyLayer`) and the nominal controllers as
//! `safe-capture run` does, so its telemetry.csv is bit-for-bit that of `run`.

pub mod admission;
pub mod component;
pub mod config;
pub mod convert;
pub mod error;
pub mod hosts;
pub mod process;
pub mod roles;
pub mod runner;

pub use component::{Component, Message, Next, Outbox, WakeSet, Wakeup};
pub use config::{ClockMode, PartitionConfig, Schedule};
pub use error::FlightError;

/// Written by the scheduler into the output directory once every process joined the
/// start-up handshake: from then on a process that dies is a degraded mode, not a failed
/// start (the launcher tears a run down at once when a process fails before it).
pub const ALL_READY: &str = "all_ready";
