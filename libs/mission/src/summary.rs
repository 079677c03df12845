//! `summary.json`: the stable, script-readable result of a run.

use crate::mission::MissionEnd;
use crate::record::StepRecord;
pub use crate::safe_mode_summary::SafeModeSummary;
use sc_cbf::faults;
use sc_sim::uncertainty::{NAVIGATION_ERROR_NAMES, NavigationError};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Statistics of a set of solve times [µs].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct TimeStats {
    pub geomean: f64,
    pub p50: f64,
    pub p99: f64,
    pub max: f64,
    pub samples: usize,
}

impl TimeStats {
    /// Geometric mean, nearest-rank percentiles and maximum of `v` (µs; zeros are
    /// counted as 1 ns so that the geometric mean stays defined).
    pub fn of(v: &[f64]) -> Self {
        if v.is_empty() {
            return Self::default();
        }
        let mut s: Vec<f64> = v.iter().map(|x| x.max(1e-3)).collect();
        s.sort_by(f64::total_cmp);
        let pct = |p: f64| s[((p / 100.0 * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1];
        let geomean = (s.iter().map(|x| x.ln()).sum::<f64>() / s.len() as f64).exp();
        Self {
            geomean,
            p50: pct(50.0),
            p99: pct(99.0),
            max: s[s.len() - 1],
            samples: s.len(),
        }
    }
}

/// Minimum of one barrier over the run, from the true state (the safety monitor), never
/// from a filter's report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConstraintSummary {
    /// Smallest h over every physics step of the run (the control steps and the states
    /// between them; NaN samples excluded, see `nan_samples`).
    pub min_h: f64,
    /// Smallest h over the control steps only (the samples the filters see).
    pub min_h_at_control_steps: f64,
    /// True if any sample, at a control or a physics step, was < 0 or NaN.
    pub violated: bool,
    /// Time of the control step at (or, for an inter-sample minimum, just after) the minimum.
    pub t_of_min_s: f64,
    /// Samples that could not be evaluated (non-finite state); each counts as a violation.
    pub nan_samples: usize,
    /// Smallest h per mission phase (by phase name), over every physics step.
    pub min_h_per_phase: BTreeMap<String, f64>,
}

/// One reported fault.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FaultEvent {
    pub step: u64,
    pub t_s: f64,
    pub filter: String,
    pub flags: Vec<String>,
}

/// Interventions of one filter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Interventions {
    /// Steps in which the safe command differed from the nominal one.
    pub steps: usize,
    pub fraction: f64,
    /// Of those steps, how many had each barrier row active (the filter's report).
    #[serde(default)]
    pub active_rows: BTreeMap<String, usize>,
    /// Of those steps, how many had no barrier row active: the input bounds (or a
    /// substitute nominal) alone changed the command.
    #[serde(default)]
    pub without_active_row: usize,
}

