//! The scenario as data: `config/scenario.toml` parsed with serde
//! (`deny_unknown_fields`) and validated with errors that name the key, the
//! value and the rule broken.
//!
//! Units are part of every key's name (`_m`, `_s`, `_deg`, `_rad_s`, `_n`,
//! `_nm`, `_kg`, …). Quaternions are scalar-first `[q0, q1, q2, q3]`.

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub mod envelope;
pub mod uncertainty;
mod validate;

pub use envelope::{FixtureBall, LineOfSightEnvelope, TumbleRule};
pub use uncertainty::{Uncertainty, UncertaintySpec};
pub use validate::{MAX_DECLARED_KEEP_OUT_SPHERES, MAX_KEEP_OUT_SPHERES, ScenarioError};

/// Three-vector as written in the file.
pub type V3 = [f64; 3];
/// Seven joint values (one per arm joint).
pub type J7 = [f64; 7];

/// The whole scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    pub orbit: Orbit,
    pub reference_frame: ReferenceFrame,
    pub servicer: Servicer,
    pub target: Target,
    pub mission: Mission,
    pub limits: Limits,
    pub safety: Safety,
    pub nominal: Nominal,
    /// The declared model, actuator and navigation errors (absent: the `exact` profile).
    /// Once loaded, its three sections hold the resolved bounds, so that the scenario
    /// written back (a Monte Carlo run's file) reproduces the run on its own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<UncertaintySpec>,
    /// What the world does that the mission does not declare (absent: nothing). Only the
    /// simulator reads it, as the truth; the controllers and filters never do — it tests
    /// that leaving the certified envelope during a run is detected (docs/SAFETY.md, "Safe
    /// mode").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world: Option<World>,
    /// Directory the scenario was loaded from; relative paths resolve against it.
    #[serde(skip)]
    pub base_dir: PathBuf,
}

/// Target orbit (circular) and the central body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Orbit {
    /// Gravitational parameter μ [m³/s²].
    pub earth_mu_m3_s2: f64,
    /// Equatorial radius [m].
    pub earth_radius_m: f64,
    /// Altitude of the circular target orbit [m].
    pub altitude_m: f64,
    pub inclination_deg: f64,
    pub raan_deg: f64,
    /// Argument of latitude of the target at t = 0 [deg].
    pub argument_of_latitude_deg: f64,
}

/// The reference frame `F_R`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceFrame {
    /// `q_HR` at t = 0: rotates F_R vectors into the Hill frame (unit, scalar-first).
    pub attitude_in_hill: [f64; 4],
}

/// The servicer: its URDF and its initial state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Servicer {
    /// URDF of base and arm, relative to the scenario file.
    pub urdf: PathBuf,
    /// Boresight `d_B`, unit vector in F_B.
    pub boresight_body: V3,
    /// Gripper axis `g_B`, unit vector in F_B normal to the boresight: in the
    /// synchronisation phase the nominal attitude controller turns it onto the grasping
    /// fixture's axis (`target.grasp_fixture_axis`). Absent: the roll about the boresight
    /// is left free.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gripper_axis_body: Option<V3>,
    /// Base origin relative to the target CoM, in F_R [m].
    pub initial_position_m: V3,
    /// Its time derivative in the non-rotating F_R [m/s].
    pub initial_velocity_m_s: V3,
    /// Base angular velocity ω_B in F_B [rad/s]; the initial attitude is F_R itself.
    pub initial_omega_rad_s: V3,
    pub initial_theta_rad: J7,
    pub initial_theta_dot_rad_s: J7,
}

/// The tumbling target (torque-free rigid body).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Target {
    pub mass_kg: f64,
    /// Inertia about the CoM in F_T [kg m²].
    pub inertia_kg_m2: [V3; 3],
    /// `q_RT` at t = 0 (unit, scalar-first).
    pub initial_attitude: [f64; 4],
    /// ω_T in F_T [rad/s].
    pub initial_omega_rad_s: V3,
    /// Grasping point `p_G,T` in F_T [m].
    pub grasp_point_m: V3,
    /// Axis of the grasping fixture (a bar), unit vector in F_T; see
    /// `servicer.gripper_axis_body`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grasp_fixture_axis: Option<V3>,
    /// The target's keep-out geometry: spheres fixed in F_T that cover its body (not the
    /// grasping fixture, which stands off it). The safety monitor keeps every arm sphere
    /// and the base's collision zone off them (docs/SAFETY.md, "The arm and the target").
    pub collision_spheres: Vec<TargetSphere>,
}

