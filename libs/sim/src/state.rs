//! Simulator state, dynamics and the RK4 integrator.

use nalgebra::{Matrix3, SVector, Vector3};
use sc_models::hill::HillFrame;
use sc_models::orbit::TwoBody;
use sc_models::quat::{self, Quat};
use sc_multibody::{NJ, Robot, Vector7, Vector13};
use sc_scenario::Scenario;
use std::sync::Arc;

pub use sc_core::Command;

/// Why the simulator stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error("command at t = {t} s is not finite")]
    NonFiniteCommand { t: f64 },
    #[error("the state became non-finite or singular at t = {t} s")]
    Diverged { t: f64 },
    #[error("model: {0}")]
    Model(String),
    #[error("plant at t = {t} s: {message}")]
    Plant { t: f64, message: String },
    /// The world's change of the target's rate (`[world]`) fell due with an external plant
    /// in the loop: only the simulator's own propagation applies it.
    #[error(
        "the world's change of the target's rate ([world]) at t = {t} s needs the simulator's own propagation, not an external plant"
    )]
    WorldNeedsOwnPropagation { t: f64 },
}

/// Relative tolerance on the time of a world event against the step count's time [-].
const WORLD_TIME_TOLERANCE: f64 = 1e-9;

pub use sc_core::BarrierState;

/// The full simulator state at one instant (inertial frame I, SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimState {
    /// Time since the start of the mission [s].
    pub t: f64,
    /// Target CoM position and velocity [m, m/s], inertial.
    pub r_t: Vector3<f64>,
    pub v_t: Vector3<f64>,
    /// Target attitude `q_IT` and body rate ω_T [rad/s, F_T].
    pub q_it: Quat,
    pub w_t: Vector3<f64>,
    /// Servicer base origin relative to the target CoM, inertial [m, m/s].
    pub dr: Vector3<f64>,
    pub dv: Vector3<f64>,
    /// Servicer base attitude `q_IB` and body rate ω_B [rad/s, F_B].
    pub q_ib: Quat,
    pub w_b: Vector3<f64>,
    /// Joint angles [rad] and rates [rad/s].
    pub theta: Vector7,
    pub theta_dot: Vector7,
}

const N: usize = 40;
type X = SVector<f64, N>;

impl SimState {
    fn pack(&self) -> X {
        let mut x = X::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(&self.r_t);
        x.fixed_rows_mut::<3>(3).copy_from(&self.v_t);
        x.fixed_rows_mut::<4>(6).copy_from_slice(&self.q_it);
        x.fixed_rows_mut::<3>(10).copy_from(&self.w_t);
        x.fixed_rows_mut::<3>(13).copy_from(&self.dr);
        x.fixed_rows_mut::<3>(16).copy_from(&self.dv);
        x.fixed_rows_mut::<4>(19).copy_from_slice(&self.q_ib);
        x.fixed_rows_mut::<3>(23).copy_from(&self.w_b);
        x.fixed_rows_mut::<NJ>(26).copy_from(&self.theta);
        x.fixed_rows_mut::<NJ>(33).copy_from(&self.theta_dot);
        x
    }

    fn unpack(t: f64, x: &X) -> Self {
        let q = |i: usize| [x[i], x[i + 1], x[i + 2], x[i + 3]];
        Self {
            t,
            r_t: x.fixed_rows::<3>(0).into(),
            v_t: x.fixed_rows::<3>(3).into(),
            q_it: q(6),
            w_t: x.fixed_rows::<3>(10).into(),
            dr: x.fixed_rows::<3>(13).into(),
            dv: x.fixed_rows::<3>(16).into(),
            q_ib: q(19),
            w_b: x.fixed_rows::<3>(23).into(),
            theta: x.fixed_rows::<NJ>(26).into(),
            theta_dot: x.fixed_rows::<NJ>(33).into(),
        }
    }
}

