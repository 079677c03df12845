//! What the filters know of the servicer's system centre of mass (issue #25): the bound on
//! the error of the CoM position and velocity they compute from the navigation's estimate
//! with the declared model, against the plant's true CoM — for every realisation of the
//! declared navigation and mass-property errors (docs/SAFETY.md, "Measurement-robust
//! rows"). The translational barriers are on that point.
//!
//! The filters compute `r̂ = d̂r + R̂ c(θ̂)` and `v̂ = d̂v + R̂(ω̂ × c(θ̂) + J_c(θ̂) θ̇̂)` with
//! the model's CoM `c(θ) = Σ mᵢ pᵢ(θ)/m` in the base frame; the plant's is
//! `c_t = c + w`, `w = (Σ mᵢ sᵢ (pᵢ − c) + m₀' δ)/m'` (body masses `mᵢ(1 + sᵢ)`, the
//! base CoM moved by `δ`, `m'` the plant's total mass). With `L_k` the configuration-free
//! bound on `‖∂c/∂θ_k‖` ([`ComKnowledge::new`]) the error is bounded by
//!
//! * position: `ē_p + ē_R ‖ĉ‖ + Σ_k L_k ē_θ + ‖w‖`;
//! * velocity: `ē_v + ē_R ‖ω̂ × ĉ + ĉ̇‖ + ē_ω ‖ĉ‖ + (‖ω̂‖ + ē_ω)(Σ_k L_k ē_θ + ‖w‖)
//!   + Σ_k L_k ē_θ̇ + 2 NJ ē_θ Σ_k L_k θ̄̇_k + ‖ẇ‖`,
//!
//! with `‖w‖ ≤ (Σ εᵢ mᵢ Dᵢ + (1 + ε₀) m₀ δ̄)/(m − Σ εᵢ mᵢ)`, where `Dᵢ` bounds `‖pᵢ − c‖`
//! in the true configuration: its value in the estimate's plus what the joint angles'
//! error can move it, `ē_θ (Σ_k chain_kᵢ + Σ_k L_k)` (`chain_kᵢ` the chain length from
//! joint `k` to body `i`'s CoM bounds `‖∂pᵢ/∂θ_k‖`), and
//! `‖ẇ‖ ≤ Σ εᵢ mᵢ (‖ṗᵢ‖ + ‖ċ‖)/(m − Σ εᵢ mᵢ)` (`θ̄̇ = |θ̇̂| + ē_θ̇`).

use nalgebra::Vector3;
use sc_multibody::{NJ, Robot, Vector7};
use sc_scenario::Uncertainty;

/// The declared bounds the CoM's error rests on, and the model's lengths and masses.
#[derive(Debug, Clone, PartialEq)]
pub struct ComKnowledge {
    /// Navigation: base position [m], velocity [m/s], attitude [rad], body rate [rad/s],
    /// each joint's angle [rad] and rate [rad/s] (bias + noise).
    pub position_m: f64,
    pub velocity_m_s: f64,
    pub attitude_rad: f64,
    pub rate_rad_s: f64,
    pub joint_angle_rad: f64,
    pub joint_rate_rad_s: f64,
    /// `εᵢ` of each body's mass (0: the base) [-] and the base CoM's offset `δ̄` [m].
    pub mass_rel: [f64; NJ + 1],
    pub base_com_m: f64,
    /// The model's body masses [kg] and total mass [kg].
    masses: [f64; NJ + 1],
    total: f64,
    /// `L_k` ≥ `‖∂c/∂θ_k‖` in every configuration [m/rad].
    lever: [f64; NJ],
    /// Each body's CoM in its own frame [m].
    com_local: [Vector3<f64>; NJ + 1],
    /// Chain length from joint `k`'s axis to body `i`'s CoM (`i > k`), [k][i] [m].
    chain: [[f64; NJ + 1]; NJ],
}

