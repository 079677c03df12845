//! The servicer as a free-flying multibody system loaded from URDF.
//!
//! * [`Robot`]: base (spacecraft bus) + 7-DoF revolute arm, validated from URDF
//!   ([`Robot::from_urdf_file`]).
//! * Kinematics in the base frame `F_B` ([`Robot::kinematics`], [`Kinematics`]): body poses,
//!   point/end-effector positions, Jacobians `J_E`, `J̇θ̇`, collision spheres.
//! * Dynamics ([`Robot::mass_matrix`], [`Robot::nonlinear_effects`],
//!   [`Robot::forward_dynamics`], …): CRBA, RNEA and ABA written on the spatial algebra of
//!   [`spatial`], Pinocchio free-flyer convention, zero gravity.
//!
//! Units: SI throughout (m, kg, s, rad, N, N m).

pub mod dynamics;
pub mod error;
pub mod kinematics;
pub mod model;
pub mod spatial;

pub use dynamics::{BaseAngularDynamics, Momentum, ReducedArmDynamics};
pub use error::ModelError;
pub use kinematics::{ComTerms, Kinematics, SphereState};
pub use model::{CollisionSphere, Frame, JointLimits, Robot};

/// Number of arm joints (revolute, serial chain).
pub const NJ: usize = 7;

/// Joint-space vector (7).
pub type Vector7 = nalgebra::SVector<f64, NJ>;
/// Joint-space matrix (7×7).
pub type Matrix7 = nalgebra::SMatrix<f64, NJ, NJ>;
/// Generalized free-flyer vector `[base linear; base angular; joints]` (13).
pub type Vector13 = nalgebra::SVector<f64, 13>;
/// Free-flyer matrix (13×13).
pub type Matrix13 = nalgebra::SMatrix<f64, 13, 13>;
/// Point (linear) Jacobian 3×7.
pub type Matrix3x7 = nalgebra::SMatrix<f64, 3, NJ>;
/// Geometric Jacobian 6×7 `[linear; angular]`.
pub type Matrix6x7 = nalgebra::SMatrix<f64, 6, NJ>;

/// Path of the servicer URDF relative to the workspace root.
pub const SERVICER_URDF: &str = "config/servicer.urdf";
