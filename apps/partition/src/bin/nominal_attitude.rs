//! The nominal attitude controller process of the partition.
use sc_partition::roles::{Subsystem, nominal};

fn main() -> std::process::ExitCode {
    sc_partition::main_of(|| nominal(Subsystem::Attitude))
}
