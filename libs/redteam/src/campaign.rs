//! The red-team campaign: every case (a strategy against a target) runs the whole mission
//! in one process with the adversary in place of the nominal controller(s), and the result
//! is measured from the simulator's true state at every physics step (the safety monitor),
//! never from a filter's report.

use crate::adversary::Adversary;
use crate::strategy::{Case, CaseLabel, Target};
use rayon::prelude::*;
use sc_cbf::faults;
use sc_mission::summary::TimeStats;
use sc_mission::{Mission, MissionEnd, RunOptions, Setup, StepRecord, TelemetryWriter, summarize};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

/// What one case measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseResult {
    /// `<target>/<strategy>`.
    pub case: String,
    pub target: String,
    pub strategy: String,
    /// How the mission ended ("captured", "timeout", "simulator_failed"; a partition run
    /// also "stopped" before the end, e.g. by `--max-ticks`, or "interrupted" by a signal).
    pub end: String,
    pub final_time_s: f64,
    pub steps: usize,
    /// Smallest value of every barrier over every physics step (true state).
    pub min_h: BTreeMap<String, f64>,
    /// Barriers that went below zero (or could not be evaluated) at any physics step.
    pub violated: Vec<String>,
    /// Applied commands with a non-finite component.
    pub nonfinite_applied: usize,
    /// Applied commands outside the input bounds (`‖f_B‖∞ ≤ F`, `‖τ_B‖∞ ≤ T`,
    /// `‖τ_M‖∞ ≤ T_M`).
    pub out_of_bounds_applied: usize,
    /// Per filter (translational, attitude, robotic): steps on the substitute nominal
    /// (invalid or missing), on the relaxed problem, on the backup law.
    pub substituted_steps: [usize; 3],
    pub relaxed_steps: [usize; 3],
    pub backup_steps: [usize; 3],
    /// Per filter: steps on which it lacked or refused an input (its nominal missing or
    /// invalid, the upstream safe command missing, the coupling ξ invalid) or ran its
    /// backup law. On a subsystem the case does not attack — a bystander — any such step
    /// is a fault of the partition's isolation, not of the adversary.
    #[serde(default)]
    pub disturbed_steps: [usize; 3],
    /// Safety-layer time per step (wall clock) [µs].
    pub solve_time_us: TimeStats,
}

impl CaseResult {
    /// True if every barrier held at every physics step and every applied command was
    /// finite and inside its bounds.
    pub fn safe(&self) -> bool {
        self.violated.is_empty() && self.nonfinite_applied == 0 && self.out_of_bounds_applied == 0
    }

    /// Disturbed steps summed over the subsystems the case does not attack.
    pub fn bystander_disturbed_steps(&self) -> usize {
        let target = Target::parse(&self.target);
        (0..3)
            .filter(|&i| target.is_some_and(|t| !t.covers(i)))
            .map(|i| self.disturbed_steps[i])
            .sum()
    }
}

/// Filter faults that mean an input did not arrive or was refused, or the backup ran.
const DISTURBED: u32 = faults::INVALID_NOMINAL
    | faults::NOMINAL_MISSING
    | faults::UPSTREAM_MISSING
    | faults::INVALID_COUPLING
    | faults::QP_FAILED_FALLBACK
    | faults::INVALID_STATE;

/// Runs one case to the end of its mission.
pub fn run_case(setup: &Setup, case: &Case) -> Result<CaseResult, String> {
    run_case_recorded(setup, case, None)
}

