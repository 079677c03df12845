//! Bounds on the servicer's dynamics over the certified operating envelope, from the
//! model: the constants the sampled-data rows of the attitude and robotic filters need
//! (how fast the base's angular acceleration and the joints' accelerations can change
//! inside one sample).
//!
//! The envelope is the set of states and inputs the safety layer can be in: joint angles
//! inside the safety limits, joint rates and body rates inside theirs, base force and
//! torque inside their bounds, joint torques inside theirs and inside the arm-reaction
//! contract, and joint accelerations that the joint-rate rows admit (`|θ̈_i| ≤
//! 2 θ̇_max,i / T`). Over it the derivatives are sampled densely with a fixed seed
//! (`d/dt` by central differences along the state's own motion) and the maxima reported;
//! the scenario's constants must exceed them by [`SAFETY_FACTOR`] — the test
//! `envelope_bounds_cover_the_model` checks it, and `safe-capture bounds` prints them.
//! Sampling is not a proof: the factor covers what the samples miss, and the closed-loop
//! red-team campaigns check the result from the simulator's true state.

use nalgebra::{Vector3, Vector6};
use sc_multibody::{Robot, Vector7, Vector13};

/// Factor the configured bounds must keep over the sampled maxima.
pub const SAFETY_FACTOR: f64 = 1.5;

/// Sampled maxima over the envelope.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnvelopeMaxima {
    /// max ‖ω̇_B‖ [rad/s²].
    pub angular_accel: f64,
    /// max |ω̈_B,i| over the axes [rad/s³].
    pub angular_jerk: f64,
    /// max |θ⃛_i| per joint [rad/s³].
    pub joint_jerk: [f64; 7],
    /// max ‖p⃛_k‖ of each link sphere's centre in the base frame [m/s³].
    pub sphere_jerk: [f64; 21],
    /// Samples drawn.
    pub samples: usize,
}

fn lcg(s: &mut u64) -> f64 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// Samples the envelope of scenario `s` with the servicer model `robot`.
pub fn sample(
    s: &sc_scenario::Scenario,
    robot: &Robot,
    samples: usize,
    seed: u64,
) -> EnvelopeMaxima {
    let rb = &s.safety.robotic;
    let at = &s.safety.attitude;
    let lim = &s.limits;
    let tmin = Vector7::from(rb.theta_min_rad);
    let tmax = Vector7::from(rb.theta_max_rad);
    let tdmax = Vector7::from(rb.theta_dot_max_rad_s);
    let wmax = Vector3::from(at.omega_max_rad_s)
        .abs()
        .sup(&Vector3::from(at.omega_min_rad_s).abs());
    let beta = Vector3::from(at.arm_reaction_budget_rad_s2);
    let period = s.mission.control_period_s;
    let mut out = EnvelopeMaxima::default();
    let mut rng = seed.max(1);
    for _ in 0..samples {
        let mut r = || lcg(&mut rng);
        let th =
            Vector7::from_fn(|i, _| 0.5 * (tmin[i] + tmax[i]) + 0.5 * (tmax[i] - tmin[i]) * r());
        let thd = Vector7::from_fn(|i, _| tdmax[i] * r());
        let w = Vector3::from_fn(|i, _| wmax[i] * r());
        let f = Vector3::from_fn(|_, _| lim.force_max_n * r());
        let tb = Vector3::from_fn(|_, _| lim.torque_max_nm * r());
        let Some(bd) = robot.base_angular_dynamics(&th, &thd, &w, &f) else {
            continue;
        };
        let wrench = Vector6::new(f.x, f.y, f.z, tb.x, tb.y, tb.z);
        let Some(red) = robot.reduced_arm_dynamics(&th, &thd, &w, &wrench) else {
            continue;
        };
        let Some(ch) = red.m_eff.cholesky() else {
            continue;
        };
        let a = ch.inverse();
        // joint torques: random in the box, scaled into the contract, then towards zero
        // until the joint accelerations are ones the joint-rate rows admit
        // the arm's torque beyond holding its rates, scaled into the contract
        let hold = red.c_eff;
        let mut delta = Vector7::from_fn(|_, _| lim.joint_torque_max_nm * r()) - hold;
        let qt = bd.q * delta;
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
        let mut tm =
            (hold + delta).map(|t| t.clamp(-lim.joint_torque_max_nm, lim.joint_torque_max_nm));
        let admitted = |t: &Vector7| {
            let qdd = a * (t - red.c_eff);
            (0..7).all(|i| qdd[i].abs() <= 2.0 * tdmax[i] / period)
        };
        if !admitted(&tm) {
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
            if !admitted(&from(lo)) {
                continue;
            }
            tm = from(lo);
        }
        let mut u = Vector13::zeros();
        u.fixed_rows_mut::<3>(0).copy_from(&f);
        u.fixed_rows_mut::<3>(3).copy_from(&tb);
        u.fixed_rows_mut::<7>(6).copy_from(&tm);
        let Some(acc) = robot.forward_dynamics_sim(&th, &w, &thd, &u) else {
            continue;
        };
        let wd: Vector3<f64> = acc.fixed_rows::<3>(3).into();
        let qdd: Vector7 = acc.fixed_rows::<7>(6).into();
        // d/dt along the state's own motion, central differences (the body-fixed base
        // force and torque and the joint torques are held, as in a sample)
        let d = 1e-5;
        let at_ = |e: f64| {
            robot.forward_dynamics_sim(&(th + thd * e), &(w + wd * e), &(thd + qdd * e), &u)
        };
        let qdd_at = |_e: f64| qdd;
        let (Some(p), Some(m)) = (at_(d), at_(-d)) else {
            continue;
        };
        let jerk = (p - m) / (2.0 * d);
        // the link spheres' centres: p̈ = J θ̈ + J̇ θ̇, differentiated the same way
        let sphere_acc = |e: f64, qdd: &Vector7| {
            let th_e = th + thd * e;
            let thd_e = thd + qdd_at(e) * e;
            let kin = robot.kinematics_vel(&th_e, &thd_e);
            let mut out = [Vector3::zeros(); 21];
            for (k, (idx, _)) in robot.arm_spheres().take(21).enumerate() {
                if let Some(sp) = robot.sphere_state(&kin, idx) {
                    out[k] = sp.jacobian * qdd + sp.jdot_qdot;
                }
            }
            out
        };
        let qdd_p: Vector7 = p.fixed_rows::<7>(6).into();
        let qdd_m: Vector7 = m.fixed_rows::<7>(6).into();
        let (ap, am) = (sphere_acc(d, &qdd_p), sphere_acc(-d, &qdd_m));
        for k in 0..21 {
            out.sphere_jerk[k] = out.sphere_jerk[k].max(((ap[k] - am[k]) / (2.0 * d)).norm());
        }
        out.angular_accel = out.angular_accel.max(wd.norm());
        for i in 0..3 {
            out.angular_jerk = out.angular_jerk.max(jerk[3 + i].abs());
        }
        for i in 0..7 {
            out.joint_jerk[i] = out.joint_jerk[i].max(jerk[6 + i].abs());
        }
        out.samples += 1;
    }
    out
}

