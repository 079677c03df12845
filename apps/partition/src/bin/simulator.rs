//! The simulator process of the partition.
fn main() -> std::process::ExitCode {
    sc_flight::main_of(sc_flight::roles::simulator)
}
