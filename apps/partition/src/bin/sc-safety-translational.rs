//! The translational safety filter process of the partition.
use sc_flight::roles::FilterRole;
use sc_flight::runner;
use sc_icd::{RoleKind, Subsystem};

fn main() -> std::process::ExitCode {
    let s = Subsystem::Translational;
    runner::main(RoleKind::Filter(s), |p| FilterRole::from_process(s, p))
}
