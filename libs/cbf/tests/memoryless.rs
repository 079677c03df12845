//! The memoryless property of every filter is in `conformance.rs`
//! (`output_depends_on_its_inputs_only`, `outputs_are_the_same_on_another_thread`). Here:
//! that its robotic pairs reach the verification path, which integrates the model — the
//! path with the most internal work whose result could depend on a previous step.

mod common;
use common::*;
use sc_cbf::{FilterOutput, RoboticFilter, RoboticParams};

/// Every bit of an output except the timings.
fn bits<const M: usize, const N: usize>(o: &FilterOutput<M, N>) -> Vec<u64> {
    o.u.iter()
        .chain(o.actuated.iter())
        .map(|x| x.to_bits())
        .chain(o.report.deterministic_bits())
        .collect()
}

/// The conformance suite's robotic pairs (seed 13, 250 pairs, the second input of each is
/// the one compared): without the model the filter cannot verify, so where the output
/// with and without the model differ, the verification path produced the command.
#[test]
fn robotic_memoryless_pairs_reach_the_verification_path() {
    let s = scenario();
    let mut rng = Lcg(13);
    let mut with_model = RoboticFilter::from_scenario(&s, robot());
    let mut blind = RoboticFilter::new(RoboticParams::from_scenario(&s));
    let mut verified = 0;
    for _ in 0..250 {
        let _ = rob_draw(&mut rng);
        let (x, u) = rob_draw(&mut rng);
        if bits(&blind.filter_with(&x, u.as_ref())) != bits(&with_model.filter_with(&x, u.as_ref()))
        {
            verified += 1;
        }
    }
    println!("{verified} commands from the verification path");
    assert!(
        verified >= 10,
        "the verification path was reached {verified} times"
    );
}
