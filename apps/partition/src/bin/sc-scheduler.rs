//! The scheduler (rate-group driver) of the partition.
use sc_flight::roles::SchedulerRole;
use sc_icd::RoleKind;

fn main() -> std::process::ExitCode {
    sc_flight::runner::main(RoleKind::Scheduler, SchedulerRole::from_process)
}
