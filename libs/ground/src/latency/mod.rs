//! Latency of the partition (`safe-capture bench latency`): per hop and for the whole
//! tick (scheduler tick sent → robotic safe command delivered to the simulator), from
//! the stamps every message carries (latency.csv written by the recorder).

mod analyse;

pub use analyse::analyse;

use crate::error::BenchError;
use crate::launcher::{LaunchOptions, launch};
use hdrhistogram::Histogram;
use sc_plots::paper::PAPER_TOTAL_MAX_MS;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

use std::path::PathBuf;
use std::time::Duration;

/// Percentiles of one hop [µs].
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct HopStats {
    pub n: u64,
    pub min_us: f64,
    pub p50_us: f64,
    pub p90_us: f64,
    pub p99_us: f64,
    pub p99_9_us: f64,
    pub max_us: f64,
}

/// Facts of the machine the benchmark ran on.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Machine {
    pub cores: usize,
    pub kernel: String,
    pub cpu: String,
    /// The CPU wake-up latency in effect during the run (the launcher's PM QoS
    /// request, config `cpu_wakeup_latency_us`); per-role priorities and CPUs are in
    /// the run's `partition.effective.toml`.
    #[serde(default)]
    pub cpu_wakeup_latency: String,
    /// CPU time the hypervisor gave to others while the run wanted it ("steal",
    /// `/proc/stat`, summed over all CPUs) during the benchmark [s]; None where the
    /// kernel does not report it. Bursts of steal are what the latency tail follows
    /// on a virtual machine.
    #[serde(default)]
    pub steal_s: Option<f64>,
}

/// The latency report.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct LatencyReport {
    pub clock: String,
    pub period_s: f64,
    pub ticks_total: u64,
    pub warmup_ticks: u64,
    /// Whole tick: scheduler send → robotic safe command delivered to the simulator.
    pub whole_tick: HopStats,
    /// Per hop, in causal order.
    pub hops: BTreeMap<String, HopStats>,
    pub cycle_slips: u64,
    /// Ticks (after warm-up) in which a stage missed its deadline: the simulator or a
    /// filter used a fallback for an input that was missing at it.
    pub deadline_misses: u64,
    /// The pre-tick warm-up lead in effect [µs] (config `warmup_lead_us`; 0 = off).
    #[serde(default)]
    pub warmup_lead_us: u32,
    /// The host's steal time around the measured ticks (from `steal.csv`, when the
    /// run has one).
    #[serde(default)]
    pub steal: Option<StealSummary>,
    pub machine: Machine,
}

/// Which ticks had host steal around them, and the latency of the others.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct StealSummary {
    /// Sampling period of the steal counter [s].
    pub sample_period_s: f64,
    /// Measured ticks whose sampling window had steal (the counter counts 10 ms units).
    pub ticks_with_steal: u64,
    /// Whole-tick latency of the ticks without steal around them.
    pub whole_tick_without_steal: HopStats,
    /// Ticks over the 1 ms target, and how many of them had steal around them.
    pub over_1ms: u64,
    pub over_1ms_with_steal: u64,
}

/// Hops measured, (name, from column, to column) of latency.csv.
pub const HOPS: [(&str, &str, &str); 9] = [
    ("1 tick -> simulator", "tick_send_ns", "sim_recv_ns"),
    (
        "2 simulator observe+publish",
        "sim_recv_ns",
        "state_publish_ns",
    ),
    (
        "3 state -> nominal translational out",
        "state_publish_ns",
        "nom_t_publish_ns",
    ),
    (
        "4 state -> nominal attitude out",
        "state_publish_ns",
        "nom_a_publish_ns",
    ),
    (
        "5 state -> nominal robotic out",
        "state_publish_ns",
        "nom_r_publish_ns",
    ),
    (
        "6 state -> translational filter out",
        "state_publish_ns",
        "safe_t_publish_ns",
    ),
    (
        "7 translational -> attitude filter out",
        "safe_t_publish_ns",
        "safe_a_publish_ns",
    ),
    (
        "8 attitude -> robotic filter out",
        "safe_a_publish_ns",
        "safe_r_publish_ns",
    ),
    (
        "9 robotic safe -> simulator",
        "safe_r_publish_ns",
        "sim_safe_recv_ns",
    ),
];

