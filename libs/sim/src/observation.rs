//! The simulator's observation of its true state, and the replayable trajectory row.

use crate::state::Simulator;
use nalgebra::Vector3;
use sc_core::Observation;
use sc_models::hill::HillFrame;
use sc_models::quat::{self, Quat};
use sc_multibody::Vector7;

impl Simulator {
    /// The observation of the current state.
    pub fn observe(&self) -> Observation {
        let s = &self.state;
        let hill = HillFrame::from_inertial_or(&s.r_t, &s.v_t, &self.p.orbit_normal);
        let (r_h, v_h) = hill.relative_to_hill(&s.dr, &s.dv);
        let q_ri = quat::conj(&self.p.q_ir);
        let r_ri = quat::to_matrix(&q_ri);
        let q_hi = quat::from_matrix(&hill.c_hi);
        let q_hr = quat::mul(&q_hi, &self.p.q_ir);
        let q_rb = quat::mul(&q_ri, &s.q_ib);
        let q_rt = quat::mul(&q_ri, &s.q_it);
        let r_rt = quat::to_matrix(&q_rt);
        let r_rb = quat::to_matrix(&q_rb);
        let r_r = r_ri * s.dr;
        let v_r = r_ri * s.dv;
        let w_dot_t = self.target_omega_dot();
        let w_r = r_rt * s.w_t;
        let wd_r = r_rt * w_dot_t;
        let grasp_r = r_rt * self.p.grasp_point_t;
        let grasp_v_r = w_r.cross(&grasp_r);
        let grasp_a_r = wd_r.cross(&grasp_r) + w_r.cross(&grasp_v_r);
        let kin = self.robot.kinematics_vel(&s.theta, &s.theta_dot);
        let ee_b = self.robot.ee_position(&kin);
        let ee_rel_v_b = self.robot.ee_jacobian(&kin).fixed_rows::<3>(0) * s.theta_dot;
        let ee_r = r_r + r_rb * ee_b;
        let ee_v_r = v_r + r_rb * (s.w_b.cross(&ee_b) + ee_rel_v_b);
        let com_b = self.robot.center_of_mass(&s.theta);
        let com_rel_v_b = self.robot.center_of_mass_velocity(&s.theta, &s.theta_dot);
        let r_ib = quat::to_matrix(&s.q_ib);
        let dr_com = s.dr + r_ib * com_b;
        let dv_com = s.dv + r_ib * (s.w_b.cross(&com_b) + com_rel_v_b);
        let (com_h, com_v_h) = hill.relative_to_hill(&dr_com, &dv_com);
        Observation {
            step: self.step,
            t: s.t,
            r_h,
            v_h,
            r_r,
            v_r,
            q_hr,
            omega_h: hill.omega,
            omega_dot_h: hill.omega_dot,
            mean_motion: hill.omega.norm(),
            q_rb,
            omega_b: s.w_b,
            theta: s.theta,
            theta_dot: s.theta_dot,
            q_rt,
            omega_t: s.w_t,
            omega_dot_t: w_dot_t,
            grasp_r,
            grasp_v_r,
            grasp_a_r,
            grasp_b: Observation::grasp_in_base(&q_rb, &r_r, &grasp_r),
            ee_b,
            ee_r,
            ee_v_r,
            com_h,
            com_v_h,
            com_r: r_ri * dr_com,
            com_v_r: r_ri * dv_com,
        }
    }

    /// One row of the replayable trajectory (inertial states of both spacecraft).
    pub fn trajectory_row(&self) -> TrajectoryRow {
        let s = &self.state;
        let o = self.observe();
        TrajectoryRow {
            t: s.t,
            servicer_r_i: s.r_t + s.dr,
            servicer_v_i: s.v_t + s.dv,
            servicer_q_ib: s.q_ib,
            servicer_w_b: s.w_b,
            target_r_i: s.r_t,
            target_v_i: s.v_t,
            target_q_it: s.q_it,
            target_w_t: s.w_t,
            theta: s.theta,
            theta_dot: s.theta_dot,
            r_h: o.r_h,
            v_h: o.v_h,
        }
    }
}

