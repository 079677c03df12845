//! Loading a scenario and its servicer model, with the cross-checks between the two.

use sc_multibody::Robot;
use sc_scenario::{Scenario, ScenarioError};
use std::path::Path;
use std::sync::Arc;

/// Why a mission could not be set up. One line each, naming the problem.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    /// (transparent: the scenario's message is printed once, not again as the source)
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error("{path}: {message}")]
    Urdf { path: String, message: String },
    #[error("`{key}` = {value}: {rule}")]
    Inconsistent {
        key: String,
        value: String,
        rule: String,
    },
    #[error("{0}")]
    Other(String),
}

/// A validated scenario with its servicer model.
#[derive(Debug, Clone)]
pub struct Setup {
    pub scenario: Scenario,
    pub robot: Arc<Robot>,
}

impl Setup {
    /// Loads `path` and the URDF it names.
    pub fn load(path: &Path) -> Result<Self, SetupError> {
        Self::from_scenario(Scenario::load(path)?)
    }

    /// Loads the URDF of an already parsed scenario and cross-checks the two.
    pub fn from_scenario(scenario: Scenario) -> Result<Self, SetupError> {
        let urdf = scenario.urdf_path();
        let robot = Robot::from_urdf_file(&urdf).map_err(|e| SetupError::Urdf {
            path: urdf.display().to_string(),
            message: e.to_string(),
        })?;
        scenario.validate_with_servicer_mass(robot.total_mass())?;
        let rb = &scenario.safety.robotic;
        let (lower, upper, velocity, effort) = robot.joint_limit_arrays();
        for i in 0..sc_multibody::NJ {
            if rb.theta_min_rad[i] < lower[i] || rb.theta_max_rad[i] > upper[i] {
                return Err(SetupError::Inconsistent {
                    key: format!("safety.robotic.theta_min_rad/theta_max_rad[{i}]"),
                    value: format!("[{}, {}]", rb.theta_min_rad[i], rb.theta_max_rad[i]),
                    rule: format!(
                        "must lie inside the URDF joint limits [{}, {}]",
                        lower[i], upper[i]
                    ),
                });
            }
            if rb.theta_dot_max_rad_s[i] > velocity[i] {
                return Err(SetupError::Inconsistent {
                    key: format!("safety.robotic.theta_dot_max_rad_s[{i}]"),
                    value: rb.theta_dot_max_rad_s[i].to_string(),
                    rule: format!("must not exceed the URDF velocity limit {}", velocity[i]),
                });
            }
            if scenario.limits.joint_torque_max_nm > effort[i] {
                return Err(SetupError::Inconsistent {
                    key: "limits.joint_torque_max_nm".into(),
                    value: scenario.limits.joint_torque_max_nm.to_string(),
                    rule: format!(
                        "must not exceed the URDF effort limit {} of joint {}",
                        effort[i],
                        i + 1
                    ),
                });
            }
        }
        check_target_geometry(&scenario, &robot)?;
        Ok(Self {
            scenario,
            robot: Arc::new(robot),
        })
    }

    /// Refuses a bound a filter's certificate rests on that the servicer model exceeds at
    /// a state of the certified envelope (a witness of `sc_cbf::envelope::witnesses`'
    /// targeted search, 0.07 s): not a bound (docs/SAFETY.md, "The envelope bounds"). Every
    /// ground command runs it before anything starts (`path`: the scenario file, for the
    /// command that reproduces the witness); the flight processes trust the launcher's.
    pub fn check_envelope_bounds(&self, path: &Path) -> Result<(), SetupError> {
        use sc_cbf::envelope::{SAFETY_FACTOR, WITNESS_ROUNDS, WITNESS_SAMPLES, WITNESS_SEED};
        let w = sc_cbf::envelope::witnesses(&self.scenario, &self.robot);
        let reproduce = format!(
            "`safe-capture bounds --scenario {} --samples {WITNESS_SAMPLES} --search-rounds {WITNESS_ROUNDS} --seed {WITNESS_SEED}`",
            path.display()
        );
        if !w.evidence() {
            return Err(SetupError::Other(format!(
                "the envelope bounds cannot be checked: the servicer model could be evaluated at only {} of {} states of the certified envelope ({reproduce}); check the URDF and the limits",
                w.usable, w.samples
            )));
        }
        match w.refuted() {
            Some(c) => Err(SetupError::Inconsistent {
                key: c.key.clone(),
                value: c.configured.to_string(),
                rule: format!(
                    "not a bound — the servicer model reaches {:.4} at a state of the certified envelope (a targeted search, {reproduce}), and the filters' certificate rests on it; set it to at least {:.4} ({SAFETY_FACTOR}× that; docs/SAFETY.md, \"The envelope bounds\")",
                    c.sampled,
                    SAFETY_FACTOR * c.sampled
                ),
            }),
            None => Ok(()),
        }
    }

