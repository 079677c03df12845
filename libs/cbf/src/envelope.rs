//! Bounds on the servicer's dynamics over the certified operating envelope, from the
//! model: the constants the sampled-data rows of the attitude and robotic filters take
//! (how fast the base's angular acceleration and the joints' accelerations can change
//! inside one sample).
//!
//! The envelope is the set of states and inputs the safety layer can be in: joint angles
//! inside the safety limits, joint rates and body rates inside theirs, base force and
//! torque inside their bounds, joint torques inside theirs and inside the arm-reaction
//! contract, and joint accelerations that the joint-rate rows admit (`|θ̈_i| ≤
//! 2 θ̇_max,i / T`). Over it the derivatives are sampled densely with a fixed seed
//! (`d/dt` by central differences along the state's own motion) and searched from the
//! worst samples ([`search`]); `safe-capture bounds` prints both against the scenario's
//! constants. Neither is a proof, so what rests on each bound is explicit ([`Reliance`]):
//! the robotic filter verifies every command on the model's sample (its bounds only make
//! the cheap certificate succeed more often), the attitude's angular jerk bound is
//! load-bearing — every command refuses it below what a targeted search finds the model
//! reaching ([`witnesses`]), and the configured value keeps [`SAFETY_FACTOR`] over the
//! searches (docs/SAFETY.md, "The envelope bounds").

use nalgebra::{Vector3, Vector6};
use sc_multibody::{Robot, Vector7, Vector13};

/// Factor the configured bounds keep over the sampled (or searched) maxima: required of
/// the load-bearing ones (test `load_bearing_bounds_keep_the_factor_over_the_search`),
/// reported for the others.
pub const SAFETY_FACTOR: f64 = 1.5;

/// Maxima over the envelope: sampled ([`sample`]) or searched ([`search`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnvelopeMaxima {
    /// max |ω̈_B,i| over the axes [rad/s³].
    pub angular_jerk: f64,
    /// max |θ⃛_i| per joint [rad/s³].
    pub joint_jerk: [f64; 7],
    /// max ‖p⃛_k‖ of each link sphere's centre in the base frame [m/s³].
    pub sphere_jerk: [f64; 21],
    /// Usable samples of the sampling stage (the search's proposals not counted).
    pub samples: usize,
}

fn lcg(s: &mut u64) -> f64 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// The envelope's limits from the scenario.
struct Envelope {
    theta_min: Vector7,
    theta_max: Vector7,
    theta_dot_max: Vector7,
    /// Per-axis body-rate limit [rad/s].
    omega_max: Vector3<f64>,
    /// The arm-reaction contract `β` [rad/s²].
    beta: Vector3<f64>,
    force_max: f64,
    torque_max: f64,
    joint_torque_max: f64,
    period: f64,
}