/// One keep-out sphere of the target, fixed in F_T.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetSphere {
    /// Centre in F_T, relative to the target's CoM [m].
    pub center_m: V3,
    /// Radius [m].
    pub radius_m: f64,
}

impl TargetSphere {
    /// How far the point `p` [m, F_T] stands off the sphere's surface [m] (negative
    /// inside): the grasping fixture's standoff from the body.
    pub fn standoff_m(&self, p: &V3) -> f64 {
        let d: f64 = (0..3)
            .map(|i| (p[i] - self.center_m[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        d - self.radius_m
    }
}

/// Timing and phases of the mission.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mission {
    /// Control period T_s of every subsystem in the in-process run [s].
    pub control_period_s: f64,
    /// RK4 step of the simulator [s]; must divide the control period.
    pub physics_step_s: f64,
    /// End of the run if no capture happened [s].
    pub duration_s: f64,
    /// End-effector distance to the grasping point that counts as capture [m].
    pub capture_tolerance_m: f64,
    /// Relative speed of end-effector and grasping point that counts as capture [m/s].
    pub capture_speed_tolerance_m_s: f64,
    /// Phases in order of their start times.
    pub phases: Vec<Phase>,
}

/// One mission phase and the nominal controller modes it activates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Phase {
    pub name: String,
    pub start_s: f64,
    pub translational: TranslationalMode,
    pub attitude: AttitudeMode,
    pub robotic: RoboticMode,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TranslationalMode {
    /// Unconstrained MPC towards the Go-for-Capture point.
    Approach,
    /// Zero force.
    Off,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AttitudeMode {
    /// Boresight at the grasping point.
    Point,
    /// Boresight at the grasping point and body rate synchronised with the target.
    PointAndSync,
    /// Zero torque.
    Off,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RoboticMode {
    /// PD towards the initial joint angles.
    Hold,
    /// PD computed torque towards the IK solution of the grasping point.
    Grasp,
    /// Zero joint torque.
    Off,
}

/// Actuator bounds, the input sets U of the paper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// ‖f_B‖∞ [N].
    pub force_max_n: f64,
    /// ‖τ_B‖∞ [N m].
    pub torque_max_nm: f64,
    /// ‖τ_M‖∞ [N m].
    pub joint_torque_max_nm: f64,
}

/// Which barrier rows the filters build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    /// Rows that hold between samples under the zero-order hold (docs/SAFETY.md).
    #[default]
    SampledData,
    /// The paper's continuous-time rows (eqs. "CBF rel deg 1/2"), which hold at the
    /// samples only; kept for comparison.
    Paper,
}

/// Parameters of the three safety filters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Safety {
    /// `sampled_data` (default) or `paper`.
    #[serde(default)]
    pub formulation: Formulation,
    /// γ_h of α(H) = γ_h H [1/s].
    pub gamma_per_s: f64,
    pub translational: SafetyTranslational,
    pub attitude: SafetyAttitude,
    pub robotic: SafetyRobotic,
    pub solver: Solver,
    pub fallback: Fallback,
    /// What the layer does once the run has left the certified envelope.
    pub safe_mode: SafeMode,
}

/// The safe mode the layer switches to when the run leaves the certified envelope
/// (docs/SAFETY.md, "Safe mode"): the servicer retreats radially from the target, the arm
/// brakes; every command still goes through the filters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SafeMode {
    /// Speed of the radial retreat from the target's CoM [m/s]: the translational nominal
    /// becomes `f_H = sat(m (v_s r̂_H − ω_H × r_H − v_H) / T_t)` (radial in the inertially
    /// fixed F_R; `T_t` the translational brake time).
    pub retreat_speed_m_s: f64,
    /// Distance from the target's CoM at which the retreat stops and the servicer holds
    /// (`v_s` = 0 beyond it) [m].
    pub hold_range_m: f64,
}

/// Events of the world the mission does not declare (`[world]`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    /// The target's body rate jumps (a collision, an outgassing burst) at `t_s`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_spin_change: Option<SpinChange>,
    /// Where the grasping fixture really is, in F_T [m] (a target that is not the one
    /// catalogued): the simulator's truth and the navigation's estimate take it, the
    /// mission's declaration stays `target.grasp_point_m`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grasp_point_m: Option<V3>,
}