    /// What every ground command checks before a single run starts (`check`, `run`,
    /// `redteam`, `bench`, `launch`'s preflight): the envelope bounds
    /// ([`Self::check_envelope_bounds`]) and the start ([`Self::check_start`]).
    pub fn check_before_run(&self, path: &Path) -> Result<(), SetupError> {
        self.check_envelope_bounds(path)?;
        self.check_start()
    }

    /// Refuses a start outside the certified set (the scenario's initial state, the
    /// declared model's; a Monte Carlo draws its own starts): a barrier already negative,
    /// or — the filters' own test — a state where a filter's rows cannot all hold within
    /// its input bounds at t = 0 (e.g. moving towards a barrier too fast to brake, `H <
    /// 0`). From there the filters could only run the relaxed problem (docs/SAFETY.md,
    /// "What is outside the promise"); a run would end unsafe or time out with faults.
    pub fn check_start(&self) -> Result<(), SetupError> {
        let sim = sc_sim::Simulator::new(&self.scenario, self.robot.clone())
            .map_err(|e| SetupError::Other(e.to_string()))?;
        let monitor = sc_cbf::monitor::Monitor::from_scenario(&self.scenario, self.robot.clone());
        let o = sim.observe();
        let h = monitor.evaluate(&o.barrier_state());
        let Some((name, v)) = crate::constraint_names()
            .into_iter()
            .zip(h)
            .find(|(_, v)| v.is_nan() || *v < 0.0)
        else {
            return self.check_start_certified(&o);
        };
        let s = &self.scenario.servicer;
        let (key, value) = start_key(name, s);
        Err(SetupError::Inconsistent {
            key: key.into(),
            value,
            rule: format!(
                "the start is outside the certified set: the barrier `{name}` is {v:.4e} < 0 at t = 0 (docs/SAFETY.md, \"The certified set\"); start where every barrier holds"
            ),
        })
    }

    /// The filters at the start `o` (on their substitute nominals: whether the rows can
    /// all hold does not depend on the nominal): none on the relaxed problem or its
    /// fallback, or the first that is, named with the initial state it rests on. A
    /// translational step on degraded margins under a declared uncertainty is the
    /// documented degraded mode, not a refusal (`check` says so in its note).
    fn check_start_certified(&self, o: &sc_core::Observation) -> Result<(), SetupError> {
        let mut layer = sc_cbf::SafetyLayer::from_scenario(&self.scenario, self.robot.clone());
        let out = layer.step(o, &sc_cbf::Nominals::default(), sc_cbf::Actuation::Safe);
        let held = |status| {
            matches!(
                status,
                sc_cbf::FilterStatus::Solved | sc_cbf::FilterStatus::Skipped
            )
        };
        let s = &self.scenario.servicer;
        let verdicts = [
            (
                "translational",
                held(out.translational.report.status),
                "servicer.initial_position_m/initial_velocity_m_s",
                format!("{:?}/{:?}", s.initial_position_m, s.initial_velocity_m_s),
            ),
            (
                "attitude",
                held(out.attitude.report.status),
                "servicer.initial_position_m/initial_omega_rad_s",
                format!("{:?}/{:?}", s.initial_position_m, s.initial_omega_rad_s),
            ),
            (
                "robotic",
                held(out.robotic.report.status),
                "servicer.initial_theta_rad/initial_theta_dot_rad_s",
                format!("{:?}/{:?}", s.initial_theta_rad, s.initial_theta_dot_rad_s),
            ),
        ];
        match verdicts.into_iter().find(|v| !v.1) {
            None => Ok(()),
            Some((filter, _, key, value)) => Err(SetupError::Inconsistent {
                key: key.into(),
                value,
                rule: format!(
                    "the start is outside the certified set: at t = 0 the {filter} filter's rows cannot all hold within its input bounds (e.g. moving towards a barrier faster than it can brake; docs/SAFETY.md, \"The certified set\"); start slower or farther from the barriers"
                ),
            }),
        }
    }

