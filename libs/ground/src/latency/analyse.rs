//! The latency report of a run's output folder: the stamps of latency.csv (written by
//! the recorder) into per-hop and whole-tick histograms, the host's steal around each
//! tick, the HDR percentile file and the two figures.

use super::{HOPS, LatencyReport, SLOW_TICK_NS, StealSummary, hist, machine, references, stats};
use crate::error::BenchError;
use crate::steal::StealSample;
use hdrhistogram::Histogram;
use std::io::Write;
use std::path::Path;

/// What latency.csv holds, after the warm-up ticks.
struct Samples {
    /// Ticks in the file (warm-up included).
    total: u64,
    /// Measured ticks in which a stage used a fallback.
    misses: u64,
    whole: Histogram<u64>,
    hops: Vec<Histogram<u64>>,
    /// (tick send, whole-tick latency) [ns] of the measured ticks.
    ticks: Vec<(u64, u64)>,
}

/// The columns of latency.csv the analysis reads.
struct Columns {
    tick: usize,
    send: usize,
    recv: usize,
    fallback: usize,
    /// Filters that applied their fallback at a stage deadline (absent in older files).
    upstream_missing: Option<usize>,
    hops: Vec<(usize, usize)>,
}

impl Columns {
    fn of(header: &str) -> Result<Self, BenchError> {
        let header: Vec<&str> = header.split(',').collect();
        let col = |n: &str| {
            header
                .iter()
                .position(|c| *c == n)
                .ok_or_else(|| BenchError::Data(format!("latency.csv: no column {n}")))
        };
        Ok(Self {
            tick: col("tick")?,
            send: col("tick_send_ns")?,
            recv: col("sim_safe_recv_ns")?,
            fallback: col("fallback_mask")?,
            upstream_missing: col("upstream_missing_mask").ok(),
            hops: HOPS
                .iter()
                .map(|(_, a, b)| Ok((col(a)?, col(b)?)))
                .collect::<Result<_, BenchError>>()?,
        })
    }
}

/// Reads latency.csv in `out`, skipping the first `warmup` ticks.
fn read_samples(out: &Path, warmup: u64) -> Result<Samples, BenchError> {
    let path = out.join("latency.csv");
    let text = std::fs::read_to_string(&path).map_err(BenchError::read(&path))?;
    let mut lines = text.lines();
    let header = lines
        .next()
        .ok_or_else(|| BenchError::Data("latency.csv is empty".into()))?;
    let c = Columns::of(header)?;
    let mut s = Samples {
        total: 0,
        misses: 0,
        whole: hist(),
        hops: HOPS.iter().map(|_| hist()).collect(),
        ticks: Vec::new(),
    };
    for l in lines {
        let v: Vec<&str> = l.split(',').collect();
        s.total += 1;
        let tick: u64 = v[c.tick]
            .parse()
            .map_err(|_| BenchError::Data("latency.csv: bad tick".into()))?;
        if tick >= warmup {
            add_tick(&mut s, &c, &v);
        }
    }
    Ok(s)
}

/// One measured tick's stamps into the histograms.
fn add_tick(s: &mut Samples, c: &Columns, v: &[&str]) {
    let flagged = |c: Option<usize>| c.and_then(|c| v.get(c)).is_some_and(|x| *x != "0");
    if flagged(Some(c.fallback)) || flagged(c.upstream_missing) {
        s.misses += 1;
    }
    let num = |i: usize| v.get(i).and_then(|x| x.parse::<u64>().ok());
    if let (Some(a), Some(b)) = (num(c.send), num(c.recv)) {
        s.whole.saturating_record(b.saturating_sub(a).max(1));
        s.ticks.push((a, b.saturating_sub(a).max(1)));
    }
    for (h, (a, b)) in s.hops.iter_mut().zip(&c.hops) {
        if let (Some(a), Some(b)) = (num(*a), num(*b)) {
            h.saturating_record(b.saturating_sub(a).max(1));
        }
    }
}

/// Which measured ticks had host steal around them, and the latency of the others.
fn steal_summary(series: &[StealSample], ticks: &[(u64, u64)]) -> Option<StealSummary> {
    if series.len() < 2 {
        return None;
    }
    let mut calm = hist();
    let (mut with, mut over, mut over_with) = (0, 0, 0);
    for (a, d) in ticks {
        let stolen = crate::steal::steal_around(series, *a, a + d).is_some_and(|x| x > 0.0);
        with += u64::from(stolen);
        if *d > SLOW_TICK_NS {
            over += 1;
            over_with += u64::from(stolen);
        }
        if !stolen {
            calm.saturating_record(*d);
        }
    }
    let span = series[series.len() - 1].t_ns.saturating_sub(series[0].t_ns) as f64 * 1e-9;
    Some(StealSummary {
        sample_period_s: span / (series.len() - 1) as f64,
        ticks_with_steal: with,
        whole_tick_without_steal: stats(&calm),
        over_1ms: over,
        over_1ms_with_steal: over_with,
    })
}

