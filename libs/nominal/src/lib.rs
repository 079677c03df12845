//! Reference nominal controllers of the servicer — **deliberately constraint-unaware**.
//!
//! The paper (Sec. "Nominal Controllers") runs MPCs for translation and attitude and a
//! joint-space PD computed-torque controller for the arm with *all constraints inactive*
//! "to eventually obtain unsafe nominal control inputs"; the subsystem safety filters
//! then minimally modify them. Accordingly nothing here saturates a command or looks
//! at the approach corridor, the collision-avoidance zone, the line-of-sight cone, the
//! rate limits or the joint limits (the IK alone respects the URDF joint range).
//!
//! * [`translational::TranslationalMpc`]: unconstrained CW MPC to the Go-for-Capture
//!   point, closed-form gain, output `f_H` [N] in the Hill frame.
//! * [`attitude::AttitudeController`]: boresight pointing at the grasping point and
//!   rate synchronisation with the target, output `τ_B` [N m] in F_B; its feedback is the
//!   unconstrained attitude MPC [`attitude_mpc::AttitudeMpc`] (the paper's) or a PD.
//! * [`robotic::RoboticController`]: PD computed torque to the initial joint angles
//!   (hold) or to a DLS-IK solution of the grasping point (grasp), output `τ_M` [N m].
//! * [`NominalControllers`]: selects per mission phase which of them run, from a plain
//!   observation [`NominalInput`]; returns [`NominalOutput`].
//!
//! Frames and conventions follow `sc-models`: scalar-first quaternions, `q_AB`
//! rotates F_B vectors into F_A; F_H Hill frame, F_R inertially fixed reference frame
//! (target-centred), F_B servicer base, F_T target body. SI units.
//!
//! Robustness: library calls never panic on bad input. A subsystem whose inputs are
//! non-finite (or a quaternion that cannot be normalised) returns a **zero command
//! flagged [`SubsystemStatus::InvalidInput`]**; construction errors are
//! [`NominalError`]. Everything is deterministic (no clocks, no randomness).

pub mod attitude;
pub mod attitude_mpc;
pub mod condensed;
pub mod robotic;
pub mod translational;

use attitude::{AttitudeController, AttitudeGains, AttitudeInput, AttitudeLaw, AttitudeTask};
use attitude_mpc::{AttitudeMpc, AttitudeMpcParams};
use robotic::{IkSolution, RoboticController, RoboticGains};
use sc_core::{Observation, Subsystem, SubsystemSet};
use sc_models::quat::{self, Quat};
use sc_models::{Mat3, Vec3};
use sc_multibody::{Robot, Vector7};
use sc_scenario::{AttitudeLawKind, AttitudeMode, RoboticMode, Scenario, TranslationalMode};
use translational::{TranslationalMpc, TranslationalMpcParams};

pub use sc_multibody::Vector7 as JointVector;

/// Construction errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NominalError {
    /// A parameter is non-finite or out of range; the message names it.
    #[error("invalid nominal-controller parameter: {0}")]
    Param(String),
}

/// What a subsystem's controller did in one step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SubsystemStatus {
    /// The controller ran and produced the command.
    Active,
    /// The phase switches the controller off: zero command.
    Off,
    /// Inputs were non-finite or degenerate: zero command (the safety layer must
    /// fall back).
    InvalidInput,
}

/// Plain observation of the state, filled by the integrator from the simulator or
/// the navigation. SI units; frames as named.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NominalInput {
    /// Mission time since the start of the run [s]; selects the phase.
    pub t: f64,
    /// `q_HR`: rotates F_R vectors into the Hill frame F_H.
    pub q_hr: Quat,
    /// `ω_H`: angular velocity of F_H w.r.t. inertial space, in F_H [rad/s]
    /// (`[0, 0, n]` on a circular orbit).
    pub omega_h: Vec3,
    /// `r_R`: servicer base origin w.r.t. the target CoM, in F_R [m].
    pub r_r: Vec3,
    /// `v_R = ṙ_R`, in the non-rotating F_R [m/s].
    pub v_r: Vec3,
    /// `q_RB`: servicer attitude, rotates F_B vectors into F_R.
    pub q_rb: Quat,
    /// `ω_B`: servicer base angular velocity (inertial), in F_B [rad/s].
    pub omega_b: Vec3,
    /// `q_RT`: target attitude, rotates F_T vectors into F_R.
    pub q_rt: Quat,
    /// `ω_T`: target angular velocity (inertial), in F_T [rad/s].
    pub omega_t: Vec3,
    /// Joint angles θ [rad].
    pub theta: Vector7,
    /// Joint rates θ̇ [rad/s].
    pub theta_dot: Vector7,
}