    /// The target's geometry against the servicer ([`check_target_geometry`]) — run when
    /// the model is loaded and again by every command after `--uncertainty` declared
    /// other mass-property errors than the scenario file's.
    pub fn check_target_geometry(&self) -> Result<(), SetupError> {
        check_target_geometry(&self.scenario, &self.robot)
    }

    /// Total servicer mass [kg] (base + arm), the `m` of the CW model.
    pub fn mass(&self) -> f64 {
        self.robot.total_mass()
    }
}

/// The target's keep-out spheres against the servicer (docs/SAFETY.md, "The arm and the
/// target"): the grasping fixture stands off every sphere by at least what the gripper's
/// own spheres stick out beyond it ([`sc_cbf::arm_target::gripper_overhang`]) — or
/// capture itself would break an arm–target barrier — and the collision-avoidance zone keeps the base off the target
/// ([`sc_cbf::arm_target::base_clearance_from_caz`]) and the stowed arm too
/// ([`check_stowed_arm`]), for every plant the declared mass-property errors allow.
fn check_target_geometry(s: &Scenario, robot: &Robot) -> Result<(), SetupError> {
    use sc_cbf::arm_target::{
        TargetBody, base_clearance_from_caz, base_com_offset_bound, gripper_overhang,
    };
    let overhang = gripper_overhang(robot);
    for (k, sp) in s.target.collision_spheres.iter().enumerate() {
        let standoff = sp.standoff_m(&s.target.grasp_point_m);
        if standoff < overhang {
            return Err(SetupError::Inconsistent {
                key: format!("target.collision_spheres[{k}]"),
                value: format!("centre {:?}, radius {} m", sp.center_m, sp.radius_m),
                rule: format!(
                    "the grasping fixture stands {standoff:.3} m off it, the gripper's spheres stick out {overhang:.3} m beyond the grasping point: capture would break an arm–target barrier; move the fixture out or shrink the sphere"
                ),
            });
        }
    }
    let model = s.uncertainty_bounds().model;
    let (Some(delta), Some(base)) = (base_com_offset_bound(robot, &model), robot.base_sphere())
    else {
        return Err(SetupError::Other(
            "the base cannot be shown off the target: the servicer model has no base collision sphere, or the declared mass errors leave it no mass".into(),
        ));
    };
    let target = TargetBody::from_scenario(s).bounding_radius();
    let r_caz = s.safety.translational.caz_radius_m;
    let clear = base_clearance_from_caz(r_caz, delta, base.radius, target);
    // NaN is no clearance
    if clear.is_nan() || clear < 0.0 {
        return Err(zone_too_small(
            r_caz,
            format!(
                "too small to keep the base off the target: the base's zone ({:.3} m), the target's keep-out spheres ({target:.3} m from its CoM) and the system CoM's offset from the base's centre (up to {delta:.3} m) need at least {:.3} m",
                base.radius,
                r_caz - clear
            ),
        ));
    }
    check_stowed_arm(s, robot, &model, target)
}

/// The refusal of a collision-avoidance zone too small for `rule`.
fn zone_too_small(r_caz: f64, rule: String) -> SetupError {
    SetupError::Inconsistent {
        key: "safety.translational.caz_radius_m".into(),
        value: r_caz.to_string(),
        rule,
    }
}