/// Fixed data of a simulation.
#[derive(Debug, Clone)]
pub(crate) struct Params {
    pub gravity: TwoBody,
    /// Unit normal of the target's orbital plane (from inclination and RAAN): Ĥ of the
    /// Hill frame when the orbit has none (μ = 0, the target at rest).
    pub orbit_normal: Vector3<f64>,
    pub target_inertia: Matrix3<f64>,
    pub target_inertia_inv: Matrix3<f64>,
    /// `q_IR`: the reference frame's (constant) attitude in the inertial frame.
    pub q_ir: Quat,
    pub grasp_point_t: Vector3<f64>,
    pub physics_step: f64,
    pub substeps: usize,
    /// The world's undeclared change of the target's rate (`[world]`): at `t` [s], ω_T
    /// [rad/s, F_T] becomes the given one.
    pub spin_change: Option<(f64, Vector3<f64>)>,
}

/// The simulator: state + models + integrator.
#[derive(Debug, Clone)]
pub struct Simulator {
    pub(crate) robot: Arc<Robot>,
    pub(crate) p: Params,
    pub(crate) state: SimState,
    pub(crate) step: u64,
    /// The states of the last control period at its physics steps, from its start to
    /// its end (an old measurement for the navigation: [`Self::state_ago`]).
    pub(crate) history: Vec<SimState>,
}

impl Simulator {
    /// Builds the initial state of the scenario (see `config/scenario.toml` for frames).
    pub fn new(scenario: &Scenario, robot: Arc<Robot>) -> Result<Self, SimError> {
        let o = &scenario.orbit;
        let gravity = TwoBody {
            mu: o.earth_mu_m3_s2,
        };
        let a = o.earth_radius_m + o.altitude_m;
        let (r_t, v_t) = gravity.circular_state(
            a,
            o.inclination_deg.to_radians(),
            o.raan_deg.to_radians(),
            o.argument_of_latitude_deg.to_radians(),
        );
        let orbit_normal =
            TwoBody::orbit_normal(o.inclination_deg.to_radians(), o.raan_deg.to_radians());
        let hill = HillFrame::from_inertial_or(&r_t, &v_t, &orbit_normal);
        let q_ih = quat::from_matrix(&hill.c_hi.transpose());
        let q_hr =
            quat::normalized(&scenario.reference_frame.attitude_in_hill).ok_or_else(|| {
                SimError::Model("reference_frame.attitude_in_hill is not a quaternion".into())
            })?;
        let q_ir = quat::normalized(&quat::mul(&q_ih, &q_hr)).unwrap_or(quat::IDENTITY);
        let r_ir = quat::to_matrix(&q_ir);
        let tg = &scenario.target;
        let q_rt = quat::normalized(&tg.initial_attitude)
            .ok_or_else(|| SimError::Model("target.initial_attitude is not a quaternion".into()))?;
        let ti = Matrix3::from_fn(|i, j| tg.inertia_kg_m2[i][j]);
        let ti_inv = ti
            .try_inverse()
            .ok_or_else(|| SimError::Model("target inertia is singular".into()))?;
        let sv = &scenario.servicer;
        let v3 = |a: [f64; 3]| Vector3::new(a[0], a[1], a[2]);
        let state = SimState {
            t: 0.0,
            r_t,
            v_t,
            q_it: quat::mul(&q_ir, &q_rt),
            w_t: v3(tg.initial_omega_rad_s),
            dr: r_ir * v3(sv.initial_position_m),
            dv: r_ir * v3(sv.initial_velocity_m_s),
            q_ib: q_ir,
            w_b: v3(sv.initial_omega_rad_s),
            theta: Vector7::from_column_slice(&sv.initial_theta_rad),
            theta_dot: Vector7::from_column_slice(&sv.initial_theta_dot_rad_s),
        };
        let p = Params {
            gravity,
            orbit_normal,
            target_inertia: ti,
            target_inertia_inv: ti_inv,
            q_ir,
            // the world's fixture where it differs from the declared one
            grasp_point_t: v3(scenario
                .world
                .as_ref()
                .and_then(|w| w.grasp_point_m)
                .unwrap_or(tg.grasp_point_m)),
            physics_step: scenario.mission.physics_step_s,
            substeps: scenario.physics_substeps(),
            spin_change: scenario
                .world
                .as_ref()
                .and_then(|w| w.target_spin_change)
                .map(|c| (c.t_s, v3(c.omega_rad_s))),
        };
        Ok(Self {
            robot,
            p,
            state,
            step: 0,
            history: Vec::new(),
        })
    }

