//! What the mission-level tests share: the default scenario, and a mission run to its end.

use sc_mission::{Mission, MissionEnd, RunOptions, Setup, StepRecord};
use std::path::Path;

/// The default scenario (config/scenario.toml) with its servicer model.
pub fn default_setup() -> Setup {
    Setup::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml")).unwrap()
}

/// Runs `setup`'s mission with the filters to its end: the mission (its filters' state
/// kept), every step's record, how it ended and the phase names.
pub fn run_mission(setup: Setup) -> (Mission, Vec<StepRecord>, MissionEnd, Vec<String>) {
    let phases = setup
        .scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let mut m = Mission::new(setup, RunOptions { no_filter: false }).unwrap();
    let mut records = Vec::new();
    let end = m.run(|_, r| records.push(*r));
    (m, records, end, phases)
}
