//! `report.md`: the campaign's numbers beside the paper's.

use crate::aggregate::{
    CampaignSummary, Spread, TREND_SYNC_PEAK, TREND_TORQUE_PEAK, TREND_TORQUE_RMS,
};
use crate::run::RunResult;
use std::fmt::Write;

use sc_plots::paper::{
    PAPER_COMPONENT_MAX_MS, PAPER_SYNC_GRASP_RAD_S, PAPER_SYNC_SYNC_RAD_S, PAPER_TOTAL_GEOMEAN_MS,
    PAPER_TOTAL_MAX_MS,
};

fn spread(s: Option<&Spread>, digits: usize) -> String {
    match s {
        Some(s) => format!(
            "{:.d$}–{:.d$} (runs {} / {})",
            s.min,
            s.max,
            s.min_run,
            s.max_run,
            d = digits
        ),
        None => "–".into(),
    }
}

/// One sentence on the host's load during each session, and why it matters.
fn host_load(load: &[crate::host::HostLoad]) -> String {
    let sample = |h: &crate::host::HostSample| {
        format!(
            "{} on {} CPUs",
            h.load_avg_1min
                .map_or("unknown".into(), |l| format!("{l:.2}")),
            h.cpus
        )
    };
    let sessions: Vec<String> = load
        .iter()
        .map(|l| {
            format!(
                "{} at the start, {} at the end",
                sample(&l.start),
                sample(&l.end)
            )
        })
        .collect();
    let which = if load.len() == 1 {
        String::new()
    } else {
        format!(
            " ({} sessions: shards, or an interrupted campaign and its resumes)",
            load.len()
        )
    };
    format!(
        "Host load (1-minute load average){which}: {}. Wall-clock maxima (solve times, wall time) are inflated under load: when the load exceeds the CPUs, threads wait for a CPU and that wait counts in them (the thread CPU times do not).",
        sessions.join("; ")
    )
}

/// The title, what was run, and the notes on interruption, host load and execution.
fn header(o: &mut String, s: &CampaignSummary, execution: sc_mission::Execution) {
    let _ = writeln!(o, "# Monte Carlo campaign\n");
    let shard = s
        .shard
        .map(|[i, n]| format!(", shard {i}/{n}"))
        .unwrap_or_default();
    let _ = writeln!(
        o,
        "{} runs (campaign of {}{shard}, seed {}), wall time {:.1} s.\n",
        s.runs, s.campaign_runs, s.seed, s.wall_time_s
    );
    if let Some(u) = &s.uncertainty {
        let _ = writeln!(
            o,
            "Declared uncertainty: profile `{u}` (docs/UNCERTAINTY.md). Each run's plant, actuators and navigation errors were drawn from its run seed; \"safe\" is every barrier ≥ 0 on the simulated truth.\n"
        );
        if !s.not_covered.is_empty() {
            let _ = writeln!(
                o,
                "The filters' margins do not cover the declared {}: for those the promise does not hold, a safe run is measured, not guaranteed (docs/SAFETY.md, \"Margins for the declared errors\").\n",
                s.not_covered.join(", ")
            );
        }
    }
    if let Some(i) = &s.interrupted {
        let _ = writeln!(
            o,
            "**Interrupted** (SIGINT/SIGTERM) after {} of {} runs: only the runs that finished are aggregated here; `safe-capture montecarlo --resume` with the same `--out` runs the rest and completes this report.\n",
            i.completed_runs, i.planned_runs
        );
    }
    if !s.host_load.is_empty() {
        let _ = writeln!(o, "{}\n", host_load(&s.host_load));
    }
    if execution == sc_mission::Execution::Partition {
        let _ = writeln!(
            o,
            "Every run executed through the process partition (one process per module, \
             iceoryx2, lock-step); its launch, scheduler and recorder reports are in \
             `runs/K/partition/`.\n"
        );
    }
    let _ = writeln!(o, "| | runs |\n|---|---|");
    let _ = writeln!(
        o,
        "| safe (every barrier ≥ 0) | {} / {} |",
        s.safe_runs, s.runs
    );
    let _ = writeln!(o, "| captured | {} / {} |", s.captured_runs, s.runs);
    let _ = writeln!(o, "| failed (error or panic) | {} |", s.failed_runs);
    let _ = writeln!(o, "| with filter faults | {} |\n", s.faulted_runs);
}

