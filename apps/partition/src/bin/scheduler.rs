//! The scheduler (rate-group driver) of the partition.
fn main() -> std::process::ExitCode {
    sc_partition::main_of(sc_partition::roles::scheduler)
}
