//! What the declared mass-property errors and base-wrench errors can do to the servicer's
//! accelerations: a bound on `|ν̇_t − ν̇|`, the plant's 13-DoF acceleration against the
//! model's under the same inputs, for every plant within the declared bounds
//! (docs/SAFETY.md, "Model error in the robotic filter").
//!
//! The inverse dynamics are linear in the bodies' inertial parameters `π` (mass, first
//! moment `h = m c`, rotational inertia about the body origin): `ID(θ, ν, ν̇; π) =
//! Y(θ, ν, ν̇) π`. With the plant's `π_t = π + Δπ`, its mass matrix `M_t = M + ΔM`, the
//! plant's base wrench `u_b + Δu_b` and joint torques `τ + Δτ`,
//!
//! ```text
//! M_t ν̇_t + b_t = u + Δu,   M ν̇ + b = u
//! ⇒ z = ν̇_t − ν̇ = M⁻¹Δu − Σ_p Δπ_p M⁻¹ w_p(ν̇) − Σ_p Δπ_p G_p z,
//! ```
//!
//! `w_p(ν̇) = Y_p(θ, ν, ν̇)` the regressor's column of direction `p` (the inverse dynamics
//! of a servicer whose only inertia is that direction: [`Robot::rnea_with`]), `G_p =
//! M⁻¹ Y_p^M` with `Y_p^M` that direction's mass matrix ([`Robot::mass_matrix_with`]). Each
//! `|Δπ_p| ≤ π̄_p` (the declared box, exactly: a link's mass and its rotational inertia
//! scale independently; the base's ten parameters by interval arithmetic over its mass
//! and inertia scales and the CoM's ball). For commands whose model acceleration is within
//! `ρ` of `ν̇₀` (`w_p(ν̇) = w_p(ν̇₀) + Y_p^M(ν̇ − ν̇₀)`), with the joint-torque error's own
//! first-order effect `M⁻¹[0; Δτ]` left to the rows that carry it already
//! (`robotic::Disturbance`), the rest `r = z − M⁻¹[0; Δτ]` has
//!
//! ```text
//! |r| ≤ f + B|r|,   f = |M⁻¹|_base |Δu_b| + Σ_p π̄_p (|M⁻¹ w_p(ν̇₀)| + |G_p| ρ + |G_p M⁻¹_J| e),
//!                   B = Σ_p π̄_p |G_p|.
//! ```
//!
//! The iteration `r ← f + B r` need not contract elementwise, so it starts from a bound
//! that always holds: every body's inertia error lies within `±ε*` of its inertia in the
//! PSD order, hence `−ε*M ⪯ ΔM ⪯ ε*M` in every configuration, `‖M⁻¹ΔM z‖_M ≤ ε*‖z‖_M`,
//! `‖z‖_M ≤ (F + T)/(1 − ε*)` (`F`, `T` the M-norms of the first-order and torque terms)
//! and `|(M⁻¹ΔMz)_i| ≤ √(M⁻¹)_ii ε*‖z‖_M`; each iterate `r ← min(r, f + B r)` is again a
//! bound ([`SECOND_ORDER_ROUNDS`]).
//!
//! Exact at first order in each parameter (the dual of the box: Tan, Nanayakkara, Tabuada,
//! Ames); the sums over parameters and the second order are where it is conservative.
//! Not covered here: the navigation's error in `θ`, `θ̇`, `ω_B` (the dynamics are evaluated
//! at the estimate).

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use sc_multibody::spatial::Inertia;
use sc_multibody::{Matrix13, NJ, Robot, Vector7, Vector13};
use sc_scenario::uncertainty::{ActuatorBounds, ModelBounds};

/// Rounds of the elementwise refinement of the second-order term
/// ([`ModelErrorBound::acceleration_error`]): each keeps a valid bound, more only tighten.
pub const SECOND_ORDER_ROUNDS: usize = 6;

/// One direction of the mass properties: the body it belongs to, the inertia of a unit
/// step along it and the declared bound on the step.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Direction {
    body: usize,
    unit: Inertia,
    bound: f64,
}