impl NominalInput {
    /// What the nominal controllers read of the known state.
    pub fn from_observation(o: &Observation) -> Self {
        Self {
            t: o.t,
            q_hr: o.q_hr,
            omega_h: o.omega_h,
            r_r: o.r_r,
            v_r: o.v_r,
            q_rb: o.q_rb,
            omega_b: o.omega_b,
            q_rt: o.q_rt,
            omega_t: o.omega_t,
            theta: o.theta,
            theta_dot: o.theta_dot,
        }
    }
}

/// Nominal commands and diagnostics of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NominalOutput {
    /// Index of the active mission phase.
    pub phase: usize,
    /// `f_H,nom`: force in the Hill frame F_H [N], unsaturated.
    pub f_h: Vec3,
    /// `τ_B,nom`: base torque in F_B [N m], unsaturated.
    pub tau_b: Vec3,
    /// `τ_M,nom`: joint torques [N m], unsaturated.
    pub tau_m: Vector7,
    pub translational: SubsystemStatus,
    pub attitude: SubsystemStatus,
    pub robotic: SubsystemStatus,
    /// Go-for-Capture point in F_H at this instant [m] (zeros unless active).
    pub gfc_point_h: Vec3,
    /// Angle between boresight and line of sight to the grasping point [rad]
    /// (0 unless the attitude controller is active).
    pub pointing_error_rad: f64,
    /// `ω_B − ω_ref` in F_B [rad/s] (zeros unless active).
    pub rate_error_b: Vec3,
    /// Joint-angle goal of the robotic controller [rad] (zeros unless active).
    pub theta_goal: Vector7,
    /// IK outcome in grasp mode.
    pub ik: Option<IkSolution>,
}

/// Modes of one mission phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseModes {
    /// Start time of the phase [s].
    pub start_s: f64,
    pub translational: TranslationalMode,
    pub attitude: AttitudeMode,
    pub robotic: RoboticMode,
}

/// `Active` for a valid command, `InvalidInput` otherwise.
fn status(valid: bool) -> SubsystemStatus {
    if valid {
        SubsystemStatus::Active
    } else {
        SubsystemStatus::InvalidInput
    }
}

impl NominalOutput {
    /// Every subsystem `Off` with zero commands and diagnostics, in phase `phase`.
    fn off(phase: usize) -> Self {
        Self {
            phase,
            f_h: Vec3::zeros(),
            tau_b: Vec3::zeros(),
            tau_m: Vector7::zeros(),
            translational: SubsystemStatus::Off,
            attitude: SubsystemStatus::Off,
            robotic: SubsystemStatus::Off,
            gfc_point_h: Vec3::zeros(),
            pointing_error_rad: 0.0,
            rate_error_b: Vec3::zeros(),
            theta_goal: Vector7::zeros(),
            ik: None,
        }
    }
}

/// The translational MPC: mean motion `n = √(μ / (R_E + h)³)`, mass = total servicer
/// mass, Go-for-Capture point `p_gfc,R = gfc_distance_m · d_R`.
fn translational_mpc(scenario: &Scenario, robot: &Robot) -> Result<TranslationalMpc, NominalError> {
    let orbit = &scenario.orbit;
    let a = orbit.earth_radius_m + orbit.altitude_m;
    let n = (orbit.earth_mu_m3_s2 / (a * a * a)).sqrt();
    let d_r = Vec3::from(scenario.safety.translational.corridor_axis);
    let d_norm = d_r.norm();
    if !d_norm.is_finite() || d_norm < 1e-9 {
        return Err(NominalError::Param(format!("corridor_axis = {d_r:?}")));
    }
    let nt = &scenario.nominal.translational;
    TranslationalMpc::new(TranslationalMpcParams {
        mean_motion: n,
        mass: robot.total_mass(),
        dt: scenario.mission.control_period_s,
        horizon: nt.horizon_steps as usize,
        gfc_point_r: d_r / d_norm * nt.gfc_distance_m,
        weight_position: nt.weight_position,
        weight_velocity: nt.weight_velocity,
        weight_force: nt.weight_force,
        weight_terminal: nt.weight_terminal,
    })
}

