//! The translational rows' margins for the declared errors (issue #25; docs/SAFETY.md,
//! "Margins for the declared errors", translational): what the thrusters, the servicer's
//! mass and the navigation let the true corridor, zone and tangential-speed terms differ
//! from the ones the filter computes.
//!
//! * **Force.** The plant's CoM accelerates by `k R f/m` for the commanded `f` (model mass
//!   `m`): `k = (1 + s) m/m'` with the thrusters' scale `|s| ≤ s̄` and the plant's mass
//!   `m' ∈ [m − Σεᵢmᵢ, m + Σεᵢmᵢ]`, so `k ∈ [k_lo, k_hi]`; `R` turns by at most the
//!   thrusters' misalignment plus the attitude knowledge's error (the force is put into
//!   the body frame with the estimated attitude): `θ̄`. A row `b·f ≥ c` holds for every
//!   `k` when `f` meets `b·f ≥ c/k_lo` (`c > 0`) or `c/k_hi` (`c ≤ 0`): exact, one row.
//!   The turn is a bounded disturbance, `k_hi θ̄ ‖b‖ √3F`.
//! * **State.** The true CoM is within `ē_r`, `ē_v` of the estimate
//!   ([`crate::knowledge::ComKnowledge`]): each barrier's `h`, `ḣ` and `ḧ` then lie within
//!   `δh`, `δḣ`, `δφ` of the estimate's ([`Unknowns`], per barrier below), and the rows
//!   are the measurement-robust ones of [`crate::sampled::phi_required_known`].

use crate::knowledge::ComKnowledge;
use crate::sampled::StateUncertainty;
use nalgebra::Vector3;
use sc_multibody::{NJ, Robot};
use sc_scenario::Uncertainty;

/// The declared errors of the force the plant's CoM receives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceError {
    /// `k_lo ≤ k ≤ k_hi` of the acceleration's scale [-].
    pub k_lo: f64,
    pub k_hi: f64,
    /// `θ̄`: the largest turn of the delivered force [rad].
    pub turn_rad: f64,
}

impl ForceError {
    pub const NONE: Self = Self {
        k_lo: 1.0,
        k_hi: 1.0,
        turn_rad: 0.0,
    };

    /// From the declared bounds and the model's body masses; [`Self::NONE`] for bounds
    /// that leave no plant mass (refused by the scenario's validation before).
    pub fn new(u: &Uncertainty, robot: &Robot) -> Self {
        let a = &u.actuators;
        let m = robot.total_mass();
        let deficit: f64 = (0..=NJ)
            .filter_map(|k| robot.body_inertia(k).map(|b| (k, b.mass)))
            .map(|(k, mass)| {
                let rel = if k == 0 {
                    u.model.servicer_mass_rel
                } else {
                    u.model.link_mass_rel
                };
                rel * mass
            })
            .sum();
        let s = a.thruster_force_scale_rel;
        if !(deficit < m && s < 1.0) {
            return Self::NONE;
        }
        Self {
            k_lo: (1.0 - s) * m / (m + deficit),
            k_hi: (1.0 + s) * m / (m - deficit),
            turn_rad: a.thruster_misalignment_rad + u.navigation.servicer_attitude_rad.bound(),
        }
    }

    pub fn is_none(&self) -> bool {
        *self == Self::NONE
    }

    /// The share `λ ∈ [0, 1]` of these errors (`1`: themselves, `0`: [`Self::NONE`]).
    pub fn share(&self, share: f64) -> Self {
        if share == 1.0 {
            return *self;
        }
        if share == 0.0 {
            return Self::NONE;
        }
        Self {
            k_lo: 1.0 - share * (1.0 - self.k_lo),
            k_hi: 1.0 + share * (self.k_hi - 1.0),
            turn_rad: share * self.turn_rad,
        }
    }

    /// The offset of a row `b·f + c ≥ 0` that holds for every scale in `[k_lo, k_hi]`:
    /// `c/k_lo` when the row needs force (`c < 0`), else `c/k_hi`.
    pub fn scaled_offset(&self, c: f64) -> f64 {
        if self.is_none() {
            c
        } else if c < 0.0 {
            c / self.k_lo
        } else {
            c / self.k_hi
        }
    }
}

