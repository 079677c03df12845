//! Validation rules of the scenario. Every error names the key, the value and the
//! rule it breaks, on one line.

use crate::{Scenario, V3};
use std::fmt::Debug;
use std::path::PathBuf;

/// Why a scenario was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScenarioError {
    #[error("cannot read {}: {message}", path.display())]
    Io { path: PathBuf, message: String },
    #[error("parse error at line {line}, column {column}: {message}")]
    Parse {
        line: usize,
        column: usize,
        message: String,
    },
    /// Another kind of configuration file where a scenario is expected.
    #[error("{kind}, not a scenario: {hint}")]
    WrongKind { kind: String, hint: String },
    #[error("`{key}` = {value}: {rule}")]
    Invalid {
        key: String,
        value: String,
        rule: String,
    },
    #[error("{}: {inner}", path.display())]
    InFile {
        path: PathBuf,
        inner: Box<ScenarioError>,
    },
}

impl ScenarioError {
    pub(crate) fn parse(text: &str, e: &toml::de::Error) -> Self {
        let (line, column) = match e.span() {
            Some(span) => {
                let before = &text[..span.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let column = before.len() - before.rfind('\n').map(|i| i + 1).unwrap_or(0) + 1;
                (line, column)
            }
            None => (0, 0),
        };
        let message = e.message().replace('\n', " ").trim().to_string();
        ScenarioError::Parse {
            line,
            column,
            message,
        }
    }

    /// `text` that failed to parse as a scenario but is another kind of configuration,
    /// told by its top-level keys (the same keys `safe-capture check` tells kinds by): a
    /// partition config (`roles`, `rate_groups`) or a Monte Carlo config
    /// (`initial_position`, `target_rate`). `None` when it is meant as a scenario.
    pub(crate) fn other_kind(text: &str) -> Option<Self> {
        let table: toml::Table = toml::from_str(text).ok()?;
        let has = |keys: &[&str]| keys.iter().any(|k| table.contains_key(*k));
        if has(&["servicer", "target", "mission"]) {
            return None;
        }
        let (kind, command) = if has(&["roles", "rate_groups"]) {
            ("a partition config", "safe-capture launch --config FILE")
        } else if has(&["initial_position", "target_rate"]) {
            (
                "a Monte Carlo config",
                "safe-capture montecarlo --config FILE",
            )
        } else {
            return None;
        };
        Some(ScenarioError::WrongKind {
            kind: kind.into(),
            hint: format!(
                "give it to `{command}`; a scenario (e.g. config/scenario.toml) has [servicer], [target] and [mission]"
            ),
        })
    }

    pub(crate) fn in_file(self, path: &std::path::Path) -> Self {
        match self {
            e @ ScenarioError::Io { .. } => e,
            e => ScenarioError::InFile {
                path: path.to_path_buf(),
                inner: Box::new(e),
            },
        }
    }

    /// The validation error without the file prefix.
    pub fn root(&self) -> &ScenarioError {
        match self {
            ScenarioError::InFile { inner, .. } => inner.root(),
            e => e,
        }
    }
}

/// The lowest altitude of a circular orbit the scenario accepts [m] (the Kármán line:
/// below it the atmosphere brings an orbit down within a revolution).
pub const MIN_ORBIT_ALTITUDE_M: f64 = 100_000.0;

/// How many keep-out spheres the robotic filter's rows combine (their smooth minimum,
/// `sc_cbf::link_target`; each costs the verification one clearance per arm sphere and
/// physics step).
pub const MAX_KEEP_OUT_SPHERES: usize = 8;
/// How many the scenario may declare: one, because with more the red team breaks the
/// arm's barriers (measured with the bus and two appendages: 4 of 116 cases unsafe,
/// docs/SAFETY.md "The arm and the target").
pub const MAX_DECLARED_KEEP_OUT_SPHERES: usize = 1;
/// How far from the target's CoM a keep-out sphere may reach [m].
pub const MAX_TARGET_EXTENT_M: f64 = 100.0;

pub(crate) fn invalid(key: &str, value: impl Debug, rule: impl Into<String>) -> ScenarioError {
    ScenarioError::Invalid {
        key: key.to_string(),
        value: format!("{value:?}"),
        rule: rule.into(),
    }
}

fn finite(key: &str, v: f64) -> Result<(), ScenarioError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(invalid(key, v, "must be a finite number"))
    }
}

