//! Leaving the certified envelope during a run (docs/SAFETY.md, "Safe mode"): the world
//! spins the target up beyond the envelope without the mission declaring it; the layer
//! detects it on the step the estimate first shows it, every filter goes to safe mode
//! (retreat, arm brake), the summary says when, what broke and whether the line of sight
//! was still certifiable at that range — and the barriers on the true state hold.

mod common;
use sc_cbf::faults;
use sc_mission::{SafeModeSummary, StepRecord, summarize};
use sc_scenario::{SpinChange, World};

/// The default mission with the target spun up to `rate` [rad/s] about its spin axis at
/// `t_s`: the summary (with its safe mode) and the records.
fn spun_up(t_s: f64, rate: f64) -> (sc_mission::Summary, Vec<StepRecord>) {
    let mut setup = common::default_setup();
    setup.scenario.world = Some(World {
        target_spin_change: Some(SpinChange {
            t_s,
            omega_rad_s: [-rate, 0.0, 0.0],
        }),
    });
    let scenario = setup.scenario.clone();
    let (_, records, end, phases) = common::run_mission(setup);
    let mut summary = summarize(&records, &end, &phases, true);
    summary.safe_mode = SafeModeSummary::of(&records, &scenario);
    (summary, records)
}

fn in_safe_mode(r: &StepRecord) -> [bool; 3] {
    [
        r.translational.report.faults,
        r.attitude.report.faults,
        r.robotic.report.faults,
    ]
    .map(|f| f & faults::SAFE_MODE != 0)
}

/// Far from the target (40 s, 2.4 m of line of sight) a spin-up to 0.25 rad/s: detected on
/// the first step after it, by every filter, until the end; the servicer retreats; the
/// line of sight was certifiable there; every barrier holds; no capture, so not passed.
#[test]
fn a_spin_up_beyond_the_envelope_puts_every_filter_in_safe_mode_at_once() {
    let (s, records) = spun_up(40.0, 0.25);
    let m = s.safe_mode.as_ref().expect("a safe mode in the summary");
    let first = records.iter().position(|r| r.t > 40.0).unwrap();
    assert_eq!(m.entered_t_s, Some(records[first].t), "{m:?}");
    assert_eq!(m.truth_left_t_s, m.entered_t_s);
    assert_eq!(m.undetected_t_s, None);
    assert_eq!(m.rule, "rate_synchronisation");
    assert!(m.line_of_sight_certifiable(), "{m:?}");
    assert!(
        records[..first]
            .iter()
            .all(|r| in_safe_mode(r) == [false; 3])
    );
    assert!(
        records[first..]
            .iter()
            .all(|r| in_safe_mode(r) == [true; 3])
    );
    assert_eq!(m.steps, records.len() - first);
    // the retreat: the servicer ends farther from the target than when it was detected
    let range = |r: &StepRecord| r.obs.com_r.norm();
    assert!(range(records.last().unwrap()) > range(&records[first]) + 1.0);
    assert!(s.violated_constraints.is_empty(), "{s:?}");
    assert!(s.safe() && !s.captured && !s.passed());
    assert!(
        s.verdict().contains("safe mode from t = 40.1 s"),
        "{}",
        s.verdict()
    );
}

/// A spin within the envelope (0.1 rad/s) changes nothing the layer does: no safe mode.
#[test]
fn a_spin_change_inside_the_envelope_is_no_safe_mode() {
    let (s, records) = spun_up(40.0, 0.1);
    assert_eq!(s.safe_mode, None);
    assert!(records.iter().all(|r| in_safe_mode(r) == [false; 3]));
    assert!(s.passed(), "{}", s.verdict());
}
