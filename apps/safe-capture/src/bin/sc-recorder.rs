//! The telemetry recorder process of the partition (a ground tool).
use sc_ground::recorder::RecorderRole;
use sc_icd::RoleKind;

fn main() -> std::process::ExitCode {
    // summary.json names the build that wrote it
    sc_mission::build::register(env!("CARGO_PKG_VERSION"), env!("SC_GIT_COMMIT"));
    // it recorded everything: exit 0 also when the mission did not capture (the
    // mission's verdict is in summary.json, which the launcher reads)
    sc_flight::runner::main(RoleKind::Recorder, RecorderRole::from_process)
}
