//! `config/montecarlo.toml`: the dispersions of a campaign, parsed with serde
//! (`deny_unknown_fields`) and validated with one-line errors `key = value: rule`.

use serde::{Deserialize, Serialize};
use std::path::Path;

/// Path of the default campaign configuration, relative to the workspace root.
pub const DEFAULT_CONFIG: &str = "config/montecarlo.toml";

/// Why a configuration was rejected. One line each.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read {path}: {message}")]
    Io { path: String, message: String },
    #[error("{path}: parse error at line {line}: {message}")]
    Parse {
        path: String,
        line: usize,
        message: String,
    },
    #[error("`{key}` = {value}: {rule}")]
    Invalid {
        key: String,
        value: String,
        rule: String,
    },
}

/// Dispersions of a campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloConfig {
    pub initial_position: InitialPosition,
    pub target_rate: TargetRate,
    pub output: Output,
}

/// Initial servicer position, sampled inside the approach corridor (F_R).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialPosition {
    /// Distance from the target CoM, uniform in [min, max] [m].
    pub distance_min_m: f64,
    pub distance_max_m: f64,
    /// Direction uniform over the spherical cap of half-angle ψ_AC − this margin about the
    /// corridor axis [deg].
    pub corridor_margin_deg: f64,
    /// Samples whose initial line of sight (base origin → grasping point, with the initial
    /// attitudes) lies outside β_ATT − this margin are redrawn [deg].
    pub los_margin_deg: f64,
}

/// Target tumbling rate: ω_T = w · axis_t, w uniform in [min, max].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetRate {
    pub rate_min_rad_s: f64,
    pub rate_max_rad_s: f64,
    /// Unit tumbling axis in F_T.
    pub axis_t: [f64; 3],
}

/// What every run keeps for the campaign figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// One trace sample every this many control steps.
    pub trace_every_steps: u32,
}

fn invalid(key: &str, value: impl std::fmt::Debug, rule: &str) -> ConfigError {
    ConfigError::Invalid {
        key: key.into(),
        value: format!("{value:?}"),
        rule: rule.into(),
    }
}

fn finite_nonneg(key: &str, v: f64) -> Result<(), ConfigError> {
    if !v.is_finite() || v < 0.0 {
        return Err(invalid(key, v, "must be finite and >= 0"));
    }
    Ok(())
}

