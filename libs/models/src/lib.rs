//! Frames, rotations, orbits, the Hill frame, the Clohessy–Wiltshire model and
//! rigid-body attitude motion — the plain models that the simulator, the
//! nominal controllers and the safety filters share.
//!
//! # Conventions
//! * Quaternions are **scalar-first**, `q = [q0, q1, q2, q3]` (paper, Sec. "Attitude
//!   Subsystem"). A quaternion `q_AB` rotates vectors expressed in frame B into
//!   frame A: `v_A = R(q_AB) v_B`.
//! * Frames: `I` inertial (Earth-centred), `H` Hill frame of the target (R-bar,
//!   V-bar, H-bar), `R` reference frame (target-centred, inertially fixed to the
//!   initial servicer attitude, paper Sec. "Reference Frame Convention"), `B`
//!   servicer base (body) frame, `T` target body frame.
//! * SI units throughout.

pub mod attitude;
pub mod cw;
pub mod hill;
pub mod orbit;
pub mod quat;

pub use nalgebra;
pub type Vec3 = nalgebra::Vector3<f64>;
pub type Mat3 = nalgebra::Matrix3<f64>;
