//! The telemetry recorder process of the partition.
fn main() -> std::process::ExitCode {
    sc_partition::main_of(sc_partition::recorder::recorder)
}