/// The solve-time rows of the table beside the paper.
fn solve_time_rows(o: &mut String, s: &CampaignSummary) {
    let t = |n: &str| s.solve_time_us.get(n).copied().unwrap_or_default();
    let _ = writeln!(
        o,
        "| total solve time per step, geometric mean | {:.1} µs | {PAPER_TOTAL_GEOMEAN_MS} ms |",
        t("total").geomean
    );
    let _ = writeln!(
        o,
        "| total solve time per step, maximum | {:.1} µs | {PAPER_TOTAL_MAX_MS} ms |",
        t("total").max
    );
    for f in ["translational", "attitude", "robotic"] {
        let _ = writeln!(
            o,
            "| {f} QP, geomean / max | {:.1} / {:.1} µs | max < {PAPER_COMPONENT_MAX_MS} ms (all filters) |",
            t(f).geomean,
            t(f).max
        );
    }
    let c = |n: &str| s.solve_cpu_us.get(n).copied().unwrap_or_default();
    let _ = writeln!(
        o,
        "| total thread CPU time per step, geomean / max (the filters' own work) | {:.1} / {:.1} µs | – |",
        c("total").geomean,
        c("total").max
    );
}

/// The rows of the table beside the paper on the synchronisation error and the joint
/// torque: ranges over the runs, and their trends with the tumbling rate.
fn result_rows(o: &mut String, s: &CampaignSummary, grasp: Option<&str>, phases: &[String]) {
    // the synchronisation phase (II) is the one before grasping (III)
    let sync_phase = grasp
        .and_then(|g| phases.iter().position(|p| p == g))
        .and_then(|i| i.checked_sub(1))
        .and_then(|i| phases.get(i));
    if let Some(g) = grasp {
        let _ = writeln!(
            o,
            "| peak sync error in grasping (III), range over runs | {} rad/s | {}–{} rad/s |",
            spread(s.sync_error_peak_rad_s.get(g), 4),
            PAPER_SYNC_GRASP_RAD_S.0,
            PAPER_SYNC_GRASP_RAD_S.1
        );
    }
    if let Some(p) = sync_phase {
        let _ = writeln!(
            o,
            "| peak sync error in synchronisation (II), range over runs | {} rad/s | up to {PAPER_SYNC_SYNC_RAD_S} rad/s |",
            spread(s.sync_error_peak_rad_s.get(p), 4)
        );
    }
    let _ = writeln!(
        o,
        "| RMS joint-torque norm in grasping, range | {} N m | (figure only) |",
        spread(s.joint_torque_norm_rms_grasp_nm.as_ref(), 3)
    );
    let corr = |v: Option<f64>| v.map_or("–".into(), |c| format!("{c:+.2}"));
    for (key, what) in [
        (TREND_SYNC_PEAK, "peak sync error in grasping"),
        (TREND_TORQUE_RMS, "RMS joint-torque norm in grasping"),
        (TREND_TORQUE_PEAK, "peak joint-torque norm in grasping"),
    ] {
        if let Some(t) = s.trend_with_tumble_rate.get(key) {
            let _ = writeln!(
                o,
                "| {what} against the tumbling rate, correlation (Pearson / Spearman, {} runs) | {} / {} | rises with the rate |",
                t.runs,
                corr(t.pearson),
                corr(t.spearman)
            );
        }
    }
}

