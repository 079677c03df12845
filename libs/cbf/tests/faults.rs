//! The fault behaviour every filter shares — no panic, a finite command inside its bound
//! and the right flags for any input — is in `conformance.rs`. Here: the robotic filter's
//! own range checks of the upstream state its verification integrates with.

mod common;
use common::*;
use nalgebra::Vector3;
use sc_cbf::robotic::Vector7;
use sc_cbf::{RoboticFilter, faults};

/// KNOWN SRC ISSUE (reported): the robotic filter accepts any finite base rate and
/// upstream wrench (`omega_b`, `force_b`, `torque_b` are only checked for finiteness, unlike
/// every other input). With `τ_B = 1e300` (or `f_B = 1e300`, `ω_B = 1e3`) the verification's
/// integration fails for every candidate and the report says `Relaxed` with
/// `violation = +inf`; with `τ_B = 1e6 N m` the relaxed candidate leaves the torque box by
/// 5.7e-5 N m and the last-line clamp fires (`OUTPUT_CLAMPED`). The command stays finite and
/// bounded. Expected: such inputs flagged (`INVALID_COUPLING`/`INVALID_STATE`), the report
/// finite.
#[test]
fn robotic_filter_refuses_an_absurd_upstream_wrench_or_rate() {
    let s = scenario();
    let mut f = RoboticFilter::from_scenario(&s, robot());
    let mut th = theta0(&s);
    th[3] += 0.159;
    for (fb, tb, wb) in [
        (
            Vector3::zeros(),
            Vector3::new(0.0, 1e300, 1e300),
            Vector3::zeros(),
        ),
        (
            Vector3::new(1e300, 0.0, 0.0),
            Vector3::zeros(),
            Vector3::zeros(),
        ),
        (
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::new(1e3, 0.0, 0.0),
        ),
        (
            Vector3::zeros(),
            Vector3::new(1e6, 0.0, 0.0),
            Vector3::zeros(),
        ),
    ] {
        let mut x = rob_input(&robot(), th, Vector7::zeros());
        x.force_b = fb;
        x.torque_b = tb;
        x.omega_b = wb;
        let o = f.filter_with(&x, None);
        assert!(o.u.iter().all(|c| c.is_finite()) && o.u.amax() <= s.limits.joint_torque_max_nm);
        assert!(
            o.report.violation.is_finite(),
            "{fb} {tb} {wb}: {:?}",
            o.report
        );
        assert_eq!(
            o.report.faults & faults::OUTPUT_CLAMPED,
            0,
            "{:?}",
            o.report
        );
        assert_ne!(
            o.report.faults & (faults::INVALID_COUPLING | faults::INVALID_STATE),
            0,
            "{:?}",
            o.report
        );
    }
}