/// The role that stamps each column of latency.csv that a hop of [`HOPS`] starts or
/// ends at.
const COLUMN_ROLE: [(&str, &str); 10] = [
    ("tick_send_ns", "scheduler"),
    ("sim_recv_ns", "simulator"),
    ("state_publish_ns", "simulator"),
    ("nom_t_publish_ns", "nominal_translational"),
    ("nom_a_publish_ns", "nominal_attitude"),
    ("nom_r_publish_ns", "nominal_robotic"),
    ("safe_t_publish_ns", "safety_translational"),
    ("safe_a_publish_ns", "safety_attitude"),
    ("safe_r_publish_ns", "safety_robotic"),
    ("sim_safe_recv_ns", "simulator"),
];

/// What a hop that crosses hosts is called in the report: its name and this.
pub const ACROSS_THE_LINK: &str = " (across the link)";

/// The hops of [`HOPS`] whose two ends run on different hosts of `cfg` (none on one host).
pub fn hops_across_hosts(cfg: &crate::PartitionConfig) -> Vec<&'static str> {
    let role = |col: &str| COLUMN_ROLE.iter().find(|(c, _)| *c == col).map(|(_, r)| *r);
    let host = |col: &str| role(col).map(|r| cfg.host_of(r).to_string());
    HOPS.iter()
        .filter(|(_, from, to)| host(from) != host(to))
        .map(|(name, _, _)| *name)
        .collect()
}

/// Marks the hops of `r` that cross hosts ([`ACROSS_THE_LINK`]).
fn mark_hops_across_hosts(r: &mut LatencyReport, cfg: &crate::PartitionConfig) {
    for name in hops_across_hosts(cfg) {
        if let Some(h) = r.hops.remove(name) {
            r.hops.insert(format!("{name}{ACROSS_THE_LINK}"), h);
        }
    }
}

pub(crate) fn hist() -> Histogram<u64> {
    // 1 ns .. 100 s, 3 significant digits
    Histogram::new_with_bounds(1, 100_000_000_000, 3)
        .unwrap_or_else(|_| Histogram::new(3).expect("histogram"))
}

pub(crate) fn stats(h: &Histogram<u64>) -> HopStats {
    let us = |v: u64| v as f64 / 1e3;
    if h.is_empty() {
        return HopStats {
            n: 0,
            min_us: 0.0,
            p50_us: 0.0,
            p90_us: 0.0,
            p99_us: 0.0,
            p99_9_us: 0.0,
            max_us: 0.0,
        };
    }
    HopStats {
        n: h.len(),
        min_us: us(h.min()),
        p50_us: us(h.value_at_quantile(0.5)),
        p90_us: us(h.value_at_quantile(0.9)),
        p99_us: us(h.value_at_quantile(0.99)),
        p99_9_us: us(h.value_at_quantile(0.999)),
        max_us: us(h.max()),
    }
}

/// The machine's cores, kernel and CPU model.
pub fn machine() -> Machine {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    Machine {
        cores: std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(0),
        kernel: std::fs::read_to_string("/proc/sys/kernel/osrelease")
            .map(|s| s.trim().to_string())
            .unwrap_or_else(|_| "unknown".into()),
        cpu,
        cpu_wakeup_latency: String::new(),
        steal_s: None,
    }
}

/// The reference latencies drawn on both figures [µs], with their labels: the
/// partition's 1 ms target and the paper's maximum.
pub(crate) fn references() -> Vec<(String, f64)> {
    const NS_PER_US: f64 = 1e3;
    const US_PER_MS: f64 = 1e3;
    let target_us = SLOW_TICK_NS as f64 / NS_PER_US;
    vec![
        (
            format!("{} ms p99 target", target_us / US_PER_MS),
            target_us,
        ),
        (
            format!("paper: {PAPER_TOTAL_MAX_MS} ms max (safety layer per step)"),
            PAPER_TOTAL_MAX_MS * US_PER_MS,
        ),
    ]
}

