//! Exact conversions between the in-process types (sc-sim, sc-cbf, sc-mission) and
//! the ICD messages. Every f64 is copied bit for bit, so a stage fed from a message
//! computes exactly what it computes in one process.

use nalgebra::{SVector, Vector3};
use sc_cbf::{FilterOutput, FilterReport, FilterStatus};
use sc_icd::{SimState, StepResult};
use sc_multibody::Vector7;
use sc_sim::{Command, Observation};

fn a3(v: &Vector3<f64>) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

fn a7(v: &Vector7) -> [f64; 7] {
    let mut o = [0.0; 7];
    o.copy_from_slice(v.as_slice());
    o
}

fn v3(a: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

fn v7(a: &[f64; 7]) -> Vector7 {
    Vector7::from_column_slice(a)
}

/// The state message of an observation (tick fields left for the caller).
pub fn sim_state(o: &Observation) -> SimState {
    SimState {
        step: o.step,
        t: o.t,
        r_h: a3(&o.r_h),
        v_h: a3(&o.v_h),
        r_r: a3(&o.r_r),
        v_r: a3(&o.v_r),
        q_hr: o.q_hr,
        omega_h: a3(&o.omega_h),
        omega_dot_h: a3(&o.omega_dot_h),
        mean_motion: o.mean_motion,
        q_rb: o.q_rb,
        omega_b: a3(&o.omega_b),
        theta: a7(&o.theta),
        theta_dot: a7(&o.theta_dot),
        q_rt: o.q_rt,
        omega_t: a3(&o.omega_t),
        omega_dot_t: a3(&o.omega_dot_t),
        grasp_r: a3(&o.grasp_r),
        grasp_v_r: a3(&o.grasp_v_r),
        grasp_a_r: a3(&o.grasp_a_r),
        grasp_b: a3(&o.grasp_b),
        ee_b: a3(&o.ee_b),
        ee_r: a3(&o.ee_r),
        ee_v_r: a3(&o.ee_v_r),
        com_h: a3(&o.com_h),
        com_v_h: a3(&o.com_v_h),
        com_r: a3(&o.com_r),
        com_v_r: a3(&o.com_v_r),
        ..SimState::default()
    }
}

/// The observation carried by a state message.
pub fn observation(s: &SimState) -> Observation {
    Observation {
        step: s.step,
        t: s.t,
        r_h: v3(&s.r_h),
        v_h: v3(&s.v_h),
        r_r: v3(&s.r_r),
        v_r: v3(&s.v_r),
        q_hr: s.q_hr,
        omega_h: v3(&s.omega_h),
        omega_dot_h: v3(&s.omega_dot_h),
        mean_motion: s.mean_motion,
        q_rb: s.q_rb,
        omega_b: v3(&s.omega_b),
        theta: v7(&s.theta),
        theta_dot: v7(&s.theta_dot),
        q_rt: s.q_rt,
        omega_t: v3(&s.omega_t),
        omega_dot_t: v3(&s.omega_dot_t),
        grasp_r: v3(&s.grasp_r),
        grasp_v_r: v3(&s.grasp_v_r),
        grasp_a_r: v3(&s.grasp_a_r),
        grasp_b: v3(&s.grasp_b),
        ee_b: v3(&s.ee_b),
        ee_r: v3(&s.ee_r),
        ee_v_r: v3(&s.ee_v_r),
        com_h: v3(&s.com_h),
        com_v_h: v3(&s.com_v_h),
        com_r: v3(&s.com_r),
        com_v_r: v3(&s.com_v_r),
    }
}

/// `FilterStatus` from its wire value (unknown values read as `Fallback`).
pub fn status_from_u32(v: u32) -> FilterStatus {
    match v {
        0 => FilterStatus::Skipped,
        1 => FilterStatus::Solved,
        2 => FilterStatus::Relaxed,
        _ => FilterStatus::Fallback,
    }
}

/// Fields shared by the three safe-command messages.
pub trait SafeMsg: Copy + Default {
    const M: usize;
    const N: usize;
    fn head(&mut self) -> SafeHead<'_>;
    fn tick(&self) -> u64;
}

/// Mutable view of the common fields of a safe-command message.
pub struct SafeHead<'a> {
    pub tick: &'a mut u64,
    pub t: &'a mut f64,
    pub recv_ns: &'a mut u64,
    pub publish_ns: &'a mut u64,
    pub active_mask: &'a mut u64,
    pub solve_ns: &'a mut u64,
    pub solve_cpu_ns: &'a mut u32,
    pub solver_status: &'a mut u32,
    pub iterations: &'a mut u32,
    pub fault_flags: &'a mut u32,
    pub n_constraints: &'a mut u32,
    pub phase: &'a mut u32,
    pub slack: &'a mut f64,
    pub h: &'a mut [f64],
    pub phi: &'a mut [f64],
    pub u: &'a mut [f64],
    pub actuated: &'a mut [f64],
    pub xi_f_b: &'a mut [f64; 3],
    pub xi_tau_b: &'a mut [f64; 3],
}