impl ComKnowledge {
    /// From the declared bounds `u` and the model `robot`.
    pub fn new(u: &Uncertainty, robot: &Robot) -> Self {
        let (n, m) = (&u.navigation, &u.model);
        let mut mass_rel = [m.link_mass_rel; NJ + 1];
        mass_rel[0] = m.servicer_mass_rel;
        let (masses, com_local) = body_masses(robot);
        let com_norm = com_local.map(|c| c.norm());
        // rigid segments: body j's origin to body j+1's (joint j's axis) in body j
        let kin = robot.kinematics(&Vector7::zeros());
        let seg: [f64; NJ] =
            std::array::from_fn(|j| (kin.pose[j + 1].trans - kin.pose[j].trans).norm());
        // from joint k (body k+1's origin) to body i's CoM, i > k
        let chain: [[f64; NJ + 1]; NJ] = std::array::from_fn(|k| {
            std::array::from_fn(|i| {
                if i <= k {
                    0.0
                } else {
                    seg[k + 1..i].iter().sum::<f64>() + com_norm[i]
                }
            })
        });
        let total: f64 = masses.iter().sum();
        let lever = std::array::from_fn(|k| {
            (k + 1..=NJ).map(|i| masses[i] * chain[k][i]).sum::<f64>() / total
        });
        Self {
            position_m: n.relative_position_m.bound(),
            velocity_m_s: n.relative_velocity_m_s.bound(),
            attitude_rad: n.servicer_attitude_rad.bound(),
            rate_rad_s: n.servicer_rate_rad_s.bound(),
            joint_angle_rad: n.joint_angle_rad.bound(),
            joint_rate_rad_s: n.joint_rate_rad_s.bound(),
            mass_rel,
            base_com_m: m.servicer_com_m,
            masses,
            total,
            lever,
            com_local,
            chain,
        }
    }

    /// Nothing declared that moves the CoM's knowledge.
    pub fn is_zero(&self) -> bool {
        [
            self.position_m,
            self.velocity_m_s,
            self.attitude_rad,
            self.rate_rad_s,
            self.joint_angle_rad,
            self.joint_rate_rad_s,
            self.base_com_m,
        ]
        .iter()
        .chain(&self.mass_rel)
        .all(|x| *x == 0.0)
    }

    /// `Σ εᵢ mᵢ` [kg]: how much lighter than the model the plant can be.
    fn mass_deficit(&self) -> f64 {
        (0..=NJ).map(|i| self.mass_rel[i] * self.masses[i]).sum()
    }

    /// The bounds `(ē_r, ē_v)` [m, m/s] on the error of the CoM position and velocity the
    /// filters compute from the estimate `(θ̂, θ̇̂, ω̂_B)` (the module's derivation).
    /// Infinite when the declared masses leave no plant mass (`Σ εᵢ mᵢ ≥ m`).
    pub fn com_error(
        &self,
        robot: &Robot,
        theta: &Vector7,
        theta_dot: &Vector7,
        omega_b: &Vector3<f64>,
    ) -> (f64, f64) {
        let light = self.total - self.mass_deficit();
        if light.is_nan() || light <= 0.0 {
            return (f64::INFINITY, f64::INFINITY);
        }
        let c = robot.center_of_mass(theta);
        let c_dot = robot.center_of_mass_velocity(theta, theta_dot);
        let rates = theta_dot.abs().add_scalar(self.joint_rate_rad_s);
        let lever_sum: f64 = self.lever.iter().sum();
        let angle_part = lever_sum * self.joint_angle_rad;
        let kin = robot.kinematics(theta);
        let spread = |i: usize| {
            let p = kin.pose[i].trans + kin.pose[i].rot * self.com_local[i];
            let moved: f64 = (0..NJ).map(|k| self.chain[k][i]).sum::<f64>() + lever_sum;
            (p - c).norm() + self.joint_angle_rad * moved
        };
        let w = ((0..=NJ)
            .map(|i| self.mass_rel[i] * self.masses[i] * spread(i))
            .sum::<f64>()
            + (1.0 + self.mass_rel[0]) * self.masses[0] * self.base_com_m)
            / light;
        let c_dot_bound: f64 = (0..NJ).map(|k| self.lever[k] * rates[k]).sum();
        let w_dot = (1..=NJ)
            .map(|i| {
                let p_dot: f64 = (0..i).map(|k| self.chain[k][i] * rates[k]).sum();
                self.mass_rel[i] * self.masses[i] * (p_dot + c_dot_bound)
            })
            .sum::<f64>()
            + self.mass_rel[0] * self.masses[0] * c_dot_bound;
        let w_dot = w_dot / light;
        let position = self.position_m + self.attitude_rad * c.norm() + angle_part + w;
        let jacobian_change: f64 = 2.0
            * NJ as f64
            * self.joint_angle_rad
            * (0..NJ).map(|k| self.lever[k] * rates[k]).sum::<f64>();
        let velocity = self.velocity_m_s
            + self.attitude_rad * (omega_b.cross(&c) + c_dot).norm()
            + self.rate_rad_s * c.norm()
            + (omega_b.norm() + self.rate_rad_s) * (angle_part + w)
            + self.lever.iter().sum::<f64>() * self.joint_rate_rad_s
            + jacobian_change
            + w_dot;
        (position, velocity)
    }
}