/// A whole tick longer than this [ns] counts as slow in the steal summary: the
/// 1 ms p99 target of the partition's latency (docs/PARTITION.md).
pub const SLOW_TICK_NS: u64 = 1_000_000;

/// How often the benchmark reads the host's steal counter.
pub const STEAL_SAMPLE_PERIOD: Duration = Duration::from_millis(100);

/// Options of the benchmark.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    pub config: PathBuf,
    pub out: PathBuf,
    pub ticks: u64,
    pub warmup: u64,
    pub bin_dir: Option<PathBuf>,
    pub run_id: Option<String>,
}

/// Runs the partition in real-time mode for `warmup + ticks` ticks and analyses it.
pub fn bench(o: &BenchOptions) -> Result<LatencyReport, BenchError> {
    let sampler = crate::steal::StealSampler::start(STEAL_SAMPLE_PERIOD);
    let rep = launch(&LaunchOptions {
        config: o.config.clone(),
        out: o.out.clone(),
        bin_dir: o.bin_dir.clone(),
        run_id: o.run_id.clone(),
        clock: Some(crate::ClockMode::RealTime),
        max_ticks: Some(o.ticks + o.warmup),
        ..Default::default()
    })?;
    let series = sampler.finish();
    let steal_csv = o.out.join("steal.csv");
    crate::steal::write_csv(&steal_csv, &series).map_err(BenchError::write(&steal_csv))?;
    if rep.interrupted {
        return Err(BenchError::Interrupted {
            planned: o.ticks + o.warmup,
        });
    }
    if rep.code == 3 {
        return Err(BenchError::Data(format!(
            "the partition run failed (see {}/logs)",
            o.out.display()
        )));
    }
    let mut r = analyse(&o.out, o.warmup)?;
    if let Ok(cfg) = crate::PartitionConfig::load(&o.config) {
        mark_hops_across_hosts(&mut r, &cfg);
    }
    r.machine.cpu_wakeup_latency = rep.cpu_wakeup_latency.clone();
    r.machine.steal_s = series
        .first()
        .zip(series.last())
        .map(|(a, b)| (b.steal_s - a.steal_s).max(0.0));
    let json = o.out.join("latency_report.json");
    let text = serde_json::to_string_pretty(&r).unwrap_or_default() + "\n";
    std::fs::write(&json, text).map_err(BenchError::write(&json))?;
    let md = o.out.join("latency_report.md");
    std::fs::write(&md, markdown(&r)).map_err(BenchError::write(&md))?;
    Ok(r)
}

