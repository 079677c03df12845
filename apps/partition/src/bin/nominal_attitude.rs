//! The nominal attitude controller process of the partition.
use sc_flight::roles::{Subsystem, nominal};

fn main() -> std::process::ExitCode {
    sc_flight::main_of(|| nominal(Subsystem::Attitude))
}