impl Envelope {
    fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        let rb = &s.safety.robotic;
        let at = &s.safety.attitude;
        Self {
            theta_min: Vector7::from(rb.theta_min_rad),
            theta_max: Vector7::from(rb.theta_max_rad),
            theta_dot_max: Vector7::from(rb.theta_dot_max_rad_s),
            omega_max: Vector3::from(at.omega_max_rad_s)
                .abs()
                .sup(&Vector3::from(at.omega_min_rad_s).abs()),
            beta: Vector3::from(at.arm_reaction_budget_rad_s2),
            force_max: s.limits.force_max_n,
            torque_max: s.limits.torque_max_nm,
            joint_torque_max: s.limits.joint_torque_max_nm,
            period: s.mission.control_period_s,
        }
    }

    /// The state and the base's force and torque at the unit coordinates `z` (each in
    /// [−1, 1]; uniform draws give the uniform distribution inside the limits):
    /// `(θ, θ̇, ω_B, f_B, τ_B)` from `z[0..23]`.
    fn state_at(&self, z: &Coordinates) -> BaseState {
        let (tmin, tmax) = (&self.theta_min, &self.theta_max);
        let th =
            Vector7::from_fn(|i, _| 0.5 * (tmin[i] + tmax[i]) + 0.5 * (tmax[i] - tmin[i]) * z[i]);
        let thd = Vector7::from_fn(|i, _| self.theta_dot_max[i] * z[7 + i]);
        let w = Vector3::from_fn(|i, _| self.omega_max[i] * z[14 + i]);
        let f = Vector3::from_fn(|i, _| self.force_max * z[17 + i]);
        let tb = Vector3::from_fn(|i, _| self.torque_max * z[20 + i]);
        (th, thd, w, f, tb)
    }

    /// Joint torques of the envelope from `z[23..30]`: in the box, the part beyond the
    /// holding torque `hold` scaled into the contract (reaction `Q` on the base within
    /// `β`), then towards `hold` until the joint accelerations `A (τ − c_eff)` are ones the
    /// joint-rate rows admit (`|θ̈_i| ≤ 2 θ̇_max,i / T`). `None` when none is.
    fn joint_torque(
        &self,
        z: &Coordinates,
        hold: &Vector7,
        q: &nalgebra::SMatrix<f64, 3, 7>,
        a: &nalgebra::SMatrix<f64, 7, 7>,
    ) -> Option<Vector7> {
        let beta = &self.beta;
        let lim = self.joint_torque_max;
        let mut delta = Vector7::from_fn(|i, _| lim * z[23 + i]) - hold;
        let qt = q * delta;
        let k = (0..3)
            .map(|i| {
                if beta[i] > 0.0 {
                    qt[i].abs() / beta[i]
                } else {
                    0.0
                }
            })
            .fold(1.0f64, f64::max);
        delta /= k;
        let tm = (hold + delta).map(|t| t.clamp(-lim, lim));
        let admitted = |t: &Vector7| {
            let qdd = a * (t - hold);
            (0..7).all(|i| qdd[i].abs() <= 2.0 * self.theta_dot_max[i] / self.period)
        };
        if admitted(&tm) {
            return Some(tm);
        }
        // towards the holding torque (θ̈ = 0)
        let (mut lo, mut hi) = (0.0, 1.0);
        let from = |s: f64| hold + (tm - hold) * s;
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if admitted(&from(mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        admitted(&from(lo)).then(|| from(lo))
    }

    /// Every quantity the bounds cover ([`Quantities`]) at the envelope's point `z`;
    /// `None` where the model cannot be evaluated or no joint torque is admitted.
    fn quantities_at(&self, robot: &Robot, z: &Coordinates) -> Option<Quantities> {
        let (th, thd, w, f, tb) = self.state_at(z);
        let bd = robot.base_angular_dynamics(&th, &thd, &w, &f)?;
        let wrench = Vector6::new(f.x, f.y, f.z, tb.x, tb.y, tb.z);
        let red = robot.reduced_arm_dynamics(&th, &thd, &w, &wrench)?;
        let a = red.m_eff.cholesky()?.inverse();
        let tm = self.joint_torque(z, &red.c_eff, &bd.q, &a)?;
        let mut u = Vector13::zeros();
        u.fixed_rows_mut::<3>(0).copy_from(&f);
        u.fixed_rows_mut::<3>(3).copy_from(&tb);
        u.fixed_rows_mut::<7>(6).copy_from(&tm);
        let mut m = EnvelopeMaxima::default();
        record_jerks(&mut m, robot, &th, &thd, &w, &u).then(|| m.quantities())
    }
}

/// `(θ, θ̇, ω_B, f_B, τ_B)`.
type BaseState = (Vector7, Vector7, Vector3<f64>, Vector3<f64>, Vector3<f64>);
/// The envelope's unit coordinates: `θ`, `θ̇`, `ω_B`, `f_B`, `τ_B`, the joint-torque draw.
type Coordinates = [f64; DIMENSIONS];
/// Their number.
const DIMENSIONS: usize = 30;
/// What the bounds cover, in [`EnvelopeMaxima`] order: the angular jerk, the seven joint
/// jerks, the 21 link spheres' jerks.
type Quantities = [f64; QUANTITIES];
const QUANTITIES: usize = 29;

impl EnvelopeMaxima {
    fn quantities(&self) -> Quantities {
        let mut q = [0.0; QUANTITIES];
        q[0] = self.angular_jerk;
        q[1..8].copy_from_slice(&self.joint_jerk);
        q[8..].copy_from_slice(&self.sphere_jerk);
        q
    }

    fn from_quantities(q: &Quantities, samples: usize) -> Self {
        let mut m = Self {
            angular_jerk: q[0],
            samples,
            ..Self::default()
        };
        m.joint_jerk.copy_from_slice(&q[1..8]);
        m.sphere_jerk.copy_from_slice(&q[8..]);
        m
    }
}

fn draw(rng: &mut u64) -> Coordinates {
    std::array::from_fn(|_| lcg(rng))
}

/// Samples the envelope of scenario `s` with the servicer model `robot`.
pub fn sample(
    s: &sc_scenario::Scenario,
    robot: &Robot,
    samples: usize,
    seed: u64,
) -> EnvelopeMaxima {
    sample_keeping_the_worst(s, robot, samples, seed).0
}

/// The worst point found so far of every quantity: `(value, where)`.
type Worst = [(f64, Coordinates); QUANTITIES];

/// [`sample`], and for every quantity the point where it was largest.
fn sample_keeping_the_worst(
    s: &sc_scenario::Scenario,
    robot: &Robot,
    samples: usize,
    seed: u64,
) -> (EnvelopeMaxima, Worst) {
    let env = Envelope::from_scenario(s);
    let mut rng = seed.max(1);
    let mut worst = [(0.0, [0.0; DIMENSIONS]); QUANTITIES];
    let mut usable = 0;
    for _ in 0..samples {
        let z = draw(&mut rng);
        let Some(q) = env.quantities_at(robot, &z) else {
            continue;
        };
        usable += 1;
        for (w, v) in worst.iter_mut().zip(q) {
            if v > w.0 {
                *w = (v, z);
            }
        }
    }
    let maxima = worst.map(|w| w.0);
    (EnvelopeMaxima::from_quantities(&maxima, usable), worst)
}

/// A targeted worst-case search: from the sampled worst point of every quantity, a
/// random local ascent inside the envelope (`rounds` proposals per quantity, steps of
/// [`SEARCH_STEP`] in the unit coordinates, halved after [`SEARCH_PATIENCE`] failures in a
/// row). Finds larger maxima than the samples; still not a proof (a local search).
pub fn search(
    s: &sc_scenario::Scenario,
    robot: &Robot,
    samples: usize,
    seed: u64,
    rounds: usize,
) -> EnvelopeMaxima {
    search_quantities(s, robot, samples, seed, rounds, &[true; QUANTITIES])
}

/// [`search`] for the quantities `which` marks only (the others keep their sampled
/// maxima).
fn search_quantities(
    s: &sc_scenario::Scenario,
    robot: &Robot,
    samples: usize,
    seed: u64,
    rounds: usize,
    which: &[bool; QUANTITIES],
) -> EnvelopeMaxima {
    let env = Envelope::from_scenario(s);
    let (sampled, worst) = sample_keeping_the_worst(s, robot, samples, seed);
    let found: Quantities = std::array::from_fn(|i| {
        // every quantity its own random stream: what the search finds for one does not
        // depend on which others were searched (`witnesses` against `bounds`)
        let mut rng = (seed.max(1) ^ SEARCH_SEED_SALT)
            .wrapping_add((i as u64).wrapping_mul(SEARCH_STREAM_STRIDE));
        let (mut best, mut z) = worst[i];
        let (mut step, mut fails) = (SEARCH_STEP, 0);
        for _ in 0..rounds {
            if best == 0.0 || !which[i] {
                break; // nothing moves there (link 1's spheres), or not asked for
            }
            let cand: Coordinates =
                std::array::from_fn(|k| (z[k] + step * lcg(&mut rng)).clamp(-1.0, 1.0));
            match env.quantities_at(robot, &cand) {
                Some(q) if q[i] > best => (best, z, fails) = (q[i], cand, 0),
                _ => fails += 1,
            }
            if fails >= SEARCH_PATIENCE {
                (step, fails) = ((step * 0.5).max(SEARCH_STEP_MIN), 0);
            }
        }
        best
    });
    EnvelopeMaxima::from_quantities(&found, sampled.samples)
}

/// The bounds a certificate rests on against a targeted search ([`witnesses_with`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Witnesses {
    /// Every [`Reliance::Certificate`] bound with the largest value the search found.
    pub checks: Vec<BoundCheck>,
    /// Usable samples of the search's sampling stage, of `samples`.
    pub usable: usize,
    pub samples: usize,
}