/// The summary of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The program's version and git commit (see [`crate::build`]).
    #[serde(default)]
    pub version: String,
    #[serde(default)]
    pub git_commit: String,
    pub filtered: bool,
    pub captured: bool,
    pub capture_time_s: Option<f64>,
    /// How the run ended ([`MissionEnd::name`]): "captured", "timeout" or
    /// "simulator_failed" when the mission ended; "stopped" (`--max-ticks`, or the
    /// partition's scheduler stopped the run) or "interrupted" (SIGINT/SIGTERM) when
    /// the run ended before the mission did.
    pub end: String,
    pub final_time_s: f64,
    pub steps: usize,
    /// The constraint with the smallest h over the run, and that h (the safety margin).
    pub min_margin: (String, f64),
    pub violated_constraints: Vec<String>,
    pub constraints: BTreeMap<String, ConstraintSummary>,
    pub interventions: BTreeMap<String, Interventions>,
    /// Wall time of each filter call per step [µs] (includes preemption).
    pub solve_time_us: BTreeMap<String, TimeStats>,
    /// CPU time the filters' thread spent per step [µs]: the filters' own work.
    #[serde(default)]
    pub solve_cpu_us: BTreeMap<String, TimeStats>,
    /// Peak ‖ω_B − R_BT ω_T‖ per phase [rad/s].
    pub sync_error_peak_rad_s: BTreeMap<String, f64>,
    /// Peak ‖τ_M‖₂ applied in each phase [N m].
    pub joint_torque_norm_peak_nm: BTreeMap<String, f64>,
    pub fault_count: usize,
    /// Fault events (the first 1000).
    pub faults: Vec<FaultEvent>,
    /// The declared uncertainty and the realised errors against it (absent for the
    /// `exact` profile); see [`UncertaintySummary::of`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<UncertaintySummary>,
    /// Per nominal controller (`nominal_<subsystem>`, the partner's role) that failed to
    /// give a valid command: how often and from when (absent when every one did).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub partner_faults: BTreeMap<String, PartnerFaults>,
    /// The safe mode and the certified envelope during the run (absent when the layer never
    /// went to safe mode and the true tumble never left the envelope); see
    /// [`SafeModeSummary::of`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safe_mode: Option<SafeModeSummary>,
}

/// Steps on which a nominal controller gave no valid command (its filter flagged
/// `nominal_missing` or `invalid_nominal` and filtered the substitute nominal instead).
/// Counted in the run's steps (the base rate: in a multi-rate partition a command held
/// over k steps counts k times), and not on steps where an upstream input was missing
/// too (the backup of a late or dead filter process runs on the substitute nominal
/// whatever the partner sent). A partner that marks its command invalid (`valid = 0`)
/// shows as `missing` (the filter does not take it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartnerFaults {
    /// Steps without a valid command.
    pub steps: usize,
    /// Of them, steps with no command taken (silent, late, dead, or marked invalid by the
    /// partner) and with an invalid one (non-finite, out of range).
    pub missing: usize,
    pub invalid: usize,
    /// Time of the first [s].
    pub first_t_s: f64,
}

impl Summary {
    /// The verdict of a run, as `run` and `launch` print it (one definition, README
    /// "Verdicts and exit codes"): how it ended, the smallest margin, the violated
    /// barriers, the fault count, and every partner that gave no valid command on some
    /// steps (`nominal_attitude: 954 of 1255 steps without a valid command (first at t =
    /// 30.0 s)`).
    pub fn verdict(&self) -> String {
        format!(
            "{} at t = {:.1} s; {}",
            self.end,
            self.final_time_s,
            self.verdict_after_end(&|_| None)
        )
    }

    /// [`Self::verdict`] after how the run ended, each partner's fault with the reason
    /// `reason(role)` gives for its first (e.g. from the partner's log).
    pub fn verdict_after_end(&self, reason: &dyn Fn(&str) -> Option<String>) -> String {
        let mut line = format!(
            "min margin {} = {:.3e}; violated: [{}]; faults: {}",
            self.min_margin.0,
            self.min_margin.1,
            self.violated_constraints.join(", "),
            self.fault_count
        );
        for (role, f) in &self.partner_faults {
            line.push_str(&format!(
                "; {}",
                f.line(role, self.steps, reason(role).as_deref())
            ));
        }
        if let Some(m) = &self.safe_mode {
            line.push_str(&format!("; {}", m.line()));
        }
        line
    }

    /// Passed, the exit code 0 of `run`, `launch` and every run of `montecarlo`:
    /// captured, [`Self::safe`], without a fault and never in safe mode (the safe mode is
    /// decided step by step: a tumble known inside again hands the commands back to the
    /// partners, but the run left the certified envelope).
    pub fn passed(&self) -> bool {
        let never_safe_mode = self
            .safe_mode
            .as_ref()
            .is_none_or(|m| m.entered_t_s.is_none());
        self.captured && self.safe() && self.fault_count == 0 && never_safe_mode
    }

