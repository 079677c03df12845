//! The red team of the safety layer: adversarial nominal controllers
//! ([`Adversary`], one [`Strategy`] against one [`Target`]) and the campaign that runs
//! them against the filters and measures every barrier from the simulator's true state.

pub mod adversary;
pub mod campaign;
pub mod partners;
pub mod report;
pub mod scales;
pub mod shard;
pub mod strategy;

pub use adversary::Adversary;
pub use campaign::{Adversaries, Campaign, CaseError, CaseResult, Progress};
pub use partners::HostilePartners;
pub use strategy::{Case, CaseLabel, CaseNameError, Strategy, Target};
