//! The adversarial nominal controller: replaces the nominal commands of its target
//! subsystem(s) with those of its [`Strategy`], step by step. It knows everything the
//! safety layer knows (the scenario, the servicer model, the true state) — a hostile
//! partner is assumed to.

use crate::strategy::{STALE_LAG, Strategy, Target, barrier_names};
use nalgebra::{SVector, Vector3};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};
use sc_cbf::arm_target::TargetBody;
use sc_cbf::link_target::{self, Surroundings};
use sc_cbf::monitor::{Barriers, Monitor};
use sc_cbf::robotic;
use sc_core::{PerSubsystem, Subsystem};
use sc_mission::{NominalCommand, NominalCommands, NominalOverride, NominalSource, Setup};
use sc_models::quat;
use sc_multibody::{Robot, Vector7};
use sc_nominal::NominalOutput;
use sc_scenario::Scenario;
use sc_sim::Observation;
use std::collections::VecDeque;
use std::sync::Arc;

/// Factor on the input bound of every saturating adversarial command: beyond the bound,
/// so the filters' input bounds are exercised too.
pub const OVERDRIVE: f64 = 1.5;

/// The three subsystems' raw commands of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Raw {
    f_h: Vector3<f64>,
    tau_b: Vector3<f64>,
    tau_m: Vector7,
}

/// An adversarial nominal controller.
pub struct Adversary {
    target: Target,
    strategy: Strategy,
    geometry: Geometry,
    monitor: Monitor,
    rng: ChaCha8Rng,
    frozen: Option<Raw>,
    history: VecDeque<Observation>,
    step: u64,
}

/// What the adversary needs to aim at each boundary.
struct Geometry {
    axis_r: Vector3<f64>,
    cos_psi: f64,
    boresight_b: Vector3<f64>,
    theta_mid: Vector7,
    force_max: f64,
    torque_max: f64,
    joint_torque_max: f64,
    /// Distance-like scale of every barrier (for the greedy choice).
    scale: Barriers,
    robot: Arc<Robot>,
    /// The target's keep-out spheres (the link–target barriers).
    target: TargetBody,
}

impl Adversary {
    /// An adversary for `target` playing `strategy` in the scenario `s`.
    pub fn new(s: &Scenario, robot: Arc<Robot>, target: Target, strategy: Strategy) -> Self {
        let t = &s.safety.translational;
        let r = &s.safety.robotic;
        let psi = t.corridor_half_angle_deg.to_radians();
        let scale = crate::scales::barrier_scales(s, &robot);
        let seed = match strategy {
            Strategy::Random(s) => s,
            _ => 0,
        };
        Self {
            target,
            strategy,
            geometry: Geometry {
                axis_r: Vector3::from(t.corridor_axis).normalize(),
                cos_psi: psi.cos(),
                boresight_b: Vector3::from(s.servicer.boresight_body).normalize(),
                theta_mid: Vector7::from_fn(|i, _| 0.5 * (r.theta_max_rad[i] + r.theta_min_rad[i])),
                force_max: s.limits.force_max_n,
                torque_max: s.limits.torque_max_nm,
                joint_torque_max: s.limits.joint_torque_max_nm,
                scale,
                robot: robot.clone(),
                target: TargetBody::from_scenario(s),
            },
            monitor: Monitor::from_scenario(s, robot),
            rng: ChaCha8Rng::seed_from_u64(seed),
            frozen: None,
            history: VecDeque::new(),
            step: 0,
        }
    }

    /// The adversary of `case` in `setup`'s scenario, as the mission's nominal source.
    pub fn nominals(setup: &Setup, case: &crate::Case) -> NominalSource {
        NominalSource::Override(Box::new(Self::new(
            &setup.scenario,
            setup.robot.clone(),
            case.target,
            case.strategy,
        )))
    }

