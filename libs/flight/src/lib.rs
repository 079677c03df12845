//! The flight side of the process partition: each module of the mission (simulator,
//! three nominal controllers, three safety filters, scheduler) in its own process,
//! talking only through iceoryx2 zero-copy messages (sc-bus, sc-icd).
//!
//! * [`config`]: `config/partition.toml` — rate groups, deadlines, clock, roles.
//! * [`roles`]: the loop of each process (thin binaries call them).
//! * [`admission`], [`fallback`], [`convert`]: what the simulator applies, the backups,
//!   messages ↔ the libraries' types.
//!
//! Nothing here plots, runs campaigns, writes MCAP or draws progress bars: the ground
//! tools (launcher, preflight, recorder, latency bench) are `sc-ground`.
//!
//! In lock-step mode with one rate group the partition calls exactly the stage
//! functions of `sc_mission::stages`, so its telemetry.csv is bit-for-bit that of
//! `safe-capture run`.

pub mod admission;
pub mod config;
pub mod convert;
pub mod process;
pub mod roles;

pub use config::{ClockMode, PartitionConfig, Schedule};

/// Written by the scheduler into the output directory once every process joined the
/// start-up handshake: from then on a process that dies is a degraded mode, not a failed
/// start (the launcher tears a run down at once when a process fails before it).
pub const ALL_READY: &str = "all_ready";

/// Runs a role's loop and turns the result into the process exit code
/// (errors are printed as one line).
pub fn main_of(f: fn() -> anyhow::Result<i32>) -> std::process::ExitCode {
    match f() {
        Ok(c) => std::process::ExitCode::from(c.clamp(0, 255) as u8),
        Err(e) => {
            let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", chain.join(": ").replace('\n', " "));
            std::process::ExitCode::from(2)
        }
    }
}
