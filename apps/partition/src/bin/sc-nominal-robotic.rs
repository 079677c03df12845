//! The nominal robotic controller process of the partition.
use sc_flight::roles::NominalRole;
use sc_flight::runner;
use sc_icd::{RoleKind, Subsystem};

fn main() -> std::process::ExitCode {
    let s = Subsystem::Robotic;
    runner::main(RoleKind::Nominal(s), |p| NominalRole::from_process(s, p))
}