/// One line of the `simulate` trajectory CSV; see [`TRAJECTORY_COLUMNS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryRow {
    pub t: f64,
    pub servicer_r_i: Vector3<f64>,
    pub servicer_v_i: Vector3<f64>,
    pub servicer_q_ib: Quat,
    pub servicer_w_b: Vector3<f64>,
    pub target_r_i: Vector3<f64>,
    pub target_v_i: Vector3<f64>,
    pub target_q_it: Quat,
    pub target_w_t: Vector3<f64>,
    pub theta: Vector7,
    pub theta_dot: Vector7,
    pub r_h: Vector3<f64>,
    pub v_h: Vector3<f64>,
}

/// Columns of the trajectory CSV, in order (SI units; `_i` inertial frame, `_b` servicer
/// base frame, `_t` target frame, `_h` Hill frame; quaternions scalar-first, rotating
/// body vectors into the inertial frame).
pub const TRAJECTORY_COLUMNS: [&str; 54] = [
    "t_s",
    "servicer_x_i_m",
    "servicer_y_i_m",
    "servicer_z_i_m",
    "servicer_vx_i_m_s",
    "servicer_vy_i_m_s",
    "servicer_vz_i_m_s",
    "servicer_q0_ib",
    "servicer_q1_ib",
    "servicer_q2_ib",
    "servicer_q3_ib",
    "servicer_wx_b_rad_s",
    "servicer_wy_b_rad_s",
    "servicer_wz_b_rad_s",
    "target_x_i_m",
    "target_y_i_m",
    "target_z_i_m",
    "target_vx_i_m_s",
    "target_vy_i_m_s",
    "target_vz_i_m_s",
    "target_q0_it",
    "target_q1_it",
    "target_q2_it",
    "target_q3_it",
    "target_wx_t_rad_s",
    "target_wy_t_rad_s",
    "target_wz_t_rad_s",
    "theta_1_rad",
    "theta_2_rad",
    "theta_3_rad",
    "theta_4_rad",
    "theta_5_rad",
    "theta_6_rad",
    "theta_7_rad",
    "theta_dot_1_rad_s",
    "theta_dot_2_rad_s",
    "theta_dot_3_rad_s",
    "theta_dot_4_rad_s",
    "theta_dot_5_rad_s",
    "theta_dot_6_rad_s",
    "theta_dot_7_rad_s",
    "r_h_x_m",
    "r_h_y_m",
    "r_h_z_m",
    "v_h_x_m_s",
    "v_h_y_m_s",
    "v_h_z_m_s",
    "grasp_distance_m",
    "ee_x_b_m",
    "ee_y_b_m",
    "ee_z_b_m",
    "grasp_x_b_m",
    "grasp_y_b_m",
    "grasp_z_b_m",
];

impl TrajectoryRow {
    /// Values in the order of [`TRAJECTORY_COLUMNS`]; `extra` = (grasp distance, EE in F_B, grasp in F_B).
    pub fn values(&self, o: &Observation) -> Vec<f64> {
        let mut v = Vec::with_capacity(TRAJECTORY_COLUMNS.len());
        v.push(self.t);
        v.extend(self.servicer_r_i.iter());
        v.extend(self.servicer_v_i.iter());
        v.extend(self.servicer_q_ib.iter());
        v.extend(self.servicer_w_b.iter());
        v.extend(self.target_r_i.iter());
        v.extend(self.target_v_i.iter());
        v.extend(self.target_q_it.iter());
        v.extend(self.target_w_t.iter());
        v.extend(self.theta.iter());
        v.extend(self.theta_dot.iter());
        v.extend(self.r_h.iter());
        v.extend(self.v_h.iter());
        v.push(o.grasp_distance());
        v.extend(o.ee_b.iter());
        v.extend(o.grasp_b.iter());
        v
    }
}
