//! Control barrier functions and the three CBF-QP safety filters of the paper
//! (Sec. "Method"): translational → attitude → robotic, in causal order, each downstream
//! filter taking the upstream safe commands as its known coupling ξ.
//!
//! * [`barrier`]: the paper's rows — relative degree one `ḣ + γh − ε ≥ 0` and relative
//!   degree two through the auxiliary barrier `H = h + |ḣ|ḣ/(2u_max)` — kept for the
//!   `paper` formulation.
//! * [`sampled`]: the sampled-data rows (the default): conditions that hold between
//!   samples under the zero-order hold (docs/SAFETY.md).
//! * [`translational`], [`attitude`], [`robotic`]: every constraint as its own function
//!   citing its paper equation, the in-sample bounds, and the filter.
//! * [`filter`]: what every filter is ([`SafetyFilter`]: its input from the known state and
//!   the upstream commands, the QP step, the backup); [`chain`]: the typed causal chain
//!   ([`SafetyLayer`]) the mission, the partition's filter processes and its backups use.
//! * [`engine`]: the filters' QP on the exact dual active-set solver of `sc-qp`, with the
//!   lexicographic relaxation; [`qp`]: the Clarabel engine, the independent reference.
//! * [`monitor`]: every barrier from the true state; [`envelope`]: the model's bounds over
//!   the certified envelope; [`safe_mode`]: leaving the envelope during a run, and what the
//!   chain does then.
//! * [`common`]: outputs, reports, [`faults`] flags; `step`: the one filter step the three
//!   filters share (resolve the nominal, solve, report, brake, clamp), each adding its own
//!   rows, certificate and braking law.
//!
//! Every filter call is deterministic: the same input sequence gives bit-identical commands
//! and reports (except `solve_time_ns`), and the result of a call does not depend on the
//! calls before it. A filter never panics, never outputs a non-finite command and never
//! one outside its input bounds.

pub mod arm_model_error;
pub mod arm_target;
pub mod attitude;
pub mod barrier;
pub mod chain;
pub mod common;
pub mod coverage;
pub mod engine;
pub mod envelope;
pub mod filter;
pub mod knowledge;
pub mod link_target;
pub mod los_contract;
pub mod monitor;
pub mod qp;
pub mod robotic;
pub mod safe_mode;
pub mod sampled;
mod step;
#[cfg(test)]
mod test_draws;
pub mod translational;
pub mod translational_margins;
pub mod verify;

pub use attitude::{AttitudeFilter, AttitudeInput, AttitudeParams};
pub use barrier::{RelDegOne, RelDegTwo, Row};
pub use chain::{Actuation, ActuatorLimits, ChainOutput, Nominals, SafetyLayer};
pub use common::{FilterOutput, FilterReport, FilterStatus, faults, thread_cpu_ns};
pub use filter::{Coupling, SafetyFilter};
pub use qp::{QpDump, QpOutcome, SolverParams};
pub use robotic::{RoboticFilter, RoboticInput, RoboticParams, robotic_input_from_model};
pub use sampled::{RateBounds, RelDeg1, RelDeg2, SampleBounds};
pub use sc_scenario::Formulation;
pub use translational::{TranslationalFilter, TranslationalInput, TranslationalParams};

/// Output of the translational filter: `u = f_H`, `actuated = f_B` (2 constraints).
pub type TranslationalOutput = FilterOutput<3, { translational::N }>;
/// Output of the attitude filter: `τ_B` (7 constraints).
pub type AttitudeOutput = FilterOutput<3, { attitude::N }>;
/// Output of the robotic filter: `τ_M` (63 constraints).
pub type RoboticOutput = FilterOutput<7, { robotic::N }>;

/// Stable constraint names of the three filters, in report order, the barriers only the
/// monitor evaluates ([`ARM_TARGET`](names::ARM_TARGET)), and their units.
pub mod names {
    pub use crate::arm_target::NAMES as ARM_TARGET;
    pub use crate::attitude::NAMES as ATTITUDE;
    pub use crate::robotic::NAMES as ROBOTIC;
    pub use crate::translational::NAMES as TRANSLATIONAL;

    /// The unit of a barrier `h` by its name, as the filters and the safety monitor
    /// compute it: the corridor `d·r − ‖r‖ cos ψ` [m], the zone `‖r‖² − R²` [m²], the line
    /// of sight `d_B·ρ̂ − cos β` [-], the rate limits [rad/s], the joint-angle limits
    /// `(θ − θ_min)(θ_max − θ)` [rad²], the link–base spheres `‖d‖² − (ρ_i + ρ_B)²` [m²]
    /// and the arm's and base's clearance from the target `‖d‖² − (ρ_i + ρ_k)²` [m²].
    /// `None` for a name it does not know.
    pub fn unit(name: &str) -> Option<&'static str> {
        Some(match name {
            "approach_corridor" => "m",
            "collision_avoidance_zone" => "m²",
            "line_of_sight" => "-",
            n if n.starts_with("omega_") || n.starts_with("theta_dot_") => "rad/s",
            n if n.starts_with("theta_") => "rad²",
            n if n.starts_with("link_base_") => "m²",
            n if n.starts_with("link_target_") || n == "base_target" => "m²",
            _ => return None,
        })
    }
}
