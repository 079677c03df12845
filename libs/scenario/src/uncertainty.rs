//! The declared uncertainty: bounds on how the real spacecraft differs from the model
//! the filters and nominal controllers use (mass properties, actuators) and on how the
//! knowledge they act on differs from the truth (navigation). A scenario's
//! `[uncertainty]` section names a profile (`exact`, `realistic` or a file of the same
//! form as `config/uncertainty/custom_example.toml`) and a seed; sections written in the
//! scenario itself replace the profile's. docs/UNCERTAINTY.md has the numbers and their
//! sources.
//!
//! Every number here is a **bound**: the realisation drawn from it never exceeds it
//! (uniform draws inside the bound, noise truncated at the bound).

use crate::validate::ScenarioError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The built-in `realistic` profile (numbers and sources: docs/UNCERTAINTY.md).
const REALISTIC: &str = include_str!("../../../config/uncertainty/realistic.toml");

/// Name of the profile without any error (the default: bit-identical to a scenario
/// without an `[uncertainty]` section).
pub const EXACT: &str = "exact";
/// Name of the built-in profile with documented numbers.
pub const REALISTIC_NAME: &str = "realistic";

/// The scenario's `[uncertainty]` section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UncertaintySpec {
    /// `exact`, `realistic` or a profile file (relative to the scenario's directory).
    #[serde(default = "exact")]
    pub profile: String,
    /// Seed of the realisation (plant, actuators, navigation bias and noise).
    #[serde(default)]
    pub seed: u64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<ModelBounds>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub actuators: Option<ActuatorBounds>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub navigation: Option<NavigationBounds>,
    /// The bounds the simulation draws the truth from when they differ from the declared
    /// ones (every key required): a plant, actuators or navigation outside what the
    /// filters were told, to show that such a run is flagged. Absent: the declared bounds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth: Option<Uncertainty>,
}

fn exact() -> String {
    EXACT.into()
}

/// A profile file: the three sections, every key required.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Uncertainty {
    pub model: ModelBounds,
    pub actuators: ActuatorBounds,
    pub navigation: NavigationBounds,
}

/// Mass-property errors of the plant against the model; drawn uniform in ±bound once
/// per run (relative bounds scale by `1 + x`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelBounds {
    /// |Δm/m| of the servicer base body [-].
    pub servicer_mass_rel: f64,
    /// |ΔI/I| of the base inertia about its CoM [-].
    pub servicer_inertia_rel: f64,
    /// ‖Δc‖ of the base CoM [m].
    pub servicer_com_m: f64,
    /// |Δm/m| of each arm link [-].
    pub link_mass_rel: f64,
    /// |ΔI/I| of each arm link about its CoM [-].
    pub link_inertia_rel: f64,
    /// |ΔI/I| of each entry of the target inertia [-].
    pub target_inertia_rel: f64,
}

/// Actuator errors: what is delivered against what was commanded.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActuatorBounds {
    /// |Δ| of the thrusters' force scale [-].
    pub thruster_force_scale_rel: f64,
    /// Angle of the fixed misalignment of the force direction [rad].
    pub thruster_misalignment_rad: f64,
    /// |Δ| of the body-torque scale [-].
    pub body_torque_scale_rel: f64,
    /// |Δ| of each joint motor's torque scale [-].
    pub joint_torque_scale_rel: f64,
    /// |bias| of each joint torque [N m].
    pub joint_torque_bias_nm: f64,
    /// |ripple| of each joint torque per control step, relative to the command [-].
    pub joint_torque_ripple_rel: f64,
}

/// A navigation error: a bias drawn once per run inside the ball of radius `bias`, plus
/// noise each step (normal, σ = noise/3, truncated at `noise`), so the error's norm
/// never exceeds `bias + noise`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BiasNoise {
    pub bias: f64,
    pub noise: f64,
}

impl BiasNoise {
    /// The bound on the error's norm.
    pub fn bound(&self) -> f64 {
        self.bias + self.noise
    }
}

/// Navigation errors of the estimate the controllers and filters act on. Vectors in the
/// reference frame F_R (positions, velocities), small rotations (attitudes) and body
/// rates as Euclidean norms; joints per joint.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NavigationBounds {
    /// Relative position of the servicer base [m].
    pub relative_position_m: BiasNoise,
    /// Relative velocity [m/s].
    pub relative_velocity_m_s: BiasNoise,
    /// Servicer attitude (rotation angle) [rad].
    pub servicer_attitude_rad: BiasNoise,
    /// Servicer body rate [rad/s].
    pub servicer_rate_rad_s: BiasNoise,
    /// Target attitude (rotation angle) [rad].
    pub target_attitude_rad: BiasNoise,
    /// Target body rate [rad/s].
    pub target_rate_rad_s: BiasNoise,
    /// Grasping point in the target frame [m] (knowledge of the target's geometry).
    pub grasp_point_m: BiasNoise,
    /// Each joint angle [rad].
    pub joint_angle_rad: BiasNoise,
    /// Each joint rate [rad/s].
    pub joint_rate_rad_s: BiasNoise,
    /// Age of the measurement the estimate rests on, at most one control period [s].
    pub measurement_age_s: f64,
}