/// The target's body rate set to `omega_rad_s` at `t_s`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpinChange {
    /// Mission time of the change [s] (applied at the first control step at or after it).
    pub t_s: f64,
    /// ω_T after the change, in F_T [rad/s].
    pub omega_rad_s: V3,
}

/// Time constants of the bounded fallback commands (saturated brakes).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fallback {
    /// T of f_H = sat(−m v_H / T) [s].
    pub translational_brake_time_s: f64,
    /// T of τ_B = sat(−I (ω_B − ω_T,B) / T) [s].
    pub attitude_brake_time_s: f64,
    /// T of τ_M = sat(−M(θ) θ̇ / T) [s].
    pub robotic_brake_time_s: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SafetyTranslational {
    /// Corridor axis d_R (unit, F_R), pointing from the target towards the servicer.
    pub corridor_axis: V3,
    /// ψ_AC [deg].
    pub corridor_half_angle_deg: f64,
    /// R_CAZ [m].
    pub caz_radius_m: f64,
    /// ε_AC [m/s].
    pub eps_ac: f64,
    /// ε_CAZ [m²/s].
    pub eps_caz: f64,
    /// u_max of the corridor's auxiliary barrier [m/s²].
    pub u_max_ac_m_s2: f64,
    /// u_max of the CAZ's auxiliary barrier [m²/s²].
    pub u_max_caz_m2_s2: f64,
    /// Share of the corridor's braking authority at the wall (`sin ψ F/m − u_max_ac`) the
    /// cone's curvature may take [-], in (0, 1]; absent: [`DEFAULT_CURVATURE_SHARE`]
    /// (docs/SAFETY.md, "The corridor's curvature").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curvature_share: Option<f64>,
    /// The line-of-sight contract: the servicer's speed across the line of sight to the
    /// grasping point, per axis, at most this times its length [rad/s], so that the
    /// servicer's own motion turns the line of sight at most √2 times this; absent:
    /// [`DEFAULT_LOS_SPEED_BUDGET`] (docs/SAFETY.md, "The certified envelope").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub los_speed_budget_rad_s: Option<f64>,
    /// γ of the line-of-sight contract's rows [1/s]; absent: [`DEFAULT_LOS_SPEED_GAMMA`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub los_speed_gamma_per_s: Option<f64>,
}

/// The curvature's share of the corridor's braking authority when a scenario does not set
/// `safety.translational.curvature_share` [-].
pub const DEFAULT_CURVATURE_SHARE: f64 = 0.5;

/// The line-of-sight contract when a scenario does not set
/// `safety.translational.los_speed_budget_rad_s` [rad/s].
pub const DEFAULT_LOS_SPEED_BUDGET: f64 = 0.005;
/// γ of the line-of-sight contract's rows when a scenario does not set
/// `safety.translational.los_speed_gamma_per_s` [1/s].
pub const DEFAULT_LOS_SPEED_GAMMA: f64 = 10.0;

impl SafetyTranslational {
    /// `curvature_share`, or [`DEFAULT_CURVATURE_SHARE`].
    pub fn curvature_share(&self) -> f64 {
        self.curvature_share.unwrap_or(DEFAULT_CURVATURE_SHARE)
    }

    /// `los_speed_budget_rad_s`, or [`DEFAULT_LOS_SPEED_BUDGET`].
    pub fn los_speed_budget(&self) -> f64 {
        self.los_speed_budget_rad_s
            .unwrap_or(DEFAULT_LOS_SPEED_BUDGET)
    }