    /// Safe (README, "Verdicts and exit codes"): every barrier held on the true state,
    /// (with a declared uncertainty) the realised errors within the declared bounds, and
    /// the true tumble never outside the certified envelope without the layer in safe mode.
    pub fn safe(&self) -> bool {
        let within = self
            .uncertainty
            .as_ref()
            .is_none_or(|u| u.outside_bounds.is_empty());
        let detected = self
            .safe_mode
            .as_ref()
            .is_none_or(|m| m.undetected_t_s.is_none());
        self.violated_constraints.is_empty() && within && detected
    }
}

/// The declared uncertainty of a run and whether the realised errors stayed inside it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UncertaintySummary {
    pub profile: String,
    pub seed: u64,
    /// The largest realised navigation error of each kind over the run, and its bound.
    pub navigation_max: BTreeMap<String, f64>,
    pub navigation_bound: BTreeMap<String, f64>,
    /// The keys whose realised error (plant, actuators, navigation) exceeded the
    /// declared bound (empty: within). A simulation knows the truth; a flight system
    /// checks only what it can measure.
    pub outside_bounds: Vec<String>,
    /// The declared error sources no filter margin covers (`sc_cbf::coverage`): outside
    /// the promise even within their bounds.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_covered: Vec<String>,
}

impl UncertaintySummary {
    /// The summary of `records` under the scenario's declared uncertainty (`filtered`:
    /// the filters were on); `None` when it declares none. The run's realisation is drawn
    /// again from its seed (it is a function of the scenario, the robot and the seed) to
    /// compare the realised plant and actuator errors with the declared bounds.
    pub fn of(
        records: &[StepRecord],
        scenario: &sc_scenario::Scenario,
        robot: &sc_multibody::Robot,
        filtered: bool,
    ) -> Option<Self> {
        let spec = scenario.uncertainty.as_ref()?;
        let declared = scenario.uncertainty_bounds();
        let bounds = NavigationError::bounds(&declared.navigation);
        let max = navigation_max(records);
        let named = |v: &[f64]| -> BTreeMap<String, f64> {
            NAVIGATION_ERROR_NAMES
                .iter()
                .map(|n| n.to_string())
                .zip(v.iter().copied())
                .collect()
        };
        let mut outside_bounds: Vec<String> = match sc_sim::Realisation::draw(
            &scenario.uncertainty_truth_bounds(),
            spec.seed,
            scenario,
            robot,
        ) {
            Ok(r) => [
                r.plant.outside(&declared.model),
                r.actuators.outside(&declared.actuators),
            ]
            .concat()
            .into_iter()
            .map(String::from)
            .collect(),
            Err(e) => vec![format!("realisation ({e})")],
        };
        outside_bounds.extend(
            NAVIGATION_ERROR_NAMES
                .iter()
                .zip(max.iter().zip(bounds))
                .filter(|(_, (m, b))| {
                    let allowed =
                        *b * (1.0 + 1e-9) + sc_sim::uncertainty::NAVIGATION_ERROR_ROUNDING;
                    (**m).partial_cmp(&allowed).is_none_or(|o| o.is_gt())
                })
                .map(|(n, _)| format!("navigation.{n}")),
        );
        Some(Self {
            profile: spec.profile.clone(),
            seed: spec.seed,
            navigation_max: named(&max),
            navigation_bound: named(&bounds),
            outside_bounds,
            not_covered: sc_cbf::coverage::not_covered_in(scenario, filtered),
        })
    }

    /// One line for the run's report.
    pub fn line(&self) -> String {
        let within = if self.outside_bounds.is_empty() {
            "realised plant, actuator and navigation errors within the declared bounds".to_string()
        } else {
            format!(
                "realised errors LEFT the declared bounds: [{}] — the promise does not cover this run",
                self.outside_bounds.join(", ")
            )
        };
        let covered = if self.not_covered.is_empty() {
            String::new()
        } else {
            format!(
                "; the filters' margins do not cover the declared [{}]: outside the promise (docs/SAFETY.md)",
                self.not_covered.join(", ")
            )
        };
        format!(
            "uncertainty: profile {} (seed {}): {within}{covered}",
            self.profile, self.seed
        )
    }
}

