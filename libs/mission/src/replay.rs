//! Replaying the nominal commands of a recorded run ([`ReplayNominals`]): the commands a
//! run's filters received — from any controller, a partner's process or a hostile one,
//! in process or through the partition — fed again, step by step, to the filters in one
//! process. With the same scenario the replay recomputes the run exactly (the filters
//! and the simulator are deterministic), so any recorded run, e.g. a red-team case
//! through the partition, can be reproduced, inspected and debugged in one process.

use crate::nominal_source::{NominalCommand, NominalCommands, NominalOverride};
use crate::record::StepRecord;
use nalgebra::SVector;
use sc_cbf::faults;
use sc_nominal::NominalOutput;
use sc_sim::Observation;

/// The recorded nominal commands, by control step.
pub struct ReplayNominals {
    steps: Vec<NominalCommands>,
}

/// A recorded nominal: `Missing` where the filter flagged it missing (it ran on its
/// substitute nominal; the record holds NaN there), else the recorded values.
fn recorded<const D: usize>(
    v: SVector<f64, D>,
    filter_faults: u32,
) -> NominalCommand<SVector<f64, D>> {
    if filter_faults & faults::NOMINAL_MISSING != 0 {
        NominalCommand::Missing
    } else {
        NominalCommand::Given(v)
    }
}

impl ReplayNominals {
    /// The nominal commands of `records` (e.g. from [`crate::parse_telemetry`]).
    pub fn new(records: &[StepRecord]) -> Self {
        let mut steps = vec![NominalCommands::REFERENCE; records.len()];
        for r in records {
            if let Some(s) = steps.get_mut(r.step as usize) {
                *s = NominalCommands {
                    translational: recorded(r.f_h_nom, r.translational.report.faults),
                    attitude: recorded(r.tau_b_nom, r.attitude.report.faults),
                    robotic: recorded(r.tau_m_nom, r.robotic.report.faults),
                };
            }
        }
        Self { steps }
    }

    /// Steps recorded.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// True if nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }
}

impl NominalOverride for ReplayNominals {
    /// The recorded commands of the observation's step; beyond the recording, nothing
    /// (the filters run on their substitute nominals).
    fn commands(&mut self, o: &Observation, _reference: &NominalOutput) -> NominalCommands {
        self.steps
            .get(o.step as usize)
            .copied()
            .unwrap_or(NominalCommands {
                translational: NominalCommand::Missing,
                attitude: NominalCommand::Missing,
                robotic: NominalCommand::Missing,
            })
    }
}
