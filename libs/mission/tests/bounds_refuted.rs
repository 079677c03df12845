//! The robotic filter verifies every command on the servicer model's sample, so the
//! configured jerk bounds are not what its certificate rests on (docs/SAFETY.md, "The
//! envelope bounds"): with them as configured, the default mission never refutes the
//! cheap certificate (its commands are the ones the bounds certified); with them cut to a
//! hundredth, the cheap certificate is refuted again and again — and the mission is still
//! safe on the true state and captures.

use sc_mission::{Mission, RunOptions, Setup, summarize};
use std::path::Path;

/// Runs the default mission with the robotic jerk bounds scaled by `scale`; returns the
/// robotic filter's refuted certificates and the run's summary.
fn run(scale: f64) -> (u64, sc_mission::Summary) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml");
    let mut setup = Setup::load(&path).unwrap();
    let rb = &mut setup.scenario.safety.robotic;
    for j in rb.joint_jerk_bound_rad_s3.iter_mut() {
        *j *= scale;
    }
    for j in rb.link_sphere_jerk_bound_m_s3.iter_mut() {
        *j *= scale;
    }
    let phases: Vec<String> = setup
        .scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let mut m = Mission::new(setup, RunOptions { no_filter: false }).unwrap();
    let mut records = Vec::new();
    let end = m.run(|_, r| records.push(*r));
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