/// The largest realised navigation error of each kind over `records` (NaN if any was).
fn navigation_max(records: &[StepRecord]) -> [f64; NAVIGATION_ERROR_NAMES.len()] {
    let mut max = [0.0f64; NAVIGATION_ERROR_NAMES.len()];
    for e in records.iter().filter_map(|r| r.navigation_error.as_ref()) {
        for (m, v) in max.iter_mut().zip(e.values()) {
            // a NaN error is outside every bound
            *m = if v.is_nan() || m.is_nan() {
                f64::NAN
            } else {
                m.max(v)
            };
        }
    }
    max
}

fn flag_names(bits: u32) -> Vec<String> {
    faults::NAMES
        .iter()
        .enumerate()
        .filter(|(i, _)| bits & (1 << i) != 0)
        .map(|(_, n)| n.to_string())
        .collect()
}

/// The filters' names in the order of the records' arrays.
const FILTERS: [&str; 3] = ["translational", "attitude", "robotic"];

/// Who a refused estimate's fault event names, and its flag (`fault::NAVIGATION_REJECTED`).
const NAVIGATION: &str = "navigation";
const NAVIGATION_REJECTED: &str = "NAVIGATION_REJECTED";

/// Most fault events kept in the summary (every one is counted in `fault_count`).
const MAX_FAULT_EVENTS: usize = 1000;

/// Builds the summary of a run from its records.
pub fn summarize(
    records: &[StepRecord],
    end: &MissionEnd,
    phase_names: &[String],
    filtered: bool,
) -> Summary {
    let phase_name = |p: usize| {
        phase_names
            .get(p)
            .cloned()
            .unwrap_or_else(|| format!("phase_{p}"))
    };
    let mut tally = Tally::new();
    for r in records {
        let pn = phase_name(r.phase);
        tally.barriers(r, &pn);
        tally.solve_times(r);
        tally.interventions(r);
        tally.peaks(r, &pn);
        tally.faults(r);
    }
    tally.finish(records.len(), end, filtered)
}

/// What [`summarize`] gathers over the records, one record at a time.
struct Tally {
    names: Vec<&'static str>,
    constraints: BTreeMap<String, ConstraintSummary>,
    /// Per filter and the total (the records' order).
    solve: [Vec<f64>; 4],
    solve_cpu: [Vec<f64>; 4],
    inter: [Interventions; 3],
    sync_peak: BTreeMap<String, f64>,
    torque_peak: BTreeMap<String, f64>,
    fault_events: Vec<FaultEvent>,
    fault_count: usize,
    partner_faults: BTreeMap<String, PartnerFaults>,
}

impl Tally {
    fn new() -> Self {
        let names = crate::constraint_names();
        let mut constraints: BTreeMap<String, ConstraintSummary> = BTreeMap::new();
        for n in &names {
            constraints.insert(
                n.to_string(),
                ConstraintSummary {
                    min_h: f64::INFINITY,
                    min_h_at_control_steps: f64::INFINITY,
                    violated: false,
                    t_of_min_s: 0.0,
                    nan_samples: 0,
                    min_h_per_phase: BTreeMap::new(),
                },
            );
        }
        Self {
            names,
            constraints,
            solve: Default::default(),
            solve_cpu: Default::default(),
            inter: Default::default(),
            sync_peak: BTreeMap::new(),
            torque_peak: BTreeMap::new(),
            fault_events: Vec::new(),
            fault_count: 0,
            partner_faults: BTreeMap::new(),
        }
    }

