//! The attitude safety filter process of the partition.
use sc_flight::roles::{Subsystem, filter};

fn main() -> std::process::ExitCode {
    sc_flight::main_of(|| filter(Subsystem::Attitude))
}