/// The report as a Markdown table.
pub fn markdown(r: &LatencyReport) -> String {
    let mut s = format!(
        "Machine: {} cores, {}, kernel {}; CPU wake-up latency {}; host steal time during the run {}. Clock {} at {} s; pre-tick warm-up {}; {} ticks measured ({} warm-up excluded); cycle slips {}; deadline misses {}.\n\n| hop | N | min | p50 | p90 | p99 | p99.9 | max |\n|---|---|---|---|---|---|---|---|\n",
        r.machine.cores,
        r.machine.cpu,
        r.machine.kernel,
        if r.machine.cpu_wakeup_latency.is_empty() {
            "not recorded"
        } else {
            &r.machine.cpu_wakeup_latency
        },
        r.machine
            .steal_s
            .map_or("not reported".to_string(), |s| format!("{s:.2} s")),
        r.clock,
        r.period_s,
        if r.warmup_lead_us == 0 {
            "off".to_string()
        } else {
            format!("{} us before each tick", r.warmup_lead_us)
        },
        r.whole_tick.n,
        r.warmup_ticks,
        r.cycle_slips,
        r.deadline_misses
    );
    let row = |n: &str, h: &HopStats| {
        format!(
            "| {n} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |\n",
            h.n, h.min_us, h.p50_us, h.p90_us, h.p99_us, h.p99_9_us, h.max_us
        )
    };
    for (n, h) in &r.hops {
        s += &row(n, h);
    }
    s += &row(
        "**whole tick** (tick -> robotic safe command at the simulator)",
        &r.whole_tick,
    );
    if let Some(st) = &r.steal {
        s += &row(
            "whole tick, ticks without host steal around them",
            &st.whole_tick_without_steal,
        );
        s += &format!(
            "\nHost steal (counter read every {:.2} s, in 10 ms units): {} of {} ticks had steal in their sampling window; of the {} ticks over 1 ms, {} had. `latency_timeline.svg` plots both over the run.\n",
            st.sample_period_s,
            st.ticks_with_steal,
            r.whole_tick.n,
            st.over_1ms,
            st.over_1ms_with_steal
        );
    }
    s += "\nAll times in µs.\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::steal::{StealSample, write_csv};
    use std::path::Path;

    #[test]
    fn the_hops_between_the_filters_host_and_home_are_the_links() {
        let across = repo_config("config/partition_across_hosts.toml");
        assert_eq!(
            hops_across_hosts(&across),
            [
                "6 state -> translational filter out",
                "9 robotic safe -> simulator"
            ]
        );
        assert!(hops_across_hosts(&repo_config("config/partition.toml")).is_empty());
        // every stamp a hop starts or ends at has its role
        for (_, from, to) in HOPS {
            for col in [from, to] {
                assert!(COLUMN_ROLE.iter().any(|(c, _)| *c == col), "{col}");
            }
        }
    }

    fn repo_config(path: &str) -> crate::PartitionConfig {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        crate::PartitionConfig::load(&root.join(path)).unwrap()
    }

    /// Ticks of the synthetic run.
    const TICKS: u64 = 20;
    /// Base period of the synthetic run [ns].
    const PERIOD_NS: u64 = 100_000_000;
    /// Time between consecutive stamps of a tick [ns].
    const HOP_NS: u64 = 40_000;

    /// A run folder as the recorder and the scheduler leave it: every stamp of a tick
    /// `HOP_NS` after the previous one, no fallback; a steal counter read every period.
    fn synthetic_run(dir: &Path) {
        std::fs::create_dir_all(dir).unwrap();
        let columns: Vec<&str> = crate::recorder::LATENCY_CSV_HEADER.split(',').collect();
        let mut csv = format!("{}\n", crate::recorder::LATENCY_CSV_HEADER);
        for k in 0..TICKS {
            let row: Vec<String> = columns
                .iter()
                .enumerate()
                .map(|(i, c)| match *c {
                    "tick" => k.to_string(),
                    c if c.ends_with("_ns") => (k * PERIOD_NS + i as u64 * HOP_NS).to_string(),
                    _ => "0".to_string(),
                })
                .collect();
            csv += &(row.join(",") + "\n");
        }
        std::fs::write(dir.join("latency.csv"), csv).unwrap();
        let sched =
            serde_json::json!({"clock": "RealTime", "base_period_s": 0.1, "cycle_slips": 0});
        std::fs::write(dir.join("scheduler.json"), sched.to_string()).unwrap();
        let steal: Vec<StealSample> = (0..TICKS)
            .map(|k| StealSample {
                t_ns: k * PERIOD_NS,
                steal_s: k as f64 * 1e-3,
            })
            .collect();
        write_csv(&dir.join("steal.csv"), &steal).unwrap();
    }

    /// Both figures are drawn, each with the 1 ms target and the paper's maximum as
    /// labelled reference lines.
    #[test]
    fn figures_carry_the_reference_latencies() {
        let dir = std::env::temp_dir().join(format!("sc-latency-figures-{}", std::process::id()));
        synthetic_run(&dir);
        let r = analyse(&dir, 0).unwrap();
        assert_eq!(r.whole_tick.n, TICKS);
        for figure in ["latency.svg", "latency_timeline.svg"] {
            let svg = std::fs::read_to_string(dir.join(figure)).unwrap();
            for (label, _) in references() {
                assert!(svg.contains(&label), "{figure}: no `{label}`");
            }
        }
        assert!(references()[0].0.starts_with("1 ms"));
        assert!(references()[1].0.contains("3.75 ms"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
