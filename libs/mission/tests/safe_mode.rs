//! Leaving the certified envelope during a run (docs/SAFETY.md, "Safe mode"): the world
//! spins the target up beyond the envelope, or presents a grasping fixture elsewhere than
//! declared, without the mission declaring it; the layer
//! detects it on the step the estimate first shows it, every filter goes to safe mode
//! (retreat, arm brake), the summary says when, what broke and whether the line of sight
//! was still certifiable at that range — and the barriers on the true state hold.

mod common;
use sc_cbf::faults;
use sc_mission::{SafeModeSummary, StepRecord, summarize};
use sc_scenario::{SpinChange, World};

/// The default mission with `world` (under the `realistic` profile if `realistic`): the
/// summary (with its safe mode) and the records.
fn in_world(world: World, realistic: bool) -> (sc_mission::Summary, Vec<StepRecord>) {
    let mut setup = common::default_setup();
    setup.scenario.world = Some(world);
    if realistic {
        let spec =
            sc_scenario::UncertaintySpec::profile(sc_scenario::uncertainty::REALISTIC_NAME, 3);
        setup.scenario.set_uncertainty(spec).unwrap();
    }
    let scenario = setup.scenario.clone();
    let (_, records, end, phases) = common::run_mission(setup);
    let mut summary = summarize(&records, &end, &phases, true);
    summary.safe_mode = SafeModeSummary::of(&records, &scenario);
    (summary, records)
}

/// The default mission with the target's rate set to `omega` [rad/s, F_T] at `t_s`.
fn changed(t_s: f64, omega: [f64; 3], realistic: bool) -> (sc_mission::Summary, Vec<StepRecord>) {
    let change = SpinChange {
        t_s,
        omega_rad_s: omega,
    };
    let world = World {
        target_spin_change: Some(change),
        ..World::default()
    };
    in_world(world, realistic)
}

/// [`changed`] about the declared spin axis to `rate`, exact navigation.
fn spun_up(t_s: f64, rate: f64) -> (sc_mission::Summary, Vec<StepRecord>) {
    changed(t_s, [-rate, 0.0, 0.0], false)
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
/// (With the arm–target rows and 4 verification rounds one robotic step at the grasp was
/// not certified here; with 8 every step is — docs/SAFETY.md, "The arm and the target".)
#[test]
fn a_spin_change_inside_the_envelope_is_no_safe_mode() {
    let (s, records) = spun_up(40.0, 0.1);
    assert_eq!(s.safe_mode, None);
    assert!(records.iter().all(|r| in_safe_mode(r) == [false; 3]));
    assert!(s.passed(), "{}", s.verdict());
}

/// Under the `realistic` profile (the target's rate known to 1e-3 rad/s) a spin-up beyond
/// the envelope is seen on the first step after it too, never silently, and the line of
/// sight holds (the profile's link-mass errors, which no robotic row covers yet, can break
/// a joint-rate barrier while the arm brakes: docs/SAFETY.md, "Model error … not in the
/// rows yet"); a change that stays near the declared axis and inside the envelope (1e-4
/// rad/s across it) is neither a false alarm nor a silent exit.
#[test]
fn under_realistic_navigation_the_watch_is_neither_late_nor_jumpy() {
    let (s, records) = changed(40.0, [-0.25, 0.0, 0.0], true);
    let m = s.safe_mode.as_ref().expect("a safe mode");
    let first = records.iter().position(|r| r.t > 40.0).unwrap();
    assert_eq!(m.entered_t_s, Some(records[first].t), "{m:?}");
    assert_eq!(m.undetected_t_s, None, "{m:?}");
    let los = "line_of_sight".to_string();
    assert!(!s.violated_constraints.contains(&los), "{}", s.verdict());
    let (s, records) = changed(40.0, [-0.08, 1e-4, 0.0], true);
    assert_eq!(s.safe_mode, None, "{}", s.verdict());
    assert!(records.iter().all(|r| in_safe_mode(r) == [false; 3]));
}

/// The default mission with the world's grasping fixture at `fixture` [m, F_T] instead of
/// the declared one.
fn fixture_at(fixture: [f64; 3], realistic: bool) -> (sc_mission::Summary, Vec<StepRecord>) {
    let world = World {
        grasp_point_m: Some(fixture),
        ..World::default()
    };
    in_world(world, realistic)
}

/// A target whose fixture is 0.45 m farther off the spin axis than declared (0.8 m: at the
/// declared 0.08 rad/s it turns the line of sight faster than the boresight may follow,
/// (E1)) is detected on the first step — the estimate shows where the fixture is — in
/// every filter, exact and under `realistic` navigation; the summary names both positions;
/// never silently; the line of sight holds.
#[test]
fn a_fixture_farther_out_than_declared_puts_the_layer_in_safe_mode_at_once() {
    for realistic in [false, true] {
        let (s, records) = fixture_at([-0.55, 0.8, 0.0], realistic);
        let m = s.safe_mode.as_ref().expect("a safe mode in the summary");
        assert_eq!(m.entered_t_s, Some(records[0].t), "{m:?}");
        assert_eq!(m.undetected_t_s, None, "{m:?}");
        assert_eq!(m.rule, "line_of_sight_rate");
        assert_eq!(m.fixture_m, Some([-0.55, 0.8, 0.0]));
        assert_eq!(m.declared_fixture_m, Some([-0.55, 0.35, 0.0]));
        assert!(m.line_of_sight_certifiable(), "{m:?}");
        assert!(records.iter().all(|r| in_safe_mode(r) == [true; 3]));
        assert!(
            s.verdict()
                .contains("its true grasping fixture at [-0.550, 0.800, 0.000] m")
        );
        let los = "line_of_sight".to_string();
        assert!(!s.violated_constraints.contains(&los), "{}", s.verdict());
        assert!(!s.passed());
    }
}

/// A fixture 5 cm off its declared place but inside the envelope changes nothing the layer
/// decides: no safe mode, and the mission captures (the filters take the fixture known).
#[test]
fn a_fixture_moved_inside_the_envelope_is_no_safe_mode() {
    let (s, records) = fixture_at([-0.55, 0.40, 0.0], false);
    assert_eq!(s.safe_mode, None);
    assert!(records.iter().all(|r| in_safe_mode(r) == [false; 3]));
    assert!(s.passed(), "{}", s.verdict());
}

/// A plant outside the simulator (Basilisk) cannot apply the world's change: refused when
/// it is set, before the run, not when the change falls due.
#[test]
fn an_external_plant_is_refused_with_a_world_event() {
    struct Never;
    impl sc_sim::Plant for Never {
        fn start(&mut self, _: &sc_sim::SimState) -> Result<(), sc_sim::PlantError> {
            Ok(())
        }
        fn propagate(
            &mut self,
            _: &sc_sim::Command,
            _: f64,
            _: usize,
        ) -> Result<Vec<sc_sim::SimState>, sc_sim::PlantError> {
            Err(sc_sim::PlantError("never propagated".into()))
        }
    }
    let mut setup = common::default_setup();
    setup.scenario.world = Some(World {
        target_spin_change: Some(SpinChange {
            t_s: 10.0,
            omega_rad_s: [-0.2, 0.0, 0.0],
        }),
        ..World::default()
    });
    let mut m = sc_mission::Mission::new(setup, sc_mission::RunOptions::default()).unwrap();
    let e = m.set_plant(Box::new(Never)).unwrap_err();
    assert!(
        e.0.contains("[world] event needs the simulator's own propagation"),
        "{e}"
    );
}
