//! The attitude safety filter process of the partition.
use sc_partition::roles::{Subsystem, filter};

fn main() -> std::process::ExitCode {
    sc_partition::main_of(|| filter(Subsystem::Attitude))
}
