//! The process partition: each module of the mission (simulator, three nominal
//! controllers, three safety filters, scheduler, recorder) in its own process,
//! talking only through iceoryx2 zero-copy messages (sc-bus, sc-icd).
//!
//! * [`config`]: `config/partition.toml` — rate groups, deadlines, clock, roles.
//! * [`roles`] / [`recorder`]: the loop of each process (thin binaries call them).
//! * [`launcher`]: starts every process from the config, supervises, tears down.
//! * [`pm_qos`]: the CPU wake-up latency request of real-time runs.
//! * [`latency`]: the latency report of `safe-capture bench latency`.
//!
//! In lock-step mode with one rate group the partition calls exactly the stage
//! functions of `sc_mission::stages`, so its telemetry.csv is bit-for-bit that of
//! `safe-capture run`.

pub mod admission;
pub mod config;
pub mod convert;
pub mod fallback;
pub mod hop_cost;
pub mod latency;
pub mod launcher;
pub mod mcap_out;
pub mod plant_process;
pub mod pm_qos;
pub mod preflight;
pub mod process;
pub mod recorder;
pub mod roles;
pub mod steal;

pub use config::{ClockMode, PartitionConfig, Schedule};
pub use launcher::{LaunchOptions, LaunchReport, launch};

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
