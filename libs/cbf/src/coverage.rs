//! Which declared error sources (the scenario's `[uncertainty]`, docs/UNCERTAINTY.md) the
//! filters' margins cover — the one place that says so, updated as margins land
//! (docs/SAFETY.md, "Margins for the declared errors"). A run, a campaign and the red team
//! name every declared source outside this list: for those the promise does not hold.

use sc_scenario::{Scenario, Uncertainty};

/// The declared sources the rows budget for: the robotic filter's joint-torque margins,
/// in the sampled-data formulation (the paper's rows have no margins).
pub const COVERED: [&str; 3] = [
    "actuators.joint_torque_scale_rel",
    "actuators.joint_torque_bias_nm",
    "actuators.joint_torque_ripple_rel",
];

/// The sources `u` declares non-zero that no margin covers, in declaration order, when
/// the filters run with margins (`margins`: filtered, sampled-data formulation);
/// without them every declared source.
pub fn not_covered(u: &Uncertainty, margins: bool) -> Vec<String> {
    u.declared_sources()
        .into_iter()
        .filter(|k| !(margins && COVERED.contains(&k.as_str())))
        .collect()
}

/// [`not_covered`] for the scenario's declared uncertainty, with the filters on
/// (`filtered`) in the scenario's formulation.
pub fn not_covered_in(s: &Scenario, filtered: bool) -> Vec<String> {
    let margins = filtered && s.safety.formulation == crate::Formulation::SampledData;
    not_covered(&s.uncertainty_bounds(), margins)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_declares_nothing_and_realistic_names_what_is_not_covered() {
        assert!(not_covered(&Uncertainty::default(), true).is_empty());
        let realistic =
            Uncertainty::profile("realistic", std::path::Path::new(".")).expect("profile");
        let open = not_covered(&realistic, true);
        assert!(
            open.contains(&"model.link_mass_rel".to_string()),
            "{open:?}"
        );
        assert!(open.contains(&"navigation.relative_position_m".to_string()));
        assert!(open.contains(&"actuators.thruster_force_scale_rel".to_string()));
        // realistic declares no measurement age: not named
        assert!(!open.contains(&"navigation.measurement_age_s".to_string()));
        // without margins (no filter, the paper's rows) nothing is covered
        let all = realistic.declared_sources();
        assert_eq!(not_covered(&realistic, false), all);
        assert_eq!(all.len(), open.len() + COVERED.len());
        // the measurement age, when declared, is named last (after the navigation errors)
        let mut aged = realistic;
        aged.navigation.measurement_age_s = 0.05;
        let named = not_covered(&aged, true);
        assert_eq!(
            named.last().map(String::as_str),
            Some("navigation.measurement_age_s")
        );
        assert_eq!(named.len(), open.len() + 1);
    }

    /// Every covered key is a key the scenario declares (a typo would cover nothing), and
    /// only they are taken out.
    #[test]
    fn the_covered_keys_are_declared_keys() {
        let mut u = Uncertainty::default();
        let a = &mut u.actuators;
        (
            a.joint_torque_scale_rel,
            a.joint_torque_bias_nm,
            a.joint_torque_ripple_rel,
        ) = (0.01, 0.002, 0.01);
        assert_eq!(u.declared_sources(), COVERED.map(String::from).to_vec());
        assert!(not_covered(&u, true).is_empty());
        assert_eq!(not_covered(&u, false).len(), COVERED.len());
    }
}
