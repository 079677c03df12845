//! The red-team campaign: every case (a strategy against a target) runs the whole mission
//! with the adversary in place of the nominal controller(s) — in this process, or as
//! hostile partner processes through the process partition, whichever
//! [`sc_mission::Executor`] the campaign is given — and the result is measured from the
//! simulator's true state at every physics step (the safety monitor), never from a
//! filter's report.

use crate::adversary::Adversary;
use crate::partners::HostilePartners;
use crate::strategy::{Case, CaseLabel, CaseNameError, Target};
use rayon::prelude::*;
use sc_cbf::faults;
use sc_core::{PerSubsystem, Subsystem};
use sc_mission::summary::TimeStats;
use sc_mission::{
    ExecError, Executed, Executor, Job, MissionEnd, NominalSource, Place, Setup, StepRecord,
    TelemetryWriter, summarize,
};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Per-filter step counts in files: `[translational, attitude, robotic]`.
mod per_subsystem {
    use sc_core::PerSubsystem;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &PerSubsystem<usize>, s: S) -> Result<S::Ok, S::Error> {
        v.as_array().serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<PerSubsystem<usize>, D::Error> {
        <[usize; 3]>::deserialize(d).map(PerSubsystem)
    }
}

/// Barrier values in files: a number, or `"NaN"`, `"inf"`, `"-inf"` for one that is not
/// finite (JSON has no such numbers), so that a recorded case reads back bit for bit.
mod float_map {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    use std::collections::BTreeMap;

    #[derive(Serialize, Deserialize)]
    #[serde(untagged)]
    enum Value {
        Number(f64),
        Text(String),
    }

    pub fn serialize<S: Serializer>(v: &BTreeMap<String, f64>, s: S) -> Result<S::Ok, S::Error> {
        v.iter()
            .map(|(k, x)| {
                let x = if x.is_finite() {
                    Value::Number(*x)
                } else {
                    Value::Text(x.to_string())
                };
                (k, x)
            })
            .collect::<BTreeMap<_, _>>()
            .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<BTreeMap<String, f64>, D::Error> {
        BTreeMap::<String, Value>::deserialize(d)?
            .into_iter()
            .map(|(k, v)| match v {
                Value::Number(x) => Ok((k, x)),
                Value::Text(t) => t
                    .parse::<f64>()
                    .map(|x| (k, x))
                    .map_err(|_| serde::de::Error::custom(format!("`{t}` is not a number"))),
            })
            .collect()
    }
}

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
    #[serde(with = "float_map")]
    pub min_h: BTreeMap<String, f64>,
    /// Barriers that went below zero (or could not be evaluated) at any physics step.
    pub violated: Vec<String>,
    /// Applied commands with a non-finite component.
    pub nonfinite_applied: usize,
    /// Applied commands outside the input bounds (`‖f_B‖∞ ≤ F`, `‖τ_B‖∞ ≤ T`,
    /// `‖τ_M‖∞ ≤ T_M`).
    pub out_of_bounds_applied: usize,
    /// Per filter: steps on the substitute nominal (invalid or missing), without a certified
    /// command (the relaxed problem, or degraded margins under a declared uncertainty), on
    /// the backup law.
    #[serde(with = "per_subsystem")]
    pub substituted_steps: PerSubsystem<usize>,
    #[serde(with = "per_subsystem")]
    pub relaxed_steps: PerSubsystem<usize>,
    #[serde(with = "per_subsystem")]
    pub backup_steps: PerSubsystem<usize>,
    /// Per filter: steps on which it lacked or refused an input (its nominal missing or
    /// invalid, the upstream safe command missing, the coupling ξ invalid) or ran its
    /// backup law. On a subsystem the case does not attack — a bystander — any such step
    /// is a fault of the partition's isolation, not of the adversary.
    #[serde(default, with = "per_subsystem")]
    pub disturbed_steps: PerSubsystem<usize>,
    /// Safety-layer time per step (wall clock) [µs].
    pub solve_time_us: TimeStats,
    /// When the layer went to safe mode (the tumble left the certified envelope), and
    /// what it said then (absent: never; docs/SAFETY.md, "Safe mode").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safe_mode: Option<CaseSafeMode>,
}

