//! Unconstrained attitude MPC: the feedback of the nominal attitude controller in the
//! paper's set-up (Sec. "Nominal Controllers": an attitude MPC "as derived and
//! parameterized in [Stadler2026]" with **all constraints inactive**).
//!
//! In the spirit of Stadler et al. — lightweight, condensed, closed-form when no
//! constraint is active — and like the translational MPC ([`crate::translational`]), it
//! predicts the attitude *error* dynamics linearised about the reference motion, with
//! the gyroscopic and reference-acceleration terms left to the feed-forward of
//! [`crate::attitude::AttitudeController`]:
//! ```text
//! x = [e_φ; e_ω] (F_B),  e_φ = −φ ê (pointing error, see attitude.rs),  e_ω = ω_B − ω_ref,
//! ė_φ = e_ω,  J ė_ω = u,   τ_B = u + ω_B × (J ω_B) + J ω̇_ref ,
//! ```
//! discretised exactly under the zero-order hold at `T_s`:
//! `A_d = [I  T_s I; 0  I]`, `B_d = [T_s²/2 J⁻¹; T_s J⁻¹]`. `J` is the servicer's inertia
//! about its centre of mass with the arm in its hold pose (the arm is 7 % of the mass; the
//! feed-forward uses the current inertia). The cost over `N` steps weighs `w_φ |e_φ|²`,
//! `w_ω |e_ω|²` (terminal `w_N` times both) and `w_τ |u|²`; the reference of the error is
//! zero, so the applied input is `u_0 = K_x x_0` with the condensed gain
//! ([`crate::condensed`]) computed once at construction.
//!
//! The MPC ignores the line-of-sight cone, the angular-rate limits and the torque bound:
//! `u` is not saturated.

use crate::NominalError;
use crate::condensed::{CondensedGain, CondensedWeights};
use nalgebra::{Matrix3x6, Matrix6, Matrix6x3, Vector6};
use sc_models::{Mat3, Vec3};

/// Parameters of [`AttitudeMpc`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeMpcParams {
    /// Control period `T_s` [s].
    pub dt: f64,
    /// Horizon `N` [steps].
    pub horizon: usize,
    /// `J`: servicer inertia about its CoM in F_B, arm in the hold pose [kg m²].
    pub inertia: Mat3,
    /// `w_φ` [1/rad²].
    pub weight_pointing: f64,
    /// `w_ω` [s²/rad²].
    pub weight_rate: f64,
    /// `w_τ` [1/(N m)²].
    pub weight_torque: f64,
    /// `w_N` (dimensionless).
    pub weight_terminal: f64,
}

/// The condensed attitude-error MPC with its precomputed closed-form gain.
#[derive(Debug, Clone, PartialEq)]
pub struct AttitudeMpc {
    params: AttitudeMpcParams,
    ad: Matrix6<f64>,
    bd: Matrix6x3<f64>,
    k_x: Matrix3x6<f64>,
}

impl AttitudeMpc {
    /// Errors if `T_s` is not positive, the inertia is not finite and invertible, or the
    /// weights or horizon are out of range (see [`CondensedGain::new`]).
    pub fn new(params: AttitudeMpcParams) -> Result<Self, NominalError> {
        let p = &params;
        if !(p.dt.is_finite() && p.dt > 0.0) {
            return Err(NominalError::Param(format!("attitude MPC dt = {}", p.dt)));
        }
        let j_inv = p
            .inertia
            .iter()
            .all(|x| x.is_finite())
            .then(|| p.inertia.try_inverse())
            .flatten()
            .ok_or_else(|| NominalError::Param(format!("attitude MPC inertia {:?}", p.inertia)))?;
        let t = p.dt;
        let mut ad = Matrix6::identity();
        ad.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(Mat3::identity() * t));
        let mut bd = Matrix6x3::zeros();
        bd.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(j_inv * (0.5 * t * t)));
        bd.fixed_view_mut::<3, 3>(3, 0).copy_from(&(j_inv * t));
        let gain = CondensedGain::new(
            "attitude",
            &ad,
            &bd,
            &CondensedWeights::two_blocks(
                p.weight_pointing,
                p.weight_rate,
                p.weight_terminal,
                p.weight_torque,
            ),
            p.horizon,
        )?;
        Ok(Self {
            params,
            ad,
            bd,
            k_x: gain.k_x,
        })
    }

    /// The parameters it was built with.
    pub fn params(&self) -> &AttitudeMpcParams {
        &self.params
    }

    /// The exact discretisation `(A_d, B_d)` at `T_s`.
    pub fn model(&self) -> (&Matrix6<f64>, &Matrix6x3<f64>) {
        (&self.ad, &self.bd)
    }

    /// `K_x` (3×6): `u_0 = K_x [e_φ; e_ω]`.
    pub fn gain(&self) -> &Matrix3x6<f64> {
        &self.k_x
    }

    /// The feedback torque `u_0` [N m] for the pointing error `e_φ` [rad] and the rate
    /// error `e_ω` [rad/s] (both F_B). Allocation-free.
    pub fn feedback(&self, e_phi: &Vec3, e_omega: &Vec3) -> Vec3 {
        self.k_x * Vector6::new(e_phi.x, e_phi.y, e_phi.z, e_omega.x, e_omega.y, e_omega.z)
    }
}