    /// Current state.
    pub fn state(&self) -> &SimState {
        &self.state
    }

    /// Replaces the state (e.g. to start from a recorded one).
    pub fn set_state(&mut self, s: SimState) {
        self.state = s;
        self.history.clear();
    }

    /// Control steps taken so far.
    pub fn step_count(&self) -> u64 {
        self.step
    }

    /// The servicer model.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// `q_IR`, the constant attitude of the reference frame.
    pub fn q_ir(&self) -> Quat {
        self.p.q_ir
    }

    /// Time derivative of the packed state under command `u`.
    fn derivative(&self, x: &X, u: &Vector13) -> Option<X> {
        let s = SimState::unpack(0.0, x);
        let mut d = X::zeros();
        // target: two-body orbit, torque-free rigid body
        d.fixed_rows_mut::<3>(0).copy_from(&s.v_t);
        d.fixed_rows_mut::<3>(3)
            .copy_from(&self.p.gravity.gravity(&s.r_t));
        d.fixed_rows_mut::<4>(6)
            .copy_from_slice(&quat::kinematics(&s.q_it, &s.w_t));
        let w_t_dot = sc_models::attitude::euler(
            &self.p.target_inertia,
            &self.p.target_inertia_inv,
            &s.w_t,
            &Vector3::zeros(),
        );
        d.fixed_rows_mut::<3>(10).copy_from(&w_t_dot);
        // servicer: multibody dynamics in the freely falling frame
        let acc = self
            .robot
            .forward_dynamics_sim(&s.theta, &s.w_b, &s.theta_dot, u)?;
        let r_ib = quat::to_matrix(&s.q_ib);
        let a_b: Vector3<f64> = acc.fixed_rows::<3>(0).into();
        let com_b = self.robot.center_of_mass(&s.theta);
        let dr_com = s.dr + r_ib * com_b;
        let dg = self.p.gravity.differential_gravity(&s.r_t, &dr_com);
        d.fixed_rows_mut::<3>(13).copy_from(&s.dv);
        d.fixed_rows_mut::<3>(16).copy_from(&(dg + r_ib * a_b));
        d.fixed_rows_mut::<4>(19)
            .copy_from_slice(&quat::kinematics(&s.q_ib, &s.w_b));
        d.fixed_rows_mut::<3>(23).copy_from(&acc.fixed_rows::<3>(3));
        d.fixed_rows_mut::<NJ>(26).copy_from(&s.theta_dot);
        d.fixed_rows_mut::<NJ>(33)
            .copy_from(&acc.fixed_rows::<NJ>(6));
        Some(d)
    }

    /// One RK4 physics step of length `h` under `u`; quaternions renormalised after the step.
    fn rk4(&self, x: &X, u: &Vector13, h: f64) -> Option<X> {
        let k1 = self.derivative(x, u)?;
        let k2 = self.derivative(&(x + k1 * (h / 2.0)), u)?;
        let k3 = self.derivative(&(x + k2 * (h / 2.0)), u)?;
        let k4 = self.derivative(&(x + k3 * h), u)?;
        let mut y = x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        for i in [6usize, 19] {
            let n = y.fixed_rows::<4>(i).norm();
            y.fixed_rows_mut::<4>(i).unscale_mut(n);
        }
        if y.iter().all(|v| v.is_finite()) {
            Some(y)
        } else {
            None
        }
    }

    /// Advances one control period under the zero-order-hold command `cmd`.
    pub fn step(&mut self, cmd: &Command) -> Result<(), SimError> {
        self.step_with(cmd, |_| {})
    }

