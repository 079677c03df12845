//! The verdict of a run (README, "Verdicts and exit codes"): partner faults are counted
//! per nominal controller from the filters' flags — not on steps where an upstream input
//! was missing too (the partition's backup of a late or dead filter process runs on the
//! substitute nominal whatever the partner sent) — and a run with faults is safe but does
//! not pass.

mod common;
use sc_cbf::faults;
use sc_mission::{StepRecord, summarize};

fn records(duration_s: f64) -> (Vec<StepRecord>, sc_mission::MissionEnd, Vec<String>) {
    let mut setup = common::default_setup();
    setup.scenario.mission.duration_s = duration_s;
    let (_, records, end, phases) = common::run_mission(setup);
    (records, end, phases)
}

#[test]
fn partner_faults_are_the_partners_and_a_run_with_faults_does_not_pass() {
    let (mut recs, end, phases) = records(3.0);
    let clean = summarize(&recs, &end, &phases, true);
    assert!(clean.partner_faults.is_empty());
    assert!(clean.safe());
    // the attitude partner's command missing at steps 10..15, invalid at 20; at 25 the
    // attitude filter process was late (the backup: its flags carry upstream_missing)
    for r in &mut recs[10..15] {
        r.attitude.report.faults |= faults::NOMINAL_MISSING;
    }
    recs[20].attitude.report.faults |= faults::INVALID_NOMINAL;
    recs[25].attitude.report.faults |= faults::NOMINAL_MISSING | faults::UPSTREAM_MISSING;
    let s = summarize(&recs, &end, &phases, true);
    let p = &s.partner_faults["nominal_attitude"];
    assert_eq!((p.steps, p.missing, p.invalid), (6, 5, 1), "{p:?}");
    assert_eq!(p.first_t_s, recs[10].t);
    assert_eq!(s.partner_faults.len(), 1);
    assert_eq!(s.fault_count, 7);
    assert!(s.safe(), "faults do not make a run unsafe");
    // (a 3 s mission does not capture: as if it had, to see what the faults do)
    let (mut clean, mut s) = (clean, s);
    (clean.captured, s.captured) = (true, true);
    assert!(clean.passed());
    assert!(!s.passed(), "a run with faults does not pass");
    assert!(
        s.verdict().contains(&format!(
            "; nominal_attitude: 6 of {} steps without a valid command (first at t = 1.0 s)",
            recs.len()
        )),
        "{}",
        s.verdict()
    );
}

/// A run that entered the safe mode does not pass, even captured, safe and without a
/// fault (the tumble known came back inside and the partners captured after all); its
/// verdict says when. A rule no range can fix is never certifiable.
#[test]
fn a_run_that_entered_the_safe_mode_does_not_pass() {
    let (recs, end, phases) = records(3.0);
    let mut s = summarize(&recs, &end, &phases, true);
    s.captured = true;
    assert!(s.passed());
    let mut m = sc_mission::SafeModeSummary {
        entered_t_s: Some(1.0),
        steps: 3,
        truth_left_t_s: Some(1.0),
        undetected_t_s: None,
        rule: "rate_synchronisation".into(),
        reason: String::new(),
        line_of_sight_m: 2.0,
        range_needed_m: 1.5,
        fixture_m: None,
        declared_fixture_m: None,
    };
    assert!(m.line_of_sight_certifiable());
    s.safe_mode = Some(m.clone());
    assert!(s.safe() && !s.passed());
    assert!(
        s.verdict().contains("safe mode from t = 1.0 s"),
        "{}",
        s.verdict()
    );
    for rule in ["off_principal", "geometry", "unknown"] {
        m.rule = rule.into();
        assert!(!m.line_of_sight_certifiable(), "{rule}");
    }
    // a fixture elsewhere than declared is named with both positions
    m.fixture_m = Some([-0.55, 0.6, 0.0]);
    m.declared_fixture_m = Some([-0.55, 0.35, 0.0]);
    s.safe_mode = Some(m.clone());
    assert!(
        s.verdict().contains(
            "the target known — its true grasping fixture at [-0.550, 0.600, 0.000] m in F_T instead of the declared [-0.550, 0.350, 0.000] —"
        ),
        "{}",
        s.verdict()
    );
    // the true tumble outside with no filter in safe mode: not safe
    m.entered_t_s = None;
    m.undetected_t_s = Some(1.0);
    s.safe_mode = Some(m);
    assert!(!s.safe());
    assert!(
        s.verdict()
            .contains("the true target left the certified envelope UNDETECTED at t = 1.0 s"),
        "{}",
        s.verdict()
    );
}