/// At least 90 % of `samples` could be evaluated (`usable`): nothing measured is no
/// evidence for a bound.
pub fn enough_samples(usable: usize, samples: usize) -> bool {
    samples > 0 && usable * 10 >= samples * 9
}

impl Witnesses {
    /// Enough of the search's samples were usable ([`enough_samples`]).
    pub fn evidence(&self) -> bool {
        enough_samples(self.usable, self.samples)
    }

    /// The first bound the model exceeds at a witness state (not a bound).
    pub fn refuted(&self) -> Option<&BoundCheck> {
        self.checks.iter().find(|c| c.refuted())
    }
}

/// For every [`Reliance::Certificate`] bound, the largest value of its quantity a
/// targeted search (`samples` samples, then `rounds` proposals, `seed`) finds inside the
/// envelope. A configured bound below that value is **not a bound**: the model reaches
/// more at a state of the envelope. Being above it is necessary, not sufficient (the
/// search is local). The same numbers as `safe-capture bounds --samples … --search-rounds
/// … --seed …` prints for those bounds.
pub fn witnesses_with(
    s: &sc_scenario::Scenario,
    robot: &Robot,
    samples: usize,
    seed: u64,
    rounds: usize,
) -> Witnesses {
    let which = std::array::from_fn(|i| QUANTITY_RELIANCE[i] == Reliance::Certificate);
    let m = search_quantities(s, robot, samples, seed, rounds, &which);
    Witnesses {
        checks: checks(s, &m)
            .into_iter()
            .filter(|c| c.reliance == Reliance::Certificate)
            .collect(),
        usable: m.samples,
        samples,
    }
}

