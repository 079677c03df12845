//! The scenario's bounds on the servicer's dynamics over the certified envelope (the
//! constants the sampled-data rows of the attitude and robotic filters take) against the
//! model: `sc_cbf::envelope::sample` draws states and inputs of the envelope with a fixed
//! seed, and every configured bound keeps the factor `SAFETY_FACTOR` (1.5) over the
//! sampled maxima; the load-bearing ones also over a targeted search.

mod common;
use common::*;
use sc_cbf::envelope::{self, SAFETY_FACTOR};

const SAMPLES: usize = 20_000;

#[test]
fn envelope_bounds_cover_the_model() {
    check_bounds(SAMPLES, 7);
}

/// The sampled maxima grow with the sample count; the configured bounds keep the factor
/// over 200 000 samples (seed 11) too — but the robotic ones not against the targeted
/// search ([`the_targeted_search_climbs_above_the_samples`], docs/SAFETY.md "The envelope
/// bounds"): sampling is not a proof, which is why the robotic filter verifies every
/// command and the load-bearing bound is checked against a search. About 7 s.
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
    assert!(m.angular_jerk > 0.0);
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
/// (What it finds against the configured bounds: docs/SAFETY.md, "The envelope bounds".)
#[test]
fn the_targeted_search_climbs_above_the_samples() {
    let s = scenario();
    let robot = robot();
    let sampled = envelope::sample(&s, &robot, 2_000, 7);
    let searched = envelope::search(&s, &robot, 2_000, 7, 300);
    assert_eq!(searched.samples, sampled.samples);
    let pairs = [(sampled.angular_jerk, searched.angular_jerk)]
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

/// The bounds a certificate rests on (`Reliance::Certificate`: the attitude's angular
/// jerk) against a targeted worst-case search, not only samples: `witnesses` (what every
/// command refuses below) finds none refuted, and the longest search documented
/// (docs/SAFETY.md, "The envelope bounds": seed 17, 20 000 samples, 100 000 rounds; about
/// 2 s) finds the value documented there — the test would see a weaker search — and
/// every load-bearing bound keeps the factor 1.5 over it. The robotic jerk bounds are
/// verified per step instead (`the_arm_stays_safe_with_its_jerk_bounds_cut_to_a_tenth`
/// in the app's red-team tests); `safe-capture bounds --search-rounds` reports them.
#[test]
fn load_bearing_bounds_keep_the_factor_over_the_search() {
    let s = scenario();
    let robot = robot();
    let w = envelope::witnesses(&s, &robot);
    assert!(w.evidence(), "{w:?}");
    assert!(!w.checks.is_empty());
    for c in &w.checks {
        assert_eq!(c.reliance, envelope::Reliance::Certificate, "{c:?}");
        assert!(c.sampled > 0.0, "{c:?}");
    }
    assert_eq!(w.refuted(), None);
    let long = envelope::witnesses_with(&s, &robot, 20_000, 17, 100_000);
    let jerk = &long.checks[0];
    assert_eq!(jerk.key, "safety.attitude.angular_jerk_bound_rad_s3");
    assert!(
        jerk.sampled > 0.226,
        "the documented search found 0.2268: {jerk:?}"
    );
    for c in &long.checks {
        assert!(
            c.holds(),
            "{}: {} < {SAFETY_FACTOR} × {}",
            c.key,
            c.configured,
            c.sampled
        );
    }
}

/// A load-bearing bound below what the model reaches is found so: with the angular jerk
/// bound at a tenth, the witness search refutes it.
#[test]
fn a_bound_below_the_model_is_refuted_by_a_witness() {
    let mut s = scenario();
    s.safety.attitude.angular_jerk_bound_rad_s3 *= 0.1;
    let w = envelope::witnesses(&s, &robot());
    assert!(
        w.refuted()
            .is_some_and(|c| c.key == "safety.attitude.angular_jerk_bound_rad_s3"),
        "{w:?}"
    );
}

/// What the search finds for one quantity does not depend on which others it searched:
/// `witnesses` (the load-bearing ones only) finds what the full search (`safe-capture
/// bounds`) finds for them.
#[test]
fn a_witness_is_what_the_full_search_finds() {
    let s = scenario();
    let robot = robot();
    let w = envelope::witnesses_with(&s, &robot, 500, 3, 200);
    let full = envelope::search(&s, &robot, 500, 3, 200);
    let all = envelope::checks(&s, &full);
    for c in &w.checks {
        let same = all.iter().find(|a| a.key == c.key).unwrap();
        assert_eq!(c.sampled, same.sampled, "{}", c.key);
    }
}