/// Our numbers beside the paper's.
fn beside_the_paper(o: &mut String, s: &CampaignSummary, grasp: Option<&str>, phases: &[String]) {
    let _ = writeln!(o, "## Beside the paper\n");
    let _ = writeln!(
        o,
        "| quantity | this campaign | paper (CasADi + OSQP, 100 runs) |\n|---|---|---|"
    );
    solve_time_rows(o, s);
    result_rows(o, s, grasp, phases);
    let _ = writeln!(
        o,
        "| capture time, range | {} s | – |\n",
        spread(s.capture_time_s.as_ref(), 1)
    );
    let _ = writeln!(
        o,
        "Solve times are wall-clock measurements on this machine (what a deadline sees, including the time the thread was preempted); the thread CPU time row is the filters' own work (percentiles from a log histogram, ±0.05 %).\n"
    );
}

/// The ten barriers that came closest to their boundary.
fn worst_margins(o: &mut String, s: &CampaignSummary) {
    let _ = writeln!(
        o,
        "## Worst barrier margins\n\n| constraint | worst min h | run |\n|---|---|---|"
    );
    let mut worst: Vec<(&String, f64, Option<usize>)> = s
        .worst
        .iter()
        .filter_map(|(n, w)| w.min_h.map(|h| (n, h, w.run)))
        .collect();
    worst.sort_by(|a, b| a.1.total_cmp(&b.1));
    for (n, h, r) in worst.iter().take(10) {
        let _ = writeln!(
            o,
            "| {n} | {h:.4e} | {} |",
            r.map(|x| x.to_string()).unwrap_or_default()
        );
    }
    let _ = writeln!(o);
}

/// A row of the table of runs that failed, were unsafe or did not capture.
fn bad_run_row(o: &mut String, r: &RunResult) {
    let (dist, off, az, w) = r
        .dispersion
        .map(|d| {
            (
                format!("{:.3}", d.distance_m),
                format!("{:.3}", d.off_axis_deg),
                format!("{:.1}", d.azimuth_deg),
                format!("{:.4}", d.tumble_rate_rad_s),
            )
        })
        .unwrap_or_default();
    let outcome = match &r.metrics {
        None => format!("failed: {}", r.error.as_deref().unwrap_or("")),
        Some(m) => {
            let mut v = Vec::new();
            if !m.safe {
                v.push(format!("violated {}", m.violated.join(", ")));
            }
            if !m.captured {
                v.push(format!("not captured ({})", m.end));
            }
            if m.fault_count > 0 {
                v.push(format!(
                    "faults on {} step{}",
                    m.fault_count,
                    if m.fault_count == 1 { "" } else { "s" }
                ));
            }
            v.join("; ")
        }
    };
    let _ = writeln!(
        o,
        "| {} | {} | {dist} | {off} | {az} | {w} | {outcome} |",
        r.run, r.seed
    );
}

/// The runs that did not pass — failed, unsafe, not captured or with faults — or that
/// there are none.
fn bad_runs(o: &mut String, results: &[RunResult]) {
    let faulted = |r: &RunResult| r.metrics.as_ref().is_some_and(|m| m.fault_count > 0);
    let bad: Vec<&RunResult> = results
        .iter()
        .filter(|r| r.failed() || !r.safe() || !r.captured() || faulted(r))
        .collect();
    if bad.is_empty() {
        let _ = writeln!(o, "Every run completed safe, captured and without a fault.");
        return;
    }
    let _ = writeln!(
        o,
        "## Runs that did not pass: failed, unsafe, not captured or with faults\n\n| run | seed | distance [m] | off-axis [deg] | azimuth [deg] | tumble rate [rad/s] | outcome |\n|---|---|---|---|---|---|---|"
    );
    for r in bad {
        bad_run_row(o, r);
    }
}

/// The Markdown report.
pub fn report(
    s: &CampaignSummary,
    results: &[RunResult],
    grasp: Option<&str>,
    phases: &[String],
    execution: sc_mission::Execution,
) -> String {
    let mut o = String::new();
    header(&mut o, s, execution);
    beside_the_paper(&mut o, s, grasp, phases);
    worst_margins(&mut o, s);
    bad_runs(&mut o, results);
    let _ = writeln!(
        o,
        "\nFigures: figures/runtime.svg, figures/trajectories_xy.svg, figures/attitude_los.svg, figures/torque_vs_sync.svg, figures/barrier_minima.svg."
    );
    o
}