fn positive(key: &str, v: f64) -> Result<(), ScenarioError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(key, v, "must be a finite number > 0"))
    }
}

fn non_negative(key: &str, v: f64) -> Result<(), ScenarioError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(invalid(key, v, "must be a finite number >= 0"))
    }
}

fn finite_all(key: &str, v: &[f64]) -> Result<(), ScenarioError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(key, v, "every component must be finite"))
    }
}

fn unit(key: &str, v: &[f64]) -> Result<(), ScenarioError> {
    finite_all(key, v)?;
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (n - 1.0).abs() <= 1e-6 {
        Ok(())
    } else {
        Err(invalid(
            key,
            v,
            format!("must have unit norm (norm is {n:.6}, tolerance 1e-6)"),
        ))
    }
}

fn angle_deg(key: &str, v: f64) -> Result<(), ScenarioError> {
    if v.is_finite() && v > 0.0 && v < 90.0 {
        Ok(())
    } else {
        Err(invalid(key, v, "must be in (0, 90) degrees"))
    }
}

fn inertia(key: &str, m: &[V3; 3]) -> Result<(), ScenarioError> {
    finite_all(key, &m.concat())?;
    for i in 0..3 {
        for j in 0..3 {
            if (m[i][j] - m[j][i]).abs() > 1e-9 * (1.0 + m[i][j].abs()) {
                return Err(invalid(key, m, "must be symmetric"));
            }
        }
    }
    // Positive definiteness by leading principal minors (Sylvester).
    let d1 = m[0][0];
    let d2 = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let d3 = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if !(d1 > 0.0 && d2 > 0.0 && d3 > 0.0) {
        return Err(invalid(key, m, "must be positive definite"));
    }
    let (a, b, c) = (m[0][0], m[1][1], m[2][2]);
    if a + b < c || b + c < a || a + c < b {
        return Err(invalid(
            key,
            m,
            "diagonal must satisfy the triangle inequality of a rigid body",
        ));
    }
    Ok(())
}