/// Everything the translational rows budget for.
#[derive(Debug, Clone, PartialEq)]
pub struct TranslationalErrors {
    pub force: ForceError,
    pub com: ComKnowledge,
}

impl TranslationalErrors {
    pub fn new(u: &Uncertainty, robot: &Robot) -> Self {
        Self {
            force: ForceError::new(u, robot),
            com: ComKnowledge::new(u, robot),
        }
    }

    pub fn is_zero(&self) -> bool {
        self.force.is_none() && self.com.is_zero()
    }
}

/// Chord between the unit vectors of `r` and `r + e`, `‖e‖ ≤ ē`, `‖r‖ = rn`:
/// `√(2(1 − √(1 − u²)))`, `u = ē/rn` (the angle's sine is at most `u`); 2 when `ē ≥ rn`.
pub fn direction_chord(e: f64, rn: f64) -> f64 {
    if e == 0.0 {
        return 0.0;
    }
    let u = e / rn;
    if u.is_nan() || u >= 1.0 {
        return 2.0;
    }
    // √(2(1 − √(1 − u²))) written without the cancellation
    u * (2.0 / (1.0 + (1.0 - u * u).sqrt())).sqrt()
}

/// The estimate's CoM state and what is unknown of it, with the magnitudes the bounds
/// use: `rn = ‖r̂‖`, `vn = ‖v̂‖`, `ē_r`, `ē_v`, the force's acceleration bound
/// `A_f = √3F/m` and the CW drift's `‖a₀‖` and change `Δa = 3n²ē_r + 2nē_v`.
#[derive(Debug, Clone, Copy)]
pub struct Unknowns {
    pub rn: f64,
    pub vn: f64,
    pub e_r: f64,
    pub e_v: f64,
    /// `ρ = ‖r̂‖ − ē_r` (the least true range) [m].
    pub rho: f64,
    /// Chord of the line-of-sight direction's error [-].
    pub chord: f64,
    pub force_acc: f64,
    pub drift: f64,
    pub drift_change: f64,
    pub force: ForceError,
}

impl Unknowns {
    /// For the estimate `(r, v)` with errors `(ē_r, ē_v)`, drift `a₀`, mean motion `n`,
    /// force acceleration bound `A_f`.
    pub fn new(
        r: &Vector3<f64>,
        v: &Vector3<f64>,
        err: (f64, f64),
        a0: &Vector3<f64>,
        n: f64,
        force_acc: f64,
        force: ForceError,
    ) -> Self {
        let (rn, vn) = (r.norm(), v.norm());
        let (e_r, e_v) = err;
        Self {
            rn,
            vn,
            e_r,
            e_v,
            rho: rn - e_r,
            chord: direction_chord(e_r, rn),
            force_acc,
            drift: a0.norm(),
            drift_change: 3.0 * n * n * e_r + 2.0 * n * e_v,
            force,
        }
    }

    /// `Δḧ` of a barrier with gradient norm `G` (to the acceleration) whose gradient can
    /// turn by `ΔG`: `ΔG (‖a₀‖ + Δa + k_hi A_f) + G (Δa + k_hi θ̄ A_f)`.
    fn acceleration_term(&self, g: f64, dg: f64) -> f64 {
        let k = self.force.k_hi;
        dg * (self.drift + self.drift_change + k * self.force_acc)
            + g * (self.drift_change + k * self.force.turn_rad * self.force_acc)
    }