/// The stowed arm (`servicer.initial_theta_rad`, where the `hold` nominal keeps it) clears
/// the target from anywhere outside the collision-avoidance zone, whatever the base's and
/// the target's attitudes ([`sc_cbf::arm_target::arm_clearance_from_caz`]), for every plant
/// the declared mass-property errors allow: the arm has a safe state against the target at
/// the zone's edge. Without it a base turning at the zone's edge can sweep even a folded
/// arm into the target, with its joints on their limits (docs/SAFETY.md, "The arm and the
/// target").
fn check_stowed_arm(
    s: &Scenario,
    robot: &Robot,
    model: &sc_scenario::uncertainty::ModelBounds,
    r_target: f64,
) -> Result<(), SetupError> {
    use sc_cbf::arm_target::{arm_clearance_from_caz, arm_reach_bound};
    let stowed = sc_multibody::Vector7::from(s.servicer.initial_theta_rad);
    let Some(reach) = arm_reach_bound(robot, &stowed, model) else {
        return Err(SetupError::Other(
            "the stowed arm cannot be shown off the target: the servicer model has no arm sphere, a sphere's reach at `servicer.initial_theta_rad` is not finite, or the declared mass errors leave it no mass".into(),
        ));
    };
    let r_caz = s.safety.translational.caz_radius_m;
    let clear = arm_clearance_from_caz(r_caz, reach, r_target);
    // NaN is no clearance
    if clear.is_nan() || clear < 0.0 {
        return Err(zone_too_small(
            r_caz,
            format!(
                "too small for the stowed arm to clear the target at the zone's edge: the arm at `servicer.initial_theta_rad` reaches {reach:.3} m from the system CoM (the declared mass errors' CoM shift included) and the target's keep-out spheres {r_target:.3} m from its CoM, so the zone needs at least {:.3} m — or a base turning at its edge can sweep the arm into the target",
                r_caz - clear
            ),
        ));
    }
    Ok(())
}

