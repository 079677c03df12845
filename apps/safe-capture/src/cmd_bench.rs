//! `safe-capture bench`: speed and latency measurements, reported as percentiles.

use clap::Subcommand;
use std::process::ExitCode;

/// Benchmarks (run them on an otherwise idle machine; build with --release).
///
/// Exit codes: 0 measured, 2 bad arguments or configuration (each benchmark's --help
/// says more).
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    what: What,
}

#[derive(Subcommand)]
enum What {
    /// Safety-layer solve time per filter and in total over whole missions.
    Filters(crate::cmd_bench_filters::Args),
    /// Partition latency in real time: per hop and whole tick, percentiles, HDR histogram.
    Latency(crate::cmd_bench_latency::Args),
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    match a.what {
        What::Filters(x) => crate::cmd_bench_filters::run(x),
        What::Latency(x) => crate::cmd_bench_latency::run(x),
    }
}