    /// Corridor `h = dᵀr − ‖r‖cos ψ` with `g = d − r̂ cos ψ` (`G = ‖ĝ‖`), axis rates
    /// `‖ḋ‖`, `‖d̈‖` and the estimate's speed along and across the line of sight `v_∥`,
    /// `‖v_⊥‖`: `δh = Gē_r + cos ψ ē_r²/(2ρ)`;
    /// `δḣ = ‖ḋ‖ē_r + cos ψ (½chord²|v_∥| + chord‖v_⊥‖) + (G + ΔG)ē_v` (the gradient turns
    /// with `r̂`, across it: `(r̂' − r̂)ᵀr̂ = −½chord²`) with `ΔG = cos ψ · chord`;
    /// `δφ = ‖d̈‖ē_r + 2‖ḋ‖ē_v + [acceleration] + cos ψ ΔC` where `ΔC` bounds the change
    /// of the curvature `‖v_⊥‖²/‖r‖`.
    pub fn corridor(
        &self,
        g: f64,
        cos_psi: f64,
        axis_rates: (f64, f64),
        v_along: f64,
        v_perp: f64,
    ) -> (StateUncertainty, f64) {
        if self.rho.is_nan() || self.rho <= 0.0 {
            return unbounded();
        }
        let (d_dot, d_ddot) = axis_rates;
        let dg = cos_psi * self.chord;
        let turn = cos_psi * (0.5 * self.chord * self.chord * v_along.abs() + self.chord * v_perp);
        let unknown = StateUncertainty {
            h: g * self.e_r + cos_psi * self.e_r * self.e_r / (2.0 * self.rho),
            hdot: d_dot * self.e_r + turn + (g + dg) * self.e_v,
        };
        let d_perp = self.e_v + 2.0 * self.chord * (self.vn + self.e_v);
        let c = v_perp * v_perp / self.rn;
        let c_hi = (v_perp + d_perp).powi(2) / self.rho;
        let c_lo = (v_perp - d_perp).max(0.0).powi(2) / (self.rn + self.e_r);
        let curvature = (c_hi - c).max(c - c_lo);
        let phi = d_ddot * self.e_r
            + 2.0 * d_dot * self.e_v
            + self.acceleration_term(g, dg)
            + cos_psi * curvature;
        (unknown, phi)
    }

    /// Zone `h = ‖r‖² − R²`: `δh = 2‖r̂‖ē_r + ē_r²`, `δḣ = 2(ē_r‖v̂‖ + ‖r̂‖ē_v + ē_rē_v)`,
    /// `δφ = 2(2‖v̂‖ē_v + ē_v²) + [acceleration with G = 2‖r̂‖, ΔG = 2ē_r]`.
    pub fn zone(&self) -> (StateUncertainty, f64) {
        let (e_r, e_v) = (self.e_r, self.e_v);
        let unknown = StateUncertainty {
            h: 2.0 * self.rn * e_r + e_r * e_r,
            hdot: 2.0 * (e_r * self.vn + self.rn * e_v + e_r * e_v),
        };
        let phi = 2.0 * (2.0 * self.vn * e_v + e_v * e_v)
            + self.acceleration_term(2.0 * self.rn, 2.0 * e_r);
        (unknown, phi)
    }

    /// Tangential speed `h_t = c_t‖r‖ − ‖v_⊥‖²` (in the inertially fixed F_R, whose
    /// velocity error — the CoM's inertial one — is at most the F_H bound `ē_v` these
    /// unknowns carry), `ḣ_t = c_t s + 2sq/‖r‖ − 2v_⊥ᵀa` (`s = r̂ᵀv`,
    /// `q = ‖v_⊥‖²`, `a` = tide + force): `(δh_t, δḣ_t)` from the errors of `s`, `q`,
    /// `1/‖r‖` and `v_⊥` term by term (`|Δ(xy)| ≤ |Δx||y| + |x||Δy| + |Δx||Δy|`).
    pub fn tangential(&self, c_t: f64, n: f64, m: &InertialMotion) -> (f64, f64) {
        let (speed, along, v_perp, tide) = (m.speed, m.along, m.v_perp, m.tide);
        if self.rho.is_nan() || self.rho <= 0.0 {
            return (f64::INFINITY, f64::INFINITY);
        }
        let e_v = self.e_v;
        let d_perp = e_v + 2.0 * self.chord * (speed + e_v);
        let d_q = 2.0 * v_perp * d_perp + d_perp * d_perp;
        let d_s = self.chord * (speed + e_v) + e_v;
        let q = v_perp * v_perp;
        let dh = c_t * self.e_r + d_q;
        let s = along.abs();
        let inv_r = self.e_r / (self.rho * self.rn);
        let curvature =
            2.0 * ((s + d_s) * (q + d_q) * inv_r + (d_s * (q + d_q) + s * d_q) / self.rn);
        let d_tide = 2.0 * n * n * self.e_r;
        let tidal = 2.0 * (d_perp * (tide + d_tide) + v_perp * d_tide);
        let force =
            2.0 * self.force.k_hi * self.force_acc * (d_perp + v_perp * self.force.turn_rad);
        (dh, c_t * d_s + curvature + tidal + force)
    }
}