/// Computes the report from a run's output directory, excluding the first `warmup` ticks;
/// writes `latency_whole_tick.hgrm` (HDR percentile distribution) and
/// `latency.svg` (log-scale percentile plot) next to it.
pub fn analyse(out: &Path, warmup: u64) -> Result<LatencyReport, BenchError> {
    let s = read_samples(out, warmup)?;
    let sched_path = out.join("scheduler.json");
    let sched_text = std::fs::read_to_string(&sched_path).map_err(BenchError::read(&sched_path))?;
    let sched: serde_json::Value = serde_json::from_str(&sched_text)
        .map_err(|e| BenchError::Data(format!("{}: {e}", sched_path.display())))?;
    let series = crate::steal::read_csv(&out.join("steal.csv"))?;
    let rep = LatencyReport {
        clock: sched["clock"].as_str().unwrap_or("").to_string(),
        period_s: sched["base_period_s"].as_f64().unwrap_or(0.0),
        ticks_total: s.total,
        warmup_ticks: warmup,
        whole_tick: stats(&s.whole),
        hops: HOPS
            .iter()
            .zip(&s.hops)
            .map(|((n, _, _), h)| (n.to_string(), stats(h)))
            .collect(),
        cycle_slips: sched["cycle_slips"].as_u64().unwrap_or(0),
        deadline_misses: s.misses,
        // what every process of the run read
        warmup_lead_us: crate::PartitionConfig::load(&out.join("partition.effective.toml"))
            .map_or(0, |c| c.warmup_lead_us),
        steal: series.as_deref().and_then(|v| steal_summary(v, &s.ticks)),
        machine: machine(),
    };
    let points = write_hgrm(&out.join("latency_whole_tick.hgrm"), &s.whole)?;
    plot(&out.join("latency.svg"), &points, &rep)?;
    let steal = series.as_deref().unwrap_or(&[]);
    plot_timeline(&out.join("latency_timeline.svg"), &s.ticks, steal, &rep)?;
    Ok(rep)
}

/// Writes the whole tick's HDR percentile distribution; returns its points
/// (1/(1 − percentile), value [µs]) for the percentile figure.
fn write_hgrm(path: &Path, whole: &Histogram<u64>) -> Result<Vec<(f64, f64)>, BenchError> {
    let e = BenchError::write(path);
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(&e)?);
    writeln!(
        f,
        "{:>12} {:>14} {:>10} {:>14}",
        "Value(us)", "Percentile", "TotalCount", "1/(1-Percentile)"
    )
    .map_err(&e)?;
    let mut points = Vec::new();
    for v in whole.iter_quantiles(4) {
        let q = v.quantile_iterated_to();
        let val = v.value_iterated_to() as f64 / 1e3;
        let inv = if q < 1.0 {
            1.0 / (1.0 - q)
        } else {
            f64::INFINITY
        };
        let count = v.count_since_last_iteration();
        writeln!(f, "{val:>12.3} {q:>14.12} {count:>10} {inv:>14.2}").map_err(&e)?;
        if q < 1.0 {
            points.push((inv, val));
        }
    }
    let (mean, sd) = (whole.mean() / 1e3, whole.stdev() / 1e3);
    writeln!(f, "#[Mean = {mean:.3}, StdDeviation = {sd:.3}]").map_err(&e)?;
    let max = whole.max() as f64 / 1e3;
    writeln!(f, "#[Max = {max:.3}, Total count = {}]", whole.len()).map_err(&e)?;
    f.flush().map_err(&e)?;
    Ok(points)
}

fn plot(path: &Path, pts: &[(f64, f64)], rep: &LatencyReport) -> Result<(), BenchError> {
    let title = format!(
        "whole-tick latency, {} ticks at {} s ({} cores, kernel {})",
        rep.whole_tick.n, rep.period_s, rep.machine.cores, rep.machine.kernel
    );
    sc_plots::latency_percentiles(
        path,
        &sc_plots::LatencyPercentiles {
            title: &title,
            points: pts,
            references: &references(),
        },
    )
    .map_err(BenchError::from)
}

/// Whole-tick latency of every measured tick over the run (log scale) above the
/// host's steal rate, so that a reader sees whether the tail follows the host.
fn plot_timeline(
    path: &Path,
    ticks: &[(u64, u64)],
    steal: &[StealSample],
    rep: &LatencyReport,
) -> Result<(), BenchError> {
    const S_PER_NS: f64 = 1e-9;
    const US_PER_NS: f64 = 1e-3;
    const MS_PER_S: f64 = 1e3;
    let t0 = ticks.first().map_or(0, |t| t.0);
    let secs = |ns: u64| ns.saturating_sub(t0) as f64 * S_PER_NS;
    let pts: Vec<(f64, f64)> = ticks
        .iter()
        .map(|(a, d)| (secs(*a), *d as f64 * US_PER_NS))
        .collect();
    // steal rate between consecutive readings [ms of CPU per s]
    let rate: Vec<(f64, f64)> = steal
        .windows(2)
        .filter(|w| w[1].t_ns > w[0].t_ns)
        .map(|w| {
            let dt = (w[1].t_ns - w[0].t_ns) as f64 * S_PER_NS;
            (
                secs(w[1].t_ns),
                (w[1].steal_s - w[0].steal_s).max(0.0) * MS_PER_S / dt,
            )
        })
        .collect();
    let title = format!(
        "whole-tick latency over the run ({} ticks at {} s)",
        rep.whole_tick.n, rep.period_s
    );
    sc_plots::latency_timeline(
        path,
        &sc_plots::LatencyTimeline {
            title: &title,
            ticks: &pts,
            steal: &rate,
            references: &references(),
        },
    )
    .map_err(BenchError::from)
}