    /// `los_speed_gamma_per_s`, or [`DEFAULT_LOS_SPEED_GAMMA`].
    pub fn los_speed_gamma(&self) -> f64 {
        self.los_speed_gamma_per_s
            .unwrap_or(DEFAULT_LOS_SPEED_GAMMA)
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SafetyAttitude {
    /// β_ATT [deg].
    pub los_half_angle_deg: f64,
    /// Upper angular-rate limits [rad/s] per body axis.
    pub omega_max_rad_s: V3,
    /// Lower angular-rate limits [rad/s] per body axis.
    pub omega_min_rad_s: V3,
    /// ε_ATT [1/s].
    pub eps_att: f64,
    /// ε_ω [rad/s²].
    pub eps_omega: f64,
    /// γ_ω [1/s].
    pub gamma_omega_per_s: f64,
    /// u_max of the line-of-sight auxiliary barrier [1/s²].
    pub u_max_att_per_s2: f64,
    /// Knee of the line of sight's class-K function, as the angle from the cone's axis
    /// [deg]: where the boresight is closer to the line of sight than this, `H_ATT` may
    /// decay at `gamma_los_inner_per_s` instead of γ_h (`sc_cbf::sampled::Decay`;
    /// 0: the paper's `α(H) = γ_h H` everywhere).
    pub los_decay_knee_deg: f64,
    /// γ of the line of sight's class-K function inside the knee [1/s] (≥ γ_h).
    pub gamma_los_inner_per_s: f64,
    /// Certified set: the boresight's angular rate across itself, `‖ω_B × d_B‖`, at most
    /// this [rad/s] (not one of the paper's barriers; docs/SAFETY.md, "Line of sight").
    pub boresight_rate_max_rad_s: f64,
    /// γ of the boresight-rate row [1/s].
    pub gamma_boresight_rate_per_s: f64,
    /// Contract with the robotic filter: the arm's reaction on the base angular
    /// acceleration, `|(Q τ_M)_i| ≤ β_i` per body axis [rad/s²].
    pub arm_reaction_budget_rad_s2: V3,
    /// Contract with the robotic filter: the joint torque the base wrench may take to
    /// hold the arm, `|(K [f_B; τ_B])_j| ≤ κ_j` per joint [N m].
    pub joint_coupling_budget_nm: J7,
    /// Bound on |ω̈_B,i| over the certified set [rad/s³] (derived: `safe-capture bounds`).
    pub angular_jerk_bound_rad_s3: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SafetyRobotic {
    pub theta_min_rad: J7,
    pub theta_max_rad: J7,
    /// Symmetric joint-velocity limits |θ̇_i| ≤ θ̇_max,i [rad/s].
    pub theta_dot_max_rad_s: J7,
    /// ε_θ [rad²/s].
    pub eps_theta: f64,
    /// ε_θ̇ [rad/s²].
    pub eps_theta_dot: f64,
    /// ε_LB [m²/s].
    pub eps_lb: f64,
    /// γ_θ̇ [1/s].
    pub gamma_theta_dot_per_s: f64,
    /// u_max of the joint-angle auxiliary barriers [rad²/s²].
    pub u_max_theta_rad2_s2: f64,
    /// u_max of the link–base auxiliary barriers [m²/s²].
    pub u_max_lb_m2_s2: f64,
    /// Bound on |θ⃛_i| over the certified set [rad/s³] per joint (derived:
    /// `safe-capture bounds`).
    pub joint_jerk_bound_rad_s3: J7,
    /// Bound on the jerk of each link's collision-sphere centres in the base frame
    /// [m/s³], links 1..7 (derived: `safe-capture bounds`).
    pub link_sphere_jerk_bound_m_s3: J7,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Solver {
    pub max_iterations: u32,
    pub tolerance: f64,
    /// Weight of the slack in the relaxed (always feasible) QP.
    pub slack_weight: f64,
}

/// Tuning of the reference nominal controllers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Nominal {
    pub translational: NominalTranslational,
    pub attitude: NominalAttitude,
    pub robotic: NominalRobotic,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NominalTranslational {
    pub horizon_steps: u32,
    /// Distance of the Go-for-Capture point from the target CoM along d_R [m].
    pub gfc_distance_m: f64,
    pub weight_position: f64,
    pub weight_velocity: f64,
    pub weight_force: f64,
    pub weight_terminal: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NominalAttitude {
    /// The feedback law: the paper's unconstrained MPC or the geometric PD (default,
    /// with the gains below).
    #[serde(default)]
    pub law: AttitudeLawKind,
    pub kp_nm_per_rad: f64,
    pub kd_nm_s_per_rad: f64,
    pub sync_gain_nm_s_per_rad: f64,
    /// `[nominal.attitude.mpc]`, required with `law = "mpc"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mpc: Option<NominalAttitudeMpc>,
}

/// Which feedback law the nominal attitude controller runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AttitudeLawKind {
    /// Geometric PD (`kp`, `kd`, `sync_gain`).
    #[default]
    Pd,
    /// Unconstrained condensed MPC of the attitude error (paper, [Stadler2026]).
    Mpc,
}

/// The attitude MPC's horizon and weights (`sc_nominal::attitude_mpc`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NominalAttitudeMpc {
    pub horizon_steps: u32,
    /// w_φ on the pointing error [1/rad²].
    pub weight_pointing_per_rad2: f64,
    /// w_ω on the rate error [s²/rad²].
    pub weight_rate_s2_per_rad2: f64,
    /// w_τ on the feedback torque [1/(N m)²].
    pub weight_torque_per_nm2: f64,
    /// w_N: terminal weight as a multiple of the stage weight [-].
    pub weight_terminal: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NominalRobotic {
    pub kp_per_s2: f64,
    pub kd_per_s: f64,
    pub ik_iterations: u32,
    pub ik_damping: f64,
    pub ik_tolerance_m: f64,
}

impl Scenario {
    /// Reads, parses and validates a scenario file.
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_toml_str(&text, &base).map_err(|e| e.in_file(path))
    }

    /// Parses and validates scenario text; relative paths resolve against `base_dir`.
    pub fn from_toml_str(text: &str, base_dir: &Path) -> Result<Self, ScenarioError> {
        let mut s: Scenario = toml::from_str(text).map_err(|e| {
            ScenarioError::other_kind(text).unwrap_or_else(|| ScenarioError::parse(text, &e))
        })?;
        s.base_dir = base_dir.to_path_buf();
        if let Some(spec) = s.uncertainty.take() {
            s.set_uncertainty(spec)?;
        }
        s.validate()?;
        Ok(s)
    }

    /// Declares the uncertainty `spec` (e.g. from `--uncertainty`): its profile is read
    /// and its bounds written into the scenario; the `exact` profile without sections of
    /// its own (all bounds zero) removes the section: a scenario without uncertainty.
    pub fn set_uncertainty(&mut self, spec: UncertaintySpec) -> Result<(), ScenarioError> {
        let u = spec.resolve(&self.base_dir)?;
        let truth_differs = spec.truth.is_some_and(|t| t != u);
        self.uncertainty = (!u.is_exact() || truth_differs).then_some(UncertaintySpec {
            model: Some(u.model),
            actuators: Some(u.actuators),
            navigation: Some(u.navigation),
            truth: spec.truth.filter(|_| truth_differs),
            ..spec
        });
        Ok(())
    }

    /// The declared bounds (all zero without an `[uncertainty]` section).
    pub fn uncertainty_bounds(&self) -> Uncertainty {
        let resolved = |s: &UncertaintySpec| Uncertainty {
            model: s.model.unwrap_or_default(),
            actuators: s.actuators.unwrap_or_default(),
            navigation: s.navigation.unwrap_or_default(),
        };
        self.uncertainty.as_ref().map(resolved).unwrap_or_default()
    }

    /// The bounds the simulation draws its truth from: `uncertainty.truth` if given,
    /// else the declared bounds.
    pub fn uncertainty_truth_bounds(&self) -> Uncertainty {
        self.uncertainty
            .as_ref()
            .and_then(|u| u.truth)
            .unwrap_or_else(|| self.uncertainty_bounds())
    }

    /// The URDF path, resolved against the scenario's directory.
    pub fn urdf_path(&self) -> PathBuf {
        if self.servicer.urdf.is_absolute() {
            self.servicer.urdf.clone()
        } else {
            self.base_dir.join(&self.servicer.urdf)
        }
    }

    /// Serialises the scenario back to TOML (e.g. to store a dispersed run).
    pub fn to_toml_string(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// Index of the phase active at time `t` [s] (phases sorted by start time).
    pub fn phase_index(&self, t: f64) -> usize {
        let mut idx = 0;
        for (i, p) in self.mission.phases.iter().enumerate() {
            if t + 1e-9 >= p.start_s {
                idx = i;
            }
        }
        idx
    }

    /// Control steps per physics step ratio: physics steps per control period.
    pub fn physics_substeps(&self) -> usize {
        (self.mission.control_period_s / self.mission.physics_step_s).round() as usize
    }

    /// Number of control steps in the whole run.
    pub fn control_steps(&self) -> usize {
        (self.mission.duration_s / self.mission.control_period_s).round() as usize
    }
}

/// Path of the default scenario shipped in `config/`, relative to the workspace root.
pub const DEFAULT_SCENARIO: &str = "config/scenario.toml";