/// [`witnesses_with`] as every command checks a scenario before it runs
/// ([`WITNESS_SAMPLES`], [`WITNESS_ROUNDS`], [`WITNESS_SEED`]; 0.07 s).
pub fn witnesses(s: &sc_scenario::Scenario, robot: &Robot) -> Witnesses {
    witnesses_with(s, robot, WITNESS_SAMPLES, WITNESS_SEED, WITNESS_ROUNDS)
}

/// The search behind [`witnesses`]: samples, proposals per quantity, seed.
pub const WITNESS_SAMPLES: usize = 2_000;
pub const WITNESS_ROUNDS: usize = 3_000;
pub const WITNESS_SEED: u64 = 7;

/// The search's first step in the unit coordinates [-].
pub const SEARCH_STEP: f64 = 0.25;
/// Its smallest step [-].
pub const SEARCH_STEP_MIN: f64 = 1e-3;
/// Failed proposals in a row before the step is halved.
pub const SEARCH_PATIENCE: usize = 40;
/// Makes the search's random stream differ from the samples'.
const SEARCH_SEED_SALT: u64 = 0x5EA2C4;
/// Separates the quantities' streams (2⁶⁴ over the golden ratio).
const SEARCH_STREAM_STRIDE: u64 = 0x9E37_79B9_7F4A_7C15;

/// The accelerations at one state under the held input `u` and their rates of change,
/// `d/dt` by central differences along the state's own motion (the body-fixed base force
/// and torque and the joint torques are held, as in a sample), into the maxima. `false`
/// when the model cannot be evaluated there.
fn record_jerks(
    out: &mut EnvelopeMaxima,
    robot: &Robot,
    th: &Vector7,
    thd: &Vector7,
    w: &Vector3<f64>,
    u: &Vector13,
) -> bool {
    let Some(acc) = robot.forward_dynamics_sim(th, w, thd, u) else {
        return false;
    };
    let wd: Vector3<f64> = acc.fixed_rows::<3>(3).into();
    let qdd: Vector7 = acc.fixed_rows::<7>(6).into();
    let d = CENTRAL_DIFFERENCE_STEP_S;
    let at_ =
        |e: f64| robot.forward_dynamics_sim(&(th + thd * e), &(w + wd * e), &(thd + qdd * e), u);
    let (Some(p), Some(m)) = (at_(d), at_(-d)) else {
        return false;
    };
    let jerk = (p - m) / (2.0 * d);
    // the link spheres' centres: p̈ = J θ̈ + J̇ θ̇, differentiated the same way
    let sphere_acc = |e: f64, qdd_e: &Vector7| {
        let th_e = th + thd * e;
        let thd_e = thd + qdd * e;
        let kin = robot.kinematics_vel(&th_e, &thd_e);
        let mut acc = [Vector3::zeros(); 21];
        for (k, (idx, _)) in robot.arm_spheres().take(21).enumerate() {
            if let Some(sp) = robot.sphere_state(&kin, idx) {
                acc[k] = sp.jacobian * qdd_e + sp.jdot_qdot;
            }
        }
        acc
    };
    let qdd_p: Vector7 = p.fixed_rows::<7>(6).into();
    let qdd_m: Vector7 = m.fixed_rows::<7>(6).into();
    let (ap, am) = (sphere_acc(d, &qdd_p), sphere_acc(-d, &qdd_m));
    for k in 0..21 {
        out.sphere_jerk[k] = out.sphere_jerk[k].max(((ap[k] - am[k]) / (2.0 * d)).norm());
    }
    for i in 0..3 {
        out.angular_jerk = out.angular_jerk.max(jerk[3 + i].abs());
    }
    for i in 0..7 {
        out.joint_jerk[i] = out.joint_jerk[i].max(jerk[6 + i].abs());
    }
    true
}

