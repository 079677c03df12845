//! The ground floor of safe-capture: the names every other crate shares.
//!
//! * [`Subsystem`]: translational, attitude, robotic — the three subsystems of the paper
//!   (Sec. "Problem Statement"), in their causal order. Wherever a subsystem is named —
//!   a filter, a nominal controller, a rate group, a red-team target, a due bit of the
//!   ICD — it is this type, never an index.
//! * [`SubsystemSet`]: a set of subsystems (a red-team target, the subsystems due in a
//!   tick, the nominal controllers one process runs).
//! * [`PerSubsystem`]: one value per subsystem, indexed by [`Subsystem`].
//! * [`Command`]: what acts on the spacecraft over one control period (`u` of the paper).
//! * [`Observation`]: the state as the guidance, navigation and control software knows it
//!   at one control step — what every nominal controller and every safety filter reads.
//!
//! No I/O, no allocation, nothing a flight processor would not carry.

mod command;
mod observation;
mod subsystem;

pub use command::Command;
pub use observation::{BarrierState, Observation};
pub use subsystem::{PerSubsystem, Subsystem, SubsystemSet};
