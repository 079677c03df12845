//! The telemetry recorder process of the partition.
fn main() -> std::process::ExitCode {
    // summary.json names the build that wrote it
    sc_mission::build::register(env!("CARGO_PKG_VERSION"), env!("SC_GIT_COMMIT"));
    sc_partition::main_of(sc_partition::recorder::recorder)
}
