//! What a run's summary says about the certified envelope during the run: when the safety
//! layer went to safe mode (the filters' [`faults::SAFE_MODE`] flags, decided on
//! knowledge), what the true tumble (with the true grasping fixture) broke then, whether
//! the line of sight was still certifiable at that range — and when the true tumble (or
//! fixture) left the envelope while the layer did not say so (docs/SAFETY.md, "Safe
//! mode").

use crate::record::StepRecord;
use sc_cbf::faults;
use sc_cbf::safe_mode::{EnvelopeWatch, fixture_in_target_frame};
use serde::{Deserialize, Serialize};

/// The safe mode of a run, from its records and the true state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SafeModeSummary {
    /// The first step a filter was in safe mode [s] (`None`: never).
    pub entered_t_s: Option<f64>,
    /// Steps on which any filter was in safe mode.
    pub steps: usize,
    /// The first step on which the true tumble (with the true fixture) broke a rule of the
    /// envelope [s].
    pub truth_left_t_s: Option<f64>,
    /// The first step on which the true tumble was outside the envelope and no filter in
    /// safe mode [s]: a silent exit (`None`: none).
    pub undetected_t_s: Option<f64>,
    /// The rule the true tumble broke when the safe mode began (`estimate_only` when only
    /// the estimate's worst case broke one), and the rule's numbers in one line.
    pub rule: String,
    pub reason: String,
    /// The true line of sight's length when the safe mode began, and the least length at
    /// which the boresight can follow the true tumble's grasping point [m].
    pub line_of_sight_m: f64,
    pub range_needed_m: f64,
    /// The true grasping fixture [m, F_T] at the step the safe mode began (or the truth
    /// left), if it is not the declared one on the watch's premise (`[world]
    /// grasp_point_m`), and the declared one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fixture_m: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub declared_fixture_m: Option<[f64; 3]>,
}

impl SafeModeSummary {
    /// From `records` of a run of `scenario` (`None` when the layer never went to safe
    /// mode and the true tumble never left the envelope).
    pub fn of(records: &[StepRecord], scenario: &sc_scenario::Scenario) -> Option<Self> {
        Self::with_watch(records, &EnvelopeWatch::from_scenario(scenario))
    }

    /// [`Self::of`] with the scenario's watch built once (a caller that asks per step).
    pub fn with_watch(records: &[StepRecord], watch: &EnvelopeWatch) -> Option<Self> {
        let in_safe_mode = |r: &StepRecord| {
            [
                r.translational.report.faults,
                r.attitude.report.faults,
                r.robotic.report.faults,
            ]
            .iter()
            .any(|f| f & faults::SAFE_MODE != 0)
        };
        let outside = |r: &StepRecord| watch.check_truth(&true_rate(r), &true_fixture(r)).is_some();
        let entered = records.iter().find(|r| in_safe_mode(r));
        let truth_left = records.iter().find(|r| outside(r));
        if entered.is_none() && truth_left.is_none() {
            return None;
        }
        let undetected = records.iter().find(|r| outside(r) && !in_safe_mode(r));
        let at = entered.or(truth_left)?;
        let fixture = true_fixture(at);
        let env = watch.truth_envelope(&true_rate(at), &fixture);
        let moved = watch.true_fixture(&fixture).map(|f| f.point_m);
        let rule = env.broken_tumble_rule();
        Some(Self {
            entered_t_s: entered.map(|r| r.t),
            steps: records.iter().filter(|r| in_safe_mode(r)).count(),
            truth_left_t_s: truth_left.map(|r| r.t),
            undetected_t_s: undetected.map(|r| r.t),
            rule: rule.map_or(ESTIMATE_ONLY, |r| r.name()).into(),
            reason: rule.map(|r| env.explain(r)).unwrap_or_else(|| {
                "the true tumble and fixture were inside the envelope; the estimate's worst case (ē and ē_G added) was not".into()
            }),
            line_of_sight_m: (at.obs.grasp_r - at.obs.com_r).norm(),
            range_needed_m: env.range_needed_m(),
            fixture_m: moved,
            declared_fixture_m: moved.map(|_| watch.declared_fixture_m()),
        })
    }

    /// The line of sight was long enough for the boresight to follow the true tumble when
    /// the safe mode began (its certificate, docs/SAFETY.md).
    pub fn line_of_sight_certifiable(&self) -> bool {
        // a tumble off the principal axes beyond the rows' bounds, a geometry the rows are
        // not defined for or an unknown one: no distance makes it certifiable
        let by_range = !matches!(self.rule.as_str(), "off_principal" | "geometry" | "unknown");
        by_range && self.line_of_sight_m >= self.range_needed_m
    }

    /// One line for the verdict.
    pub fn line(&self) -> String {
        let mut s = match self.entered_t_s {
            Some(t) => format!(
                "safe mode from t = {t:.1} s ({} left the certified envelope: {}; {})",
                self.what_left(),
                self.rule,
                self.range_line()
            ),
            None => String::new(),
        };
        if let Some(t) = self.undetected_t_s {
            if !s.is_empty() {
                s.push_str("; ");
            }
            s.push_str(&format!(
                "the true {} left the certified envelope UNDETECTED at t = {t:.1} s ({})",
                if self.fixture_m.is_some() {
                    "target"
                } else {
                    "tumble"
                },
                self.rule
            ));
        }
        s
    }

    /// What the layer knew to leave the envelope: the tumble, or the target whose true
    /// fixture is elsewhere than declared.
    fn what_left(&self) -> String {
        match (self.fixture_m, self.declared_fixture_m) {
            (Some(p), Some(d)) => format!(
                "the target known — its true grasping fixture at [{:.3}, {:.3}, {:.3}] m in F_T instead of the declared [{:.3}, {:.3}, {:.3}] —",
                p[0], p[1], p[2], d[0], d[1], d[2]
            ),
            _ => "the tumble known".into(),
        }
    }

    fn range_line(&self) -> String {
        if matches!(self.rule.as_str(), "off_principal" | "geometry" | "unknown") {
            return "no range makes the line of sight certifiable: AT RISK".into();
        }
        if self.line_of_sight_certifiable() {
            format!(
                "line of sight {:.2} m, the tumble needs {:.2} m: certifiable",
                self.line_of_sight_m, self.range_needed_m
            )
        } else {
            format!(
                "line of sight {:.2} m, the tumble needs {:.2} m: AT RISK until the retreat gets there",
                self.line_of_sight_m, self.range_needed_m
            )
        }
    }
}

/// `rule` when the watch's worst case left the envelope while the true tumble did not.
const ESTIMATE_ONLY: &str = "estimate_only";

/// The true grasping fixture [m, F_T] of a record.
fn true_fixture(r: &StepRecord) -> [f64; 3] {
    fixture_in_target_frame(&r.obs.q_rt, &r.obs.grasp_r)
}

/// The true ω_T [rad/s, F_T] of a record.
fn true_rate(r: &StepRecord) -> [f64; 3] {
    let w = r.obs.omega_t;
    [w.x, w.y, w.z]
}
