//! The translational safety filter process of the partition.
fn main() -> std::process::ExitCode {
    sc_partition::main_of(|| sc_partition::roles::filter(0))
}
