//! The stages of one control step as pure functions of their inputs. The in-process
//! [`crate::Mission`] and every process of the partition call exactly these, in the
//! causal order translational → attitude → robotic.

use nalgebra::{Matrix3, Vector3};
use sc_cbf::monitor::MonitorState;
use sc_cbf::{AttitudeInput, RoboticInput, TranslationalInput, attitude::tidal_acceleration};
use sc_models::quat;
use sc_multibody::{Robot, Vector7};
use sc_nominal::NominalInput;
use sc_sim::{BarrierState, Observation};

/// What the safety monitor reads, from an observation (the true state at a control step).
pub fn monitor_state(o: &Observation) -> MonitorState {
    MonitorState {
        com_r: o.com_r,
        q_rb: o.q_rb,
        omega_b: o.omega_b,
        grasp_r: o.grasp_r,
        theta: o.theta,
        theta_dot: o.theta_dot,
    }
}

/// What the safety monitor reads, from the simulator's state at a physics step.
pub fn monitor_state_between(b: &BarrierState) -> MonitorState {
    MonitorState {
        com_r: b.com_r,
        q_rb: b.q_rb,
        omega_b: b.omega_b,
        grasp_r: b.grasp_r,
        theta: b.theta,
        theta_dot: b.theta_dot,
    }
}

/// Input of the nominal controllers from an observation.
pub fn nominal_input(o: &Observation) -> NominalInput {
    NominalInput::from_observation(o)
}

/// Input of the translational filter (ξ_tr = 0: it runs first): the servicer's CoM.
pub fn translational_input(o: &Observation) -> TranslationalInput {
    TranslationalInput {
        r_h: o.com_h,
        v_h: o.com_v_h,
        q_hr: o.q_hr,
        omega_h: o.omega_h,
        omega_dot_h: o.omega_dot_h,
        q_rb: o.q_rb,
        omega_b: o.omega_b,
    }
}

/// Input of the attitude filter; `f_b_sf` is the upstream safe (actuated) force in F_B,
/// which enters as ξ_att (the CoM's acceleration along the line of sight, and its torque
/// about the system CoM in the base dynamics). A non-finite state gives NaN dynamics, which
/// the filter refuses (its braking law then applies).
pub fn attitude_input(o: &Observation, robot: &Robot, f_b_sf: &Vector3<f64>) -> AttitudeInput {
    let mass = robot.total_mass();
    let r_rh = quat::to_matrix(&quat::conj(&o.q_hr));
    let radial_r = r_rh * Vector3::x();
    let r_bt = quat::to_matrix(&quat::mul(&quat::conj(&o.q_rb), &o.q_rt));
    let nan3 = Vector3::from_element(f64::NAN);
    let nan73 = nalgebra::SMatrix::<f64, 7, 3>::from_element(f64::NAN);
    let nan7 = Vector7::from_element(f64::NAN);
    let finite = f_b_sf.iter().all(|x| x.is_finite());
    let (p, r) = robot
        .base_angular_dynamics(&o.theta, &o.theta_dot, &o.omega_b, f_b_sf)
        .filter(|_| finite)
        .map(|d| (d.p_locked, d.r_locked))
        .unwrap_or((Matrix3::from_element(f64::NAN), nan3));
    let wrench = nalgebra::Vector6::new(f_b_sf.x, f_b_sf.y, f_b_sf.z, 0.0, 0.0, 0.0);
    let (k_tau, k_force) = robot
        .reduced_arm_dynamics(&o.theta, &o.theta_dot, &o.omega_b, &wrench)
        .filter(|_| finite)
        .map(|d| (d.wrench_map.fixed_columns::<3>(3).into(), d.xi))
        .unwrap_or((nan73, nan7));
    AttitudeInput {
        q_rb: o.q_rb,
        omega_b: o.omega_b,
        p,
        r,
        r_r: o.com_r,
        v_r: o.com_v_r,
        a_drift_r: tidal_acceleration(o.mean_motion, &radial_r, &o.com_r),
        grasp_r: o.grasp_r,
        grasp_vel_r: o.grasp_v_r,
        grasp_acc_r: o.grasp_a_r,
        xi_r: sc_cbf::attitude::xi_att_from_force(f_b_sf, &o.q_rb, mass),
        omega_target_b: r_bt * o.omega_t,
        joint_coupling: k_tau,
        joint_coupling_force: k_force,
    }
}

/// Input of the robotic filter; the upstream safe force and torque (F_B) enter as ξ_rob.
/// `None` when the model cannot be evaluated (non-finite state): the filter's fallback applies.
pub fn robotic_input(
    o: &Observation,
    robot: &Robot,
    f_b_sf: &Vector3<f64>,
    tau_b_sf: &Vector3<f64>,
) -> Option<RoboticInput> {
    sc_cbf::robotic_input_from_model(robot, &o.theta, &o.theta_dot, &o.omega_b, f_b_sf, tau_b_sf)
}

/// One robotic filter step on nominal `tau_m_nom` (`None`: missing): the filter on
/// [`robotic_input`], or the braking output of [`robotic_invalid_state`] when the model
/// cannot be evaluated.
pub fn robotic_step(
    filter: &mut sc_cbf::RoboticFilter,
    o: &Observation,
    robot: &Robot,
    f_b_sf: &Vector3<f64>,
    tau_b_sf: &Vector3<f64>,
    tau_m_nom: Option<&Vector7>,
) -> sc_cbf::RoboticOutput {
    match robotic_input(o, robot, f_b_sf, tau_b_sf) {
        Some(x) => filter.filter_with(&x, tau_m_nom),
        None => robotic_invalid_state(),
    }
}

/// Saturates a nominal command to the actuator bounds (what the hardware does when no
/// filter is in the loop); non-finite components become zero.
pub fn saturate<const M: usize>(
    u: &nalgebra::SVector<f64, M>,
    limit: f64,
) -> nalgebra::SVector<f64, M> {
    u.map(|x| {
        if x.is_finite() {
            x.clamp(-limit, limit)
        } else {
            0.0
        }
    })
}

/// `f_B = R_BH f_H` for a force given in the Hill frame.
pub fn hill_to_body(o: &Observation, f_h: &Vector3<f64>) -> Vector3<f64> {
    let r_hb = quat::to_matrix(&quat::mul(&o.q_hr, &o.q_rb));
    r_hb.transpose() * f_h
}

/// The robotic filter's defined output when its model cannot even be evaluated (a
/// non-finite state): zero joint torque, status `Fallback`, flag `INVALID_STATE`.
pub fn robotic_invalid_state() -> sc_cbf::RoboticOutput {
    let mut report = sc_cbf::FilterReport::default();
    report.faults |= sc_cbf::faults::INVALID_STATE;
    sc_cbf::FilterOutput {
        u: Vector7::zeros(),
        actuated: Vector7::zeros(),
        report,
    }
}
