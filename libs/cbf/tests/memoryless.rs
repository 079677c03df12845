//! The filters are memoryless: a filter step's output depends on its inputs only, not on
//! the steps the same filter object took before. The partition relies on this for its
//! pre-tick warm-up (each filter rehearses its step on the previous tick's inputs and drops
//! the result, docs/PARTITION.md), and the in-process and partition runs rely on it to give
//! the same bits.
//!
//! For random pairs of inputs (a, b): a fresh filter's output on b equals, bit for bit, the
//! output on b of a filter that first took a step on a (and then on b itself once more).
//! The pairs reach the skip path, the solved QP, the relaxed QP and — for the robotic
//! filter — the verification path that integrates the model.

mod common;
use common::*;
use nalgebra::{SVector, Vector3};
use sc_cbf::robotic::Vector7;
use sc_cbf::{
    AttitudeFilter, FilterOutput, FilterStatus, RoboticFilter, RoboticParams, TranslationalFilter,
};

/// Every bit of an output except the wall-clock solve time.
fn bits<const M: usize, const N: usize>(o: &FilterOutput<M, N>) -> Vec<u64> {
    o.u.iter()
        .chain(o.actuated.iter())
        .map(|x| x.to_bits())
        .chain(o.report.deterministic_bits())
        .collect()
}

/// Counts of the statuses reached, to check the test exercised every path.
#[derive(Default, Debug)]
struct Reached {
    skipped: usize,
    solved: usize,
    relaxed: usize,
    other: usize,
}

impl Reached {
    fn add(&mut self, s: FilterStatus) {
        match s {
            FilterStatus::Skipped => self.skipped += 1,
            FilterStatus::Solved => self.solved += 1,
            FilterStatus::Relaxed => self.relaxed += 1,
            FilterStatus::Fallback => self.other += 1,
        }
    }
}

/// A nominal, missing one time in ten.
fn maybe<const M: usize>(rng: &mut Lcg, u: SVector<f64, M>) -> Option<SVector<f64, M>> {
    (rng.next() > -0.8).then_some(u)
}

#[test]
fn translational_output_depends_on_its_inputs_only() {
    let s = scenario();
    let mut rng = Lcg(11);
    let fmax = s.limits.force_max_n;
    let draw = |rng: &mut Lcg| {
        // inside, near and outside the corridor (5°) and the collision-avoidance zone
        let ang = (3.0 + 3.0 * rng.next()).to_radians();
        let phi = std::f64::consts::PI * rng.next();
        let dir = Vector3::new(-ang.cos(), ang.sin() * phi.cos(), ang.sin() * phi.sin());
        let r = dir * (5.0 + 3.5 * rng.next());
        let x = tr_input(&s, r, rng.v3(0.04), rng.unit_quat(), rng.v3(0.1));
        let u = rng.v3(1.5 * fmax);
        (x, maybe(rng, u))
    };
    let mut seen = Reached::default();
    for _ in 0..400 {
        let (xa, fa) = draw(&mut rng);
        let (xb, fb) = draw(&mut rng);
        let fresh = TranslationalFilter::from_scenario(&s, mass()).filter_with(&xb, fb.as_ref());
        let mut used = TranslationalFilter::from_scenario(&s, mass());
        used.filter_with(&xa, fa.as_ref());
        assert_eq!(
            bits(&used.filter_with(&xb, fb.as_ref())),
            bits(&fresh),
            "after a step on {xa:?}"
        );
        assert_eq!(
            bits(&used.filter_with(&xb, fb.as_ref())),
            bits(&fresh),
            "repeated"
        );
        seen.add(fresh.report.status);
    }
    println!("{seen:?}");
    assert!(
        seen.skipped >= 20 && seen.solved >= 20 && seen.relaxed >= 20,
        "{seen:?}"
    );
}

