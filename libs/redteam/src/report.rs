//! The red-team campaign's outputs: `cases.csv` (one line per case), `min_h.csv` (every
//! case's smallest value of every barrier), `summary.json`, `report.md` and
//! `figures/redteam_margins.svg`.

use crate::campaign::{CaseError, CaseResult};
use crate::strategy::CaseLabel;
use sc_core::PerSubsystem;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The campaign's verdict (`summary.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignSummary {
    pub cases: usize,
    pub safe: usize,
    /// Cases with a barrier below zero at some physics step, or a non-finite or
    /// out-of-bound applied command.
    pub unsafe_cases: Vec<String>,
    /// Cases whose mission could not be set up, with the reason.
    pub errors: Vec<String>,
    pub nonfinite_applied: usize,
    pub out_of_bounds_applied: usize,
    /// Cases in which a subsystem the case does not attack lost or refused an input or ran
    /// its backup (`CaseResult::bystander_disturbed_steps` > 0): the attack reached past
    /// its own subsystem.
    #[serde(default)]
    pub bystanders_disturbed: Vec<String>,
    /// Cases in which the layer went to safe mode (the tumble left the certified envelope),
    /// and of the unsafe ones those whose first barrier below zero came after the layer
    /// had said, entering it, that the line of sight was at risk (docs/SAFETY.md, "Safe
    /// mode"); absent when none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub safe_mode_cases: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub announced_unsafe: Vec<String>,
    /// Per barrier: the smallest value over all cases and the case it came from.
    pub worst: BTreeMap<String, (f64, String)>,
    /// Safety-layer time per step over all cases [µs]: the largest geometric mean of a
    /// case and the largest single step (wall clock, so the maximum includes preemption
    /// by the other cases running in parallel).
    pub solve_time_geomean_max_us: f64,
    pub solve_time_max_us: f64,
    pub wall_s: f64,
}

/// Why the campaign's outputs could not be written. One line each.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("cannot write {}: {error}", .path.display())]
    Write {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    #[error(transparent)]
    Figure(#[from] sc_plots::PlotError),
}

/// The header of `cases.csv`.
const CASES_COLUMNS: &str = "case,target,strategy,end,final_time_s,steps,safe,violated,nonfinite_applied,out_of_bounds_applied,\
substituted_translational,substituted_attitude,substituted_robotic,relaxed_translational,relaxed_attitude,relaxed_robotic,\
backup_translational,backup_attitude,backup_robotic,bystander_disturbed_steps,worst_barrier,worst_normalised_margin,solve_geomean_us,solve_max_us,\
safe_mode_t_s,safe_mode_at_risk\n";

/// The campaign's verdict before any case.
fn empty_summary(cases: usize, wall_s: f64) -> CampaignSummary {
    CampaignSummary {
        cases,
        safe: 0,
        unsafe_cases: Vec::new(),
        errors: Vec::new(),
        nonfinite_applied: 0,
        out_of_bounds_applied: 0,
        bystanders_disturbed: Vec::new(),
        safe_mode_cases: Vec::new(),
        announced_unsafe: Vec::new(),
        worst: BTreeMap::new(),
        solve_time_geomean_max_us: 0.0,
        solve_time_max_us: 0.0,
        wall_s,
    }
}

/// Counts case `r` in the verdict.
fn tally(summary: &mut CampaignSummary, r: &CaseResult) {
    if r.safe() {
        summary.safe += 1;
    } else {
        summary.unsafe_cases.push(r.case.clone());
    }
    if r.bystander_disturbed_steps() > 0 {
        summary.bystanders_disturbed.push(r.case.clone());
    }
    if let Some(m) = r.safe_mode.filter(|m| m.entered_t_s.is_some()) {
        summary.safe_mode_cases.push(r.case.clone());
        let commands_fine = r.nonfinite_applied == 0 && r.out_of_bounds_applied == 0;
        // the entry announced the line of sight at risk, nothing else
        let only_los = r.violated.iter().all(|b| b == "line_of_sight");
        if !r.safe() && m.announced() && commands_fine && only_los {
            summary.announced_unsafe.push(r.case.clone());
        }
    }
    summary.nonfinite_applied += r.nonfinite_applied;
    summary.out_of_bounds_applied += r.out_of_bounds_applied;
    summary.solve_time_geomean_max_us = summary
        .solve_time_geomean_max_us
        .max(r.solve_time_us.geomean);
    summary.solve_time_max_us = summary.solve_time_max_us.max(r.solve_time_us.max);
    for n in sc_mission::constraint_names() {
        let h = min_h(r, n);
        let e = summary
            .worst
            .entry(n.to_string())
            .or_insert((f64::INFINITY, String::new()));
        if h.is_nan() || h < e.0 {
            *e = (h, r.case.clone());
        }
    }
}

/// The smallest value of barrier `name` in case `r` (NaN: none).
fn min_h(r: &CaseResult, name: &str) -> f64 {
    r.min_h.get(name).copied().unwrap_or(f64::NAN)
}

/// Every barrier's smallest value in case `r` over its scale, in
/// [`sc_mission::constraint_names`] order.
fn normalised(r: &CaseResult, scales: &sc_cbf::monitor::Barriers) -> Vec<f64> {
    sc_mission::constraint_names()
        .iter()
        .enumerate()
        .map(|(i, n)| min_h(r, n) / scales[i])
        .collect()
}

/// The barrier closest to its boundary relative to its scale: its index and that margin.
fn closest(normalised: &[f64]) -> (usize, f64) {
    normalised
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, v)| (i, *v))
        .unwrap_or((0, f64::NAN))
}