/// Time step of the central differences along the state's motion [s].
const CENTRAL_DIFFERENCE_STEP_S: f64 = 1e-5;

/// What rests on an envelope bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reliance {
    /// A filter's certificate: the attitude rows' in-sample bounds take the angular jerk
    /// bound as it is (docs/SAFETY.md, "Line of sight").
    Certificate,
    /// Only how often the cheap certificate suffices: the robotic filter verifies every
    /// command on the sample the servicer model predicts, so a bound the arm exceeds
    /// costs a verification round, never the certificate (docs/SAFETY.md, "The arm at
    /// 10 Hz").
    Verified,
}

impl Reliance {
    /// As printed by `safe-capture bounds`.
    pub fn name(self) -> &'static str {
        match self {
            Reliance::Certificate => "certificate",
            Reliance::Verified => "verified per step",
        }
    }
}

/// What rests on each quantity's bound, in [`Quantities`] order.
const QUANTITY_RELIANCE: [Reliance; QUANTITIES] = {
    let mut r = [Reliance::Verified; QUANTITIES];
    r[0] = Reliance::Certificate;
    r
};

/// One configured envelope bound against its sampled (or searched) maximum.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundCheck {
    /// The scenario key, e.g. `safety.robotic.joint_jerk_bound_rad_s3[6]`.
    pub key: String,
    pub configured: f64,
    pub sampled: f64,
    /// What rests on it.
    pub reliance: Reliance,
}

impl BoundCheck {
    /// The configured bound keeps [`SAFETY_FACTOR`] over the sampled maximum.
    pub fn holds(&self) -> bool {
        self.configured >= SAFETY_FACTOR * self.sampled
    }

    /// The model reaches more than the configured bound (a witness state of the
    /// envelope): it is not a bound.
    pub fn refuted(&self) -> bool {
        self.configured < self.sampled
    }
}

/// Every envelope bound of scenario `s` against the maxima `m` (the link-sphere bound
/// is per link: the largest of its three spheres).
pub fn checks(s: &sc_scenario::Scenario, m: &EnvelopeMaxima) -> Vec<BoundCheck> {
    let a = &s.safety.attitude;
    let r = &s.safety.robotic;
    let mut v = vec![BoundCheck {
        key: "safety.attitude.angular_jerk_bound_rad_s3".into(),
        configured: a.angular_jerk_bound_rad_s3,
        sampled: m.angular_jerk,
        reliance: QUANTITY_RELIANCE[0],
    }];
    for i in 0..7 {
        v.push(BoundCheck {
            key: format!("safety.robotic.joint_jerk_bound_rad_s3[{i}]"),
            configured: r.joint_jerk_bound_rad_s3[i],
            sampled: m.joint_jerk[i],
            reliance: QUANTITY_RELIANCE[1 + i],
        });
    }
    for link in 0..7 {
        v.push(BoundCheck {
            key: format!("safety.robotic.link_sphere_jerk_bound_m_s3[{link}]"),
            configured: r.link_sphere_jerk_bound_m_s3[link],
            sampled: (0..3)
                .map(|k| m.sphere_jerk[3 * link + k])
                .fold(0.0, f64::max),
            reliance: QUANTITY_RELIANCE[8 + 3 * link],
        });
    }
    v
}
