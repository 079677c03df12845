//! The pieces of one control step that are not the safety layer's own: what the
//! nominal controllers read. The in-process [`crate::Mission`] and every process of the
//! partition use these and the safety layer's typed causal chain
//! ([`sc_cbf::chain::SafetyLayer`]), so the partition's results are bit for bit the
//! mission's.

use sc_nominal::NominalInput;
use sc_sim::Observation;

/// Input of the nominal controllers from an observation.
pub fn nominal_input(o: &Observation) -> NominalInput {
    NominalInput::from_observation(o)
}
