//! What acts on the spacecraft over one control period.

use nalgebra::{SVector, Vector3};

/// One actuation command `u = [f_B; τ_B; τ_M]` (paper eq. "u") held constant over a
/// control period: base force [N] and torque [N m] in the base frame F_B (about the base
/// origin), joint torques [N m].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    pub force_b: Vector3<f64>,
    pub torque_b: Vector3<f64>,
    pub tau: SVector<f64, 7>,
}

impl Command {
    /// The zero command.
    pub fn zero() -> Self {
        Self {
            force_b: Vector3::zeros(),
            torque_b: Vector3::zeros(),
            tau: SVector::zeros(),
        }
    }

    /// As the 13-vector of the free-flyer dynamics.
    pub fn as_vector(&self) -> SVector<f64, 13> {
        let mut u = SVector::<f64, 13>::zeros();
        u.fixed_rows_mut::<3>(0).copy_from(&self.force_b);
        u.fixed_rows_mut::<3>(3).copy_from(&self.torque_b);
        u.fixed_rows_mut::<7>(6).copy_from(&self.tau);
        u
    }

    /// True if every component is finite.
    pub fn is_finite(&self) -> bool {
        self.as_vector().iter().all(|x| x.is_finite())
    }
}
