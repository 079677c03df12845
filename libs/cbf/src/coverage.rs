//! Which declared error sources (the scenario's `[uncertainty]`, docs/UNCERTAINTY.md) the
//! filters' margins cover — the one place that says so, updated as margins land
//! (docs/SAFETY.md, "Margins for the declared errors"). A run, a campaign and the red team
//! name every declared source outside this list: for those the promise does not hold.

use sc_scenario::Uncertainty;

/// The declared sources the rows budget for: the robotic filter's joint-torque margins.
pub const COVERED: [&str; 3] = [
    "actuators.joint_torque_scale_rel",
    "actuators.joint_torque_bias_nm",
    "actuators.joint_torque_ripple_rel",
];

/// The sources `u` declares non-zero that no margin covers, in declaration order.
pub fn not_covered(u: &Uncertainty) -> Vec<String> {
    u.declared_sources()
        .into_iter()
        .filter(|k| !COVERED.contains(&k.as_str()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_declares_nothing_and_realistic_names_what_is_not_covered() {
        assert!(not_covered(&Uncertainty::default()).is_empty());
        let realistic =
            Uncertainty::profile("realistic", std::path::Path::new(".")).expect("profile");
        let open = not_covered(&realistic);
        assert!(
            open.contains(&"model.link_mass_rel".to_string()),
            "{open:?}"
        );
        assert!(open.contains(&"navigation.relative_position_m".to_string()));
        assert!(open.contains(&"actuators.thruster_force_scale_rel".to_string()));
        assert!(COVERED.iter().all(|c| !open.iter().any(|o| o == c)));
        // realistic declares no measurement age: not named
        assert!(!open.contains(&"navigation.measurement_age_s".to_string()));
        let mut only_motors = Uncertainty::default();
        only_motors.actuators.joint_torque_bias_nm = 0.002;
        only_motors.actuators.joint_torque_scale_rel = 0.01;
        assert!(not_covered(&only_motors).is_empty());
    }
}
