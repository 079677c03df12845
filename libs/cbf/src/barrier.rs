//! The generic barrier machinery of the paper's Sec. "Method".
//!
//! Every safety constraint of every filter is reduced to **one affine row** in the
//! filter's decision variable `u ∈ ℝᴹ`:
//!
//! ```text
//! Φ(u) = c + a·u ≥ 0        (c = Φ(0), a = ∂Φ/∂u)
//! ```
//!
//! * Relative degree one (paper eq. "CBF rel deg 1" with α(h) = γ h, ε offset as in the
//!   rate-limit conditions φ_ω, φ_θ̇):
//!   `φ = ḣ + γ h − ε`, with `ḣ = ḣ_drift + (∂ḣ/∂u)·u` → `c = ḣ_drift + γh − ε`, `a = ∂ḣ/∂u`.
//! * Relative degree two (paper, auxiliary barrier after Breeden & Panagou):
//!   `H = h + |ḣ| ḣ / (2 u_max)`, `Ḣ = ḣ + |ḣ| ḧ / u_max`, and
//!   `Φ = ∂H/∂t + L_f̃ H + L_g H u + γ H − ε` (paper eq. "CBF rel deg 2"), i.e. with
//!   `ḧ = ḧ_drift + (∂ḧ/∂u)·u`:
//!   `c = ḣ + |ḣ| ḧ_drift / u_max + γ H − ε`, `a = |ḣ| (∂ḧ/∂u) / u_max`.
//!   `ḧ_drift` contains *everything* that does not multiply `u`: the drift `f`, the explicit
//!   time dependence (∂/∂t terms, e.g. the rotating corridor axis or the moving grasping
//!   point) and the known exogenous coupling `ξ` of the paper's eq. "control-affine system".
//!
//! # How `u_max` is chosen (per constraint, from `config/scenario.toml`)
//! `H` is the value `h` would reach if the present rate `ḣ` were braked at the constant
//! rate `|ḧ| = u_max`: for `ḣ < 0`, `h − ḣ²/(2 u_max)` is the stopping value. Keeping
//! `H ≥ 0` therefore only makes sense if the subsystem can really produce `ḧ` of size
//! `u_max` *along this barrier* with its bounded input, after the drift has taken its
//! share: `u_max` must not exceed the braking authority `min_u∈U |L_g L_f h · u|` minus the
//! worst drift. Too large a `u_max` promises braking the actuators cannot deliver (the QP
//! becomes infeasible near the boundary, the relaxed problem takes over); too small a
//! `u_max` is merely conservative (the filter starts braking earlier). The scenario owner
//! therefore sets one derated `u_max` per constraint family (`u_max_ac_m_s2`,
//! `u_max_caz_m2_s2`, `u_max_att_per_s2`, `u_max_theta_rad2_s2`, `u_max_lb_m2_s2`) from the
//! actuator bounds and the geometry (see the comments next to each key); the filters take
//! them verbatim and never adapt them online, so results are reproducible.

use nalgebra::SVector;

/// One affine CBF row `Φ(u) = c + a·u ≥ 0` in the filter's decision variable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row<const M: usize> {
    /// `∂Φ/∂u`.
    pub a: SVector<f64, M>,
    /// `Φ(0)`: every term of Φ that does not multiply `u` (drift, ∂/∂t, ξ, γ·(h or H), −ε).
    pub c: f64,
}

impl<const M: usize> Row<M> {
    /// `Φ(u) = c + a·u`.
    pub fn phi(&self, u: &SVector<f64, M>) -> f64 {
        self.c + self.a.dot(u)
    }

    /// `true` when every coefficient is finite.
    pub fn is_finite(&self) -> bool {
        self.c.is_finite() && self.a.iter().all(|x| x.is_finite())
    }
}

/// Terms of a relative-degree-one barrier: `h`, and `ḣ = hdot_drift + hdot_u·u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelDegOne<const M: usize> {
    pub h: f64,
    /// `∂h/∂t + L_f̃ h` (drift incl. ξ).
    pub hdot_drift: f64,
    /// `L_g h`.
    pub hdot_u: SVector<f64, M>,
}

