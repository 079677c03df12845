//! Where a step's nominal commands come from when they are not the reference
//! controllers': a partner's controller or a red-team adversary
//! ([`NominalOverride`]). Whatever it returns — any values, or nothing — goes to the
//! safety filters like a nominal command; the filters never trust it.

use nalgebra::Vector3;
use sc_multibody::Vector7;
use sc_nominal::NominalOutput;
use sc_sim::Observation;

/// The nominal command of one subsystem for one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NominalCommand<T> {
    /// The reference controller's command.
    Reference,
    /// This command (any values: the filter validates it).
    Given(T),
    /// No command arrived (a silent, dead or late controller).
    Missing,
}

impl<T: Copy> NominalCommand<T> {
    /// `Some(command)` or `None` when missing, given the reference command.
    pub fn resolve(&self, reference: T) -> Option<T> {
        match self {
            NominalCommand::Reference => Some(reference),
            NominalCommand::Given(u) => Some(*u),
            NominalCommand::Missing => None,
        }
    }
}

/// The three subsystems' commands of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NominalCommands {
    /// `f_H` [N], Hill frame.
    pub translational: NominalCommand<Vector3<f64>>,
    /// `τ_B` [N m], F_B.
    pub attitude: NominalCommand<Vector3<f64>>,
    /// `τ_M` [N m].
    pub robotic: NominalCommand<Vector7>,
}

impl NominalCommands {
    /// The reference controllers' commands for every subsystem.
    pub const REFERENCE: Self = Self {
        translational: NominalCommand::Reference,
        attitude: NominalCommand::Reference,
        robotic: NominalCommand::Reference,
    };
}

/// Replaces the nominal commands of some subsystems, step by step.
pub trait NominalOverride: Send {
    /// The commands of the step at observation `o`; `reference` is what the reference
    /// controllers computed (an adversary may use or ignore it).
    fn commands(&mut self, o: &Observation, reference: &NominalOutput) -> NominalCommands;
}