/// The attitude controller with the scenario's law (the MPC on the servicer's inertia
/// at the hold angles, or the PD), boresight and, when both axes are given, the
/// gripper's alignment with the fixture.
fn attitude_controller(
    scenario: &Scenario,
    inertia_hold: Mat3,
) -> Result<AttitudeController, NominalError> {
    let na = &scenario.nominal.attitude;
    let target_inertia = Mat3::from_fn(|i, j| scenario.target.inertia_kg_m2[i][j]);
    let law = match (na.law, &na.mpc) {
        (AttitudeLawKind::Mpc, Some(m)) => {
            AttitudeLaw::Mpc(Box::new(AttitudeMpc::new(AttitudeMpcParams {
                dt: scenario.mission.control_period_s,
                horizon: m.horizon_steps as usize,
                inertia: inertia_hold,
                weight_pointing: m.weight_pointing_per_rad2,
                weight_rate: m.weight_rate_s2_per_rad2,
                weight_torque: m.weight_torque_per_nm2,
                weight_terminal: m.weight_terminal,
            })?))
        }
        (AttitudeLawKind::Mpc, None) => {
            return Err(NominalError::Param(
                "nominal.attitude.law = mpc without [nominal.attitude.mpc]".into(),
            ));
        }
        (AttitudeLawKind::Pd, _) => AttitudeLaw::Pd(AttitudeGains {
            kp: na.kp_nm_per_rad,
            kd: na.kd_nm_s_per_rad,
            k_sync: na.sync_gain_nm_s_per_rad,
        }),
    };
    let attitude = AttitudeController::with_law(
        law,
        Vec3::from(scenario.servicer.boresight_body),
        Some(target_inertia),
    )
    .ok_or_else(|| NominalError::Param("attitude gains or boresight".into()))?;
    match (
        scenario.servicer.gripper_axis_body,
        scenario.target.grasp_fixture_axis,
    ) {
        (Some(g), Some(a)) => attitude
            .with_alignment(Vec3::from(g), Vec3::from(a))
            .ok_or_else(|| NominalError::Param("gripper_axis_body or grasp_fixture_axis".into())),
        _ => Ok(attitude),
    }
}

/// The phases' modes sorted by start time.
fn phase_schedule(scenario: &Scenario) -> Result<Vec<PhaseModes>, NominalError> {
    let mut phases: Vec<PhaseModes> = scenario
        .mission
        .phases
        .iter()
        .map(|p| PhaseModes {
            start_s: p.start_s,
            translational: p.translational,
            attitude: p.attitude,
            robotic: p.robotic,
        })
        .collect();
    if phases.is_empty() || phases.iter().any(|p| !p.start_s.is_finite()) {
        return Err(NominalError::Param(
            "mission.phases empty or non-finite start".into(),
        ));
    }
    phases.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
    Ok(phases)
}

/// The three nominal controllers and the phase schedule that switches them.
#[derive(Debug, Clone)]
pub struct NominalControllers {
    phases: Vec<PhaseModes>,
    translational: TranslationalMpc,
    attitude: AttitudeController,
    robotic: RoboticController,
    robot: Robot,
    /// Grasping point `p_G,T` in F_T [m].
    grasp_point_t: Vec3,
    /// θ of hold mode [rad].
    theta_hold: Vector7,
    /// Servicer inertia about its CoM at `theta_hold`, F_B; used if θ is non-finite.
    inertia_hold: Mat3,
}