macro_rules! safe_impl {
    ($t:ty, $m:expr, $n:expr) => {
        impl SafeMsg for $t {
            const M: usize = $m;
            const N: usize = $n;
            fn head(&mut self) -> SafeHead<'_> {
                SafeHead {
                    tick: &mut self.tick,
                    t: &mut self.t,
                    recv_ns: &mut self.recv_ns,
                    publish_ns: &mut self.publish_ns,
                    active_mask: &mut self.active_mask,
                    solve_ns: &mut self.solve_ns,
                    solve_cpu_ns: &mut self.solve_cpu_ns,
                    solver_status: &mut self.solver_status,
                    iterations: &mut self.iterations,
                    fault_flags: &mut self.fault_flags,
                    n_constraints: &mut self.n_constraints,
                    phase: &mut self.phase,
                    slack: &mut self.slack,
                    h: &mut self.h,
                    phi: &mut self.phi,
                    u: &mut self.u,
                    actuated: &mut self.actuated,
                    xi_f_b: &mut self.xi_f_b,
                    xi_tau_b: &mut self.xi_tau_b,
                }
            }
            fn tick(&self) -> u64 {
                self.tick
            }
        }
    };
}

safe_impl!(
    sc_icd::SafeTranslational,
    3,
    sc_icd::N_CONSTRAINTS_TRANSLATIONAL
);
safe_impl!(sc_icd::SafeAttitude, 3, sc_icd::N_CONSTRAINTS_ATTITUDE);
safe_impl!(sc_icd::SafeRobotic, 7, sc_icd::N_CONSTRAINTS_ROBOTIC);

/// The message of a filter output certified against the upstream commands `xi` (the
/// force and torque acting upstream; zero where the filter has no such upstream).
pub fn safe_msg<T: SafeMsg, const M: usize, const N: usize>(
    out: &FilterOutput<M, N>,
    xi: &Coupling,
    tick: u64,
    t: f64,
    phase: usize,
) -> T {
    let mut m = T::default();
    {
        let h = m.head();
        *h.tick = tick;
        *h.t = t;
        *h.active_mask = out.report.active;
        *h.solve_ns = out.report.solve_time_ns;
        *h.solve_cpu_ns = out.report.solve_cpu_ns.min(u32::MAX as u64) as u32;
        *h.solver_status = out.report.status as u32;
        *h.iterations = out.report.iterations;
        *h.fault_flags = out.report.faults;
        *h.n_constraints = N as u32;
        *h.phase = phase as u32;
        *h.slack = out.report.violation;
        h.h.copy_from_slice(&out.report.h);
        h.phi.copy_from_slice(&out.report.phi);
        h.u.copy_from_slice(out.u.as_slice());
        h.actuated.copy_from_slice(out.actuated.as_slice());
        *h.xi_f_b = a3(&xi.force_b);
        *h.xi_tau_b = a3(&xi.torque_b);
    }
    m
}

/// The upstream commands a filter's command was certified against (the paper's ξ): the
/// base force and torque acting [N, N m, F_B].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Coupling {
    pub force_b: Vector3<f64>,
    pub torque_b: Vector3<f64>,
}

impl Coupling {
    /// The coupling a safe command `m` says it was certified against.
    pub fn of<T: SafeMsg>(m: &T) -> Self {
        let mut m = *m;
        let h = m.head();
        Self {
            force_b: v3(h.xi_f_b),
            torque_b: v3(h.xi_tau_b),
        }
    }
}

/// The filter output carried by a message.
pub fn filter_output<T: SafeMsg, const M: usize, const N: usize>(msg: &T) -> FilterOutput<M, N> {
    let mut m = *msg;
    let h = m.head();
    let mut report = FilterReport::<N>::default();
    report.h.copy_from_slice(&h.h[..N]);
    report.phi.copy_from_slice(&h.phi[..N]);
    report.active = *h.active_mask;
    report.status = status_from_u32(*h.solver_status);
    report.iterations = *h.iterations;
    report.solve_time_ns = *h.solve_ns;
    report.solve_cpu_ns = *h.solve_cpu_ns as u64;
    report.faults = *h.fault_flags;
    report.violation = *h.slack;
    FilterOutput {
        u: SVector::<f64, M>::from_column_slice(&h.u[..M]),
        actuated: SVector::<f64, M>::from_column_slice(&h.actuated[..M]),
        report,
    }
}