/// The declared model and base-wrench errors of the servicer, as the robotic filter
/// bounds their effect.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ModelErrorBound {
    directions: Vec<Direction>,
    /// `ε*`: every body's inertia error within `±ε*` of its inertia in the PSD order, so
    /// `−ε*M ⪯ ΔM ⪯ ε*M` in every configuration.
    relative: f64,
    /// Thrusters' relative force error (scale and misalignment) [-].
    force_rel: f64,
    /// Body-torque scale error [-].
    torque_rel: f64,
}

/// What [`ModelErrorBound::acceleration_error`] is evaluated for.
#[derive(Debug, Clone, Copy)]
pub struct Operating<'a> {
    pub theta: &'a Vector7,
    /// `[0; ω_B; θ̇]` (the base's linear velocity does not enter the internal dynamics).
    pub nu: &'a Vector13,
    /// The centre of the model accelerations the bound is for [`ν̇`, 13].
    pub nu_dot0: &'a Vector13,
    /// Their radius, elementwise.
    pub rho: &'a Vector13,
    /// The commanded base force [N] and torque [N m] (F_B).
    pub force_b: &'a Vector3<f64>,
    pub torque_b: &'a Vector3<f64>,
    /// The declared joint-torque error at the command `e` [N m] (its own first-order
    /// effect is not part of the result).
    pub joint_torque_error: &'a Vector7,
}

impl ModelErrorBound {
    /// The bound of the declared `model` and `actuators` errors on `robot` (the model).
    pub fn new(robot: &Robot, model: &ModelBounds, actuators: &ActuatorBounds) -> Self {
        let mut directions = base_directions(robot, model);
        for k in 1..=NJ {
            let Some(b) = robot.body_inertia(k) else {
                continue;
            };
            let c = b.com();
            directions.push(Direction {
                body: k,
                unit: Inertia::from_com(b.mass, c, Matrix3::zeros()),
                bound: model.link_mass_rel,
            });
            directions.push(Direction {
                body: k,
                unit: Inertia {
                    mass: 0.0,
                    h: Vector3::zeros(),
                    i_o: b.i_com(),
                },
                bound: model.link_inertia_rel,
            });
        }
        let relative = model
            .link_mass_rel
            .max(model.link_inertia_rel)
            .max(base_relative(robot, model));
        directions.retain(|d| d.bound > 0.0);
        let a = actuators;
        Self {
            directions,
            relative,
            force_rel: a.thruster_force_scale_rel
                + a.thruster_misalignment_rad * (1.0 + a.thruster_force_scale_rel),
            torque_rel: a.body_torque_scale_rel,
        }
    }

    /// From the scenario's declared uncertainty (none: zero).
    pub fn from_scenario(s: &sc_scenario::Scenario, robot: &Robot) -> Self {
        let b = s.uncertainty_bounds();
        Self::new(robot, &b.model, &b.actuators)
    }

    /// Nothing declared: the bound is zero everywhere.
    pub fn is_zero(&self) -> bool {
        self.directions.is_empty() && self.force_rel == 0.0 && self.torque_rel == 0.0
    }

