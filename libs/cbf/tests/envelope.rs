//! The scenario's bounds on the servicer's dynamics over the certified envelope (the
//! constants the sampled-data rows of the attitude and robotic filters rely on) against the
//! model: `sc_cbf::envelope::sample` draws states and inputs of the envelope with a fixed
//! seed, and every configured bound must keep the factor `SAFETY_FACTOR` (1.5) over the
//! sampled maxima.

mod common;
use common::*;
use sc_cbf::envelope::{self, SAFETY_FACTOR};

const SAMPLES: usize = 20_000;

#[test]
fn envelope_bounds_cover_the_model() {
    check_bounds(SAMPLES, 7);
}

/// The sampled maxima grow with the sample count; the configured bounds keep the factor
/// over 200 000 samples (seed 11) too — but not against the targeted search
/// ([`the_targeted_search_climbs_above_the_samples`], docs/SAFETY.md "The envelope
/// bounds"): sampling is not a proof. About 7 s.
#[test]
fn envelope_bounds_cover_the_model_with_200k_samples() {
    check_bounds(200_000, 11);
}

fn check_bounds(samples: usize, seed: u64) {
    let s = scenario();
    let robot = robot();
    let m = envelope::sample(&s, &robot, samples, seed);
    println!("{m:?}");
    // the sampling really ran over the envelope
    assert!(
        m.samples * 10 >= samples * 9,
        "only {} of {samples} samples were usable",
        m.samples
    );
    assert!(m.angular_accel > 0.0 && m.angular_jerk > 0.0);
    assert!(m.joint_jerk.iter().all(|j| *j > 0.0), "{:?}", m.joint_jerk);
    assert_eq!(SAFETY_FACTOR, 1.5);
    let short: Vec<String> = envelope::checks(&s, &m)
        .iter()
        .filter(|c| !c.holds())
        .map(|c| {
            format!(
                "{}: configured {} < {SAFETY_FACTOR} × sampled {:.4} = {:.4}",
                c.key,
                c.configured,
                c.sampled,
                SAFETY_FACTOR * c.sampled
            )
        })
        .collect();
    assert!(
        short.is_empty(),
        "bounds below the model's sampled maxima:\n{}",
        short.join("\n")
    );
}

/// The sampling is deterministic (the bounds are reproducible): the same seed gives the
/// same maxima, another seed different ones of the same size.
#[test]
fn envelope_sampling_is_reproducible() {
    let s = scenario();
    let robot = robot();
    let a = envelope::sample(&s, &robot, 500, 3);
    let b = envelope::sample(&s, &robot, 500, 3);
    assert_eq!(a, b);
    let c = envelope::sample(&s, &robot, 500, 4);
    assert_ne!(a, c);
    assert!(c.angular_jerk < 3.0 * a.angular_jerk && a.angular_jerk < 3.0 * c.angular_jerk);
}

/// The targeted search starts from the sampled worst points and only climbs: it finds at
/// least the sampled maximum of every quantity, and more than the samples for most of them.
/// (What it finds is measured against the configured bounds in docs/SAFETY.md, "The
/// envelope bounds": 7–8 of 16 are exceeded — issue #26 item 2 is open.)
#[test]
fn the_targeted_search_climbs_above_the_samples() {
    let s = scenario();
    let robot = robot();
    let sampled = envelope::sample(&s, &robot, 2_000, 7);
    let searched = envelope::search(&s, &robot, 2_000, 7, 300);
    assert_eq!(searched.samples, sampled.samples);
    let pairs = [
        (sampled.angular_accel, searched.angular_accel),
        (sampled.angular_jerk, searched.angular_jerk),
    ]
    .into_iter()
    .chain(sampled.joint_jerk.into_iter().zip(searched.joint_jerk))
    .chain(sampled.sphere_jerk.into_iter().zip(searched.sphere_jerk));
    let (mut higher, mut moving) = (0, 0);
    for (a, b) in pairs {
        assert!(b >= a, "the search lost a maximum: {b} < {a}");
        if a > 0.0 {
            moving += 1;
            higher += usize::from(b > a);
        }
    }
    assert!(
        higher * 10 >= moving * 8,
        "only {higher} of {moving} maxima raised"
    );
}
