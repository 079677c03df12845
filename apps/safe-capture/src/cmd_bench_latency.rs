//! `safe-capture bench latency`: the partition's latency in real time (logic in sc-ground).

use sc_ground::latency::{BenchOptions, bench, markdown};
use std::path::PathBuf;
use std::process::ExitCode;

/// Exit code of a measurement stopped by SIGINT/SIGTERM (as `launch` and `montecarlo`).
const EXIT_INTERRUPTED: u8 = 3;

/// Runs the partition in real-time mode (paced ticks) and reports per-hop and
/// whole-tick latency (scheduler tick → robotic safe command delivered to the
/// simulator): N, min/p50/p90/p99/p99.9/max, cycle slips, deadline misses, an HDR
/// histogram (latency_whole_tick.hgrm), log-scale figures (latency.svg per hop,
/// latency_timeline.svg per tick with the host's steal; both with the 1 ms p99 target and
/// the paper's 3.75 ms maximum as labelled lines) and the machine's facts. Writes latency_report.{json,md} into OUT.
///
/// While it runs, one line every 10 s on stderr says how many steps were recorded.
///
/// Exit codes: 0 measured, 2 bad arguments or configuration, or the partition did not
/// run, 3 interrupted (SIGINT/SIGTERM: no report; what was written stays in
/// OUT.incomplete, OUT is not replaced).
#[derive(clap::Args)]
pub struct Args {
    /// Measured ticks (after the warm-up; at least 1).
    #[arg(long, default_value_t = 3000, value_parser = clap::value_parser!(u64).range(1..))]
    ticks: u64,
    /// Warm-up ticks excluded from the statistics.
    #[arg(long, default_value_t = 50)]
    warmup: u64,
    /// Partition config (its rate groups set the period).
    #[arg(long, value_name = "FILE", default_value_os_t = crate::home::shipped("config/partition.toml"))]
    config: PathBuf,
    #[arg(long, value_name = "DIR", default_value = "out/bench-latency", help = crate::out_help!())]
    out: PathBuf,
    #[arg(long, help = crate::out_folder::FORCE_HELP)]
    force: bool,
    #[command(flatten)]
    figures: crate::figure_format::FigureFormatArg,
    /// The run's id (its iceoryx2 prefix; default: a fresh one). Across hosts (the config's
    /// `[hosts]`) this runs the home host's side and prints the command that starts each
    /// other host's; the report marks the hops that cross the link.
    #[arg(long, value_name = "ID")]
    run_id: Option<String>,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    // nothing starts unless the scenario and every program are there
    let cfg = sc_ground::PartitionConfig::load(&a.config)?;
    sc_ground::preflight::preflight(&cfg, &None)
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.config.display()))?;
    a.figures.check()?;
    let run_id =
        match (&cfg.hosts, &a.run_id) {
            (Some(_), id) => Some(id.clone().unwrap_or_else(|| {
                format!("bench-{}-{}", std::process::id(), sc_icd::monotonic_ns())
            })),
            (None, id) => id.clone(),
        };
    let staged = crate::out_folder::stage(&a.out, "bench latency", a.force)?;
    // said once every check passed: the other hosts' commands
    if let (Some(hosts), Some(id)) = (&cfg.hosts, &run_id) {
        let real_time = ["--real-time".to_string()];
        crate::cmd_launch::say_other_hosts(&a.config, hosts, &hosts.home, None, id, &real_time);
    }
    let r = match bench(&BenchOptions {
        config: a.config,
        out: staged.path().to_path_buf(),
        ticks: a.ticks,
        warmup: a.warmup,
        bin_dir: None,
        run_id,
    }) {
        Ok(r) => r,
        Err(e @ sc_ground::error::BenchError::Interrupted { .. }) => {
            let kept = staged.abandon();
            errln!(
                "bench latency: {e}; no report (partial output in {}; {} not replaced)",
                kept.as_deref().unwrap_or(&a.out).display(),
                a.out.display()
            );
            return Ok(ExitCode::from(EXIT_INTERRUPTED));
        }
        Err(e) => return Err(e.into()),
    };
    a.figures.export_dir(staged.path())?;
    staged.commit()?;
    out!("{}", markdown(&r));
    outln!("-> {}", a.out.display());
    Ok(ExitCode::SUCCESS)
}