/// A case's safe mode: when it began, whether the line of sight was certifiable at that
/// range (the layer said "at risk" otherwise), when the true tumble was outside the
/// envelope with no filter in safe mode (a silent exit), and the first step with a
/// barrier below zero, if any (the true state).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CaseSafeMode {
    pub entered_t_s: Option<f64>,
    pub certifiable: bool,
    pub undetected_t_s: Option<f64>,
    pub first_violation_t_s: Option<f64>,
    /// The first step after the entry with no filter in safe mode (the tumble known back
    /// inside) [s].
    #[serde(default)]
    pub exited_t_s: Option<f64>,
}

impl CaseSafeMode {
    /// A barrier went below zero only after the layer had said, entering the safe mode,
    /// that the line of sight was at risk, while it was still in safe mode, and the true
    /// tumble never left the envelope unseen: announced, not silent. The first violation
    /// must come at a later control step than the entry (a record's between-samples minima
    /// cover the physics steps before it, when nothing had been said yet). Which barrier
    /// broke is the campaign's to check (only the line of sight was announced).
    pub fn announced(&self) -> bool {
        match (self.entered_t_s, self.first_violation_t_s) {
            (Some(entered), Some(violated)) => {
                let still_in = self.exited_t_s.is_none_or(|t| violated < t);
                !self.certifiable && violated > entered && still_in && self.undetected_t_s.is_none()
            }
            _ => false,
        }
    }
}

impl CaseResult {
    /// True if every barrier held at every physics step, every applied command was finite
    /// and inside its bounds, and the true tumble never left the certified envelope
    /// without the layer in safe mode.
    pub fn safe(&self) -> bool {
        let detected = self.safe_mode.is_none_or(|m| m.undetected_t_s.is_none());
        self.violated.is_empty()
            && self.nonfinite_applied == 0
            && self.out_of_bounds_applied == 0
            && detected
    }