/// The `cases.csv` line of case `r` (with a newline).
fn cases_line(r: &CaseResult, normalised: &[f64]) -> String {
    let names = sc_mission::constraint_names();
    let (wi, wv) = closest(normalised);
    let per = |v: &PerSubsystem<usize>| {
        let [t, a, ro] = v.as_array();
        format!("{t},{a},{ro}")
    };
    format!(
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
        r.case,
        r.target,
        r.strategy,
        r.end,
        r.final_time_s,
        r.steps,
        r.safe(),
        r.violated.join(" "),
        r.nonfinite_applied,
        r.out_of_bounds_applied,
        per(&r.substituted_steps),
        per(&r.relaxed_steps),
        per(&r.backup_steps),
        r.bystander_disturbed_steps(),
        names[wi],
        wv,
        r.solve_time_us.geomean,
        r.solve_time_us.max,
        r.safe_mode
            .and_then(|m| m.entered_t_s)
            .map(|t| t.to_string())
            .unwrap_or_default(),
        r.safe_mode
            .filter(|m| m.entered_t_s.is_some())
            .map(|m| (!m.certifiable).to_string())
            .unwrap_or_default(),
    )
}

/// The `min_h.csv` line of case `r` (with a newline).
fn min_h_line(r: &CaseResult) -> String {
    let values: Vec<String> = sc_mission::constraint_names()
        .iter()
        .map(|n| min_h(r, n).to_string())
        .collect();
    format!("{},{}\n", r.case, values.join(","))
}

/// The tables and the figure's data, case by case.
struct Tables {
    cases_csv: String,
    min_csv: String,
    /// The figure's rows (case names) and their normalised margins.
    rows: Vec<String>,
    values: Vec<Vec<f64>>,
}

/// Writes every output into `dir`; returns the summary. `scales` are every barrier's
/// scale of the normalised margins ([`crate::scales::barrier_scales`]), `how` the report's paragraph on
/// how the cases were run.
pub fn write(
    dir: &Path,
    scales: &sc_cbf::monitor::Barriers,
    how: &str,
    cases: &[CaseLabel],
    results: &[Result<CaseResult, CaseError>],
    wall_s: f64,
) -> Result<CampaignSummary, ReportError> {
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|error| ReportError::Write { path, error })
    };
    std::fs::create_dir_all(dir.join("figures")).map_err(|error| ReportError::Write {
        path: dir.to_path_buf(),
        error,
    })?;
    let names = sc_mission::constraint_names();
    let mut summary = empty_summary(cases.len(), wall_s);
    let mut t = Tables {
        cases_csv: CASES_COLUMNS.to_string(),
        min_csv: format!("case,{}\n", names.join(",")),
        rows: Vec::new(),
        values: Vec::new(),
    };
    for (case, r) in cases.iter().zip(results) {
        let r = match r {
            Ok(r) => r,
            Err(e) => {
                summary.errors.push(format!("{}: {e}", case.name()));
                continue;
            }
        };
        tally(&mut summary, r);
        let normalised = normalised(r, scales);
        t.cases_csv += &cases_line(r, &normalised);
        t.min_csv += &min_h_line(r);
        t.rows.push(r.case.clone());
        t.values.push(normalised);
    }
    write("cases.csv", &t.cases_csv)?;
    write("min_h.csv", &t.min_csv)?;
    write(
        "summary.json",
        &(serde_json::to_string_pretty(&summary)? + "\n"),
    )?;
    write(
        "report.md",
        &markdown(&summary, how, cases, results, scales),
    )?;
    let barrier_names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    sc_plots::redteam_margins(
        &dir.join("figures/redteam_margins.svg"),
        &sc_plots::RedTeamMargins {
            cases: &t.rows,
            barriers: &barrier_names,
            values: &t.values,
        },
    )?;
    Ok(summary)
}

