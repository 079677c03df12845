//! The robotic filter verifies every command on the servicer model's sample, so the
//! configured jerk bounds are not what its certificate rests on (docs/SAFETY.md, "The
//! envelope bounds"): with them as configured, the default mission never refutes the
//! cheap certificate (its commands are the ones the bounds certified); with them cut to a
//! hundredth, the cheap certificate is refuted again and again — and the mission is still
//! safe on the true state and captures.

mod common;
use sc_mission::summarize;

/// Runs the default mission with the robotic jerk bounds scaled by `scale`; returns the
/// robotic filter's refuted certificates and the run's summary.
fn run(scale: f64) -> (u64, sc_mission::Summary) {
    let mut setup = common::default_setup();
    let rb = &mut setup.scenario.safety.robotic;
    for j in rb.joint_jerk_bound_rad_s3.iter_mut() {
        *j *= scale;
    }
    for j in rb.link_sphere_jerk_bound_m_s3.iter_mut() {
        *j *= scale;
    }
    let (m, records, end, phases) = common::run_mission(setup);
    let summary = summarize(&records, &end, &phases, true);
    (m.safety.robotic.bounds_refuted(), summary)
}

#[test]
fn the_configured_bounds_are_never_refuted_in_the_default_mission() {
    let (refuted, summary) = run(1.0);
    assert_eq!(refuted, 0);
    assert!(summary.passed(), "{summary:?}");
}

#[test]
fn bounds_cut_to_a_hundredth_are_refuted_and_the_mission_stays_safe() {
    let (refuted, summary) = run(0.01);
    assert!(refuted > 0, "no refuted certificate with the bounds at 1 %");
    assert!(summary.violated_constraints.is_empty(), "{summary:?}");
    assert!(summary.captured, "{summary:?}");
}