    /// The barriers' minima, at the control step and between it and the next one.
    fn barriers(&mut self, r: &StepRecord, pn: &str) {
        for (i, n) in self.names.iter().enumerate() {
            let c = self.constraints.get_mut(*n).expect("constraint present");
            let at_step = r.barriers[i];
            if !at_step.is_nan() {
                c.min_h_at_control_steps = c.min_h_at_control_steps.min(at_step);
            }
            for h in [at_step, r.barriers_between[i]] {
                if h.is_nan() {
                    c.nan_samples += 1;
                    c.violated = true;
                    continue;
                }
                if h < c.min_h {
                    c.min_h = h;
                    c.t_of_min_s = r.t;
                }
                if h < 0.0 {
                    c.violated = true;
                }
                let e = c
                    .min_h_per_phase
                    .entry(pn.to_string())
                    .or_insert(f64::INFINITY);
                *e = e.min(h);
            }
        }
    }

    fn solve_times(&mut self, r: &StepRecord) {
        let t = r.solve_time_us();
        let c = r.solve_cpu_us();
        for i in 0..4 {
            self.solve[i].push(t[i]);
            self.solve_cpu[i].push(c[i]);
        }
    }

    /// The steps where a filter changed the nominal command, and the rows it had active.
    fn interventions(&mut self, r: &StepRecord) {
        let row_names: [&[&str]; 3] = [
            &sc_cbf::names::TRANSLATIONAL,
            &sc_cbf::names::ATTITUDE,
            &sc_cbf::names::ROBOTIC,
        ];
        let changed = [
            (r.translational.u - r.f_h_nom).amax() > 1e-9,
            (r.attitude.u - r.tau_b_nom).amax() > 1e-9,
            (r.robotic.u - r.tau_m_nom).amax() > 1e-9,
        ];
        let active = [
            r.translational.report.active,
            r.attitude.report.active,
            r.robotic.report.active,
        ];
        for i in 0..3 {
            if !changed[i] {
                continue;
            }
            let inter = &mut self.inter[i];
            inter.steps += 1;
            if active[i] == 0 {
                inter.without_active_row += 1;
            }
            for (bit, name) in row_names[i].iter().enumerate() {
                if bit < 64 && active[i] & (1u64 << bit) != 0 {
                    *inter.active_rows.entry(name.to_string()).or_insert(0) += 1;
                }
            }
        }
    }

    /// The per-phase peaks of the synchronisation error and the joint torque.
    fn peaks(&mut self, r: &StepRecord, pn: &str) {
        let s = self.sync_peak.entry(pn.to_string()).or_insert(0.0);
        *s = s.max(r.obs.sync_error().norm());
        let tq = self.torque_peak.entry(pn.to_string()).or_insert(0.0);
        *tq = tq.max(r.applied.tau.norm());
    }

    fn faults(&mut self, r: &StepRecord) {
        let reported = [
            r.translational.report.faults,
            r.attitude.report.faults,
            r.robotic.report.faults,
        ];
        for (name, f) in FILTERS.into_iter().zip(reported) {
            // the safe mode is the defined reaction to leaving the envelope, reported on
            // its own (`Summary::safe_mode`), not a fault of the step
            if f & !faults::SAFE_MODE != 0 {
                self.fault(r, name, flag_names(f));
            }
            self.partner(r, name, f);
        }
        if r.navigation_rejected {
            self.fault(r, NAVIGATION, vec![NAVIGATION_REJECTED.into()]);
        }
    }

    /// Counts a step on which the nominal controller of `filter`'s subsystem gave no valid
    /// command (the filter's flags `f`).
    fn partner(&mut self, r: &StepRecord, filter: &str, f: u32) {
        let missing = f & faults::NOMINAL_MISSING != 0;
        let invalid = f & faults::INVALID_NOMINAL != 0;
        // a step on which an upstream input was missing — the partition's backup of a
        // late or dead filter process carries the flag too, and runs on the substitute
        // nominal whatever the partner sent — is no evidence against the partner
        if !(missing || invalid) || f & faults::UPSTREAM_MISSING != 0 {
            return;
        }
        let p = self
            .partner_faults
            .entry(format!("nominal_{filter}"))
            .or_insert(PartnerFaults {
                steps: 0,
                missing: 0,
                invalid: 0,
                first_t_s: r.t,
            });
        p.steps += 1;
        p.missing += usize::from(missing);
        p.invalid += usize::from(invalid && !missing);
    }