impl MonteCarloConfig {
    /// Reads, parses and validates a configuration file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Self::from_toml_str(&text).map_err(|e| match e {
            ConfigError::Parse { line, message, .. } => ConfigError::Parse {
                path: path.display().to_string(),
                line,
                message,
            },
            e => e,
        })
    }

    /// Parses and validates configuration text.
    pub fn from_toml_str(text: &str) -> Result<Self, ConfigError> {
        let c: Self = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1)
                .unwrap_or(0);
            ConfigError::Parse {
                path: "<text>".into(),
                line,
                message: e.message().replace('\n', " ").trim().to_string(),
            }
        })?;
        c.validate()?;
        Ok(c)
    }

    /// The rules; the ones that depend on the scenario are in [`Self::check_against`].
    pub fn validate(&self) -> Result<(), ConfigError> {
        let p = &self.initial_position;
        finite_nonneg("initial_position.distance_min_m", p.distance_min_m)?;
        finite_nonneg("initial_position.distance_max_m", p.distance_max_m)?;
        if p.distance_max_m < p.distance_min_m {
            return Err(invalid(
                "initial_position.distance_max_m",
                p.distance_max_m,
                "must be >= initial_position.distance_min_m",
            ));
        }
        finite_nonneg(
            "initial_position.corridor_margin_deg",
            p.corridor_margin_deg,
        )?;
        finite_nonneg("initial_position.los_margin_deg", p.los_margin_deg)?;
        let r = &self.target_rate;
        finite_nonneg("target_rate.rate_min_rad_s", r.rate_min_rad_s)?;
        finite_nonneg("target_rate.rate_max_rad_s", r.rate_max_rad_s)?;
        if r.rate_max_rad_s < r.rate_min_rad_s {
            return Err(invalid(
                "target_rate.rate_max_rad_s",
                r.rate_max_rad_s,
                "must be >= target_rate.rate_min_rad_s",
            ));
        }
        if r.rate_max_rad_s > 1.0 {
            return Err(invalid(
                "target_rate.rate_max_rad_s",
                r.rate_max_rad_s,
                "must be <= 1 rad/s",
            ));
        }
        let n = r.axis_t.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !n.is_finite() || (n - 1.0).abs() > 1e-6 {
            return Err(invalid(
                "target_rate.axis_t",
                r.axis_t,
                "must be a unit vector",
            ));
        }
        if self.output.trace_every_steps == 0 {
            return Err(invalid("output.trace_every_steps", 0, "must be >= 1"));
        }
        Ok(())
    }

    /// Rules against the scenario the campaign disperses.
    pub fn check_against(&self, s: &sc_scenario::Scenario) -> Result<(), ConfigError> {
        let p = &self.initial_position;
        let psi = s.safety.translational.corridor_half_angle_deg;
        if p.corridor_margin_deg >= psi {
            return Err(invalid(
                "initial_position.corridor_margin_deg",
                p.corridor_margin_deg,
                &format!("must be < the corridor half-angle {psi} deg"),
            ));
        }
        let beta = s.safety.attitude.los_half_angle_deg;
        if p.los_margin_deg >= beta {
            return Err(invalid(
                "initial_position.los_margin_deg",
                p.los_margin_deg,
                &format!("must be < the line-of-sight half-angle {beta} deg"),
            ));
        }
        let caz = s.safety.translational.caz_radius_m;
        if p.distance_min_m <= caz {
            return Err(invalid(
                "initial_position.distance_min_m",
                p.distance_min_m,
                &format!("must be > the collision-avoidance radius {caz} m"),
            ));
        }
        self.check_envelope(s)
    }

    /// The fastest tumble the campaign draws is inside the scenario's certified envelope
    /// (docs/SAFETY.md, "The certified envelope"): otherwise some runs would start outside
    /// the promise.
    fn check_envelope(&self, s: &sc_scenario::Scenario) -> Result<(), ConfigError> {
        let r = &self.target_rate;
        let axis = r.axis_t;
        let k =
            r.rate_max_rad_s / (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        // as the start checks a run's own tumble (each run declares its draw): with the
        // run-time watch's margin about the drawn axis
        let mut fastest = s.clone();
        fastest.target.initial_omega_rad_s = axis.map(|a| a * k);
        let env = fastest.watched_envelope_for(&fastest.target.initial_omega_rad_s);
        if env.contains() {
            return Ok(());
        }
        if !env.geometry_is_certifiable() {
            return Err(invalid(
                "target_rate.axis_t",
                axis,
                &format!(
                    "outside the scenario's certified envelope (docs/SAFETY.md, \"The certified envelope\"): a tumble about this axis lets the servicer come to {:.3} m of the grasping point, or see it more than 84 deg off the corridor axis, or (off the target's principal axes, inertia ratio {:.2}) speed up beyond the filters' bounds; `safe-capture check` on the scenario with this tumble names which",
                    env.los_min_m, env.amplification
                ),
            ));
        }
        Err(invalid(
            "target_rate.rate_max_rad_s",
            r.rate_max_rad_s,
            &format!(
                "outside the scenario's certified envelope (docs/SAFETY.md, \"The certified envelope\"): with the grasping point's lever {:.3} m (from the spin axis, or the CoM off the principal axes), the servicer as close as {:.3} m to it and the base's rate limits, the tumble may be at most {:.4} rad/s{}",
                env.lever_m,
                env.los_min_m,
                (env.max_spin_rad_s() - s.watch_margin_rad_s()).max(0.0),
                if s.watch_margin_rad_s() > 0.0 {
                    format!(
                        " (the limit less twice the declared error of the target's rate estimate, {:.4} rad/s, the run-time watch's margin)",
                        s.watch_margin_rad_s()
                    )
                } else {
                    String::new()
                }
            ),
        ))
    }
}