    /// The bound on `|ν̇_t − ν̇|` beyond the joint-torque error's own first-order effect
    /// (module documentation), elementwise, `[v̇_B; ω̇_B; θ̈]`; `None` when the model's mass
    /// matrix is singular, `ε*` is not below 1, or the result is not finite. `rho` and the
    /// torque error are taken by magnitude.
    pub fn acceleration_error(&self, robot: &Robot, op: &Operating) -> Option<Vector13> {
        // NaN as well as ε* ≥ 1: no bound
        if self.relative.is_nan() || self.relative >= 1.0 {
            return None;
        }
        let m = robot.mass_matrix(op.theta);
        let chol = m.cholesky()?;
        let minv = chol.inverse();
        let m_norm = |v: &Vector13| v.dot(&(minv * v)).max(0.0).sqrt();
        // first order, elementwise (f̄) and in the M-norm (F)
        let mut f = Vector13::zeros();
        let mut f_norm = 0.0;
        let mut b = Matrix13::zeros();
        let minv_joints = minv.fixed_columns::<NJ>(6).into_owned();
        let (rho, e) = (op.rho.abs(), op.joint_torque_error.abs());
        let mut inertias = [Inertia::ZERO; NJ + 1];
        for d in &self.directions {
            inertias[d.body] = d.unit;
            let w = robot.rnea_with(&inertias, op.theta, op.nu, op.nu_dot0);
            let g = chol.solve(&robot.mass_matrix_with(&inertias, op.theta));
            inertias[d.body] = Inertia::ZERO;
            // the direction's own effect, and its coupling with the joint-torque error
            // (`Σ_k |(G_p M⁻¹_J)_ik| e_k`: the exact dual over both boxes)
            f += (chol.solve(&w).abs() + g.abs() * rho + (g * minv_joints).abs() * e) * d.bound;
            f_norm += m_norm(&w) * d.bound;
            b += g.abs() * d.bound;
        }
        let du = self.base_wrench_error(op.force_b, op.torque_b);
        let mut du13 = Vector13::zeros();
        du13.fixed_rows_mut::<6>(0).copy_from(&du);
        f += minv.abs() * du13;
        f_norm += du13.dot(&(minv.abs() * du13)).sqrt();
        f_norm += self.relative * rho.dot(&(m.abs() * rho)).sqrt();
        let mut e13 = Vector13::zeros();
        e13.fixed_rows_mut::<NJ>(6).copy_from(&e);
        let torque_norm = e13.dot(&(minv.abs() * e13)).sqrt();
        // second order: |(M⁻¹ΔM z)_i| ≤ √(M⁻¹)_ii ε* ‖z‖_M, ‖z‖_M ≤ (F + T)/(1 − ε*)
        let z_norm = (f_norm + torque_norm) / (1.0 - self.relative);
        let mut z =
            Vector13::from_fn(|i, _| f[i] + minv[(i, i)].max(0.0).sqrt() * self.relative * z_norm);
        // and elementwise, |r| ≤ f + B|r| with B = Σ_p π̄_p |G_p|: every iterate of
        // r ← min(r, f + B r) is again a bound
        for _ in 0..SECOND_ORDER_ROUNDS {
            z = z.inf(&(f + b * z));
        }
        z.iter().all(|v| v.is_finite()).then_some(z)
    }

    /// `|Δu_B|` bound of the base wrench `[f_B; τ_B]` (F_B) under the declared thruster
    /// and body-torque errors.
    fn base_wrench_error(&self, force_b: &Vector3<f64>, torque_b: &Vector3<f64>) -> Vector6<f64> {
        let f = self.force_rel * force_b.norm();
        Vector6::new(
            f,
            f,
            f,
            self.torque_rel * torque_b.x.abs(),
            self.torque_rel * torque_b.y.abs(),
            self.torque_rel * torque_b.z.abs(),
        )
    }
}

