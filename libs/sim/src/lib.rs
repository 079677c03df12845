//! The high-fidelity simulator core.
//!
//! * Both spacecraft are propagated in the Earth-centred inertial frame under full
//!   two-body gravity (not the CW model the filters use): the target's absolute orbit,
//!   and the servicer's base origin **relative to the target** in inertial coordinates,
//!   with the differential gravity evaluated without cancellation, so relative
//!   positions keep full double precision (no subtraction of two 7000 km vectors).
//! * The servicer is the coupled free-flying multibody system (bus + 7-DoF arm) of
//!   [`sc_multibody`]; orbital gravity acts on the whole system at its centre of mass
//!   (no gravity gradient inside the body), i.e. in the freely falling frame the
//!   multibody dynamics are gravity-free.
//! * The target is a torque-free rigid body.
//! * Fixed-step RK4 with a configurable physics step under zero-order-hold commands:
//!   the command computed at `t_k` acts on `(t_k, t_k+1]`; the base force and torque
//!   are fixed in the base frame (body-mounted thrusters) and so rotate with the base
//!   inside every RK4 stage.
//!
//! [`Simulator::observe`] gives what each subsystem needs ([`Observation`]).

pub mod navigation;
mod observation;
mod plant;
pub mod plant_process;
mod profile;
mod report;
mod state;
pub mod uncertainty;

pub use navigation::{Estimator, NavSample, NavigationGate, Rejection};
pub use observation::{TRAJECTORY_COLUMNS, TrajectoryRow};
pub use plant::{Plant, PlantError, SIM_STATE_LEN};
pub use plant_process::ProcessPlant;
pub use profile::{CommandProfile, GRID_TOLERANCE_S, PROFILE_COLUMNS, ProfileError};
pub use report::{ModelReport, ModelState, evaluate_model};
pub use sc_core::Observation;
pub use state::{BarrierState, Command, SimError, SimState, Simulator};
pub use uncertainty::{NavigationError, Realisation};
