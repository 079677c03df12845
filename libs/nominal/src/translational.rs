//! Unconstrained linear MPC of the relative translational motion (paper, Sec.
//! "Nominal Controllers": an MPC "as derived and parameterized in [Meinert2026]" with
//! **all constraints inactive**, so that its commands may be unsafe and the
//! translational safety filter has work to do).
//!
//! # Model
//! The Clohessy–Wiltshire–Hill model of the paper's eq. (rel motion system),
//! `x = [r_H; v_H]` in the Hill frame `F_H` [m, m/s], input `f_H` [N], discretised
//! exactly (zero-order hold) at the control period `T_s`:
//! `x_{k+1} = A_d x_k + B_d u_k`.
//!
//! # Cost
//! Over `N` steps, with `Q = diag(w_p I₃, w_v I₃)`, `Q_N = w_N Q` and `R = w_f I₃`,
//! ```text
//! J(U) = Σ_{k=1}^{N-1} |x_k − x_ref,k|²_Q + |x_N − x_ref,N|²_{Q_N} + Σ_{k=0}^{N-1} |u_k|²_R .
//! ```
//! Stacking `X = Φ x_0 + Γ U` gives the condensed QP `min ½ Uᵀ H U + …` with
//! `H = Γᵀ Q̄ Γ + R̄`. Without constraints the minimiser is closed-form,
//! `U* = H⁻¹ Γᵀ Q̄ (X_ref − Φ x_0)`, and only its first block is applied:
//! `u_0 = K_x x_0 + Σ_k G_k x_ref,k` with `K_x = −G Φ`, `G = [I₃ 0 …] H⁻¹ Γᵀ Q̄`.
//! `H` is factorised once (Cholesky) at construction; a step is then a handful of
//! fixed-size matrix–vector products, free of heap allocation.
//!
//! # Reference
//! The Go-for-Capture point `p_gfc,R = d_gfc d_R` is fixed in the inertially fixed
//! reference frame `F_R`, so in the rotating Hill frame it moves:
//! `p_gfc,H(t) = R_HR(t) p_gfc,R` with `Ṙ_HR = −[ω_H]× R_HR` (`ω_H`: angular velocity
//! of `F_H` w.r.t. inertial space, in `F_H`). Over the horizon the reference is
//! `x_ref,k = [R_k p; −ω_H × R_k p]`, `R_k = exp(−[ω_H]× k T_s)`, `p = R(q_HR) p_gfc,R`.
//!
//! # Output
//! The force `f_H` [N] in `F_H` is **not saturated** and ignores the approach
//! corridor and the collision-avoidance zone: the safety filter enforces the
//! input bound `‖f‖∞ ≤ f_max` and the state constraints.

use crate::NominalError;
use crate::condensed::{CondensedGain, CondensedWeights};
use nalgebra::{DMatrix, Matrix3, Matrix6, Matrix6x3, Vector3, Vector6};
use sc_models::Vec3;
use sc_models::cw::ClohessyWiltshire;
use sc_models::quat::{self, Quat};

/// Parameters of [`TranslationalMpc`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TranslationalMpcParams {
    /// Mean motion `n` of the circular target orbit [rad/s].
    pub mean_motion: f64,
    /// Servicer mass `m` [kg] (whole servicer: bus and arm).
    pub mass: f64,
    /// Control period `T_s` [s]; the model is discretised exactly at it.
    pub dt: f64,
    /// Horizon `N` [steps].
    pub horizon: usize,
    /// Go-for-Capture point `p_gfc,R` in `F_R` [m] (`gfc_distance · d_R`).
    pub gfc_point_r: Vec3,
    /// `w_p` [1/m²].
    pub weight_position: f64,
    /// `w_v` [s²/m²].
    pub weight_velocity: f64,
    /// `w_f` [1/N²].
    pub weight_force: f64,
    /// `w_N`: the terminal weight is `w_N Q` (dimensionless).
    pub weight_terminal: f64,
}

/// Result of one MPC step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TranslationalCommand {
    /// Nominal force `f_H,nom` in `F_H` [N], unsaturated. Zero when `valid` is false.
    pub f_h: Vec3,
    /// The reference position `p_gfc,H` at the current instant, in `F_H` [m].
    pub gfc_point_h: Vec3,
    /// False if an input was non-finite (the command is then zero).
    pub valid: bool,
}

/// The unconstrained CW MPC with its precomputed closed-form gain.
#[derive(Debug, Clone)]
pub struct TranslationalMpc {
    params: TranslationalMpcParams,
    ad: Matrix6<f64>,
    bd: Matrix6x3<f64>,
    /// `K_x` and the `G_k` of the closed-form solution.
    gain: CondensedGain,
}