impl Scenario {
    /// Checks every rule; returns the first broken one. The sections are checked
    /// in the order of the file (docs/SCENARIO.md), so the first error is the
    /// first broken key.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        self.validate_orbit()?;
        unit(
            "reference_frame.attitude_in_hill",
            &self.reference_frame.attitude_in_hill,
        )?;
        self.validate_servicer()?;
        self.validate_target()?;
        self.validate_mission()?;
        self.validate_limits()?;
        self.validate_safety()?;
        self.validate_nominal()?;
        self.validate_uncertainty()?;
        self.validate_world()?;
        self.validate_envelope()
    }

    fn validate_world(&self) -> Result<(), ScenarioError> {
        let sm = &self.safety.safe_mode;
        positive("safety.safe_mode.retreat_speed_m_s", sm.retreat_speed_m_s)?;
        positive("safety.safe_mode.hold_range_m", sm.hold_range_m)?;
        if let Some(g) = self.world.as_ref().and_then(|w| w.grasp_point_m) {
            finite_all("world.grasp_point_m", &g)?;
        }
        let Some(c) = self.world.as_ref().and_then(|w| w.target_spin_change) else {
            return Ok(());
        };
        finite("world.target_spin_change.t_s", c.t_s)?;
        if c.t_s < 0.0 {
            return Err(invalid(
                "world.target_spin_change.t_s",
                c.t_s,
                "must not be negative (the change happens during the run)",
            ));
        }
        finite_all("world.target_spin_change.omega_rad_s", &c.omega_rad_s)
    }

    fn validate_uncertainty(&self) -> Result<(), ScenarioError> {
        if let Some(t) = self.uncertainty.as_ref().and_then(|u| u.truth) {
            t.validate("uncertainty.truth")?;
        }
        let u = self.uncertainty_bounds();
        u.validate("uncertainty")?;
        let bias = u.actuators.joint_torque_bias_nm;
        if bias >= self.limits.joint_torque_max_nm {
            return Err(invalid(
                "uncertainty.actuators.joint_torque_bias_nm",
                bias,
                format!(
                    "below the joint torque limit (limits.joint_torque_max_nm = {}): a bias as large leaves the filters no command that keeps the delivered torque in the box",
                    self.limits.joint_torque_max_nm
                ),
            ));
        }
        let age = u.navigation.measurement_age_s;
        if age > self.mission.control_period_s {
            return Err(invalid(
                "uncertainty.navigation.measurement_age_s",
                age,
                format!(
                    "at most one control period (mission.control_period_s = {})",
                    self.mission.control_period_s
                ),
            ));
        }
        Ok(())
    }

    fn validate_orbit(&self) -> Result<(), ScenarioError> {
        let o = &self.orbit;
        // 0 is zero gravity (docs/SCENARIO.md): the target rests, the Hill frame is fixed
        non_negative("orbit.earth_mu_m3_s2", o.earth_mu_m3_s2)?;
        positive("orbit.earth_radius_m", o.earth_radius_m)?;
        positive("orbit.altitude_m", o.altitude_m)?;
        if o.earth_mu_m3_s2 > 0.0 && o.altitude_m < MIN_ORBIT_ALTITUDE_M {
            return Err(invalid(
                "orbit.altitude_m",
                o.altitude_m,
                format!(
                    "an orbit at least {MIN_ORBIT_ALTITUDE_M} m above the Earth's surface (below ~100 km no orbit lasts a revolution; the key is in metres — 600 km is 600000.0)"
                ),
            ));
        }
        finite("orbit.inclination_deg", o.inclination_deg)?;
        finite("orbit.raan_deg", o.raan_deg)?;
        finite("orbit.argument_of_latitude_deg", o.argument_of_latitude_deg)
    }

    fn validate_servicer(&self) -> Result<(), ScenarioError> {
        let s = &self.servicer;
        let urdf = self.urdf_path();
        if !urdf.is_file() {
            return Err(invalid(
                "servicer.urdf",
                s.urdf.display().to_string(),
                format!("file not found at {}", urdf.display()),
            ));
        }
        unit("servicer.boresight_body", &s.boresight_body)?;
        self.validate_grasp_axes()?;
        finite_all("servicer.initial_position_m", &s.initial_position_m)?;
        finite_all("servicer.initial_velocity_m_s", &s.initial_velocity_m_s)?;
        finite_all("servicer.initial_omega_rad_s", &s.initial_omega_rad_s)?;
        finite_all("servicer.initial_theta_rad", &s.initial_theta_rad)?;
        finite_all(
            "servicer.initial_theta_dot_rad_s",
            &s.initial_theta_dot_rad_s,
        )
    }

    /// The gripper's axis and the fixture's axis come together (or neither), and
    /// the gripper's axis is (nearly) normal to the boresight.
    fn validate_grasp_axes(&self) -> Result<(), ScenarioError> {
        let s = &self.servicer;
        match (&s.gripper_axis_body, &self.target.grasp_fixture_axis) {
            (Some(g), Some(a)) => {
                unit("servicer.gripper_axis_body", g)?;
                unit("target.grasp_fixture_axis", a)?;
                let along: f64 = g.iter().zip(&s.boresight_body).map(|(x, y)| x * y).sum();
                if along.abs() > 0.5 {
                    return Err(invalid(
                        "servicer.gripper_axis_body",
                        g,
                        "must be (nearly) normal to the boresight: the alignment turns it about the boresight",
                    ));
                }
                Ok(())
            }
            (None, None) => Ok(()),
            (Some(_), None) => Err(invalid(
                "target.grasp_fixture_axis",
                "missing",
                "servicer.gripper_axis_body is set: give the fixture's axis too (or neither)",
            )),
            (None, Some(_)) => Err(invalid(
                "servicer.gripper_axis_body",
                "missing",
                "target.grasp_fixture_axis is set: give the gripper's axis too (or neither)",
            )),
        }
    }

    fn validate_target(&self) -> Result<(), ScenarioError> {
        let t = &self.target;
        positive("target.mass_kg", t.mass_kg)?;
        inertia("target.inertia_kg_m2", &t.inertia_kg_m2)?;
        unit("target.initial_attitude", &t.initial_attitude)?;
        finite_all("target.initial_omega_rad_s", &t.initial_omega_rad_s)?;
        finite_all("target.grasp_point_m", &t.grasp_point_m)?;
        self.validate_keep_out_spheres()
    }

    /// [`MAX_DECLARED_KEEP_OUT_SPHERES`] keep-out sphere, finite, with a positive radius,
    /// within [`MAX_TARGET_EXTENT_M`] of the CoM, and the grasping fixture outside it (the
    /// gripper must be able to reach it).
    fn validate_keep_out_spheres(&self) -> Result<(), ScenarioError> {
        let t = &self.target;
        if t.collision_spheres.is_empty() {
            return Err(invalid(
                "target.collision_spheres",
                "[]",
                "declare one keep-out sphere covering the target's body",
            ));
        }
        if t.collision_spheres.len() > MAX_DECLARED_KEEP_OUT_SPHERES {
            return Err(invalid(
                "target.collision_spheres",
                format!("{} spheres", t.collision_spheres.len()),
                "one keep-out sphere for now: with more, the red team found the arm's barriers broken (docs/SAFETY.md, \"The arm and the target\")",
            ));
        }
        for (k, sp) in t.collision_spheres.iter().enumerate() {
            let key = format!("target.collision_spheres[{k}]");
            finite_all(&format!("{key}.center_m"), &sp.center_m)?;
            positive(&format!("{key}.radius_m"), sp.radius_m)?;
            let far = sp.center_m.iter().any(|c| c.abs() > MAX_TARGET_EXTENT_M);
            if far || sp.radius_m > MAX_TARGET_EXTENT_M {
                return Err(invalid(
                    &key,
                    format!("centre {:?}, radius {} m", sp.center_m, sp.radius_m),
                    format!("must lie within {MAX_TARGET_EXTENT_M} m of the target's CoM"),
                ));
            }
            let standoff = sp.standoff_m(&t.grasp_point_m);
            if standoff <= 0.0 {
                let d = standoff + sp.radius_m;
                return Err(invalid(
                    &format!("target.collision_spheres[{k}]"),
                    format!("centre {:?}, radius {} m", sp.center_m, sp.radius_m),
                    format!(
                        "contains the grasping fixture (target.grasp_point_m {:?}, {d:.3} m from its centre): the fixture must stand off the body",
                        t.grasp_point_m
                    ),
                ));
            }
        }
        Ok(())
    }

    fn validate_mission(&self) -> Result<(), ScenarioError> {
        let m = &self.mission;
        positive("mission.control_period_s", m.control_period_s)?;
        positive("mission.physics_step_s", m.physics_step_s)?;
        positive("mission.duration_s", m.duration_s)?;
        positive("mission.capture_tolerance_m", m.capture_tolerance_m)?;
        positive(
            "mission.capture_speed_tolerance_m_s",
            m.capture_speed_tolerance_m_s,
        )?;
        let ratio = m.control_period_s / m.physics_step_s;
        if ratio < 1.0 - 1e-9 || (ratio - ratio.round()).abs() > 1e-9 * ratio {
            return Err(invalid(
                "mission.physics_step_s",
                m.physics_step_s,
                format!(
                    "must divide mission.control_period_s = {} into a whole number of steps",
                    m.control_period_s
                ),
            ));
        }
        self.validate_phases()
    }

    /// At least one phase; the first starts at 0, the others in strictly increasing order.
    fn validate_phases(&self) -> Result<(), ScenarioError> {
        let phases = &self.mission.phases;
        if phases.is_empty() {
            return Err(invalid(
                "mission.phases",
                "[]",
                "at least one phase is required",
            ));
        }
        for (i, p) in phases.iter().enumerate() {
            let key = format!("mission.phases[{i}].start_s");
            non_negative(&key, p.start_s)?;
            if i == 0 && p.start_s != 0.0 {
                return Err(invalid(&key, p.start_s, "the first phase must start at 0"));
            }
            if i > 0 && p.start_s <= phases[i - 1].start_s {
                return Err(invalid(
                    &key,
                    p.start_s,
                    "phases must start in strictly increasing order",
                ));
            }
        }
        Ok(())
    }

    fn validate_limits(&self) -> Result<(), ScenarioError> {
        let l = &self.limits;
        positive("limits.force_max_n", l.force_max_n)?;
        positive("limits.torque_max_nm", l.torque_max_nm)?;
        positive("limits.joint_torque_max_nm", l.joint_torque_max_nm)
    }

    fn validate_safety(&self) -> Result<(), ScenarioError> {
        positive("safety.gamma_per_s", self.safety.gamma_per_s)?;
        self.validate_safety_translational()?;
        self.validate_safety_attitude()?;
        self.validate_safety_robotic()?;
        self.validate_safety_solver()?;
        self.validate_safety_fallback()
    }

    fn validate_safety_translational(&self) -> Result<(), ScenarioError> {
        let tr = &self.safety.translational;
        unit("safety.translational.corridor_axis", &tr.corridor_axis)?;
        angle_deg(
            "safety.translational.corridor_half_angle_deg",
            tr.corridor_half_angle_deg,
        )?;
        positive("safety.translational.caz_radius_m", tr.caz_radius_m)?;
        non_negative("safety.translational.eps_ac", tr.eps_ac)?;
        non_negative("safety.translational.eps_caz", tr.eps_caz)?;
        positive("safety.translational.u_max_ac_m_s2", tr.u_max_ac_m_s2)?;
        let share = tr.curvature_share();
        if share.is_nan() || share <= 0.0 || share > 1.0 {
            return Err(invalid(
                "safety.translational.curvature_share",
                share,
                "must be in (0, 1]",
            ));
        }
        positive("safety.translational.u_max_caz_m2_s2", tr.u_max_caz_m2_s2)?;
        positive(
            "safety.translational.los_speed_budget_rad_s",
            tr.los_speed_budget(),
        )?;
        positive(
            "safety.translational.los_speed_gamma_per_s",
            tr.los_speed_gamma(),
        )
    }

    /// The rules that need the servicer's total mass `m` [kg], which the scenario does not
    /// hold (its URDF does; `sc_mission::Setup` checks them when it loads the model): the
    /// tangential-speed coefficient `c_t = curvature_share (sin ψ_AC F/m − u_max_ac)/cos ψ_AC`
    /// of the translational filter must be positive. With `c_t ≤ 0` the corridor's budget
    /// `u_max_ac_m_s2` takes all of its braking authority at the wall, `sin ψ_AC F/m`, and
    /// the tangential-speed limit `‖v_⊥‖² ≤ c_t ‖r‖` allows no motion across the line of
    /// sight at all.
    pub fn validate_with_servicer_mass(&self, mass_kg: f64) -> Result<(), ScenarioError> {
        let tr = &self.safety.translational;
        // as the filter computes it (`sc_cbf::translational::tangential_coefficient`)
        let cos_psi = tr.corridor_half_angle_deg.to_radians().cos();
        let sin_psi = (1.0 - cos_psi * cos_psi).max(0.0).sqrt();
        let authority = sin_psi * self.limits.force_max_n / mass_kg;
        let c_t = tr.curvature_share() * (authority - tr.u_max_ac_m_s2) / cos_psi;
        if c_t > 0.0 {
            return Ok(());
        }
        Err(invalid(
            "safety.translational.u_max_ac_m_s2",
            tr.u_max_ac_m_s2,
            format!(
                "must be below the corridor's braking authority at its wall, sin(corridor_half_angle_deg) limits.force_max_n / m = {authority:.6} m/s² with the servicer's mass m = {mass_kg} kg (its URDF): otherwise the tangential-speed coefficient c_t = {c_t:.3e} m/s² is not > 0 and no motion across the line of sight is allowed"
            ),
        ))
    }

    fn validate_safety_attitude(&self) -> Result<(), ScenarioError> {
        let at = &self.safety.attitude;
        angle_deg("safety.attitude.los_half_angle_deg", at.los_half_angle_deg)?;
        finite_all("safety.attitude.omega_max_rad_s", &at.omega_max_rad_s)?;
        finite_all("safety.attitude.omega_min_rad_s", &at.omega_min_rad_s)?;
        for i in 0..3 {
            if at.omega_min_rad_s[i] >= at.omega_max_rad_s[i] {
                return Err(invalid(
                    &format!("safety.attitude.omega_min_rad_s[{i}]"),
                    at.omega_min_rad_s[i],
                    format!("limits with min >= max (max is {})", at.omega_max_rad_s[i]),
                ));
            }
        }
        non_negative("safety.attitude.eps_att", at.eps_att)?;
        non_negative("safety.attitude.eps_omega", at.eps_omega)?;
        positive("safety.attitude.gamma_omega_per_s", at.gamma_omega_per_s)?;
        positive("safety.attitude.u_max_att_per_s2", at.u_max_att_per_s2)?;
        self.validate_safety_attitude_los()?;
        positive(
            "safety.attitude.boresight_rate_max_rad_s",
            at.boresight_rate_max_rad_s,
        )?;
        positive(
            "safety.attitude.gamma_boresight_rate_per_s",
            at.gamma_boresight_rate_per_s,
        )?;
        self.validate_safety_attitude_bounds()
    }

    /// The line-of-sight barrier's decay: its knee inside the cone, its inner
    /// rate at least the outer one.
    fn validate_safety_attitude_los(&self) -> Result<(), ScenarioError> {
        let sf = &self.safety;
        let at = &sf.attitude;
        if !(at.los_decay_knee_deg >= 0.0 && at.los_decay_knee_deg < at.los_half_angle_deg) {
            return Err(invalid(
                "safety.attitude.los_decay_knee_deg",
                at.los_decay_knee_deg,
                format!(
                    "an angle in [0, los_half_angle_deg = {}) deg",
                    at.los_half_angle_deg
                ),
            ));
        }
        if !(at.gamma_los_inner_per_s >= sf.gamma_per_s && at.gamma_los_inner_per_s.is_finite()) {
            return Err(invalid(
                "safety.attitude.gamma_los_inner_per_s",
                at.gamma_los_inner_per_s,
                format!(
                    "a finite rate >= safety.gamma_per_s = {} 1/s",
                    sf.gamma_per_s
                ),
            ));
        }
        Ok(())
    }

    /// The attitude filter's disturbance budgets and derivative bounds.
    fn validate_safety_attitude_bounds(&self) -> Result<(), ScenarioError> {
        let at = &self.safety.attitude;
        for i in 0..3 {
            non_negative(
                &format!("safety.attitude.arm_reaction_budget_rad_s2[{i}]"),
                at.arm_reaction_budget_rad_s2[i],
            )?;
        }
        for i in 0..7 {
            non_negative(
                &format!("safety.attitude.joint_coupling_budget_nm[{i}]"),
                at.joint_coupling_budget_nm[i],
            )?;
        }
        non_negative(
            "safety.attitude.angular_jerk_bound_rad_s3",
            at.angular_jerk_bound_rad_s3,
        )
    }

    fn validate_safety_robotic(&self) -> Result<(), ScenarioError> {
        let rb = &self.safety.robotic;
        finite_all("safety.robotic.theta_min_rad", &rb.theta_min_rad)?;
        finite_all("safety.robotic.theta_max_rad", &rb.theta_max_rad)?;
        for i in 0..7 {
            self.validate_joint(i)?;
        }
        non_negative("safety.robotic.eps_theta", rb.eps_theta)?;
        non_negative("safety.robotic.eps_theta_dot", rb.eps_theta_dot)?;
        non_negative("safety.robotic.eps_lb", rb.eps_lb)?;
        positive(
            "safety.robotic.gamma_theta_dot_per_s",
            rb.gamma_theta_dot_per_s,
        )?;
        positive("safety.robotic.u_max_theta_rad2_s2", rb.u_max_theta_rad2_s2)?;
        positive("safety.robotic.u_max_lb_m2_s2", rb.u_max_lb_m2_s2)?;
        for i in 0..7 {
            non_negative(
                &format!("safety.robotic.joint_jerk_bound_rad_s3[{i}]"),
                rb.joint_jerk_bound_rad_s3[i],
            )?;
            non_negative(
                &format!("safety.robotic.link_sphere_jerk_bound_m_s3[{i}]"),
                rb.link_sphere_jerk_bound_m_s3[i],
            )?;
        }
        Ok(())
    }

    /// Joint `i`'s limits are ordered, its rate limit positive, and the initial
    /// angle strictly inside the limits.
    fn validate_joint(&self, i: usize) -> Result<(), ScenarioError> {
        let rb = &self.safety.robotic;
        if rb.theta_min_rad[i] >= rb.theta_max_rad[i] {
            return Err(invalid(
                &format!("safety.robotic.theta_min_rad[{i}]"),
                rb.theta_min_rad[i],
                format!("limits with min >= max (max is {})", rb.theta_max_rad[i]),
            ));
        }
        positive(
            &format!("safety.robotic.theta_dot_max_rad_s[{i}]"),
            rb.theta_dot_max_rad_s[i],
        )?;
        let th = self.servicer.initial_theta_rad[i];
        if th <= rb.theta_min_rad[i] || th >= rb.theta_max_rad[i] {
            return Err(invalid(
                &format!("servicer.initial_theta_rad[{i}]"),
                th,
                format!(
                    "must lie strictly inside the joint limits ({}, {})",
                    rb.theta_min_rad[i], rb.theta_max_rad[i]
                ),
            ));
        }
        Ok(())
    }

    fn validate_safety_solver(&self) -> Result<(), ScenarioError> {
        let so = &self.safety.solver;
        if so.max_iterations == 0 {
            return Err(invalid("safety.solver.max_iterations", 0, "must be >= 1"));
        }
        if !(so.tolerance > 0.0 && so.tolerance <= 1e-3) {
            return Err(invalid(
                "safety.solver.tolerance",
                so.tolerance,
                "must be in (0, 1e-3]",
            ));
        }
        positive("safety.solver.slack_weight", so.slack_weight)
    }

    fn validate_safety_fallback(&self) -> Result<(), ScenarioError> {
        let fb = &self.safety.fallback;
        positive(
            "safety.fallback.translational_brake_time_s",
            fb.translational_brake_time_s,
        )?;
        positive(
            "safety.fallback.attitude_brake_time_s",
            fb.attitude_brake_time_s,
        )?;
        positive(
            "safety.fallback.robotic_brake_time_s",
            fb.robotic_brake_time_s,
        )
    }

    fn validate_nominal(&self) -> Result<(), ScenarioError> {
        self.validate_nominal_translational()?;
        self.validate_nominal_attitude()?;
        self.validate_nominal_robotic()
    }

    fn validate_nominal_translational(&self) -> Result<(), ScenarioError> {
        let nt = &self.nominal.translational;
        if nt.horizon_steps == 0 {
            return Err(invalid(
                "nominal.translational.horizon_steps",
                0,
                "must be >= 1",
            ));
        }
        positive("nominal.translational.gfc_distance_m", nt.gfc_distance_m)?;
        let caz_radius_m = self.safety.translational.caz_radius_m;
        if nt.gfc_distance_m <= caz_radius_m {
            return Err(invalid(
                "nominal.translational.gfc_distance_m",
                nt.gfc_distance_m,
                format!(
                    "the Go-for-Capture point must lie outside the CAZ (R_CAZ = {} m)",
                    caz_radius_m
                ),
            ));
        }
        non_negative("nominal.translational.weight_position", nt.weight_position)?;
        non_negative("nominal.translational.weight_velocity", nt.weight_velocity)?;
        positive("nominal.translational.weight_force", nt.weight_force)?;
        non_negative("nominal.translational.weight_terminal", nt.weight_terminal)
    }

    fn validate_nominal_attitude(&self) -> Result<(), ScenarioError> {
        let na = &self.nominal.attitude;
        non_negative("nominal.attitude.kp_nm_per_rad", na.kp_nm_per_rad)?;
        non_negative("nominal.attitude.kd_nm_s_per_rad", na.kd_nm_s_per_rad)?;
        non_negative(
            "nominal.attitude.sync_gain_nm_s_per_rad",
            na.sync_gain_nm_s_per_rad,
        )?;
        match (na.law, &na.mpc) {
            (crate::AttitudeLawKind::Mpc, None) => Err(invalid(
                "nominal.attitude.law",
                "mpc",
                "needs a [nominal.attitude.mpc] table (horizon_steps and the weights)",
            )),
            (_, Some(m)) => validate_attitude_mpc(m),
            _ => Ok(()),
        }
    }

    fn validate_nominal_robotic(&self) -> Result<(), ScenarioError> {
        let nr = &self.nominal.robotic;
        non_negative("nominal.robotic.kp_per_s2", nr.kp_per_s2)?;
        non_negative("nominal.robotic.kd_per_s", nr.kd_per_s)?;
        if nr.ik_iterations == 0 {
            return Err(invalid("nominal.robotic.ik_iterations", 0, "must be >= 1"));
        }
        positive("nominal.robotic.ik_damping", nr.ik_damping)?;
        positive("nominal.robotic.ik_tolerance_m", nr.ik_tolerance_m)
    }
}

