//! The arm and the base kept off the target's body (issue #26 item 5; beyond the paper,
//! whose robotic barriers cover only the arm against its own base).
//!
//! The target's body is covered by keep-out spheres fixed in F_T
//! (`target.collision_spheres`: centre `c_k,T`, radius `ρ_k`); the grasping fixture stands
//! off them, so the gripper reaching the fixture needs no exception. Per arm sphere `i`
//! (centre `p_i` in F_B, radius `ρ_i`) and for the base's collision zone (`c_B`, `R_B`),
//! with the base origin `r_B` and the attitudes `R_RB`, `R_RT` in F_R:
//!
//! ```text
//! h_i = min_k ‖r_B + R_RB p_i − R_RT c_k,T‖² − (ρ_i + ρ_k)²        [m²]
//! ```
//!
//! — the nearest keep-out sphere's clearance, in the link–base barriers' form
//! (`link_target_<link>_<k>`, `base_target`).
//!
//! The arm's spheres are kept off by the robotic filter's rows (`link_target_*`,
//! [`crate::link_target`]); the base's zone (`base_target`) follows from the
//! collision-avoidance zone where `R_CAZ` is large enough ([`base_clearance_from_caz`],
//! checked before every run), and the safety monitor evaluates all of them from the true
//! state at every physics step.

use nalgebra::{Matrix3, Vector3};
use sc_multibody::{Robot, Vector7};
use sc_scenario::TargetSphere;
use sc_scenario::uncertainty::ModelBounds;

/// The barriers only the monitor evaluates: the base's zone against the target (the
/// arm's spheres are the robotic filter's `link_target_*` rows, [`crate::link_target`]).
pub const N: usize = 1;

/// Names in report order.
pub const NAMES: [&str; N] = ["base_target"];

/// Sharpness `κ` of the smooth minimum over keep-out spheres [1/m²]: it lowers the row's
/// barrier below the nearest sphere's by at most `ln(K)/κ` (K spheres).
pub const KEEP_OUT_SHARPNESS_PER_M2: f64 = 200.0;

/// The target's keep-out spheres (F_T).
#[derive(Debug, Clone, PartialEq)]
pub struct TargetBody {
    spheres: Vec<TargetSphere>,
    sharpness: f64,
}

impl TargetBody {
    /// From the scenario's `target.collision_spheres` (validated: at least one, finite,
    /// radii > 0).
    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        Self {
            spheres: s.target.collision_spheres.clone(),
            sharpness: KEEP_OUT_SHARPNESS_PER_M2,
        }
    }

    /// Keep-out spheres with the smooth minimum's sharpness `κ` [1/m²] (tests; a
    /// scenario's body comes from [`Self::from_scenario`]).
    pub fn new(spheres: Vec<TargetSphere>, sharpness: f64) -> Self {
        Self { spheres, sharpness }
    }

    /// `κ` [1/m²] of the robotic rows' smooth minimum over the spheres
    /// ([`crate::link_target`]).
    pub fn sharpness(&self) -> f64 {
        self.sharpness
    }

    /// The keep-out spheres (F_T).
    pub fn spheres(&self) -> &[TargetSphere] {
        &self.spheres
    }

    /// The clearance `min_k ‖p − c_k‖² − (ρ + ρ_k)²` [m²] of a sphere at `p` (F_R,
    /// relative to the target's CoM) with radius `rho`, the target at attitude `r_rt`.
    /// NaN when anything is not finite (every consumer counts NaN as a violation); `+∞`
    /// without keep-out spheres.
    pub fn clearance(&self, p: &Vector3<f64>, rho: f64, r_rt: &Matrix3<f64>) -> f64 {
        let mut h = f64::INFINITY;
        for sp in &self.spheres {
            let d = p - r_rt * Vector3::from(sp.center_m);
            let rr = rho + sp.radius_m;
            let v = d.dot(&d) - rr * rr;
            if !v.is_finite() {
                return f64::NAN;
            }
            h = h.min(v);
        }
        h
    }

    /// The largest distance of any keep-out sphere's surface from the target's CoM [m]:
    /// the target's bounding radius.
    pub fn bounding_radius(&self) -> f64 {
        self.spheres
            .iter()
            .map(|sp| Vector3::from(sp.center_m).norm() + sp.radius_m)
            .fold(0.0, f64::max)
    }
}