/// One configured envelope bound against its sampled maximum.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundCheck {
    /// The scenario key, e.g. `safety.robotic.joint_jerk_bound_rad_s3[6]`.
    pub key: String,
    pub configured: f64,
    pub sampled: f64,
}

impl BoundCheck {
    /// The configured bound keeps [`SAFETY_FACTOR`] over the sampled maximum.
    pub fn holds(&self) -> bool {
        self.configured >= SAFETY_FACTOR * self.sampled
    }
}

/// Every envelope bound of scenario `s` against the maxima `m` (the link-sphere bound
/// is per link: the largest of its three spheres).
pub fn checks(s: &sc_scenario::Scenario, m: &EnvelopeMaxima) -> Vec<BoundCheck> {
    let a = &s.safety.attitude;
    let r = &s.safety.robotic;
    let mut v = vec![
        BoundCheck {
            key: "safety.attitude.angular_accel_bound_rad_s2".into(),
            configured: a.angular_accel_bound_rad_s2,
            sampled: m.angular_accel,
        },
        BoundCheck {
            key: "safety.attitude.angular_jerk_bound_rad_s3".into(),
            configured: a.angular_jerk_bound_rad_s3,
            sampled: m.angular_jerk,
        },
    ];
    for i in 0..7 {
        v.push(BoundCheck {
            key: format!("safety.robotic.joint_jerk_bound_rad_s3[{i}]"),
            configured: r.joint_jerk_bound_rad_s3[i],
            sampled: m.joint_jerk[i],
        });
    }
    for link in 0..7 {
        v.push(BoundCheck {
            key: format!("safety.robotic.link_sphere_jerk_bound_m_s3[{link}]"),
            configured: r.link_sphere_jerk_bound_m_s3[link],
            sampled: (0..3)
                .map(|k| m.sphere_jerk[3 * link + k])
                .fold(0.0, f64::max),
        });
    }
    v
}