/// How the in-process campaign runs its cases (the report's paragraph).
pub const IN_PROCESS: &str = "Each case runs the whole mission in one process with the adversary in place of the nominal controller of its target (`all`: all three).";

/// The report's verdict, isolation and columns paragraphs.
fn markdown_header(m: &mut String, s: &CampaignSummary, how: &str) {
    let _ = writeln!(m, "# Red team of the safety layer\n");
    let _ = writeln!(
        m,
        "**{} of {} cases safe**: every barrier ≥ 0 at every physics step (computed from the simulator's true state, never from a filter's report) and every applied command finite and within its bounds. {} non-finite and {} out-of-bound applied commands; wall time {:.1} s.\n",
        s.safe, s.cases, s.nonfinite_applied, s.out_of_bounds_applied, s.wall_s
    );
    if !s.unsafe_cases.is_empty() {
        let _ = writeln!(m, "Unsafe: {}\n", s.unsafe_cases.join(", "));
    }
    if !s.errors.is_empty() {
        let _ = writeln!(m, "Could not run: {}\n", s.errors.join("; "));
    }
    if !s.safe_mode_cases.is_empty() {
        let _ = writeln!(
            m,
            "Safe mode (the tumble left the certified envelope; docs/SAFETY.md, \"Safe mode\") in {} cases: {}. Unsafe after the layer had said, entering it, that the line of sight was at risk: {}.\n",
            s.safe_mode_cases.len(),
            s.safe_mode_cases.join(", "),
            if s.announced_unsafe.is_empty() {
                "none".to_string()
            } else {
                s.announced_unsafe.join(", ")
            }
        );
    }
    let _ = writeln!(
        m,
        "Isolation: {} of the cases disturbed a subsystem they do not attack (an input of its filter missing or refused, or its backup law run){}.\n",
        s.bystanders_disturbed.len(),
        if s.bystanders_disturbed.is_empty() {
            String::new()
        } else {
            format!(": {}", s.bystanders_disturbed.join(", "))
        }
    );
    let _ = writeln!(
        m,
        "{how} Columns: how the mission ended, the barrier closest to its boundary (value / barrier scale, `figures/redteam_margins.svg`), and per filter (translational/attitude/robotic) the steps on the substitute nominal, without a certified command (on the relaxed problem, or with degraded margins under a declared uncertainty) and on the backup law, and the steps on which a subsystem the case does not attack was disturbed.\n"
    );
}

/// A case's row of the report's table.
fn markdown_row(r: &CaseResult, scales: &sc_cbf::monitor::Barriers) -> String {
    let names = sc_mission::constraint_names();
    let (wn, wv) = names
        .iter()
        .enumerate()
        .map(|(i, n)| (*n, min_h(r, n) / scales[i]))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or(("", f64::NAN));
    format!(
        "| {} | {} | {} | {} | {:.3e} | {:?} | {:?} | {:?} | {} | {:.1} / {:.0} |",
        r.strategy,
        r.end,
        if r.safe() { "yes" } else { "**NO**" },
        wn,
        wv,
        r.substituted_steps.as_array(),
        r.relaxed_steps.as_array(),
        r.backup_steps.as_array(),
        r.bystander_disturbed_steps(),
        r.solve_time_us.geomean,
        r.solve_time_us.max
    )
}

fn markdown(
    s: &CampaignSummary,
    how: &str,
    cases: &[CaseLabel],
    results: &[Result<CaseResult, CaseError>],
    scales: &sc_cbf::monitor::Barriers,
) -> String {
    let mut m = String::new();
    markdown_header(&mut m, s, how);
    let mut target = "";
    for (case, r) in cases.iter().zip(results) {
        if case.target.name() != target {
            target = case.target.name();
            let _ = writeln!(
                m,
                "\n## {target}\n\n| strategy | end | safe | closest barrier | margin / scale | substituted | relaxed | backup | bystanders disturbed | solve geomean / max [µs] |\n|---|---|---|---|---|---|---|---|---|---|"
            );
        }
        match r {
            Ok(r) => {
                let _ = writeln!(m, "{}", markdown_row(r, scales));
            }
            Err(e) => {
                let _ = writeln!(m, "| {} | error: {e} | | | | | | | | |", case.strategy);
            }
        }
    }
    let _ = writeln!(
        m,
        "\n## Smallest value of every barrier over all cases\n\n| barrier | min h | case |\n|---|---|---|"
    );
    for (n, (v, c)) in &s.worst {
        let _ = writeln!(m, "| {n} | {v:.3e} | {c} |");
    }
    m
}