/// How far the end effector's own body sticks out beyond the grasping point at the
/// least [m]: the largest `ρ_i − ‖c_i − p_EE‖` over the collision spheres on the body
/// that carries the end effector (fixed in that body, so the same at every joint state),
/// i.e. with the gripper turned the best way, straight away from the target. A fixture
/// standing less than this off a keep-out sphere cannot be grasped without breaking an
/// arm–target barrier, whatever the approach (a necessary condition: how the gripper
/// approaches decides the rest, and the monitor measures it). `−∞` when that body has no
/// sphere.
pub fn gripper_overhang(robot: &Robot) -> f64 {
    let kin = robot.kinematics(&Vector7::zeros());
    let ee = robot.ee_position(&kin);
    let body = robot.ee_frame().body;
    robot
        .arm_spheres()
        .filter(|(_, sp)| sp.link == body)
        .filter_map(|(idx, _)| robot.sphere_state(&kin, idx))
        .map(|sp| sp.radius - (sp.center - ee).norm())
        .fold(f64::NEG_INFINITY, f64::max)
}

/// A bound over every joint state and every plant inside the declared mass-property
/// errors on the distance of the base's collision-zone centre `c_B` from the servicer's
/// system CoM [m]: `‖c_B − c_com‖ ≤ Σ_k m_k ‖c_B − c_k‖ / m` with each body's bound
/// ([`Robot::body_com_distance_bounds`]), the masses at their declared extremes (the
/// numerator's largest, the total's smallest) and the base's CoM moved by its declared
/// shift. `None` without a base sphere.
pub fn base_com_offset_bound(robot: &Robot, model: &ModelBounds) -> Option<f64> {
    let base = robot.base_sphere()?;
    let b = robot.body_com_distance_bounds(&base.center);
    let m_base = robot.body_mass(0);
    let up_base = m_base * (1.0 + model.servicer_mass_rel) * (b[0] + model.servicer_com_m);
    let up_arm: f64 = (1..b.len())
        .map(|k| robot.body_mass(k) * (1.0 + model.link_mass_rel) * b[k])
        .sum();
    let low_total = m_base * (1.0 - model.servicer_mass_rel)
        + (1..b.len())
            .map(|k| robot.body_mass(k) * (1.0 - model.link_mass_rel))
            .sum::<f64>();
    (low_total > 0.0).then(|| (up_base + up_arm) / low_total)
}

/// What the collision-avoidance zone proves about the base's barrier: the base's collision
/// zone (radius `R_B`) stays off every keep-out sphere (inside the target's bounding
/// sphere, radius `R_T`, [`TargetBody::bounding_radius`]) whenever `‖r_com‖ ≥ R_CAZ`, if
/// `R_CAZ − δ ≥ R_B + R_T` ([`base_com_offset_bound`] `δ`). Returns that clearance
/// `R_CAZ − δ − R_B − R_T` [m] (≥ 0: `base_target` follows from the zone's barrier).
pub fn base_clearance_from_caz(r_caz: f64, delta: f64, r_base: f64, r_target: f64) -> f64 {
    r_caz - delta - r_base - r_target
}

/// How far the arm reaches from the system CoM at the joint state `theta` [m], for every
/// plant inside the declared mass-property errors: `max_i ‖p_i − c‖ + ρ_i` over the arm's
/// spheres, with the model's CoM `c`, plus the bound on the plant's CoM's offset from it
/// ([`Robot::com_shift_bound`]). `None` without an arm sphere, when a sphere's reach is
/// not finite, or when the declared errors leave the servicer no mass.
pub fn arm_reach_bound(robot: &Robot, theta: &Vector7, model: &ModelBounds) -> Option<f64> {
    let kin = robot.kinematics(theta);
    let com = robot.center_of_mass(theta);
    let mut reach: Option<f64> = None;
    for (idx, _) in robot.arm_spheres() {
        let sp = robot.sphere_state(&kin, idx)?;
        let r = (sp.center - com).norm() + sp.radius;
        if !r.is_finite() {
            return None;
        }
        reach = Some(reach.map_or(r, |m| m.max(r)));
    }
    let reach = reach?;
    let shift = robot.com_shift_bound(
        theta,
        model.servicer_mass_rel,
        model.servicer_com_m,
        model.link_mass_rel,
    )?;
    Some(reach + shift)
}