/// The scenario key of the initial state a barrier depends on, and its value.
fn start_key(barrier: &str, s: &sc_scenario::Servicer) -> (&'static str, String) {
    if barrier.starts_with("link_target") || barrier == "base_target" {
        (
            "servicer.initial_position_m/initial_theta_rad",
            format!("{:?}/{:?}", s.initial_position_m, s.initial_theta_rad),
        )
    } else if barrier.starts_with("theta_dot") {
        (
            "servicer.initial_theta_dot_rad_s",
            format!("{:?}", s.initial_theta_dot_rad_s),
        )
    } else if barrier.starts_with("theta_") || barrier.starts_with("link_base") {
        (
            "servicer.initial_theta_rad",
            format!("{:?}", s.initial_theta_rad),
        )
    } else if barrier.starts_with("omega_") {
        (
            "servicer.initial_omega_rad_s",
            format!("{:?}", s.initial_omega_rad_s),
        )
    } else {
        // the corridor, the zone and the line of sight: where the servicer starts
        (
            "servicer.initial_position_m",
            format!("{:?}", s.initial_position_m),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rules that need the servicer's mass are checked when its model is loaded: a
    /// corridor budget above the braking authority at the wall (tangential coefficient
    /// `c_t ≤ 0`) is refused, on one line naming the key.
    #[test]
    fn a_corridor_budget_above_the_walls_authority_is_refused_with_the_model() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml");
        let setup = Setup::load(&path).expect("the default loads");
        let mut s = setup.scenario;
        s.safety.translational.u_max_ac_m_s2 = 0.01;
        let msg = Setup::from_scenario(s).expect_err("refused").to_string();
        assert!(!msg.contains('\n'), "{msg}");
        assert!(
            msg.starts_with("`safety.translational.u_max_ac_m_s2` = 0.01: ") && msg.contains("c_t"),
            "{msg}"
        );
    }

    /// The target's geometry against the servicer: a fixture the gripper's own spheres
    /// cannot reach without touching a keep-out sphere, and a collision-avoidance zone too
    /// small to keep the base, or the stowed arm, off the target, are refused on one line
    /// naming the key; the default keeps all three with room (its numbers below are the
    /// model's).
    #[test]
    fn a_target_geometry_the_servicer_cannot_respect_is_refused() {
        use sc_cbf::arm_target::{TargetBody, base_com_offset_bound, gripper_overhang};
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml");
        let setup = Setup::load(&path).expect("the default loads");
        // link 7's last sphere (radius 0.06) 0.02 m short of the end effector
        assert!((gripper_overhang(&setup.robot) - 0.04).abs() < 1e-12);
        let model = setup.scenario.uncertainty_bounds().model;
        let delta = base_com_offset_bound(&setup.robot, &model).unwrap();
        // the numbers docs/SAFETY.md quotes ("The base: derived")
        assert!((delta - 0.1004).abs() < 1e-4, "{delta}");
        let refused = |s: sc_scenario::Scenario, key: &str| {
            let msg = Setup::from_scenario(s).expect_err("refused").to_string();
            assert!(!msg.contains('\n'), "{msg}");
            assert!(msg.starts_with(&format!("`{key}`")), "{msg}");
            msg
        };
        // the fixture (0.652 m from the CoM) 0.03 m off a 0.622 m sphere: refused
        let mut s = setup.scenario.clone();
        s.target.collision_spheres[0].radius_m = 0.622;
        let msg = refused(s.clone(), "target.collision_spheres[0]");
        assert!(msg.contains("stick out 0.040 m"), "{msg}");
        // 0.05 m off: accepted (with a zone that leaves the stowed arm room from the
        // larger sphere: 1.353 + 0.602 m)
        s.target.collision_spheres[0].radius_m = 0.602;
        s.safety.translational.caz_radius_m = 1.96;
        Setup::from_scenario(s).expect("0.05 m off the sphere is accepted");
        // a zone that leaves the base's sphere (0.6 m) and the target's (0.45 m) no room
        let mut s = setup.scenario.clone();
        s.safety.translational.caz_radius_m = 1.05 + delta - 1e-3;
        let msg = refused(s.clone(), "safety.translational.caz_radius_m");
        assert!(msg.contains("keep the base off the target"), "{msg}");
        // room for the base, none for the stowed arm (it reaches 1.353 m from the CoM)
        s.safety.translational.caz_radius_m = 1.05 + delta + 1e-3;
        let msg = refused(s.clone(), "safety.translational.caz_radius_m");
        assert!(
            msg.contains("stowed arm to clear the target") && msg.contains("at least 1.803 m"),
            "{msg}"
        );
        s.safety.translational.caz_radius_m = 1.81;
        let mut exact = Setup::from_scenario(s).expect("room for the stowed arm is accepted");
        // mass errors declared afterwards (`--uncertainty`) widen the CoM's offset: the
        // check after declaring them refuses what the exact model left room for
        let spec =
            sc_scenario::UncertaintySpec::profile(sc_scenario::uncertainty::REALISTIC_NAME, 3);
        exact.scenario.set_uncertainty(spec).unwrap();
        let real = base_com_offset_bound(&exact.robot, &exact.scenario.uncertainty_bounds().model);
        let real = real.unwrap();
        assert!((real - 0.1579).abs() < 1e-4, "{real} vs {delta}");
        let msg = exact
            .check_target_geometry()
            .expect_err("refused")
            .to_string();
        assert!(
            msg.starts_with("`safety.translational.caz_radius_m`")
                && msg.contains("at least 1.849 m"),
            "{msg}"
        );
        // and the base's own rule under them, just short of its room (the base's zone and
        // the target's sphere plus the realistic δ)
        let base = exact.robot.base_sphere().unwrap().radius;
        let target = TargetBody::from_scenario(&exact.scenario).bounding_radius();
        exact.scenario.safety.translational.caz_radius_m = base + target + real - 1e-3;
        let msg = exact
            .check_target_geometry()
            .expect_err("refused")
            .to_string();
        assert!(msg.contains("keep the base off the target"), "{msg}");
    }
}