    /// Disturbed steps summed over the subsystems the case does not attack.
    pub fn bystander_disturbed_steps(&self) -> usize {
        let target = Target::parse(&self.target);
        self.disturbed_steps
            .iter()
            .filter(|(s, _)| target.is_some_and(|t| !t.attacks(*s)))
            .map(|(_, n)| n)
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

/// Why a case gave no result. One line each.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error(transparent)]
    Name(#[from] CaseNameError),
    /// Its mission could not run (set up, launched, read back).
    #[error(transparent)]
    Run(#[from] ExecError),
    /// Its telemetry could not be written.
    #[error("{}: {error}", .dir.display())]
    Telemetry { dir: PathBuf, error: std::io::Error },
    /// The error a shard recorded for it ([`crate::shard`]).
    #[error("{0}")]
    Recorded(String),
}

/// Where the nominal commands of the cases come from.
pub enum Adversaries {
    /// An [`Adversary`] in this process, playing the case's [`crate::Strategy`].
    InProcess,
    /// Hostile partner processes (through the process partition).
    Partners(HostilePartners),
}

impl Adversaries {
    /// The nominal source of `case` in `setup`'s scenario.
    pub fn nominals(
        &self,
        setup: &Setup,
        case: &CaseLabel,
    ) -> Result<NominalSource, CaseNameError> {
        match self {
            Adversaries::InProcess => Ok(Adversary::nominals(setup, &Case::parse(&case.name())?)),
            Adversaries::Partners(p) => Ok(p.nominals(case)),
        }
    }
}

/// How a campaign runs its cases.
pub struct Campaign<'a> {
    pub setup: &'a Setup,
    /// The file `setup` was read from (an executor outside this process reads it).
    pub scenario_file: &'a Path,
    pub executor: &'a dyn Executor,
    pub adversaries: Adversaries,
    /// The campaign's folder: each case's files go to `out/cases/<case>/`
    /// ([`CaseLabel::dir_name`]; a partition run's outputs, the telemetry).
    pub out: Option<&'a Path>,
    /// Writes each case's `telemetry.csv` and `timing.csv` into its folder as
    /// `safe-capture run` does (in process; the partition's recorder always does).
    pub telemetry: bool,
}

impl Campaign<'_> {
    /// The mission of case `k`, `case`, writing into `dir`.
    fn job<'s>(
        &self,
        k: usize,
        case: &CaseLabel,
        dir: Option<&Path>,
    ) -> Result<Job<'s>, CaseError> {
        let mut job = Job::new(self.setup.clone());
        job.nominals = self.adversaries.nominals(self.setup, case)?;
        job.place = dir.map(|d| Place {
            name: format!("rt{k}"),
            scenario_file: self.scenario_file.to_path_buf(),
            out: d.to_path_buf(),
        });
        Ok(job)
    }

    /// Runs case `k`, `case`, with its telemetry written into `dir`.
    fn execute_recorded(
        &self,
        k: usize,
        case: &CaseLabel,
        dir: &Path,
    ) -> Result<Executed, CaseError> {
        let failed = |error| CaseError::Telemetry {
            dir: dir.to_path_buf(),
            error,
        };
        std::fs::create_dir_all(dir).map_err(failed)?;
        let file = |n: &str| std::fs::File::create(dir.join(n)).map(std::io::BufWriter::new);
        let (tel, tim) = (
            file("telemetry.csv").map_err(failed)?,
            file("timing.csv").map_err(failed)?,
        );
        let mut w = TelemetryWriter::new(tel, tim).map_err(failed)?;
        let mut job = self.job(k, case, Some(dir))?;
        job.sinks.telemetry = Some(&mut w);
        let executed = self.executor.execute(job).map_err(|e| match e {
            ExecError::Sink(error) => failed(error),
            e => CaseError::Run(e),
        })?;
        w.flush().map_err(failed)?;
        Ok(executed)
    }

    /// Runs case `k` of the campaign, `case`, to the end of its mission and measures it.
    pub fn run_case(&self, k: usize, case: &CaseLabel) -> Result<CaseResult, CaseError> {
        let dir = self.out.map(|o| o.join("cases").join(case.dir_name()));
        let executed = match dir.as_deref().filter(|_| self.telemetry) {
            Some(d) => self.execute_recorded(k, case, d)?,
            None => self.executor.execute(self.job(k, case, dir.as_deref())?)?,
        };
        Ok(measure(self.setup, case, &executed.records, &executed.end))
    }

    /// Runs every case in parallel (rayon), calling `progress(done, total, result)` as
    /// cases finish (from worker threads), and records each outcome in its folder as it
    /// finishes ([`crate::shard::record`]: what `--resume` and `merge` read; a case whose
    /// outcome cannot be recorded is an error). Results come back in the order of `cases`.
    pub fn run(
        &self,
        cases: &[CaseLabel],
        progress: &Progress,
    ) -> Vec<Result<CaseResult, CaseError>> {
        let done = AtomicUsize::new(0);
        cases
            .par_iter()
            .enumerate()
            .map(|(k, case)| {
                let mut r = self.run_case(k, case);
                // a case stopped by a signal did not finish (also one that failed once the
                // executor was told to stop): --resume runs it again
                let stopped = matches!(r, Err(CaseError::Run(ExecError::Interrupted)))
                    || (r.is_err() && self.executor.stopped());
                if let Some(out) = self.out.filter(|_| !stopped)
                    && let Err(e) = crate::shard::record(out, case, &r)
                {
                    r = Err(CaseError::Recorded(format!(
                        "its result could not be recorded: {e}"
                    )));
                }
                let n = done.fetch_add(1, Ordering::SeqCst) + 1;
                progress(n, cases.len(), &r);
                r
            })
            .collect()
    }
}

/// The faults every filter flagged at one step.
fn filter_faults(rec: &StepRecord) -> PerSubsystem<u32> {
    PerSubsystem::from_fn(|s| match s {
        Subsystem::Translational => rec.translational.report.faults,
        Subsystem::Attitude => rec.attitude.report.faults,
        Subsystem::Robotic => rec.robotic.report.faults,
    })
}

/// Counts the applied commands that were non-finite or out of bounds, and per filter the
/// steps on the substitute nominal, relaxed, on the backup and disturbed.
fn count_steps(r: &mut CaseResult, records: &[StepRecord], lim: &sc_scenario::Limits) {
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
        for (s, f) in filter_faults(rec).iter() {
            if f & (faults::INVALID_NOMINAL | faults::NOMINAL_MISSING) != 0 {
                r.substituted_steps[s] += 1;
            }
            if f & (faults::QP_INFEASIBLE_RELAXED | faults::MARGINS_DEGRADED) != 0 {
                r.relaxed_steps[s] += 1;
            }
            if f & (faults::QP_FAILED_FALLBACK | faults::INVALID_STATE) != 0 {
                r.backup_steps[s] += 1;
            }
            if f & DISTURBED != 0 {
                r.disturbed_steps[s] += 1;
            }
        }
    }
}