/// The attitude MPC's horizon and weights.
fn validate_attitude_mpc(m: &crate::NominalAttitudeMpc) -> Result<(), ScenarioError> {
    if m.horizon_steps == 0 || m.horizon_steps > 1000 {
        return Err(invalid(
            "nominal.attitude.mpc.horizon_steps",
            m.horizon_steps,
            "must be 1..=1000",
        ));
    }
    non_negative(
        "nominal.attitude.mpc.weight_pointing_per_rad2",
        m.weight_pointing_per_rad2,
    )?;
    non_negative(
        "nominal.attitude.mpc.weight_rate_s2_per_rad2",
        m.weight_rate_s2_per_rad2,
    )?;
    positive(
        "nominal.attitude.mpc.weight_torque_per_nm2",
        m.weight_torque_per_nm2,
    )?;
    non_negative("nominal.attitude.mpc.weight_terminal", m.weight_terminal)
}

/// A relative bound above which a scaled mass or inertia could reach zero or flip a
/// principal moment's order: the plant would no longer be a plant.
const MAX_RELATIVE_MASS_ERROR: f64 = 0.5;
/// A misalignment beyond the small-angle regime the margins assume [rad] (≈ 5.7°).
const MAX_MISALIGNMENT_RAD: f64 = 0.1;