impl NominalControllers {
    /// Builds the controllers from the scenario (`[nominal.*]`, `[mission]`,
    /// geometry) and the servicer model (mass, inertia, kinematics, dynamics).
    ///
    /// * mean motion `n = √(μ / (R_E + h)³)`, mass = total servicer mass;
    /// * `p_gfc,R = gfc_distance_m · d_R` (`d_R` = `safety.translational.corridor_axis`);
    /// * boresight `servicer.boresight_body`, grasping point `target.grasp_point_m`;
    /// * hold goal `servicer.initial_theta_rad`.
    pub fn new(scenario: &Scenario, robot: Robot) -> Result<Self, NominalError> {
        let translational = translational_mpc(scenario, &robot)?;
        let theta_hold = Vector7::from(scenario.servicer.initial_theta_rad);
        let grasp_point_t = Vec3::from(scenario.target.grasp_point_m);
        if !theta_hold
            .iter()
            .chain(grasp_point_t.iter())
            .all(|x| x.is_finite())
        {
            return Err(NominalError::Param(
                "initial_theta_rad or grasp_point_m".into(),
            ));
        }
        let inertia_hold = robot.system_inertia_com(&theta_hold);
        let attitude = attitude_controller(scenario, inertia_hold)?;
        let nr = &scenario.nominal.robotic;
        let robotic = RoboticController::new(
            RoboticGains {
                kp: nr.kp_per_s2,
                kd: nr.kd_per_s,
                ik_iterations: nr.ik_iterations,
                ik_damping: nr.ik_damping,
                ik_tolerance: nr.ik_tolerance_m,
            },
            &robot,
        )
        .ok_or_else(|| NominalError::Param("robotic gains or IK settings".into()))?;
        Ok(Self {
            phases: phase_schedule(scenario)?,
            translational,
            attitude,
            robotic,
            robot,
            grasp_point_t,
            theta_hold,
            inertia_hold,
        })
    }

    /// The phase schedule (sorted by start time).
    pub fn phases(&self) -> &[PhaseModes] {
        &self.phases
    }

    /// Index of the phase active at `t` [s]: the last phase with `start_s ≤ t`
    /// (1e-9 s tolerance), the first phase before its start or for non-finite `t`.
    pub fn phase_at(&self, t: f64) -> usize {
        if !t.is_finite() {
            return 0;
        }
        self.phases
            .iter()
            .rposition(|p| t + 1e-9 >= p.start_s)
            .unwrap_or(0)
    }

    pub fn translational(&self) -> &TranslationalMpc {
        &self.translational
    }
    pub fn attitude(&self) -> &AttitudeController {
        &self.attitude
    }
    pub fn robotic(&self) -> &RoboticController {
        &self.robotic
    }
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// Grasping point and its velocity w.r.t. the target CoM in F_R [m, m/s]:
    /// `R_RT p_G,T` and `R_RT (ω_T × p_G,T)`. `None` if `q_rt` cannot be normalised.
    pub fn grasp_point_r(&self, q_rt: &Quat, omega_t: &Vec3) -> Option<(Vec3, Vec3)> {
        let r_rt = quat::to_matrix(&quat::normalized(q_rt)?);
        Some((
            r_rt * self.grasp_point_t,
            r_rt * omega_t.cross(&self.grasp_point_t),
        ))
    }

    /// Runs the controllers of the phase active at `x.t`. Never panics; see
    /// [`SubsystemStatus`] for the handling of bad inputs. A non-finite `t` makes
    /// every subsystem `InvalidInput`.
    pub fn command(&self, x: &NominalInput) -> NominalOutput {
        self.command_subsystems(x, SubsystemSet::ALL)
    }

    /// Like [`Self::command`] but computes only the selected subsystems (the others
    /// stay `Off` with a zero command). Each selected subsystem's command is exactly
    /// what [`Self::command`] returns for it: one process per controller gives the
    /// same results as all three in one process.
    pub fn command_subsystems(&self, x: &NominalInput, which: SubsystemSet) -> NominalOutput {
        let phase = self.phase_at(x.t);
        let modes = self.phases[phase];
        let mut out = NominalOutput::off(phase);
        if !x.t.is_finite() {
            out.translational = SubsystemStatus::InvalidInput;
            out.attitude = SubsystemStatus::InvalidInput;
            out.robotic = SubsystemStatus::InvalidInput;
            return out;
        }
        if which.contains(Subsystem::Translational)
            && modes.translational == TranslationalMode::Approach
        {
            self.command_translational(x, &mut out);
        }
        let grasp = self.grasp_point_r(&x.q_rt, &x.omega_t);
        let theta_ok = x.theta.iter().all(|v| v.is_finite());
        let task = match modes.attitude {
            AttitudeMode::Point => Some(AttitudeTask::Point),
            AttitudeMode::PointAndSync => Some(AttitudeTask::PointAndSync),
            AttitudeMode::Off => None,
        };
        if let Some(task) = task.filter(|_| which.contains(Subsystem::Attitude)) {
            self.command_attitude(x, task, grasp, theta_ok, &mut out);
        }
        let robotic_mode = if which.contains(Subsystem::Robotic) {
            modes.robotic
        } else {
            RoboticMode::Off
        };
        match robotic_mode {
            RoboticMode::Off => {}
            RoboticMode::Hold => {
                let c = self.robotic.computed_torque(
                    &self.robot,
                    &x.theta,
                    &x.theta_dot,
                    &self.theta_hold,
                    &Vector7::zeros(),
                );
                out.tau_m = c.tau_m;
                out.theta_goal = c.theta_goal;
                out.robotic = status(c.valid);
            }
            RoboticMode::Grasp => {
                let valid = theta_ok && self.command_grasp(x, grasp, &mut out);
                if !valid {
                    out.tau_m = Vector7::zeros();
                }
                out.robotic = status(valid);
            }
        }
        if out.translational == SubsystemStatus::InvalidInput {
            out.f_h = Vec3::zeros();
        }
        if out.attitude == SubsystemStatus::InvalidInput {
            out.tau_b = Vec3::zeros();
        }
        out
    }