    /// Counts a fault of `by` and keeps its event while there is room.
    fn fault(&mut self, r: &StepRecord, by: &str, flags: Vec<String>) {
        self.fault_count += 1;
        if self.fault_events.len() < MAX_FAULT_EVENTS {
            self.fault_events.push(FaultEvent {
                step: r.step,
                t_s: r.t,
                filter: by.into(),
                flags,
            });
        }
    }

    /// The summary of `steps` records gathered here.
    fn finish(self, steps: usize, end: &MissionEnd, filtered: bool) -> Summary {
        let mut min_margin = (String::new(), f64::INFINITY);
        for (n, c) in &self.constraints {
            if c.min_h < min_margin.1 {
                min_margin = (n.clone(), c.min_h);
            }
        }
        let violated_constraints = self
            .constraints
            .iter()
            .filter(|(_, c)| c.violated)
            .map(|(n, _)| n.clone())
            .collect();
        let fraction = |k: usize| {
            if steps == 0 {
                0.0
            } else {
                k as f64 / steps as f64
            }
        };
        let interventions = FILTERS
            .iter()
            .zip(self.inter)
            .map(|(n, mut k)| {
                k.fraction = fraction(k.steps);
                (n.to_string(), k)
            })
            .collect();
        let (captured, capture_time_s) = match end {
            MissionEnd::Captured { t } => (true, Some(*t)),
            _ => (false, None),
        };
        let build = crate::build::current();
        Summary {
            version: build.version,
            git_commit: build.git_commit,
            filtered,
            captured,
            capture_time_s,
            end: end.name().into(),
            final_time_s: end.t(),
            steps,
            min_margin,
            violated_constraints,
            constraints: self.constraints,
            interventions,
            solve_time_us: time_stats(&self.solve),
            solve_cpu_us: time_stats(&self.solve_cpu),
            sync_error_peak_rad_s: self.sync_peak,
            joint_torque_norm_peak_nm: self.torque_peak,
            fault_count: self.fault_count,
            faults: self.fault_events,
            uncertainty: None,
            partner_faults: self.partner_faults,
            safe_mode: None,
        }
    }
}

impl PartnerFaults {
    /// `nominal_attitude: 954 of 1255 steps without a valid command (first at t = 30.0 s)`,
    /// with the first's reason when known (`… (first at t = 30.0 s: step raised …)`).
    pub fn line(&self, role: &str, steps: usize, reason: Option<&str>) -> String {
        format!(
            "{role}: {} of {steps} steps without a valid command (first at t = {:.1} s{})",
            self.steps,
            self.first_t_s,
            reason.map(|r| format!(": {r}")).unwrap_or_default()
        )
    }
}

/// The statistics of each filter's times and the total's, by name.
fn time_stats(v: &[Vec<f64>; 4]) -> BTreeMap<String, TimeStats> {
    ["translational", "attitude", "robotic", "total"]
        .iter()
        .zip(v.iter())
        .map(|(n, v)| (n.to_string(), TimeStats::of(v)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_stats_nearest_rank() {
        let v: Vec<f64> = (1..=100).map(|x| x as f64).collect();
        let s = TimeStats::of(&v);
        assert_eq!(s.p50, 50.0);
        assert_eq!(s.p99, 99.0);
        assert_eq!(s.max, 100.0);
        let g = TimeStats::of(&[1.0, 100.0]).geomean;
        assert!((g - 10.0).abs() < 1e-12);
        assert_eq!(TimeStats::of(&[]).samples, 0);
    }
}