#[test]
fn attitude_output_depends_on_its_inputs_only() {
    let s = scenario();
    let robot = robot();
    let mut rng = Lcg(12);
    let tmax = s.limits.torque_max_nm;
    let draw = |rng: &mut Lcg| {
        let com = Vector3::new(-3.0, 0.0, 0.0) + rng.v3(0.5);
        let t = 40.0 * (1.0 + rng.next());
        let st = ServicerState {
            theta: theta_inside(&s, rng, 0.1),
            theta_dot: rng.v7(0.1),
            // the roll about the boresight (body x) free, the rates across it mostly
            // inside the certified set's boresight-rate limit
            omega_b: Vector3::new(0.06 * rng.next(), 0.035 * rng.next(), 0.035 * rng.next()),
            q_rb: pointing(&s, &com, t, &rng.v3(1.0), 5f64.to_radians() * rng.next()),
            com_r: com,
            com_v_r: rng.v3(0.02),
            t,
            f_b: rng.v3(5.0),
        };
        let u = rng.v3(1.5 * tmax);
        (att_input(&s, &robot, &st), maybe(rng, u))
    };
    let mut seen = Reached::default();
    for _ in 0..400 {
        let (xa, ta) = draw(&mut rng);
        let (xb, tb) = draw(&mut rng);
        let fresh = AttitudeFilter::from_scenario(&s, mass()).filter_with(&xb, tb.as_ref());
        let mut used = AttitudeFilter::from_scenario(&s, mass());
        used.filter_with(&xa, ta.as_ref());
        assert_eq!(
            bits(&used.filter_with(&xb, tb.as_ref())),
            bits(&fresh),
            "after a step on {xa:?}"
        );
        assert_eq!(
            bits(&used.filter_with(&xb, tb.as_ref())),
            bits(&fresh),
            "repeated"
        );
        seen.add(fresh.report.status);
    }
    println!("{seen:?}");
    assert!(
        seen.skipped >= 20 && seen.solved >= 20 && seen.relaxed >= 20,
        "{seen:?}"
    );
}

#[test]
fn robotic_output_depends_on_its_inputs_only() {
    let s = scenario();
    let robot = robot();
    let mut rng = Lcg(13);
    let tmax = s.limits.joint_torque_max_nm;
    let th0 = theta0(&s);
    let draw = |rng: &mut Lcg| {
        // near the start (the nominal is often feasible) or anywhere inside the limits,
        // moving
        let x = if rng.next() > 0.0 {
            rob_input(&robot, th0 + rng.v7(1e-3), rng.v7(1e-3))
        } else {
            rob_input(&robot, theta_inside(&s, rng, 0.0), rng.v7(0.3))
        };
        let hold = -(x.m_eff * (x.drift + x.xi));
        let k = if rng.next() > 0.0 { 1e-3 } else { 1.5 };
        let u = hold + rng.v7(k * tmax);
        (x, maybe(rng, u))
    };
    // without the model the filter cannot verify: where both differ, the verification
    // path produced the command
    let mut blind = RoboticFilter::new(RoboticParams::from_scenario(&s));
    let mut seen = Reached::default();
    let mut verified = 0;
    for _ in 0..250 {
        let (xa, ta): (_, Option<Vector7>) = draw(&mut rng);
        let (xb, tb) = draw(&mut rng);
        let fresh = RoboticFilter::from_scenario(&s, robot.clone()).filter_with(&xb, tb.as_ref());
        let mut used = RoboticFilter::from_scenario(&s, robot.clone());
        used.filter_with(&xa, ta.as_ref());
        assert_eq!(
            bits(&used.filter_with(&xb, tb.as_ref())),
            bits(&fresh),
            "after a step"
        );
        assert_eq!(
            bits(&used.filter_with(&xb, tb.as_ref())),
            bits(&fresh),
            "repeated"
        );
        seen.add(fresh.report.status);
        if bits(&blind.filter_with(&xb, tb.as_ref())) != bits(&fresh) {
            verified += 1;
        }
    }
    println!("{seen:?}, {verified} commands from the verification path");
    assert!(
        seen.skipped >= 20 && seen.solved >= 20 && seen.relaxed >= 5,
        "{seen:?}"
    );
    assert!(
        verified >= 10,
        "the verification path was reached {verified} times"
    );
}

/// Threads do not share state either: the same sequence on another thread gives the
/// same bits.
#[test]
fn outputs_are_the_same_on_another_thread() {
    let run = || {
        let s = scenario();
        let mut rng = Lcg(99);
        let mut ft = TranslationalFilter::from_scenario(&s, mass());
        let mut fr = RoboticFilter::from_scenario(&s, robot());
        let mut out = Vec::new();
        for _ in 0..50 {
            let x = tr_input(
                &s,
                Vector3::new(-3.0, 0.2, 0.1) + rng.v3(1.0),
                rng.v3(0.1),
                rng.unit_quat(),
                rng.v3(0.1),
            );
            out.extend(bits(&ft.filter(&x, &rng.v3(10.0))));
            let xr = rob_input(&robot(), theta_inside(&s, &mut rng, 0.0), rng.v7(0.3));
            out.extend(bits(&fr.filter(&xr, &rng.v7(3.0))));
        }
        out
    };
    let here = run();
    let there = std::thread::spawn(run).join().unwrap();
    assert_eq!(here, there);
}