/// The estimate's motion in the inertially fixed F_R, as the tangential-speed limit sees
/// it.
#[derive(Debug, Clone, Copy)]
pub struct InertialMotion {
    /// `‖v‖`, `r̂ᵀv`, `‖v_⊥‖` [m/s].
    pub speed: f64,
    pub along: f64,
    pub v_perp: f64,
    /// `‖a_tide‖` [m/s²].
    pub tide: f64,
}

/// Nothing is known (the CoM's error reaches the target's centre): no row can be built,
/// and the filter refuses the state (`INVALID_STATE`, no force).
fn unbounded() -> (StateUncertainty, f64) {
    (
        StateUncertainty {
            h: f64::INFINITY,
            hdot: f64::INFINITY,
        },
        f64::INFINITY,
    )
}

/// Step of the range grid of [`wall_uncertifiable_below`] [m].
pub const WALL_RANGE_STEP_M: f64 = 0.05;
/// Most grid points [`wall_uncertifiable_below`] evaluates (200 m at 0.05 m).
pub const WALL_RANGE_MAX_STEPS: usize = 4000;

/// Where the declared errors leave the translational rows without a certified command:
/// the largest range [m] on a grid of [`WALL_RANGE_STEP_M`] from `R_CAZ` to the servicer's
/// initial distance (at most [`WALL_RANGE_MAX_STEPS`] points) at which the filter's own rows are infeasible for a servicer on the
/// corridor's wall, at rest towards it (`ḣ = 0`) and moving across the line of sight at
/// the tangential-speed limit, with the CoM's error bound of the initial arm
/// configuration — there the filter keeps only a share of the margins (docs/SAFETY.md,
/// "Translational: what the declared errors cost"). `None`: certified at every range of
/// the grid, or nothing declared.
pub fn wall_uncertifiable_below(s: &sc_scenario::Scenario, robot: &Robot) -> Option<f64> {
    use crate::translational::{TranslationalFilter, TranslationalInput, TranslationalParams};
    let params = TranslationalParams::from_model(s, robot);
    let errors = params.errors.clone()?;
    let (cos_psi, n) = (params.cos_psi, params.mean_motion);
    let c_t = crate::translational::tangential_coefficient(&params).max(0.0);
    let d = params.axis_r;
    let mut filter = TranslationalFilter::new(params.clone());
    let theta = sc_multibody::Vector7::from(s.servicer.initial_theta_rad);
    let zero = sc_multibody::Vector7::zeros();
    let com_error = errors
        .com
        .com_error(robot, &theta, &zero, &Vector3::zeros());
    // a unit vector across the axis, and the wall's direction at half-angle ψ
    let across = d
        .cross(&Vector3::z())
        .try_normalize(1e-9)
        .unwrap_or_else(|| d.cross(&Vector3::x()).normalize());
    let sin_psi = (1.0 - cos_psi * cos_psi).max(0.0).sqrt();
    let wall = d * cos_psi + across * sin_psi;
    let sideways = d.cross(&across).normalize();
    let q_hr = s.reference_frame.attitude_in_hill;
    let r_hr = sc_models::quat::to_matrix(&q_hr);
    let far = Vector3::from(s.servicer.initial_position_m)
        .norm()
        .max(params.r_caz);
    let steps =
        (((far - params.r_caz) / WALL_RANGE_STEP_M).floor() as usize).min(WALL_RANGE_MAX_STEPS);
    (0..=steps)
        .map(|i| params.r_caz + i as f64 * WALL_RANGE_STEP_M)
        .filter(|&range| {
            let r_r = wall * range;
            // at the tangential-speed limit and inside the line-of-sight contract (the
            // line of sight to the target's centre here: `|e_kᵀv| ≤ w L`)
            let v_r = sideways * (c_t * range).sqrt().min(params.los_speed_budget * range);
            let r_h = r_hr * r_r;
            let w = Vector3::new(0.0, 0.0, n);
            let mut x = TranslationalInput::circular(
                r_h,
                r_hr * v_r - w.cross(&r_h),
                q_hr,
                n,
                sc_models::quat::IDENTITY,
            );
            x.com_error = com_error;
            // relaxed, degraded, refused or braked without a solver: not certified
            let r = filter.backup(&x).report;
            !crate::common::certified(&r)
        })
        .last()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_draws::{ball, lcg};
    use crate::translational::{
        approach_corridor, collision_avoidance_zone, corridor_axis, cw_drift,
    };
    use nalgebra::Matrix3;

    /// Servicer mass [kg], mean motion [rad/s] and force bound [N] of the draws, and a
    /// force error of about `realistic`'s size.
    const MASS: f64 = 269.0;
    const N_ORBIT: f64 = 1.1e-3;
    const F_MAX: f64 = 7.0;
    const FORCE: ForceError = ForceError {
        k_lo: 0.88,
        k_hi: 1.14,
        turn_rad: 0.0052,
    };

    /// A command in the box, a scale in `[k_lo, k_hi]` and the force the plant receives.
    fn delivered(seed: &mut u64) -> (Vector3<f64>, f64, Vector3<f64>) {
        let f = Vector3::from_fn(|_, _| F_MAX * (2.0 * lcg(seed) - 1.0));
        let k = FORCE.k_lo + (FORCE.k_hi - FORCE.k_lo) * lcg(seed);
        let f_true = nalgebra::Rotation3::new(ball(seed, FORCE.turn_rad)) * f * k;
        (f, k, f_true)
    }

    /// The corridor's and the zone's true `h`, `ḣ`, `ḧ` (true state, scaled and turned
    /// force) against the estimate's, for errors at random points of their bounds.
    #[test]
    fn true_barrier_terms_stay_within_the_unknowns() {
        let seed = &mut 9u64;
        let (mass, n, cos_psi, force) = (MASS, N_ORBIT, 5f64.to_radians().cos(), FORCE);
        let f_acc = 3f64.sqrt() * F_MAX / mass;
        let axis = corridor_axis(
            &Matrix3::identity(),
            &Vector3::new(-1.0, 0.0, 0.0),
            &Vector3::new(0.0, 0.0, n),
            &Vector3::zeros(),
        );
        for _ in 0..20000 {
            let rn = 1.6 + 10.0 * lcg(seed);
            let r = (Vector3::new(-1.0, 0.0, 0.0) + ball(seed, 0.1)).normalize() * rn;
            let v = ball(seed, 0.2);
            let err = (0.1 * lcg(seed), 0.01 * lcg(seed));
            let (er, ev) = (ball(seed, err.0), ball(seed, err.1));
            let (rt, vt) = (r + er, v + ev);
            let (f, k, f_true) = delivered(seed);
            let a0 = cw_drift(n, &r, &v);
            let at = cw_drift(n, &rt, &vt);
            let u = Unknowns::new(&r, &v, err, &a0, n, f_acc, force);
            let est = [
                approach_corridor(&r, &v, &axis, &a0, mass, cos_psi),
                collision_avoidance_zone(&r, &v, &a0, mass, 1.6),
            ];
            let tru = [
                approach_corridor(&rt, &vt, &axis, &at, mass, cos_psi),
                collision_avoidance_zone(&rt, &vt, &at, mass, 1.6),
            ];
            let rhat = r / rn;
            let v_perp = (v - rhat * rhat.dot(&v)).norm();
            let g = (axis.d - rhat * cos_psi).norm();
            let rates = (axis.d_dot.norm(), axis.d_ddot.norm());
            let bounds = [
                u.corridor(g, cos_psi, rates, rhat.dot(&v), v_perp),
                u.zone(),
            ];
            for ((e, t), (unk, dphi)) in est.iter().zip(&tru).zip(&bounds) {
                assert!((t.h - e.h).abs() <= unk.h * (1.0 + 1e-9) + 1e-15);
                assert!((t.hdot - e.hdot).abs() <= unk.hdot * (1.0 + 1e-9) + 1e-15);
                // the truth's ḧ under the delivered force against the estimate's under k f
                let phi_true = t.hddot_drift + t.hddot_u.dot(&f_true);
                let diff = phi_true - (e.hddot_drift + k * e.hddot_u.dot(&f));
                assert!(diff.abs() <= dphi * (1.0 + 1e-9) + 1e-15, "{diff} > {dphi}");
            }
        }
    }

    /// The tangential-speed term's true `h_t`, `ḣ_t` against the estimate's, in F_R.
    #[test]
    fn true_tangential_terms_stay_within_the_unknowns() {
        let seed = &mut 21u64;
        let (mass, n, c_t, force) = (MASS, N_ORBIT, 6.4e-4, FORCE);
        let f_acc = 3f64.sqrt() * F_MAX / mass;
        let radial = Vector3::new(0.3, -0.2, 0.9).normalize();
        let tide_of = |r: &Vector3<f64>| (radial * (3.0 * radial.dot(r)) - r) * (n * n);
        for _ in 0..20000 {
            let rn = 1.6 + 10.0 * lcg(seed);
            let r = ball(seed, 1.0).normalize() * rn;
            let v = ball(seed, 0.2);
            let err = (0.1 * lcg(seed), 0.01 * lcg(seed));
            let (er, ev) = (ball(seed, err.0), ball(seed, err.1));
            let (rt, vt) = (r + er, v + ev);
            let (f, k, f_true) = delivered(seed);
            let (tide, tide_t) = (tide_of(&r), tide_of(&rt));
            let eye = Matrix3::identity();
            let e = crate::translational::tangential_speed(&r, &v, &tide, &eye, mass, c_t);
            let t = crate::translational::tangential_speed(&rt, &vt, &tide_t, &eye, mass, c_t);
            let a0 = Vector3::zeros();
            let u = Unknowns::new(&r, &v, err, &a0, n, f_acc, force);
            let rhat = r / rn;
            let along = rhat.dot(&v);
            let v_perp = (v - rhat * along).norm();
            let motion = InertialMotion {
                speed: v.norm(),
                along,
                v_perp,
                tide: tide.norm(),
            };
            let (dh, dd) = u.tangential(c_t, n, &motion);
            assert!(
                (t.h - e.h).abs() <= dh * (1.0 + 1e-9) + 1e-15,
                "{} > {dh}",
                (t.h - e.h).abs()
            );
            let diff =
                (t.hdot_drift + t.hdot_u.dot(&f_true)) - (e.hdot_drift + k * e.hdot_u.dot(&f));
            assert!(diff.abs() <= dd * (1.0 + 1e-9) + 1e-15, "{diff} > {dd}");
        }
    }

    /// Under `realistic` the wall is not certifiable (docs/SAFETY.md: the CoM's knowledge
    /// and the mass's error take more than the corridor's braking budget); with the
    /// thrusters' errors alone it is, at every range; with nothing declared the question
    /// does not arise.
    #[test]
    fn the_uncertifiable_wall_range_is_reported_for_realistic() {
        let path = std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../config/scenario.toml"
        ));
        let mut s = sc_scenario::Scenario::load(path).expect("scenario");
        let robot = Robot::from_urdf_file(&s.urdf_path()).expect("urdf");
        assert_eq!(wall_uncertifiable_below(&s, &robot), None);
        let realistic = Uncertainty::profile("realistic", path).expect("profile");
        let declare = |s: &mut sc_scenario::Scenario, u: Uncertainty| {
            s.set_uncertainty(sc_scenario::UncertaintySpec {
                profile: "exact".into(),
                seed: 0,
                model: Some(u.model),
                actuators: Some(u.actuators),
                navigation: Some(u.navigation),
                truth: None,
            })
            .expect("declared");
        };
        declare(&mut s, realistic);
        let below = wall_uncertifiable_below(&s, &robot).expect("realistic: not certifiable");
        assert!(below > s.safety.translational.caz_radius_m, "{below}");
        let thrusters = Uncertainty {
            actuators: realistic.actuators,
            ..Uncertainty::default()
        };
        declare(&mut s, thrusters);
        assert_eq!(wall_uncertifiable_below(&s, &robot), None);
    }

    #[test]
    fn the_scaled_offset_holds_for_every_scale() {
        let f = ForceError {
            k_lo: 0.9,
            k_hi: 1.1,
            turn_rad: 0.0,
        };
        for c in [-1.0, -0.1, 0.0, 0.3] {
            let c_k = f.scaled_offset(c);
            // the least b·f the scaled row admits, times every k, still meets b·f + c ≥ 0
            for k in [0.9, 1.0, 1.1] {
                assert!(k * (-c_k) + c >= -1e-15, "c {c} k {k}");
            }
        }
        assert_eq!(ForceError::NONE.scaled_offset(-0.3), -0.3);
    }
}
