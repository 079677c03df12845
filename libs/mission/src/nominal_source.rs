//! Where a mission's nominal commands come from ([`NominalSource`]): the reference
//! controllers, a replacement in this process ([`NominalOverride`]: a red-team
//! adversary, a replay of a recorded run), or partner processes in place of the nominal
//! controller processes of the partition ([`PartnerProcess`]). Whatever a replacement
//! sends — any values, or nothing — goes to the safety filters like a nominal command;
//! the filters never trust it.

use nalgebra::Vector3;
use sc_core::Subsystem;
use sc_multibody::Vector7;
use sc_nominal::NominalOutput;
use sc_sim::Observation;
use std::path::PathBuf;

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

/// A process that replaces the nominal controller process of one subsystem in the
/// process partition (a partner's controller, or a hostile one): its program and
/// arguments (the partition adds its own, see `sc_ground::launcher`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PartnerProcess {
    /// The subsystem whose nominal controller it replaces.
    pub subsystem: Subsystem,
    pub program: PathBuf,
    pub args: Vec<String>,
}

/// Where a mission's nominal commands come from.
#[derive(Default)]
pub enum NominalSource {
    /// The reference controllers (`sc_nominal`), every subsystem.
    #[default]
    Reference,
    /// Replaced step by step in this process (a red-team adversary, a replay).
    Override(Box<dyn NominalOverride>),
    /// Partner processes in place of the nominal controller processes of their
    /// subsystems (the process partition only), in causal order.
    Partners(Vec<PartnerProcess>),
}