impl NavigationBounds {
    /// Every bias-plus-noise error with its key.
    pub fn errors(&self) -> [(&'static str, BiasNoise); 9] {
        [
            ("relative_position_m", self.relative_position_m),
            ("relative_velocity_m_s", self.relative_velocity_m_s),
            ("servicer_attitude_rad", self.servicer_attitude_rad),
            ("servicer_rate_rad_s", self.servicer_rate_rad_s),
            ("target_attitude_rad", self.target_attitude_rad),
            ("target_rate_rad_s", self.target_rate_rad_s),
            ("grasp_point_m", self.grasp_point_m),
            ("joint_angle_rad", self.joint_angle_rad),
            ("joint_rate_rad_s", self.joint_rate_rad_s),
        ]
    }
}

/// The number of scalar bounds ([`Uncertainty::scalar_bounds`]).
pub const SCALAR_BOUNDS: usize = 13;

impl Uncertainty {
    /// Every scalar bound with its key (`model.*`, `actuators.*`,
    /// `navigation.measurement_age_s`); the navigation's bias-plus-noise errors are
    /// [`NavigationBounds::errors`].
    pub fn scalar_bounds(&self) -> [(&'static str, f64); SCALAR_BOUNDS] {
        let (m, a, n) = (&self.model, &self.actuators, &self.navigation);
        [
            ("model.servicer_mass_rel", m.servicer_mass_rel),
            ("model.servicer_inertia_rel", m.servicer_inertia_rel),
            ("model.servicer_com_m", m.servicer_com_m),
            ("model.link_mass_rel", m.link_mass_rel),
            ("model.link_inertia_rel", m.link_inertia_rel),
            ("model.target_inertia_rel", m.target_inertia_rel),
            (
                "actuators.thruster_force_scale_rel",
                a.thruster_force_scale_rel,
            ),
            (
                "actuators.thruster_misalignment_rad",
                a.thruster_misalignment_rad,
            ),
            ("actuators.body_torque_scale_rel", a.body_torque_scale_rel),
            ("actuators.joint_torque_scale_rel", a.joint_torque_scale_rel),
            ("actuators.joint_torque_bias_nm", a.joint_torque_bias_nm),
            (
                "actuators.joint_torque_ripple_rel",
                a.joint_torque_ripple_rel,
            ),
            ("navigation.measurement_age_s", n.measurement_age_s),
        ]
    }

    /// The keys of every error declared non-zero, in the order of the sections (model,
    /// actuators, navigation; the navigation's errors as `navigation.<kind>`, its
    /// measurement age last).
    pub fn declared_sources(&self) -> Vec<String> {
        let age = "navigation.measurement_age_s";
        let scalars = self.scalar_bounds().into_iter().filter(|(_, v)| *v != 0.0);
        let (ages, others): (Vec<_>, Vec<_>) = scalars.partition(|(k, _)| *k == age);
        let nav = self
            .navigation
            .errors()
            .into_iter()
            .filter(|(_, b)| b.bound() != 0.0)
            .map(|(k, _)| format!("navigation.{k}"));
        others
            .into_iter()
            .map(|(k, _)| k.to_string())
            .chain(nav)
            .chain(ages.into_iter().map(|(k, _)| k.to_string()))
            .collect()
    }

    /// True if no error of any kind is declared.
    pub fn is_exact(&self) -> bool {
        *self == Uncertainty::default()
    }

    /// Reads a profile: `exact`, `realistic` or a file (relative to `base_dir`).
    pub fn profile(name: &str, base_dir: &Path) -> Result<Self, ScenarioError> {
        match name {
            EXACT => Ok(Self::default()),
            REALISTIC_NAME => {
                parse_profile(REALISTIC, Path::new("config/uncertainty/realistic.toml"))
            }
            file => {
                let path = base_dir.join(file);
                let text = std::fs::read_to_string(&path).map_err(|e| ScenarioError::Io {
                    path: path.clone(),
                    message: format!(
                        "{e} (`uncertainty.profile` is `{EXACT}`, `{REALISTIC_NAME}` or a profile file)"
                    ),
                })?;
                parse_profile(&text, &path)
            }
        }
    }
}

fn parse_profile(text: &str, path: &Path) -> Result<Uncertainty, ScenarioError> {
    let u: Uncertainty =
        toml::from_str(text).map_err(|e| ScenarioError::parse(text, &e).in_file(path))?;
    u.validate("uncertainty").map_err(|e| e.in_file(path))?;
    Ok(u)
}

impl UncertaintySpec {
    /// A named profile alone (`exact`, `realistic` or a file), with `seed`: no section
    /// overridden, no separate truth.
    pub fn profile(name: &str, seed: u64) -> Self {
        Self {
            profile: name.into(),
            seed,
            model: None,
            actuators: None,
            navigation: None,
            truth: None,
        }
    }

    /// The bounds: the profile's, with the sections written in the scenario instead
    /// (the profile is not read when the scenario writes all three).
    pub fn resolve(&self, base_dir: &Path) -> Result<Uncertainty, ScenarioError> {
        if let (Some(model), Some(actuators), Some(navigation)) =
            (self.model, self.actuators, self.navigation)
        {
            return Ok(Uncertainty {
                model,
                actuators,
                navigation,
            });
        }
        let mut u = Uncertainty::profile(&self.profile, base_dir)?;
        if let Some(m) = self.model {
            u.model = m;
        }
        if let Some(a) = self.actuators {
            u.actuators = a;
        }
        if let Some(n) = self.navigation {
            u.navigation = n;
        }
        Ok(u)
    }
}