impl<const M: usize> RelDegOne<M> {
    /// `ḣ` at input `u`.
    pub fn hdot(&self, u: &SVector<f64, M>) -> f64 {
        self.hdot_drift + self.hdot_u.dot(u)
    }

    /// The condition `φ = ḣ + γ h − ε ≥ 0` as a row (paper eq. "CBF rel deg 1", α(h) = γh).
    pub fn row(&self, gamma: f64, eps: f64) -> Row<M> {
        Row {
            a: self.hdot_u,
            c: self.hdot_drift + gamma * self.h - eps,
        }
    }
}

/// Terms of a relative-degree-two barrier: `h`, `ḣ` (input-free), and
/// `ḧ = hddot_drift + hddot_u·u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelDegTwo<const M: usize> {
    pub h: f64,
    pub hdot: f64,
    /// `∂²h/∂t² + L²_f̃ h + …`: every part of `ḧ` that does not multiply `u` (incl. ξ).
    pub hddot_drift: f64,
    /// `L_g L_f̃ h`.
    pub hddot_u: SVector<f64, M>,
}

impl<const M: usize> RelDegTwo<M> {
    /// `ḧ` at input `u`.
    pub fn hddot(&self, u: &SVector<f64, M>) -> f64 {
        self.hddot_drift + self.hddot_u.dot(u)
    }

    /// Auxiliary barrier `H = h + |ḣ| ḣ / (2 u_max)`.
    pub fn big_h(&self, u_max: f64) -> f64 {
        aux_barrier(self.h, self.hdot, u_max)
    }

    /// `Ḣ = ḣ + |ḣ| ḧ / u_max` at input `u`.
    pub fn big_h_dot(&self, u: &SVector<f64, M>, u_max: f64) -> f64 {
        self.hdot + self.hdot.abs() * self.hddot(u) / u_max
    }

    /// The condition `Φ = Ḣ + γ H − ε ≥ 0` as a row (paper eq. "CBF rel deg 2").
    pub fn row(&self, gamma: f64, eps: f64, u_max: f64) -> Row<M> {
        let k = self.hdot.abs() / u_max;
        Row {
            a: self.hddot_u * k,
            c: self.hdot + k * self.hddot_drift + gamma * self.big_h(u_max) - eps,
        }
    }
}

/// `H = h + |ḣ| ḣ / (2 u_max)` (paper, auxiliary barrier function).
pub fn aux_barrier(h: f64, hdot: f64, u_max: f64) -> f64 {
    h + hdot.abs() * hdot / (2.0 * u_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// Double integrator x'' = u: h = x, ḣ = v, ḧ = u.
    #[test]
    fn aux_barrier_is_stopping_value_and_row_matches_h_dot() {
        let k = RelDegTwo::<2> {
            h: 1.0,
            hdot: -0.4,
            hddot_drift: 0.1,
            hddot_u: Vector2::new(1.0, -2.0),
        };
        let umax = 0.2;
        // braking at u_max from v = -0.4 covers 0.16/0.4 = 0.4
        assert!((k.big_h(umax) - 0.6).abs() < 1e-15);
        let u = Vector2::new(0.3, 0.7);
        let row = k.row(1.5, 0.01, umax);
        let phi = k.big_h_dot(&u, umax) + 1.5 * k.big_h(umax) - 0.01;
        assert!((row.phi(&u) - phi).abs() < 1e-14);
        // H is C¹ in ḣ: dH/dḣ = |ḣ|/u_max, continuous through 0
        let e = 1e-7;
        let dh = (aux_barrier(1.0, e, umax) - aux_barrier(1.0, -e, umax)) / (2.0 * e);
        assert!(dh.abs() < 1e-6);
    }

    #[test]
    fn rel_deg_one_row() {
        let k = RelDegOne::<2> {
            h: 0.5,
            hdot_drift: -0.2,
            hdot_u: Vector2::new(0.0, 3.0),
        };
        let row = k.row(2.0, 0.1);
        let u = Vector2::new(5.0, -1.0);
        assert!((row.phi(&u) - (k.hdot(&u) + 2.0 * 0.5 - 0.1)).abs() < 1e-15);
    }
}