    /// Like [`Self::step`], and calls `at_physics_step` with the [`BarrierState`] after
    /// every RK4 step of the period (the last call sees the state of the next control
    /// step): the inter-sample states that a monitor must see too.
    pub fn step_with(
        &mut self,
        cmd: &Command,
        mut at_physics_step: impl FnMut(&BarrierState),
    ) -> Result<(), SimError> {
        if !cmd.is_finite() {
            return Err(SimError::NonFiniteCommand { t: self.state.t });
        }
        self.apply_world();
        let u = cmd.as_vector();
        let mut x = self.state.pack();
        let h = self.p.physics_step;
        let t0 = self.state.t;
        self.history.clear();
        self.history.push(self.state);
        for j in 0..self.p.substeps {
            x = self
                .rk4(&x, &u, h)
                .ok_or(SimError::Diverged { t: self.state.t })?;
            let s = SimState::unpack(t0 + (j + 1) as f64 * h, &x);
            at_physics_step(&self.barrier_state_of(&s));
            self.history.push(s);
        }
        self.step += 1;
        // time from the step count, so that it never accumulates rounding
        let period = h * self.p.substeps as f64;
        self.state = SimState::unpack(self.step as f64 * period, &x);
        Ok(())
    }

    /// The world's change of the target's rate, once it is due (at the start of the first
    /// control period that begins at or after its time).
    fn apply_world(&mut self) {
        if let Some((_, w)) = self.world_due() {
            self.state.w_t = w;
            self.p.spin_change = None;
        }
    }

    /// The world's change of the target's rate if it is due now.
    pub(crate) fn world_due(&self) -> Option<(f64, Vector3<f64>)> {
        let (t, w) = self.p.spin_change?;
        // (within a rounding of the step count's time)
        (self.state.t + WORLD_TIME_TOLERANCE * t.abs().max(1.0) >= t).then_some((t, w))
    }

    /// True while a world event (`[world]`) is still to come.
    pub fn world_event_pending(&self) -> bool {
        self.p.spin_change.is_some()
    }

    /// The true state `k` physics steps ago (`k` ≤ the steps of a period); before the
    /// first period, and for `k = 0`, the current state.
    pub fn state_ago(&self, k: usize) -> SimState {
        let n = self.history.len();
        if k == 0 || n <= k {
            return self.state;
        }
        self.history[n - 1 - k]
    }

    /// What the safety barriers depend on, at the current state.
    pub fn barrier_state(&self) -> BarrierState {
        self.barrier_state_of(&self.state)
    }

    pub(crate) fn barrier_state_of(&self, s: &SimState) -> BarrierState {
        let q_ri = quat::conj(&self.p.q_ir);
        let r_ri = quat::to_matrix(&q_ri);
        let com_b = self.robot.center_of_mass(&s.theta);
        let dr_com = s.dr + quat::to_matrix(&s.q_ib) * com_b;
        let q_rt = quat::mul(&q_ri, &s.q_it);
        BarrierState {
            t: s.t,
            com_r: r_ri * dr_com,
            q_rb: quat::mul(&q_ri, &s.q_ib),
            omega_b: s.w_b,
            grasp_r: quat::to_matrix(&q_rt) * self.p.grasp_point_t,
            theta: s.theta,
            theta_dot: s.theta_dot,
            base_r: r_ri * s.dr,
            q_rt,
        }
    }

    /// Generalised velocity ν = [v_B; ω_B; θ̇] with the base linear velocity taken
    /// relative to the freely falling frame of the target (base frame).
    pub fn nu_relative(&self) -> Vector13 {
        let s = &self.state;
        let r_ib = quat::to_matrix(&s.q_ib);
        let mut nu = Vector13::zeros();
        nu.fixed_rows_mut::<3>(0)
            .copy_from(&(r_ib.transpose() * s.dv));
        nu.fixed_rows_mut::<3>(3).copy_from(&s.w_b);
        nu.fixed_rows_mut::<NJ>(6).copy_from(&s.theta_dot);
        nu
    }

    /// The target's rotational state derivative ω̇_T (torque-free) [rad/s², F_T].
    pub(crate) fn target_omega_dot(&self) -> Vector3<f64> {
        sc_models::attitude::euler(
            &self.p.target_inertia,
            &self.p.target_inertia_inv,
            &self.state.w_t,
            &Vector3::zeros(),
        )
    }
}
