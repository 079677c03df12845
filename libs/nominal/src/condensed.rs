//! The condensed, unconstrained linear MPC both nominal MPCs share (translational:
//! [`crate::translational`], attitude: [`crate::attitude_mpc`]).
//!
//! For `x_{k+1} = A_d x_k + B_d u_k` (6 states, 3 inputs) over `N` steps, with stage
//! weights `Q = diag(q)`, terminal `Q_N = w_N Q` and `R = w_u I₃`,
//! ```text
//! J(U) = Σ_{k=1}^{N-1} |x_k − x_ref,k|²_Q + |x_N − x_ref,N|²_{Q_N} + Σ_{k=0}^{N-1} |u_k|²_R .
//! ```
//! Stacking `X = Φ x_0 + Γ U` gives `min ½ Uᵀ H U + …` with `H = Γᵀ Q̄ Γ + R̄`. Without
//! constraints the minimiser is closed-form, `U* = H⁻¹ Γᵀ Q̄ (X_ref − Φ x_0)`, and only its
//! first block is applied: `u_0 = K_x x_0 + Σ_k G_k x_ref,k` with `K_x = −G Φ`,
//! `G = [I₃ 0 …] H⁻¹ Γᵀ Q̄`. `H` is factorised once (Cholesky) when the gain is built; a
//! step is then a few fixed-size matrix–vector products.

use crate::NominalError;
use nalgebra::{DMatrix, Matrix3x6, Matrix6, Matrix6x3};

/// The first block row of the condensed MPC's closed-form solution.
#[derive(Debug, Clone, PartialEq)]
pub struct CondensedGain {
    /// `K_x = −G Φ` (3×6): acts on the current state.
    pub k_x: Matrix3x6<f64>,
    /// `G_k`, k = 1..N: act on the reference `x_ref,k` (3×6 each).
    pub g: Vec<Matrix3x6<f64>>,
}

/// Weights of the condensed cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CondensedWeights {
    /// Diagonal of the stage weight `Q` (6), each ≥ 0.
    pub state: [f64; 6],
    /// `w_N`: the terminal weight is `w_N Q`, ≥ 0.
    pub terminal: f64,
    /// `w_u` of `R = w_u I₃`, > 0.
    pub input: f64,
}

impl CondensedWeights {
    /// Weights of a state made of two 3-vectors (position and rate, attitude and rate
    /// errors): `Q = diag(w₁ I₃, w₂ I₃)`, terminal `w_N Q`, `R = w_u I₃`.
    pub fn two_blocks(first: f64, second: f64, terminal: f64, input: f64) -> Self {
        Self {
            state: [first, first, first, second, second, second],
            terminal,
            input,
        }
    }
}

impl CondensedGain {
    /// Builds `Φ`, `Γ` and the gain. `what` names the controller in errors.
    pub fn new(
        what: &str,
        ad: &Matrix6<f64>,
        bd: &Matrix6x3<f64>,
        w: &CondensedWeights,
        horizon: usize,
    ) -> Result<Self, NominalError> {
        if horizon == 0 || horizon > 1000 {
            return Err(NominalError::Param(format!(
                "{what} horizon = {horizon} (1..=1000)"
            )));
        }
        let weights_ok = w.state.iter().all(|q| q.is_finite() && *q >= 0.0)
            && w.terminal.is_finite()
            && w.terminal >= 0.0
            && w.input.is_finite()
            && w.input > 0.0;
        if !weights_ok {
            return Err(NominalError::Param(format!("{what} MPC weights {w:?}")));
        }
        let (phi, gamma) = batch_prediction(ad, bd, horizon);
        let qbar = stage_weights(w, horizon);
        let nu = 3 * horizon;
        // H = Γᵀ Q̄ Γ + R̄ (Q̄ diagonal, stored as a vector)
        let qg = DMatrix::from_fn(6 * horizon, nu, |i, j| qbar[i] * gamma[(i, j)]);
        let mut h = gamma.transpose() * &qg;
        for i in 0..nu {
            h[(i, i)] += w.input;
        }
        let chol = h.cholesky().ok_or_else(|| {
            NominalError::Param(format!("{what} MPC Hessian not positive definite"))
        })?;
        // H⁻¹ Γᵀ Q̄ = (Q̄ Γ H⁻¹)ᵀ; solve for the full matrix, keep the first 3 rows.
        let full = chol.solve(&qg.transpose());
        let gmat = full.rows(0, 3).into_owned();
        let k_x_dyn = -(&gmat * &phi);
        if !k_x_dyn.iter().chain(gmat.iter()).all(|x| x.is_finite()) {
            return Err(NominalError::Param(format!("{what} MPC gain not finite")));
        }
        Ok(Self {
            k_x: Matrix3x6::from_fn(|i, j| k_x_dyn[(i, j)]),
            g: (0..horizon)
                .map(|k| Matrix3x6::from_fn(|i, j| gmat[(i, 6 * k + j)]))
                .collect(),
        })
    }

    /// `[K_x | G_1 … G_N]` (3 × (6 + 6N)). For tests and analysis (allocates).
    pub fn matrix(&self) -> DMatrix<f64> {
        let n = self.g.len();
        let mut m = DMatrix::zeros(3, 6 + 6 * n);
        m.view_mut((0, 0), (3, 6)).copy_from(&self.k_x);
        for (k, gk) in self.g.iter().enumerate() {
            m.view_mut((0, 6 + 6 * k), (3, 6)).copy_from(gk);
        }
        m
    }
}

/// `Φ = [A_d; A_d²; …; A_dᴺ]` (6N×6) and the lower block-triangular
/// `Γ_{k,j} = A_d^{k−j} B_d` for `j ≤ k` (6N×3N), rows `x_1 … x_N`.
pub fn batch_prediction(
    ad: &Matrix6<f64>,
    bd: &Matrix6x3<f64>,
    n: usize,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut phi = DMatrix::zeros(6 * n, 6);
    let mut gamma = DMatrix::zeros(6 * n, 3 * n);
    // powers A_d^k B_d, k = 0..N-1
    let mut akb = Vec::with_capacity(n);
    let mut apow = Matrix6::identity();
    for _ in 0..n {
        akb.push(apow * bd);
        apow = ad * apow;
    }
    let mut ak = Matrix6::identity();
    for k in 0..n {
        ak = ad * ak;
        phi.view_mut((6 * k, 0), (6, 6)).copy_from(&ak);
        for j in 0..=k {
            gamma
                .view_mut((6 * k, 3 * j), (6, 3))
                .copy_from(&akb[k - j]);
        }
    }
    (phi, gamma)
}

/// Diagonal of `Q̄ = blkdiag(Q, …, Q, Q_N)` (6N).
fn stage_weights(w: &CondensedWeights, horizon: usize) -> Vec<f64> {
    let mut q = Vec::with_capacity(6 * horizon);
    for k in 0..horizon {
        let s = if k + 1 == horizon { w.terminal } else { 1.0 };
        q.extend(w.state.iter().map(|x| s * x));
    }
    q
}