/// The result of a case from its records (in process, or read back from a partition
/// run's telemetry).
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
        substituted_steps: PerSubsystem::default(),
        relaxed_steps: PerSubsystem::default(),
        backup_steps: PerSubsystem::default(),
        disturbed_steps: PerSubsystem::default(),
        solve_time_us: summary
            .solve_time_us
            .get("total")
            .copied()
            .unwrap_or_default(),
        safe_mode: None,
    };
    count_steps(&mut r, records, &setup.scenario.limits);
    r.safe_mode = sc_mission::SafeModeSummary::of(records, &setup.scenario).map(|m| CaseSafeMode {
        entered_t_s: m.entered_t_s,
        certifiable: m.line_of_sight_certifiable(),
        undetected_t_s: m.undetected_t_s,
        first_violation_t_s: first_violation(records),
        exited_t_s: m.entered_t_s.and_then(|t| first_exit(records, t)),
    });
    r
}

/// The first record after `entered` [s] on which no filter is in safe mode [s].
fn first_exit(records: &[StepRecord], entered: f64) -> Option<f64> {
    records
        .iter()
        .filter(|r| r.t > entered)
        .find(|r| {
            filter_faults(r)
                .iter()
                .all(|(_, f)| f & faults::SAFE_MODE == 0)
        })
        .map(|r| r.t)
}

/// The time of the first record with a barrier below zero (or not evaluable) at its
/// control step or the physics steps before it [s].
fn first_violation(records: &[StepRecord]) -> Option<f64> {
    records
        .iter()
        .find(|r| !(sc_mission::all_hold(&r.barriers) && sc_mission::all_hold(&r.barriers_between)))
        .map(|r| r.t)
}

/// Called as cases finish: `(done, total, result)`.
pub type Progress<'a> = dyn Fn(usize, usize, &Result<CaseResult, CaseError>) + Sync + 'a;

#[cfg(test)]
mod tests {
    use super::*;

    fn result(target: &str, disturbed: [usize; 3]) -> CaseResult {
        CaseResult {
            case: format!("{target}/greedy"),
            target: target.into(),
            strategy: "greedy".into(),
            end: "timeout".into(),
            final_time_s: 1.0,
            steps: 10,
            min_h: BTreeMap::new(),
            violated: Vec::new(),
            nonfinite_applied: 0,
            out_of_bounds_applied: 0,
            substituted_steps: PerSubsystem::default(),
            relaxed_steps: PerSubsystem::default(),
            backup_steps: PerSubsystem::default(),
            disturbed_steps: PerSubsystem(disturbed),
            solve_time_us: TimeStats::default(),
            safe_mode: None,
        }
    }

    /// Announced: a violation strictly after the at-risk entry, while still in safe mode,
    /// with no silent exit; anything else is not.
    #[test]
    fn a_violation_is_announced_only_after_an_at_risk_entry_while_in_safe_mode() {
        let m = CaseSafeMode {
            entered_t_s: Some(100.1),
            certifiable: false,
            undetected_t_s: None,
            first_violation_t_s: Some(104.0),
            exited_t_s: None,
        };
        assert!(m.announced());
        for not in [
            CaseSafeMode {
                certifiable: true,
                ..m
            },
            CaseSafeMode {
                first_violation_t_s: Some(100.1),
                ..m
            },
            CaseSafeMode {
                first_violation_t_s: None,
                ..m
            },
            CaseSafeMode {
                undetected_t_s: Some(100.0),
                ..m
            },
            CaseSafeMode {
                exited_t_s: Some(103.0),
                ..m
            },
            CaseSafeMode {
                entered_t_s: None,
                ..m
            },
        ] {
            assert!(!not.announced(), "{not:?}");
        }
        assert!(
            CaseSafeMode {
                exited_t_s: Some(110.0),
                ..m
            }
            .announced()
        );
    }

    /// Only the subsystems a case does not attack count as disturbed bystanders.
    #[test]
    fn bystanders_are_the_subsystems_not_attacked() {
        assert_eq!(
            result("attitude", [1, 20, 300]).bystander_disturbed_steps(),
            301
        );
        assert_eq!(result("all", [1, 20, 300]).bystander_disturbed_steps(), 0);
    }

    /// The per-filter counts are `[translational, attitude, robotic]` in JSON.
    #[test]
    fn per_filter_counts_are_arrays_in_json() {
        let r = result("robotic", [4, 5, 6]);
        let v = serde_json::to_value(&r).unwrap();
        assert_eq!(v["disturbed_steps"], serde_json::json!([4, 5, 6]));
        let back: CaseResult = serde_json::from_value(v).unwrap();
        assert_eq!(back.disturbed_steps[Subsystem::Robotic], 6);
    }
}