impl TranslationalMpc {
    /// Builds the batch matrices and factorises the condensed Hessian.
    ///
    /// Errors if a parameter is non-finite or out of range (`n ≥ 0`, `m > 0`,
    /// `T_s > 0`, `N ≥ 1`, weights ≥ 0 with `w_f > 0`) or the Hessian is not
    /// positive definite.
    pub fn new(params: TranslationalMpcParams) -> Result<Self, NominalError> {
        let p = &params;
        let check = |name: &str, v: f64, ok: bool| {
            if v.is_finite() && ok {
                Ok(())
            } else {
                Err(NominalError::Param(format!("translational {name} = {v}")))
            }
        };
        check("mean_motion", p.mean_motion, p.mean_motion >= 0.0)?;
        check("mass", p.mass, p.mass > 0.0)?;
        check("dt", p.dt, p.dt > 0.0)?;
        check(
            "weight_position",
            p.weight_position,
            p.weight_position >= 0.0,
        )?;
        check(
            "weight_velocity",
            p.weight_velocity,
            p.weight_velocity >= 0.0,
        )?;
        check("weight_force", p.weight_force, p.weight_force > 0.0)?;
        check(
            "weight_terminal",
            p.weight_terminal,
            p.weight_terminal >= 0.0,
        )?;
        for i in 0..3 {
            check("gfc_point", p.gfc_point_r[i], true)?;
        }
        let cw = ClohessyWiltshire {
            n: p.mean_motion,
            mass: p.mass,
        };
        let (ad, bd) = cw.discretize(p.dt);
        let gain = CondensedGain::new(
            "translational",
            &ad,
            &bd,
            &CondensedWeights::two_blocks(
                p.weight_position,
                p.weight_velocity,
                p.weight_terminal,
                p.weight_force,
            ),
            p.horizon,
        )?;
        Ok(Self {
            params,
            ad,
            bd,
            gain,
        })
    }

    /// The parameters it was built with.
    pub fn params(&self) -> &TranslationalMpcParams {
        &self.params
    }

    /// The exact discretisation `(A_d, B_d)` at `T_s`.
    pub fn model(&self) -> (&Matrix6<f64>, &Matrix6x3<f64>) {
        (&self.ad, &self.bd)
    }

    /// The first block row of the batch gain, `[K_x | G_1 … G_N]` (3 × (6 + 6N)), so
    /// that `u_0 = K_x x_0 + Σ G_k x_ref,k`. For tests and analysis (allocates).
    pub fn gain(&self) -> DMatrix<f64> {
        self.gain.matrix()
    }

    /// One MPC step.
    ///
    /// * `r_h`, `v_h`: servicer position relative to the target CoM and its
    ///   derivative in the rotating Hill frame, in `F_H` [m, m/s].
    /// * `q_hr`: attitude of `F_R` w.r.t. `F_H` (rotates `F_R` vectors into `F_H`).
    /// * `omega_h`: angular velocity of `F_H` w.r.t. inertial space, in `F_H` [rad/s]
    ///   (`[0, 0, n]` on a circular orbit).
    ///
    /// Non-finite inputs or a non-normalisable `q_hr` give `valid = false` and a
    /// zero force. Allocation-free.
    pub fn command(
        &self,
        r_h: &Vec3,
        v_h: &Vec3,
        q_hr: &Quat,
        omega_h: &Vec3,
    ) -> TranslationalCommand {
        let invalid = TranslationalCommand {
            f_h: Vec3::zeros(),
            gfc_point_h: Vec3::zeros(),
            valid: false,
        };
        let finite = |v: &Vec3| v.iter().all(|x| x.is_finite());
        if !finite(r_h) || !finite(v_h) || !finite(omega_h) {
            return invalid;
        }
        let Some(q) = quat::normalized(q_hr) else {
            return invalid;
        };
        let p0 = quat::rotate(&q, &self.params.gfc_point_r);
        let step = rotation_exp(&(-omega_h * self.params.dt));
        let x0 = Vector6::new(r_h.x, r_h.y, r_h.z, v_h.x, v_h.y, v_h.z);
        let mut u: Vector3<f64> = self.gain.k_x * x0;
        let mut pk = p0;
        for gk in &self.gain.g {
            pk = step * pk;
            let vk = -omega_h.cross(&pk);
            let xr = Vector6::new(pk.x, pk.y, pk.z, vk.x, vk.y, vk.z);
            u += gk * xr;
        }
        if !finite(&u) {
            return invalid;
        }
        TranslationalCommand {
            f_h: u,
            gfc_point_h: p0,
            valid: true,
        }
    }
}

/// Rotation matrix `exp([φ]×)` of the rotation vector `φ` (Rodrigues).
pub(crate) fn rotation_exp(phi: &Vec3) -> Matrix3<f64> {
    let angle = phi.norm();
    if angle < 1e-12 {
        return Matrix3::identity() + quat::skew(phi);
    }
    let k = quat::skew(&(phi / angle));
    Matrix3::identity() + k * angle.sin() + k * k * (1.0 - angle.cos())
}