/// A bound on the base's inertia error relative to its inertia in the PSD order:
/// `−λI₀ ⪯ ΔI₀ ⪯ λI₀` for every plant in the declared box (the base's inertia in its own
/// frame is constant, so this is computed once). With `‖·‖` the spectral norm after the
/// congruence `X ↦ I₀^{-½} X I₀^{-½}` and `P(c) = from_com(1, c, 0)` a unit point mass:
/// `ΔI₀ = δm m P(c) + δI [0 0; 0 I_c] + m(1 + δm)(P(c + δ) − P(c))`, and
/// `P(c + δ) − P(c) = Σ_k δ_k L_k + [0 0; 0 ‖δ‖²1 − δδᵀ]` with `L_k` the derivative along
/// `e_k`; `m P(c)` and `[0 0; 0 I_c]` are ⪰ 0 and add up to `I₀`, so
/// `λ = max(ε_m, ε_I) + m(1 + ε_m)(d √(Σ_k ‖L_k‖²) + d² ‖[0 0; 0 1]‖)`.
/// Infinite when the base's inertia is not positive definite.
fn base_relative(robot: &Robot, model: &ModelBounds) -> f64 {
    let Some(body) = robot.body_inertia(0) else {
        return f64::INFINITY;
    };
    let Some(l_inv) = body
        .to_matrix()
        .cholesky()
        .and_then(|c| c.l().try_inverse())
    else {
        return f64::INFINITY;
    };
    let norm = |x: Matrix6<f64>| {
        let s = l_inv * x * l_inv.transpose();
        s.symmetric_eigenvalues()
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let (m, c) = (body.mass, body.com());
    let point = |c: Vector3<f64>| Inertia::from_com(1.0, c, Matrix3::zeros()).to_matrix();
    let angular = |a: Matrix3<f64>| {
        let mut x = Matrix6::zeros();
        x.fixed_view_mut::<3, 3>(3, 3).copy_from(&a);
        x
    };
    // the derivative of P along e_k, exactly: P is quadratic in c, so the central difference is
    let along = |k: usize| point(c + Vector3::ith(k, 0.5)) - point(c - Vector3::ith(k, 0.5));
    let linear = (0..3).map(|k| norm(along(k)).powi(2)).sum::<f64>().sqrt();
    let (em, ei, d) = (
        model.servicer_mass_rel,
        model.servicer_inertia_rel,
        model.servicer_com_m,
    );
    // m P(c) ⪰ 0 and [0 0; 0 I_c] ⪰ 0 add up to I₀: scaled by δm and δI they stay
    // within ±max(ε_m, ε_I) I₀
    em.max(ei) + m * (1.0 + em) * (d * linear + d * d * norm(angular(Matrix3::identity())))
}

/// The base's ten inertial parameters (mass, first moment, rotational inertia about the
/// body origin) as unit directions with their interval bounds over the declared box:
/// mass scale `|δm| ≤ ε_m`, inertia scale `|δI| ≤ ε_I`, CoM moved by `‖δ‖ ≤ d`:
/// `Δm = m δm`, `Δh = m δm c + m(1 + δm) δ`,
/// `Δi_o = δI I_c + m δm S(c) + m(1 + δm)(S(c + δ) − S(c))`, `S(a) = ‖a‖²1 − aaᵀ`.
fn base_directions(robot: &Robot, model: &ModelBounds) -> Vec<Direction> {
    let Some(body) = robot.body_inertia(0) else {
        return Vec::new();
    };
    let (m, c, i_c) = (body.mass, body.com(), body.i_com());
    let (em, ei, d) = (
        model.servicer_mass_rel,
        model.servicer_inertia_rel,
        model.servicer_com_m,
    );
    let s = Matrix3::identity() * c.norm_squared() - c * c.transpose();
    let shift = |i: usize, j: usize| {
        if i == j {
            let rest = (c.norm_squared() - c[i] * c[i]).sqrt();
            2.0 * d * rest + d * d
        } else {
            d * (c[i].abs() + c[j].abs()) + 0.5 * d * d
        }
    };
    let io_bound = |i: usize, j: usize| {
        ei * i_c[(i, j)].abs() + m * em * s[(i, j)].abs() + m * (1.0 + em) * shift(i, j)
    };
    let unit = |mass: f64, h: Vector3<f64>, i_o: Matrix3<f64>| Inertia { mass, h, i_o };
    let mut dirs = vec![Direction {
        body: 0,
        unit: unit(1.0, Vector3::zeros(), Matrix3::zeros()),
        bound: m * em,
    }];
    for i in 0..3 {
        dirs.push(Direction {
            body: 0,
            unit: unit(0.0, Vector3::ith(i, 1.0), Matrix3::zeros()),
            bound: m * em * c[i].abs() + m * (1.0 + em) * d,
        });
    }
    for i in 0..3 {
        for j in i..3 {
            let mut e = Matrix3::zeros();
            e[(i, j)] = 1.0;
            e[(j, i)] = 1.0;
            dirs.push(Direction {
                body: 0,
                unit: unit(0.0, Vector3::zeros(), e),
                bound: io_bound(i, j),
            });
        }
    }
    dirs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_draws::{lcg, pick, plant};
    use sc_multibody::Vector7;

    fn robot() -> Robot {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../config/servicer.urdf");
        Robot::from_urdf_file(std::path::Path::new(path)).unwrap()
    }

    /// For plants anywhere in the `realistic` box, states and commands over the arm's
    /// range, the base wrench's errors within the declared scales and the joint torques'
    /// within theirs: the realised `|ν̇_t − ν̇ − M⁻¹[0; Δτ]|` is within the bound evaluated at the model's own acceleration
    /// (`ρ = 0`), and within the bound for a box of accelerations around another centre
    /// that contains it. Prints how tight it is per component.
    #[test]
    fn the_bound_covers_every_plant_in_the_declared_box() {
        let r = robot();
        let u =
            sc_scenario::uncertainty::Uncertainty::profile("realistic", std::path::Path::new("."))
                .expect("profile");
        let (model, act) = (u.model, u.actuators);
        let bound = ModelErrorBound::new(&r, &model, &act);
        assert!(!bound.is_zero());
        let mut seed = 25u64;
        let (lo, hi, _, vmax) = r.joint_limit_arrays();
        let mut worst = [0.0f64; 13];
        for _ in 0..400 {
            let p = plant(&mut seed, &r, &model);
            let mut draw = |a: f64, b: f64| a + (b - a) * lcg(&mut seed);
            let theta = Vector7::from_fn(|i, _| draw(lo[i], hi[i]));
            let mut nu = Vector13::zeros();
            let mut u = Vector13::zeros();
            for i in 0..3 {
                nu[3 + i] = draw(-0.05, 0.05);
                u[i] = draw(-20.0, 20.0);
                u[3 + i] = draw(-5.0, 5.0);
            }
            for i in 0..NJ {
                nu[6 + i] = draw(-vmax[i], vmax[i]);
                u[6 + i] = draw(-1.0, 1.0);
            }
            let mut u_t = u;
            for i in 0..3 {
                u_t[i] *= 1.0 + pick(&mut seed, act.thruster_force_scale_rel);
                u_t[3 + i] *= 1.0 + pick(&mut seed, act.body_torque_scale_rel);
            }
            // the joint torques' declared error, whose own first-order effect the rows
            // carry: the bound is for the rest
            // scale and ripple multiply (TorqueError: rel = s + r + s r)
            let (s, rp) = (act.joint_torque_scale_rel, act.joint_torque_ripple_rel);
            let rel = s + rp + s * rp;
            let e = Vector7::from_fn(|k, _| act.joint_torque_bias_nm + rel * u[6 + k].abs());
            let mut du = Vector13::zeros();
            for k in 0..NJ {
                du[6 + k] = pick(&mut seed, e[k]);
            }
            u_t += du;
            let nd = r.forward_dynamics(&theta, &nu, &u).unwrap();
            let first = r.mass_matrix(&theta).cholesky().unwrap().solve(&du);
            let nd_t = p.forward_dynamics(&theta, &nu, &u_t).unwrap() - first;
            let fb = Vector3::new(u[0], u[1], u[2]);
            let tb = Vector3::new(u[3], u[4], u[5]);
            let at = |centre: &Vector13, rho: &Vector13| {
                let op = Operating {
                    theta: &theta,
                    nu: &nu,
                    nu_dot0: centre,
                    rho,
                    force_b: &fb,
                    torque_b: &tb,
                    joint_torque_error: &e,
                };
                bound.acceleration_error(&r, &op).expect("a bound")
            };
            let own = at(&nd, &Vector13::zeros());
            let centre = nd * 0.5;
            let boxed = at(&centre, &(nd - centre).abs());
            for i in 0..13 {
                let got = (nd_t[i] - nd[i]).abs();
                let tol = |b: f64| b * (1.0 + 1e-9) + 1e-12;
                assert!(got <= tol(own[i]), "component {i}: {got} > {}", own[i]);
                assert!(
                    got <= tol(boxed[i]),
                    "component {i}: {got} > {} (box)",
                    boxed[i]
                );
                worst[i] = worst[i].max(got / own[i]);
            }
        }
        println!(
            "realised / bound, largest per component [v̇_B; ω̇_B; θ̈]: {worst:.2?}; ε* = {:.3}",
            bound.relative
        );
    }
}