/// The bounds `(ē_r, ē_v)` of [`ComKnowledge::com_error`] (inertial) as bounds on the
/// error of the CoM's state in the rotating F_H, which turns at `ω_H`: the position's is
/// `ē_r` (`r_H = C_HI δr`, a rotation) and the velocity's `ē_v + ‖ω_H‖ē_r`
/// (`v_H = C_HI δv − ω_H × r_H`, so its error is `C_HI e_v − ω_H × C_HI e_r`). The
/// translational rows are built with these.
pub fn in_hill(err: (f64, f64), omega_h: &Vector3<f64>) -> (f64, f64) {
    (err.0, err.1 + omega_h.norm() * err.0)
}

/// Each body's mass [kg] and its CoM in its own frame [m].
fn body_masses(robot: &Robot) -> ([f64; NJ + 1], [Vector3<f64>; NJ + 1]) {
    let mut masses = [0.0; NJ + 1];
    let mut com = [Vector3::zeros(); NJ + 1];
    for k in 0..=NJ {
        if let Some(b) = robot.body_inertia(k) {
            masses[k] = b.mass;
            com[k] = b.com();
        }
    }
    (masses, com)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_draws::{ball, lcg};
    use sc_models::quat;

    /// The default scenario, its servicer model and the `realistic` bounds' knowledge.
    fn realistic() -> (sc_scenario::Scenario, Robot, ComKnowledge) {
        let s = sc_scenario::Scenario::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../config/scenario.toml"
        )))
        .expect("scenario");
        let model = Robot::from_urdf_file(&s.urdf_path()).expect("urdf");
        let u = Uncertainty::profile("realistic", std::path::Path::new(".")).expect("profile");
        let k = ComKnowledge::new(&u, &model);
        (s, model, k)
    }

    /// A plant and its true motion relative to the base, and the estimate of it.
    struct Draw {
        plant: Robot,
        theta: Vector7,
        theta_dot: Vector7,
        /// The true body rate [rad/s, F_B] and attitude `q_IB`.
        w_t: Vector3<f64>,
        q_t: sc_models::quat::Quat,
        th_e: Vector7,
        thd_e: Vector7,
        w_e: Vector3<f64>,
        q_e: sc_models::quat::Quat,
        /// The errors of the base's (inertial) relative position [m] and velocity [m/s].
        dr: Vector3<f64>,
        dv: Vector3<f64>,
    }

    /// A plant at the edges of `k`'s bounds in a random configuration and motion, and an
    /// estimate with every navigation error at its bound in a random direction.
    fn draw(seed: &mut u64, model: &Robot, k: &ComKnowledge) -> Draw {
        let sign = |seed: &mut u64| if lcg(seed) < 0.5 { -1.0 } else { 1.0 };
        // the plant: every body's mass at ± its bound, the base CoM on its sphere
        let mut plant = model
            .with_body_mass_properties(
                0,
                1.0 + sign(seed) * k.mass_rel[0],
                1.0,
                ball(seed, 1.0).normalize() * k.base_com_m,
            )
            .unwrap();
        for b in 1..=NJ {
            plant = plant
                .with_body_mass_properties(
                    b,
                    1.0 + sign(seed) * k.mass_rel[b],
                    1.0,
                    Vector3::zeros(),
                )
                .unwrap();
        }
        let theta = Vector7::from_fn(|_, _| 3.0 * (2.0 * lcg(seed) - 1.0));
        let theta_dot = Vector7::from_fn(|_, _| 0.2 * (2.0 * lcg(seed) - 1.0));
        let w_t = ball(seed, 0.2);
        let q_t = quat::from_axis_angle(&ball(seed, 1.0), 3.0 * lcg(seed));
        // the estimate: every error at its bound in a random direction
        let dth = Vector7::from_fn(|_, _| sign(seed) * k.joint_angle_rad);
        let dthd = Vector7::from_fn(|_, _| sign(seed) * k.joint_rate_rad_s);
        let th_e = theta + dth;
        let thd_e = theta_dot + dthd;
        let w_e = w_t + ball(seed, 1.0).normalize() * k.rate_rad_s;
        let q_e = quat::mul(
            &q_t,
            &quat::from_axis_angle(&ball(seed, 1.0), k.attitude_rad),
        );
        let dr = ball(seed, 1.0).normalize() * k.position_m;
        let dv = ball(seed, 1.0).normalize() * k.velocity_m_s;
        Draw {
            plant,
            theta,
            theta_dot,
            w_t,
            q_t,
            th_e,
            thd_e,
            w_e,
            q_e,
            dr,
            dv,
        }
    }

    /// The CoM's position and velocity relative to the base's origin, in the inertial
    /// frame, of the truth and of the estimate (`model` the declared one).
    fn com_offsets(d: &Draw, model: &Robot) -> [(Vector3<f64>, Vector3<f64>); 2] {
        let (rt, re) = (quat::to_matrix(&d.q_t), quat::to_matrix(&d.q_e));
        let c_t = d.plant.center_of_mass(&d.theta);
        let c_e = model.center_of_mass(&d.th_e);
        let v_t =
            rt * (d.w_t.cross(&c_t) + d.plant.center_of_mass_velocity(&d.theta, &d.theta_dot));
        let v_e = re * (d.w_e.cross(&c_e) + model.center_of_mass_velocity(&d.th_e, &d.thd_e));
        [(rt * c_t, v_t), (re * c_e, v_e)]
    }

    /// The bound against the realised error of plants and estimates drawn at the edges of
    /// the `realistic` bounds, in random configurations and motions.
    #[test]
    fn the_com_error_bound_holds_for_realistic_plants_and_estimates() {
        let (s, model, k) = realistic();
        let seed = &mut 3u64;
        let mut worst = (0.0f64, 0.0f64);
        for _ in 0..400 {
            let d = draw(seed, &model, &k);
            let [(c_t, v_t), (c_e, v_e)] = com_offsets(&d, &model);
            let e_r = (d.dr + c_e - c_t).norm();
            let e_v = (d.dv + v_e - v_t).norm();
            let (b_r, b_v) = k.com_error(&model, &d.th_e, &d.thd_e, &d.w_e);
            assert!(e_r <= b_r, "position {e_r} > {b_r}");
            assert!(e_v <= b_v, "velocity {e_v} > {b_v}");
            worst = (worst.0.max(e_r / b_r), worst.1.max(e_v / b_v));
        }
        eprintln!(
            "largest realised / bound: position {:.2}, velocity {:.2}",
            worst.0, worst.1
        );
        // the bound docs/SAFETY.md quotes: the scenario's initial arm, at rest
        let (e_r, e_v) = k.com_error(
            &model,
            &Vector7::from(s.servicer.initial_theta_rad),
            &Vector7::zeros(),
            &Vector3::zeros(),
        );
        eprintln!("initial arm at rest: e_r = {e_r:.4} m, e_v = {e_v:.5} m/s");
        // nothing declared: no error
        let zero = ComKnowledge::new(&Uncertainty::default(), &model);
        assert!(zero.is_zero());
        assert_eq!(
            zero.com_error(
                &model,
                &Vector7::zeros(),
                &Vector7::zeros(),
                &Vector3::zeros()
            ),
            (0.0, 0.0)
        );
    }

    /// End to end in F_H, as the translational filter sees the CoM: the truth's and the
    /// estimate's CoM put into the Hill frame of the target's orbit as the simulator's
    /// observation does (`relative_to_hill` of the base's inertial relative state plus the
    /// CoM's lever), the estimate's inertial relative position and velocity off by errors
    /// within their declared bounds (every other error at its bound): the realised errors
    /// of `r_H` and `v_H` stay within [`in_hill`] of [`ComKnowledge::com_error`] — and its
    /// frame term `‖ω_H‖ē_r` is needed: a position error across `ω_H` with the velocity's
    /// against `ω_H × e_r` attains it.
    #[test]
    fn the_com_error_bound_in_the_hill_frame_covers_the_realised_error() {
        use sc_models::hill::HillFrame;
        let (s, model, k) = realistic();
        let orbit = sc_models::orbit::TwoBody {
            mu: s.orbit.earth_mu_m3_s2,
        };
        let a = s.orbit.earth_radius_m + s.orbit.altitude_m;
        let tau = std::f64::consts::TAU;
        let seed = &mut 5u64;
        let mut worst = (0.0f64, 0.0f64);
        for i in 0..400 {
            let d = draw(seed, &model, &k);
            let [(c_t, v_t), (c_e, v_e)] = com_offsets(&d, &model);
            // the target somewhere on its circular orbit, the servicer's base within 30 m
            // and 0.3 m/s of it; the estimate's relative state at its bounds (even draws)
            // or inside them (odd)
            let (r_o, v_o) =
                orbit.circular_state(a, 0.5 * tau * lcg(seed), tau * lcg(seed), tau * lcg(seed));
            let hill = HillFrame::from_inertial(&r_o, &v_o);
            let (dr, dv) = (ball(seed, 30.0), ball(seed, 0.3));
            let inside = if i % 2 == 0 { 1.0 } else { lcg(seed) };
            let (dr_e, dv_e) = (dr + d.dr * inside, dv + d.dv * inside);
            let (r_h, v_h) = hill.relative_to_hill(&(dr + c_t), &(dv + v_t));
            let (r_he, v_he) = hill.relative_to_hill(&(dr_e + c_e), &(dv_e + v_e));
            let (e_r, e_v) = ((r_he - r_h).norm(), (v_he - v_h).norm());
            let (b_r, b_v) = in_hill(k.com_error(&model, &d.th_e, &d.thd_e, &d.w_e), &hill.omega);
            assert!(e_r <= b_r, "position in F_H {e_r} > {b_r}");
            assert!(e_v <= b_v, "velocity in F_H {e_v} > {b_v}");
            worst = (worst.0.max(e_r / b_r), worst.1.max(e_v / b_v));
        }
        eprintln!(
            "in F_H, largest realised / bound: position {:.2}, velocity {:.2}",
            worst.0, worst.1
        );
        // the frame term is attained: e_r across ω_H, e_v against ω_H × e_r (in F_H)
        let (r_o, v_o) = orbit.circular_state(a, 0.9, 0.3, 1.7);
        let hill = HillFrame::from_inertial(&r_o, &v_o);
        let (b_r, b_v) = (0.066, 0.002);
        let e_rh = Vector3::new(0.6, 0.8, 0.0) * b_r;
        let e_vh = -hill.omega.cross(&e_rh).normalize() * b_v;
        let (dr, dv) = (
            Vector3::new(-12.0, 3.0, 1.0),
            Vector3::new(0.01, -0.02, 0.0),
        );
        let c_ih = hill.c_hi.transpose();
        let (r_h, v_h) = hill.relative_to_hill(&dr, &dv);
        let (r_he, v_he) = hill.relative_to_hill(&(dr + c_ih * e_rh), &(dv + c_ih * e_vh));
        let bound = in_hill((b_r, b_v), &hill.omega);
        assert!(((r_he - r_h).norm() - bound.0).abs() < 1e-9);
        let e_v = (v_he - v_h).norm();
        assert!(
            (e_v - bound.1).abs() < 1e-9 * bound.1,
            "{e_v} vs {}",
            bound.1
        );
        assert!(e_v > b_v + 0.5 * hill.omega.norm() * b_r, "{e_v}");
    }
}