/// What the collision-avoidance zone proves about an arm held at a joint state of reach
/// `reach` ([`arm_reach_bound`]): every arm sphere `i` stays off every keep-out sphere `k`
/// whatever the base's and the target's attitudes, since
/// `‖d‖ − ρ_i − ρ_k ≥ ‖r_com‖ − (‖p_i − c‖ + ρ_i) − (‖c_k‖ + ρ_k) ≥ R_CAZ − reach − R_T`
/// whenever `‖r_com‖ ≥ R_CAZ` (the triangle inequality on
/// `d = r_com + R_RB (p_i − c) − R_RT c_k`). Returns that clearance [m] (≥ 0: the pose is a
/// safe state for the arm against the target from anywhere outside the zone).
pub fn arm_clearance_from_caz(r_caz: f64, reach: f64, r_target: f64) -> f64 {
    r_caz - reach - r_target
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_draws::{ball, lcg, plant};
    use sc_models::quat;

    fn default_scenario() -> (sc_scenario::Scenario, Robot) {
        let s = crate::test_draws::default_scenario();
        let robot = Robot::from_urdf_file(&s.urdf_path()).unwrap();
        (s, robot)
    }

    fn realistic() -> ModelBounds {
        sc_scenario::uncertainty::Uncertainty::profile("realistic", std::path::Path::new("."))
            .expect("profile")
            .model
    }

    /// The arm's farthest sphere from a plant's own CoM, `max_i ‖p_i − c‖ + ρ_i` [m].
    fn reach_of(robot: &Robot, theta: &Vector7) -> f64 {
        let kin = robot.kinematics(theta);
        let com = robot.center_of_mass(theta);
        robot
            .arm_spheres()
            .filter_map(|(idx, _)| robot.sphere_state(&kin, idx))
            .map(|sp| (sp.center - com).norm() + sp.radius)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// For plants anywhere in the `realistic` mass-property box (corners half the time)
    /// and joint states over the arm's range, the reach from the plant's own CoM is within
    /// the bound the model gives; without mass errors the bound is the model's reach.
    #[test]
    fn the_reach_bound_covers_every_plant_in_the_declared_box() {
        let (s, robot) = default_scenario();
        let model = realistic();
        let (lo, hi, _, _) = robot.joint_limit_arrays();
        let stowed = Vector7::from(s.servicer.initial_theta_rad);
        let exact = arm_reach_bound(&robot, &stowed, &ModelBounds::default()).unwrap();
        assert_eq!(exact, reach_of(&robot, &stowed));
        let mut seed = 41u64;
        let (mut tightest, mut moved) = (f64::INFINITY, 0.0f64);
        for n in 0..400 {
            let p = plant(&mut seed, &robot, &model);
            let theta = if n % 4 == 0 {
                stowed
            } else {
                Vector7::from_fn(|i, _| lo[i] + (hi[i] - lo[i]) * lcg(&mut seed))
            };
            let bound = arm_reach_bound(&robot, &theta, &model).unwrap();
            let real = reach_of(&p, &theta);
            assert!(real <= bound, "{real} > {bound} at {theta:?}");
            tightest = tightest.min(bound - real);
            moved = moved.max(real - reach_of(&robot, &theta));
        }
        // the plants' CoM shift takes spheres beyond the model's reach: the shift's term
        // is needed, not decoration
        assert!(moved > 0.01, "{moved}");
        println!(
            "the reach bound's least slack over 400 plants: {tightest:.4} m; the plants reach up to {moved:.4} m beyond the model"
        );
    }

    /// The default zone leaves the stowed arm clear of the target whatever the attitudes
    /// and wherever the CoM is outside the zone, for every plant in the `realistic` box;
    /// with the CoM straight behind the farthest sphere the clearance is the bound's, so a
    /// zone a millimetre short of what `Setup` demands lets that sphere into the target.
    #[test]
    fn the_stowed_arm_clears_the_target_from_anywhere_outside_the_zone() {
        let (s, robot) = default_scenario();
        let model = realistic();
        let body = TargetBody::from_scenario(&s);
        let r_t = body.bounding_radius();
        let stowed = Vector7::from(s.servicer.initial_theta_rad);
        let r_caz = s.safety.translational.caz_radius_m;
        let reach = arm_reach_bound(&robot, &stowed, &model).unwrap();
        assert!(arm_clearance_from_caz(r_caz, reach, r_t) >= 0.0);
        let mut seed = 43u64;
        let attitude = |seed: &mut u64| {
            let q: quat::Quat = std::array::from_fn(|_| 2.0 * lcg(seed) - 1.0);
            quat::to_matrix(&quat::normalized(&q).unwrap())
        };
        for _ in 0..2000 {
            let p = plant(&mut seed, &robot, &model);
            let kin = p.kinematics(&stowed);
            let com = p.center_of_mass(&stowed);
            let (r_rb, r_rt) = (attitude(&mut seed), attitude(&mut seed));
            let r_c = ball(&mut seed, 1.0).normalize() * (r_caz + 0.3 * lcg(&mut seed));
            for (idx, _) in p.arm_spheres() {
                let sp = p.sphere_state(&kin, idx).unwrap();
                let h = body.clearance(&(r_c + r_rb * (sp.center - com)), sp.radius, &r_rt);
                assert!(h >= 0.0, "sphere {idx}: {h}");
            }
        }
        // the exact model, the farthest sphere turned straight at the target's one sphere,
        // at its centre (the default's: R_T is its radius)
        let kin = robot.kinematics(&stowed);
        let com = robot.center_of_mass(&stowed);
        let exact = reach_of(&robot, &stowed);
        let far = robot
            .arm_spheres()
            .filter_map(|(idx, _)| robot.sphere_state(&kin, idx))
            .find(|sp| (sp.center - com).norm() + sp.radius == exact)
            .unwrap();
        let q = far.center - com;
        let id = Matrix3::identity();
        for (r, inside) in [(exact + r_t + 1e-3, false), (exact + r_t - 1e-3, true)] {
            let r_c = -q.normalize() * r;
            let h = body.clearance(&(r_c + q), far.radius, &id);
            assert_eq!(h < 0.0, inside, "zone {r}: {h}");
        }
    }

    fn body() -> TargetBody {
        TargetBody {
            spheres: vec![
                TargetSphere {
                    center_m: [0.0, 0.0, 0.0],
                    radius_m: 0.5,
                },
                TargetSphere {
                    center_m: [0.0, 2.0, 0.0],
                    radius_m: 0.2,
                },
            ],
            sharpness: KEEP_OUT_SHARPNESS_PER_M2,
        }
    }

    /// The nearest sphere decides, in the target's attitude; NaN is never hidden.
    #[test]
    fn the_nearest_keep_out_sphere_decides() {
        let b = body();
        let id = Matrix3::identity();
        // 1 m out along x: 1 − (0.1 + 0.5)² from the bus, far from the panel
        let h = b.clearance(&Vector3::new(1.0, 0.0, 0.0), 0.1, &id);
        assert!((h - (1.0 - 0.36)).abs() < 1e-15, "{h}");
        // next to the second sphere
        let h = b.clearance(&Vector3::new(0.0, 2.3, 0.0), 0.05, &id);
        assert!((h - (0.09 - 0.0625)).abs() < 1e-15, "{h}");
        // the target turned by 90° about z: the second sphere now at −x
        let rz = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let h = b.clearance(&Vector3::new(-2.3, 0.0, 0.0), 0.05, &rz);
        assert!((h - (0.09 - 0.0625)).abs() < 1e-12, "{h}");
        // inside: negative
        assert!(b.clearance(&Vector3::new(0.3, 0.0, 0.0), 0.1, &id) < 0.0);
        assert!(
            b.clearance(&Vector3::new(f64::NAN, 0.0, 0.0), 0.1, &id)
                .is_nan()
        );
        assert!((b.bounding_radius() - 2.2).abs() < 1e-15);
    }
}
