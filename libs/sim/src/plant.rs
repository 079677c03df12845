//! Another propagator of the true state in the loop (e.g. Basilisk in its own process):
//! the simulator keeps its frames, observation and barrier states, and asks the plant
//! only for the states after each physics step of a control period.

use crate::state::{Command, SimError, SimState, Simulator};

/// Why an external propagator failed (it could not start, left, or answered nonsense),
/// in one line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct PlantError(pub String);

/// An external propagator of [`SimState`] (frames and units as documented there).
pub trait Plant {
    /// Starts the plant at `state` (called once, before the first [`Plant::propagate`]).
    fn start(&mut self, state: &SimState) -> Result<(), PlantError>;

    /// The states after each of the `substeps` physics steps of length `physics_step` [s]
    /// under the zero-order-hold command `cmd`, starting from the plant's current state.
    fn propagate(
        &mut self,
        cmd: &Command,
        physics_step: f64,
        substeps: usize,
    ) -> Result<Vec<SimState>, PlantError>;
}

/// The numbers of a [`SimState`] in the plant protocol's order: `t`, `r_t`, `v_t`,
/// `q_it` (scalar first), `w_t`, `dr`, `dv`, `q_ib`, `w_b`, `theta`, `theta_dot` (41).
pub const SIM_STATE_LEN: usize = 41;

impl SimState {
    /// The state as [`SIM_STATE_LEN`] numbers.
    pub fn to_array(&self) -> [f64; SIM_STATE_LEN] {
        let mut a = [0.0; SIM_STATE_LEN];
        a[0] = self.t;
        let parts: [&[f64]; 10] = [
            self.r_t.as_slice(),
            self.v_t.as_slice(),
            &self.q_it,
            self.w_t.as_slice(),
            self.dr.as_slice(),
            self.dv.as_slice(),
            &self.q_ib,
            self.w_b.as_slice(),
            self.theta.as_slice(),
            self.theta_dot.as_slice(),
        ];
        let mut k = 1;
        for p in parts {
            a[k..k + p.len()].copy_from_slice(p);
            k += p.len();
        }
        a
    }

    /// The state from [`SIM_STATE_LEN`] numbers ([`Self::to_array`]'s order).
    pub fn from_array(a: &[f64; SIM_STATE_LEN]) -> Self {
        let v3 = |k: usize| nalgebra::Vector3::new(a[k], a[k + 1], a[k + 2]);
        let q = |k: usize| [a[k], a[k + 1], a[k + 2], a[k + 3]];
        Self {
            t: a[0],
            r_t: v3(1),
            v_t: v3(4),
            q_it: q(7),
            w_t: v3(11),
            dr: v3(14),
            dv: v3(17),
            q_ib: q(20),
            w_b: v3(24),
            theta: sc_multibody::Vector7::from_column_slice(&a[27..34]),
            theta_dot: sc_multibody::Vector7::from_column_slice(&a[34..41]),
        }
    }
}

impl Simulator {
    /// [`Simulator::step_with`] with the plant propagating instead of the simulator's own
    /// RK4: the plant's states are checked (count, finite, unit quaternions to 1e-9) and
    /// handed to `at_physics_step` as barrier states; time stays the simulator's own.
    pub fn step_with_plant(
        &mut self,
        plant: &mut dyn Plant,
        cmd: &Command,
        mut at_physics_step: impl FnMut(&crate::BarrierState),
    ) -> Result<(), SimError> {
        if !cmd.is_finite() {
            return Err(SimError::NonFiniteCommand { t: self.state.t });
        }
        let (h, n) = (self.p.physics_step, self.p.substeps);
        let t0 = self.state.t;
        if let Some((t, _)) = self.world_due() {
            return Err(SimError::WorldNeedsOwnPropagation { t });
        }
        let states = plant.propagate(cmd, h, n).map_err(|e| SimError::Plant {
            t: t0,
            message: e.0,
        })?;
        if states.len() != n {
            return Err(SimError::Plant {
                t: t0,
                message: format!("{} states for {n} physics steps", states.len()),
            });
        }
        let unit = |q: &[f64; 4]| (q.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-9;
        self.history.clear();
        self.history.push(self.state);
        for (j, s) in states.iter().enumerate() {
            let mut s = *s;
            if !s.to_array().iter().all(|x| x.is_finite()) || !unit(&s.q_it) || !unit(&s.q_ib) {
                return Err(SimError::Diverged { t: t0 });
            }
            s.t = t0 + (j + 1) as f64 * h;
            at_physics_step(&self.barrier_state_of(&s));
            self.history.push(s);
        }
        self.step += 1;
        let mut last = states[n - 1];
        // as in step_with: time from the step count and the period
        let period = h * n as f64;
        last.t = self.step as f64 * period;
        self.state = last;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_protocol_order_round_trips() {
        let a: [f64; SIM_STATE_LEN] = std::array::from_fn(|i| i as f64 * 0.5 - 3.0);
        assert_eq!(SimState::from_array(&a).to_array(), a);
    }
}