    /// The translational MPC's force in F_H towards the Go-for-Capture point, from the
    /// state taken into the Hill frame.
    fn command_translational(&self, x: &NominalInput, out: &mut NominalOutput) {
        let valid = match quat::normalized(&x.q_hr) {
            Some(q_hr) => {
                let r_hr = quat::to_matrix(&q_hr);
                let r_h = r_hr * x.r_r;
                let v_h = r_hr * x.v_r - x.omega_h.cross(&r_h);
                let c = self.translational.command(&r_h, &v_h, &q_hr, &x.omega_h);
                out.f_h = c.f_h;
                out.gfc_point_h = c.gfc_point_h;
                c.valid
            }
            None => false,
        };
        out.translational = status(valid);
    }

    /// The attitude controller's torque for `task`, pointing at the grasping point
    /// `grasp` (position and velocity in F_R); the servicer's inertia at the current
    /// joint angles (at the hold angles when those are not finite).
    fn command_attitude(
        &self,
        x: &NominalInput,
        task: AttitudeTask,
        grasp: Option<(Vec3, Vec3)>,
        theta_ok: bool,
        out: &mut NominalOutput,
    ) {
        let valid = match grasp {
            Some((p_g, v_g)) => {
                let inertia_b = if theta_ok {
                    self.robot.system_inertia_com(&x.theta)
                } else {
                    self.inertia_hold
                };
                let c = self.attitude.command(
                    task,
                    &AttitudeInput {
                        q_rb: x.q_rb,
                        omega_b: x.omega_b,
                        inertia_b,
                        r_r: x.r_r,
                        v_r: x.v_r,
                        grasp_r: p_g,
                        grasp_vel_r: v_g,
                        q_rt: x.q_rt,
                        omega_t: x.omega_t,
                    },
                );
                out.tau_b = c.tau_b;
                out.pointing_error_rad = c.pointing_error_rad;
                out.rate_error_b = c.rate_error;
                c.valid
            }
            None => false,
        };
        out.attitude = status(valid);
    }

    /// Grasp mode (with finite joint angles): computed torque to the IK solution of the
    /// grasping point in F_B, with the DLS rate of its motion as feed-forward. `false`
    /// when an input is degenerate or the result is not valid.
    fn command_grasp(
        &self,
        x: &NominalInput,
        grasp: Option<(Vec3, Vec3)>,
        out: &mut NominalOutput,
    ) -> bool {
        let (Some((p_g, v_g)), Some(q_rb)) = (grasp, quat::normalized(&x.q_rb)) else {
            return false;
        };
        let r_br = quat::to_matrix(&q_rb).transpose();
        // grasping point relative to the base origin, in F_B, and its rate of change as
        // seen in the rotating F_B
        let p_gb = r_br * (p_g - x.r_r);
        let v_gb = r_br * (v_g - x.v_r) - x.omega_b.cross(&p_gb);
        let ik = self
            .robotic
            .inverse_kinematics(&self.robot, &p_gb, &x.theta);
        let rate_ff = if v_gb.iter().all(|v| v.is_finite()) {
            self.robotic.dls_rate(&self.robot, &ik.theta, &v_gb)
        } else {
            Vector7::zeros()
        };
        let c =
            self.robotic
                .computed_torque(&self.robot, &x.theta, &x.theta_dot, &ik.theta, &rate_ff);
        out.tau_m = c.tau_m;
        out.theta_goal = c.theta_goal;
        out.ik = Some(ik);
        c.valid && ik.error_m.is_finite()
    }
}