    /// The command of every subsystem pushing towards barrier `which[s]` of that
    /// subsystem `s` (indices into the subsystem's constraint names).
    fn toward(&self, o: &Observation, which: PerSubsystem<usize>) -> Raw {
        let g = &self.geometry;
        // translational: the CoM out of the corridor / into the zone (Hill frame)
        let r = o.com_h;
        let rhat = r / r.norm().max(1e-9);
        let f_h = if which[Subsystem::Translational] == 0 {
            let d_h = quat::rotate(&o.q_hr, &g.axis_r);
            let grad = d_h - rhat * g.cos_psi;
            -unit_or(&grad, &perpendicular(&rhat)) * (OVERDRIVE * g.force_max)
        } else {
            -rhat * (OVERDRIVE * g.force_max)
        };
        // attitude: the boresight off the line of sight, or spin about an axis
        let tmax = OVERDRIVE * g.torque_max;
        let tau_b = match which[Subsystem::Attitude] {
            0 => {
                let rho = o.grasp_r - o.com_r;
                let s_b = quat::to_matrix(&o.q_rb).transpose() * rho;
                let axis = g.boresight_b.cross(&s_b);
                -unit_or(&axis, &perpendicular(&g.boresight_b)) * tmax
            }
            k => {
                let mut t = Vector3::zeros();
                let axis = (k - 1) % 3;
                t[axis] = if k <= 3 { tmax } else { -tmax };
                t
            }
        };
        // robotic: a joint to its nearer limit, a joint rate up or down, a link sphere
        // into the base or into the target
        let nj = robotic::NJ;
        let tm = OVERDRIVE * g.joint_torque_max;
        let k = which[Subsystem::Robotic];
        let tau_m = if k < nj {
            let mut t = Vector7::zeros();
            t[k] = tm * (o.theta[k] - g.theta_mid[k]).signum();
            t
        } else if k < 2 * nj {
            let mut t = Vector7::zeros();
            t[k - nj] = tm;
            t
        } else if k < 3 * nj {
            let mut t = Vector7::zeros();
            t[k - 2 * nj] = -tm;
            t
        } else if k < robotic::LINK_TARGET {
            self.sphere_into_base(o, k - 3 * nj)
                .map(|d| d.map(|x| -tm * x.signum()))
                .unwrap_or_else(Vector7::zeros)
        } else {
            self.sphere_into_target(o, k - robotic::LINK_TARGET)
                .map(|d| d.map(|x| -tm * x.signum()))
                .unwrap_or_else(Vector7::zeros)
        };
        Raw { f_h, tau_b, tau_m }
    }

    /// `∂ḧ_LB/∂τ_M = 2 Aᵀ Jᵀ d` of link sphere `k` (A = M_eff⁻¹).
    fn sphere_into_base(&self, o: &Observation, k: usize) -> Option<Vector7> {
        let robot = &self.geometry.robot;
        let red = robot.reduced_arm_dynamics(
            &o.theta,
            &o.theta_dot,
            &o.omega_b,
            &nalgebra::Vector6::zeros(),
        )?;
        let a = red.m_eff.cholesky()?.inverse();
        let kin = robot.kinematics(&o.theta);
        let base = robot.base_sphere()?;
        let (idx, _) = robot.arm_spheres().nth(k)?;
        let sp = robot.sphere_state(&kin, idx)?;
        let d = sp.center - base.center;
        Some(a.transpose() * (sp.jacobian.transpose() * d) * 2.0)
    }

    /// `∂ḧ_LT/∂τ_M` of link sphere `k` against the nearest keep-out sphere of the target:
    /// the robotic filter's own row (`sc_cbf::link_target`), from the observation — the
    /// attacker knows the filter's model and pushes straight down its gradient.
    fn sphere_into_target(&self, o: &Observation, k: usize) -> Option<Vector7> {
        let z = Vector3::zeros();
        let x = sc_cbf::robotic_input_from_model(
            &self.geometry.robot,
            &o.theta,
            &o.theta_dot,
            &o.omega_b,
            &z,
            &z,
        )?;
        let x = sc_cbf::RoboticInput {
            around: Some(Surroundings::from_observation(o)),
            ..x
        };
        let row = link_target::link_target(x.spheres.get(k)?, &x, &self.geometry.target);
        Some(row.hddot_u)
    }

    /// The index, per subsystem, of the barrier closest to its boundary (distance-normalised).
    fn greedy_choice(&self, o: &Observation) -> PerSubsystem<usize> {
        let h = self.monitor.evaluate(&o.barrier_state());
        PerSubsystem::from_fn(|s| {
            let from = first_barrier(s);
            (0..barrier_names(s).len())
                .min_by(|&a, &b| {
                    let va = h[from + a] / self.geometry.scale[from + a];
                    let vb = h[from + b] / self.geometry.scale[from + b];
                    va.total_cmp(&vb)
                })
                .unwrap_or(0)
        })
    }

    fn greedy(&self, o: &Observation) -> Raw {
        self.toward(o, self.greedy_choice(o))
    }

    fn random(&mut self) -> Raw {
        let g = &self.geometry;
        let (f, t, tm) = (
            OVERDRIVE * g.force_max,
            OVERDRIVE * g.torque_max,
            OVERDRIVE * g.joint_torque_max,
        );
        let mut sign = || {
            if self.rng.next_u64() & 1 == 0 {
                1.0
            } else {
                -1.0
            }
        };
        Raw {
            f_h: Vector3::from_fn(|_, _| f * sign()),
            tau_b: Vector3::from_fn(|_, _| t * sign()),
            tau_m: Vector7::from_fn(|_, _| tm * sign()),
        }
    }