impl crate::Uncertainty {
    /// Every bound finite and ≥ 0; relative mass and inertia errors below
    /// [`MAX_RELATIVE_MASS_ERROR`], scale errors and ripple below 1, misalignment below
    /// [`MAX_MISALIGNMENT_RAD`]. `prefix` names the section in errors.
    pub fn validate(&self, prefix: &str) -> Result<(), ScenarioError> {
        let rel = MAX_RELATIVE_MASS_ERROR;
        let inf = f64::INFINITY;
        // one limit per scalar bound, in its order (a bound without one does not compile)
        let below: [f64; crate::uncertainty::SCALAR_BOUNDS] = [
            rel,
            rel,
            inf,
            rel,
            rel,
            rel,
            1.0,
            MAX_MISALIGNMENT_RAD,
            1.0,
            1.0,
            inf,
            1.0,
            inf,
        ];
        let checks = self
            .scalar_bounds()
            .into_iter()
            .zip(below)
            .map(|((key, v), b)| (key, v, b));
        for (key, v, below) in checks {
            bounded(&format!("{prefix}.{key}"), v, below)?;
        }
        for (key, b) in self.navigation.errors() {
            bounded(
                &format!("{prefix}.navigation.{key}.bias"),
                b.bias,
                f64::INFINITY,
            )?;
            bounded(
                &format!("{prefix}.navigation.{key}.noise"),
                b.noise,
                f64::INFINITY,
            )?;
        }
        Ok(())
    }
}

/// `v` finite, ≥ 0 and below `below`.
fn bounded(key: &str, v: f64, below: f64) -> Result<(), ScenarioError> {
    finite(key, v)?;
    if v < 0.0 || v >= below {
        let rule = if below.is_finite() {
            format!("a bound: at least 0 and below {below}")
        } else {
            "a bound: at least 0".into()
        };
        return Err(invalid(key, v, rule));
    }
    Ok(())
}
