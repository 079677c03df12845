//! The filters are memoryless: a filter step's output depends on its inputs only,
//! not on the steps the same filter object took before. The partition relies on
//! this for its pre-tick warm-up (each filter rehearses its step on the previous
//! tick's inputs and drops the result, docs/PARTITION.md), and the in-process and
//! partition runs rely on it to give the same bits.
//!
//! For random pairs of inputs (a, b): a fresh filter's output on b equals, bit for
//! bit, the output on b of a filter that first took a step on a (and on b itself).
//! The pairs reach the skip path, the solved QP and the relaxed QP.

mod common;
use common::*;
use nalgebra::Vector3;
use sc_cbf::robotic::Vector7;
use sc_cbf::{AttitudeFilter, FilterOutput, FilterStatus, RoboticFilter, TranslationalFilter};
use sc_models::quat;

/// Every bit of an output except the wall-clock solve time.
fn bits<const M: usize, const N: usize>(o: &FilterOutput<M, N>) -> Vec<u64> {
    let r = &o.report;
    o.u.iter()
        .chain(o.actuated.iter())
        .chain(r.h.iter())
        .chain(r.phi.iter())
        .chain([&r.slack])
        .map(|x| x.to_bits())
        .chain([
            r.active,
            r.status as u64,
            u64::from(r.iterations),
            u64::from(r.faults),
        ])
        .collect()
}

/// Counts of the statuses the test reached, to check it exercised the solver.
#[derive(Default, Debug)]
struct Reached {
    skipped: usize,
    solved: usize,
    relaxed: usize,
}

impl Reached {
    fn add(&mut self, s: FilterStatus) {
        match s {
            FilterStatus::Skipped => self.skipped += 1,
            FilterStatus::Solved => self.solved += 1,
            FilterStatus::Relaxed => self.relaxed += 1,
            _ => {}
        }
    }
}

fn unit_quat(rng: &mut Lcg) -> quat::Quat {
    let q = [rng.next(), rng.next(), rng.next(), rng.next()];
    quat::normalized(&q).unwrap_or(quat::IDENTITY)
}

#[test]
fn translational_output_depends_on_its_inputs_only() {
    let s = scenario();
    let mut rng = Lcg(11);
    let fmax = s.limits.force_max_n;
    let draw = |rng: &mut Lcg| {
        // inside, near and outside the corridor and the collision-avoidance zone
        let r = Vector3::new(rng.next() * 30.0, rng.next() * 8.0, rng.next() * 8.0);
        let v = rng.v3(0.4);
        let x = tr_input(&s, r, v, unit_quat(rng));
        (x, rng.v3(1.5 * fmax))
    };
    let mut seen = Reached::default();
    for _ in 0..400 {
        let (xa, fa) = draw(&mut rng);
        let (xb, fb) = draw(&mut rng);
        let fresh = TranslationalFilter::from_scenario(&s, MASS).filter(&xb, &fb);
        let mut used = TranslationalFilter::from_scenario(&s, MASS);
        used.filter(&xa, &fa);
        assert_eq!(
            bits(&used.filter(&xb, &fb)),
            bits(&fresh),
            "after a step on {xa:?}"
        );
        assert_eq!(bits(&used.filter(&xb, &fb)), bits(&fresh), "repeated");
        seen.add(fresh.report.status);
    }
    assert!(
        seen.skipped > 0 && seen.solved > 0 && seen.relaxed > 0,
        "{seen:?}"
    );
}

#[test]
fn attitude_output_depends_on_its_inputs_only() {
    let s = scenario();
    let mut rng = Lcg(12);
    let tmax = s.limits.torque_max_nm;
    let draw = |rng: &mut Lcg| {
        let r = Vector3::new(-3.0 + rng.next(), rng.next(), rng.next());
        let x = att_input(r, unit_quat(rng), rng.v3(0.1), 40.0 * (1.0 + rng.next()));
        (x, rng.v3(1.5 * tmax))
    };
    let mut seen = Reached::default();
    for _ in 0..400 {
        let (xa, ta) = draw(&mut rng);
        let (xb, tb) = draw(&mut rng);
        let fresh = AttitudeFilter::from_scenario(&s).filter(&xb, &tb);
        let mut used = AttitudeFilter::from_scenario(&s);
        used.filter(&xa, &ta);
        assert_eq!(
            bits(&used.filter(&xb, &tb)),
            bits(&fresh),
            "after a step on {xa:?}"
        );
        assert_eq!(bits(&used.filter(&xb, &tb)), bits(&fresh), "repeated");
        seen.add(fresh.report.status);
    }
    assert!(seen.skipped > 0 && seen.solved > 0, "{seen:?}");
}

#[test]
fn robotic_output_depends_on_its_inputs_only() {
    let s = scenario();
    let robot = robot();
    let mut rng = Lcg(13);
    let tmax = s.limits.joint_torque_max_nm;
    let th0 = theta0(&s);
    let draw = |rng: &mut Lcg| {
        // near the start (the nominal is often feasible) or far out at the limits
        let far = rng.next() > 0.0;
        let k = if far { 1.0 } else { 1e-3 };
        let x = rob_input(&robot, th0 + rng.v7(1.5 * k), rng.v7(0.4 * k));
        (x, rng.v7(1.5 * k * tmax))
    };
    let mut seen = Reached::default();
    for _ in 0..300 {
        let (xa, ta): (_, Vector7) = draw(&mut rng);
        let (xb, tb) = draw(&mut rng);
        let fresh = RoboticFilter::from_scenario(&s).filter(&xb, &tb);
        let mut used = RoboticFilter::from_scenario(&s);
        used.filter(&xa, &ta);
        assert_eq!(bits(&used.filter(&xb, &tb)), bits(&fresh), "after a step");
        assert_eq!(bits(&used.filter(&xb, &tb)), bits(&fresh), "repeated");
        seen.add(fresh.report.status);
    }
    assert!(seen.skipped > 0 && seen.solved > 0, "{seen:?}");
}
