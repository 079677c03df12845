//! The simulator's re-validation of every safe command before it applies it: the
//! filters are ours, but what arrives on a service is only bytes from whoever holds
//! its publisher. A command that is not finite or beyond the input bounds is
//! rejected, counted, flagged (`sc_icd::fault::REJECTED_COMMAND`) and replaced by the
//! filter's backup — the same path as a missing command (docs/PARTITION.md, "Faults").

use sc_icd::{SafeAttitude, SafeRobotic, SafeTranslational};
use sc_scenario::Limits;

/// Every component finite and within `±limit`.
pub fn within(v: &[f64], limit: f64) -> bool {
    v.iter().all(|x| x.is_finite() && x.abs() <= limit)
}

/// The translational safe command may be applied: the body-frame force it applies
/// within the force box, its Hill-frame force finite.
pub fn translational(m: &SafeTranslational, lim: &Limits) -> bool {
    within(&m.actuated, lim.force_max_n) && m.u.iter().all(|x| x.is_finite())
}

/// The attitude safe command may be applied: the torque within the torque box.
pub fn attitude(m: &SafeAttitude, lim: &Limits) -> bool {
    within(&m.u, lim.torque_max_nm) && within(&m.actuated, lim.torque_max_nm)
}

/// The robotic safe command may be applied: the joint torques within their box.
pub fn robotic(m: &SafeRobotic, lim: &Limits) -> bool {
    within(&m.u, lim.joint_torque_max_nm) && within(&m.actuated, lim.joint_torque_max_nm)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> Limits {
        sc_scenario::Scenario::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../config/scenario.toml"
        )))
        .unwrap()
        .limits
    }

    #[test]
    fn bounds_and_finiteness_are_enforced() {
        let lim = limits();
        let mut t = SafeTranslational::default();
        assert!(translational(&t, &lim));
        t.actuated[1] = lim.force_max_n;
        assert!(translational(&t, &lim));
        t.actuated[1] = lim.force_max_n * (1.0 + 1e-12);
        assert!(!translational(&t, &lim));
        t.actuated[1] = 0.0;
        t.u[2] = f64::NAN;
        assert!(!translational(&t, &lim));
        let mut a = SafeAttitude::default();
        a.u[0] = -lim.torque_max_nm;
        a.actuated[0] = -lim.torque_max_nm;
        assert!(attitude(&a, &lim));
        a.u[0] = f64::NEG_INFINITY;
        assert!(!attitude(&a, &lim));
        let mut r = SafeRobotic::default();
        r.u[6] = 1e300;
        assert!(!robotic(&r, &lim));
        r.u[6] = lim.joint_torque_max_nm;
        r.actuated[6] = lim.joint_torque_max_nm;
        assert!(robotic(&r, &lim));
    }
}