    fn raw(&mut self, o: &Observation) -> Option<Raw> {
        Some(match self.strategy {
            // the barrier of that index, or each subsystem's last
            Strategy::Toward(i) => self.toward(
                o,
                PerSubsystem::from_fn(|s| i.min(barrier_names(s).len() - 1)),
            ),
            Strategy::Greedy => self.greedy(o),
            Strategy::Random(_) => self.random(),
            Strategy::NonFinite => {
                let v = match self.step % 4 {
                    0 => f64::NAN,
                    1 => f64::INFINITY,
                    2 => f64::NEG_INFINITY,
                    _ => 0.0,
                };
                let mut r = Raw {
                    f_h: Vector3::repeat(v),
                    tau_b: Vector3::repeat(v),
                    tau_m: Vector7::repeat(v),
                };
                if self.step % 4 == 3 {
                    r.f_h[1] = f64::NAN;
                    r.tau_b[2] = f64::NAN;
                    r.tau_m[6] = f64::NAN;
                }
                r
            }
            Strategy::Huge => {
                let g = self.greedy(o);
                let k = match self.step % 3 {
                    0 => 1e300 / OVERDRIVE,
                    1 => 1000.0 / OVERDRIVE,
                    _ => -1e300 / OVERDRIVE,
                };
                Raw {
                    f_h: scale(&g.f_h, k),
                    tau_b: scale(&g.tau_b, k),
                    tau_m: scale(&g.tau_m, k),
                }
            }
            Strategy::Frozen => match self.frozen {
                Some(r) => r,
                None => {
                    let r = self.greedy(o);
                    self.frozen = Some(r);
                    r
                }
            },
            Strategy::Stale => {
                self.history.push_back(*o);
                while self.history.len() > STALE_LAG + 1 {
                    self.history.pop_front();
                }
                let old = self.history.front().copied().unwrap_or(*o);
                self.greedy(&old)
            }
            Strategy::Silent => return None,
        })
    }
}

impl NominalOverride for Adversary {
    fn commands(&mut self, o: &Observation, _reference: &NominalOutput) -> NominalCommands {
        let raw = self.raw(o);
        self.step += 1;
        let attacks = |s: Subsystem| self.target.attacks(s);
        NominalCommands {
            translational: command(attacks(Subsystem::Translational), raw.map(|r| r.f_h)),
            attitude: command(attacks(Subsystem::Attitude), raw.map(|r| r.tau_b)),
            robotic: command(attacks(Subsystem::Robotic), raw.map(|r| r.tau_m)),
        }
    }
}

/// The command of one subsystem: the reference when not attacked, else the adversary's
/// (or missing).
fn command<T>(attacked: bool, v: Option<T>) -> NominalCommand<T> {
    match (attacked, v) {
        (false, _) => NominalCommand::Reference,
        (true, Some(u)) => NominalCommand::Given(u),
        (true, None) => NominalCommand::Missing,
    }
}

/// Index of subsystem `s`'s first barrier among all barriers ([`sc_mission::constraint_names`]).
fn first_barrier(s: Subsystem) -> usize {
    s.upstream_all().map(|u| barrier_names(u).len()).sum()
}

/// `v · k` keeping the direction (a zero vector stays zero; 1e300 × a unit component
/// overflows to ±∞ only where the component is large, as a real partner's would).
fn scale<const M: usize>(v: &SVector<f64, M>, k: f64) -> SVector<f64, M> {
    v.map(|x| x * k)
}

fn unit_or(v: &Vector3<f64>, fallback: &Vector3<f64>) -> Vector3<f64> {
    let n = v.norm();
    if n > 1e-12 { v / n } else { *fallback }
}

/// A unit vector perpendicular to `v`.
fn perpendicular(v: &Vector3<f64>) -> Vector3<f64> {
    let pick = if v.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    unit_or(&v.cross(&pick), &Vector3::z())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A subsystem's barriers follow those of the subsystems upstream of it.
    #[test]
    fn barriers_are_numbered_in_causal_order() {
        assert_eq!(first_barrier(Subsystem::Translational), 0);
        assert_eq!(first_barrier(Subsystem::Attitude), sc_cbf::translational::N);
        assert_eq!(
            first_barrier(Subsystem::Robotic),
            sc_cbf::translational::N + sc_cbf::attitude::N
        );
    }
}