/// [`run_case`], and with `telemetry` (a directory, created) its `telemetry.csv` and
/// `timing.csv` written there as `safe-capture run` writes them.
pub fn run_case_recorded(
    setup: &Setup,
    case: &Case,
    telemetry: Option<&Path>,
) -> Result<CaseResult, String> {
    let adversary = Adversary::new(
        &setup.scenario,
        setup.robot.clone(),
        case.target,
        case.strategy,
    );
    let mut mission =
        Mission::new(setup.clone(), RunOptions::default()).map_err(|e| e.to_string())?;
    mission.nominal_override = Some(Box::new(adversary));
    let mut records: Vec<StepRecord> = Vec::new();
    let end = mission.run(|_, r| records.push(*r));
    if let Some(dir) = telemetry {
        write_telemetry(dir, &records).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    Ok(measure(setup, &case.label(), &records, &end))
}

fn write_telemetry(dir: &Path, records: &[StepRecord]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let file = |n: &str| std::fs::File::create(dir.join(n)).map(std::io::BufWriter::new);
    let mut w = TelemetryWriter::new(file("telemetry.csv")?, file("timing.csv")?)?;
    for r in records {
        w.write(r)?;
    }
    w.flush()
}

/// The result of a case from its records (in process, or read back from a partition
/// run's telemetry with [`sc_mission::parse_telemetry`]).
pub fn measure(
    setup: &Setup,
    case: &CaseLabel,
    records: &[StepRecord],
    end: &MissionEnd,
) -> CaseResult {
    let phases: Vec<String> = setup
        .scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let summary = summarize(records, end, &phases, true);
    let lim = &setup.scenario.limits;
    let mut r = CaseResult {
        case: case.name(),
        target: case.target.name().into(),
        strategy: case.strategy.clone(),
        end: end.name().into(),
        final_time_s: end.t(),
        steps: records.len(),
        min_h: summary
            .constraints
            .iter()
            .map(|(n, c)| {
                (
                    n.clone(),
                    if c.nan_samples > 0 { f64::NAN } else { c.min_h },
                )
            })
            .collect(),
        violated: summary.violated_constraints.clone(),
        nonfinite_applied: 0,
        out_of_bounds_applied: 0,
        substituted_steps: [0; 3],
        relaxed_steps: [0; 3],
        backup_steps: [0; 3],
        disturbed_steps: [0; 3],
        solve_time_us: summary
            .solve_time_us
            .get("total")
            .copied()
            .unwrap_or_default(),
    };
    for rec in records {
        let a = &rec.applied;
        if !a.is_finite() {
            r.nonfinite_applied += 1;
        } else if a.force_b.amax() > lim.force_max_n
            || a.torque_b.amax() > lim.torque_max_nm
            || a.tau.amax() > lim.joint_torque_max_nm
        {
            r.out_of_bounds_applied += 1;
        }
        let flags = [
            rec.translational.report.faults,
            rec.attitude.report.faults,
            rec.robotic.report.faults,
        ];
        for (i, f) in flags.iter().enumerate() {
            if f & (faults::INVALID_NOMINAL | faults::NOMINAL_MISSING) != 0 {
                r.substituted_steps[i] += 1;
            }
            if f & faults::QP_INFEASIBLE_RELAXED != 0 {
                r.relaxed_steps[i] += 1;
            }
            if f & (faults::QP_FAILED_FALLBACK | faults::INVALID_STATE) != 0 {
                r.backup_steps[i] += 1;
            }
            if f & DISTURBED != 0 {
                r.disturbed_steps[i] += 1;
            }
        }
    }
    r
}

/// Called as cases finish: `(done, total, result)`.
pub type Progress<'a> = dyn Fn(usize, usize, &Result<CaseResult, String>) + Sync + 'a;

/// Runs every case in parallel (rayon), calling `progress(done, total, result)` as cases
/// finish (from worker threads). Results come back in the order of `cases`; a case whose
/// mission cannot be set up is an `Err` with the reason.
pub fn run_campaign(
    setup: &Setup,
    cases: &[Case],
    progress: &Progress,
) -> Vec<Result<CaseResult, String>> {
    run_campaign_recorded(setup, cases, progress, None)
}

/// [`run_campaign`], and with `out` each case's telemetry in
/// `out/cases/<case>/` ([`CaseLabel::dir_name`], [`run_case_recorded`]).
pub fn run_campaign_recorded(
    setup: &Setup,
    cases: &[Case],
    progress: &Progress,
    out: Option<&Path>,
) -> Vec<Result<CaseResult, String>> {
    let done = AtomicUsize::new(0);
    let total = cases.len();
    cases
        .par_iter()
        .map(|c| {
            let dir = out.map(|o| o.join("cases").join(c.label().dir_name()));
            let r = run_case_recorded(setup, c, dir.as_deref());
            let k = done.fetch_add(1, Ordering::SeqCst) + 1;
            progress(k, total, &r);
            r
        })
        .collect()
}