/// The command of a step result.
pub fn applied(r: &StepResult) -> Command {
    Command {
        force_b: v3(&r.force_b),
        torque_b: v3(&r.torque_b),
        tau: v7(&r.tau),
    }
}

/// Writes the applied command into a step result.
pub fn set_applied(r: &mut StepResult, c: &Command) {
    r.force_b = a3(&c.force_b);
    r.torque_b = a3(&c.torque_b);
    r.tau = a7(&c.tau);
}

/// Vector helpers for the loops.
pub fn vec3(a: &[f64; 3]) -> Vector3<f64> {
    v3(a)
}
/// Vector helper.
pub fn vec7(a: &[f64; 7]) -> Vector7 {
    v7(a)
}
/// Array helper.
pub fn arr3(v: &Vector3<f64>) -> [f64; 3] {
    a3(v)
}
/// Array helper.
pub fn arr7(v: &Vector7) -> [f64; 7] {
    a7(v)
}

/// The message of the realised navigation errors `e` of tick `tick` at time `t`.
pub fn navigation_error(
    tick: u64,
    t: f64,
    e: &sc_sim::uncertainty::NavigationError,
) -> sc_icd::NavigationError {
    sc_icd::NavigationError {
        tick,
        t,
        relative_position_m: e.relative_position_m,
        relative_velocity_m_s: e.relative_velocity_m_s,
        servicer_attitude_rad: e.servicer_attitude_rad,
        servicer_rate_rad_s: e.servicer_rate_rad_s,
        target_attitude_rad: e.target_attitude_rad,
        target_rate_rad_s: e.target_rate_rad_s,
        grasp_point_m: e.grasp_point_m,
        joint_angle_rad: e.joint_angle_rad,
        joint_rate_rad_s: e.joint_rate_rad_s,
        measurement_age_s: e.measurement_age_s,
    }
}

/// The realised navigation errors a message carries ([`navigation_error`]'s inverse).
pub fn navigation_error_of(m: &sc_icd::NavigationError) -> sc_sim::uncertainty::NavigationError {
    sc_sim::uncertainty::NavigationError {
        relative_position_m: m.relative_position_m,
        relative_velocity_m_s: m.relative_velocity_m_s,
        servicer_attitude_rad: m.servicer_attitude_rad,
        servicer_rate_rad_s: m.servicer_rate_rad_s,
        target_attitude_rad: m.target_attitude_rad,
        target_rate_rad_s: m.target_rate_rad_s,
        grasp_point_m: m.grasp_point_m,
        joint_angle_rad: m.joint_angle_rad,
        joint_rate_rad_s: m.joint_rate_rad_s,
        measurement_age_s: m.measurement_age_s,
    }
}

/// The message of a navigation state (publish stamp left for the runner).
pub fn nav_state(n: &sc_sim::NavSample) -> sc_icd::NavState {
    let s = &n.state;
    sc_icd::NavState {
        tick: n.tick,
        t: s.t,
        measured_t: n.measured_t,
        publish_ns: 0,
        target_r: a3(&s.r_t),
        target_v: a3(&s.v_t),
        q_it: s.q_it,
        omega_t: a3(&s.w_t),
        r_i: a3(&s.dr),
        v_i: a3(&s.dv),
        q_ib: s.q_ib,
        omega_b: a3(&s.w_b),
        theta: a7(&s.theta),
        theta_dot: a7(&s.theta_dot),
        grasp_t: a3(&n.grasp_t),
    }
}

/// The navigation state of a message ([`nav_state`]'s inverse).
pub fn nav_sample(m: &sc_icd::NavState) -> sc_sim::NavSample {
    sc_sim::NavSample {
        tick: m.tick,
        measured_t: m.measured_t,
        state: sc_sim::SimState {
            t: m.t,
            r_t: v3(&m.target_r),
            v_t: v3(&m.target_v),
            q_it: m.q_it,
            w_t: v3(&m.omega_t),
            dr: v3(&m.r_i),
            dv: v3(&m.v_i),
            q_ib: m.q_ib,
            w_b: v3(&m.omega_b),
            theta: v7(&m.theta),
            theta_dot: v7(&m.theta_dot),
        },
        grasp_t: v3(&m.grasp_t),
    }
}
