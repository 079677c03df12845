//! The simulator process of the partition.
use sc_flight::roles::SimulatorRole;
use sc_icd::RoleKind;

fn main() -> std::process::ExitCode {
    sc_flight::runner::main(RoleKind::Simulator, SimulatorRole::from_process)
}
