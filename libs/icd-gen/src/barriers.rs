//! The entries of the ICD's array fields by name and unit: the barriers (names of
//! `sc_cbf::names`, in the filters' report order and, concatenated, in telemetry order)
//! with the unit each filter and the simulator's monitor compute it in.

use sc_core::Subsystem;
use sc_icd::spec::Components;

/// The unit of a barrier `h` by its name (`sc_mission::constraint_names()`): one
/// definition, with the names (`sc_cbf::names::unit`).
pub use sc_cbf::names::unit as barrier_unit;

/// The constraints of `s`'s safety filter, in its report's order (`h`, `phi`, bits of
/// `active_mask`).
pub fn constraint_names(s: Subsystem) -> &'static [&'static str] {
    match s {
        Subsystem::Translational => &sc_cbf::names::TRANSLATIONAL,
        Subsystem::Attitude => &sc_cbf::names::ATTITUDE,
        Subsystem::Robotic => &sc_cbf::names::ROBOTIC,
    }
}

/// Every barrier of the safety layer in telemetry order (the filters' constraints in
/// causal order, then the arm–target barriers only the monitor evaluates;
/// `SimState.barriers`).
pub fn all_barrier_names() -> Vec<&'static str> {
    Subsystem::ALL
        .into_iter()
        .flat_map(|s| constraint_names(s).iter().copied())
        .chain(sc_cbf::names::ARM_TARGET.iter().copied())
        .collect()
}

/// "by index: 0 name [unit], 1 …" of `names`, each unit followed by `per` (`/s` for rates).
fn by_index(names: &[&str], per: &str) -> String {
    let list: Vec<String> = names
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{i} {n} [{}{per}]", barrier_unit(n).unwrap_or("?")))
        .collect();
    format!("by index: {}", list.join(", "))
}

/// What the entries of an array field are, one line (`None` for a scalar).
pub fn components_line(c: Components) -> Option<String> {
    Some(match c {
        Components::One => return None,
        Components::Xyz => "x, y, z".to_string(),
        Components::Wxyz => "w, x, y, z (scalar first)".to_string(),
        Components::Joints => format!("joints 1..{} in order", sc_icd::N_JOINTS),
        Components::Barriers => by_index(&all_barrier_names(), ""),
        Components::Constraints {
            subsystem,
            per_second,
        } => by_index(
            constraint_names(subsystem),
            if per_second { "/s" } else { "" },
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every barrier has a unit (a new constraint cannot appear without one).
    #[test]
    fn every_barrier_has_a_unit() {
        for n in all_barrier_names() {
            assert!(barrier_unit(n).is_some(), "{n}");
        }
        assert_eq!(barrier_unit("theta_dot_max_3"), Some("rad/s"));
        assert_eq!(barrier_unit("theta_3"), Some("rad²"));
        assert_eq!(barrier_unit("link_base_2_1"), Some("m²"));
        assert_eq!(barrier_unit("something_else"), None);
    }

    /// The names are the telemetry's and the ICD's array lengths.
    #[test]
    fn names_are_the_telemetry_order_and_fit_the_arrays() {
        assert_eq!(all_barrier_names(), sc_mission::constraint_names());
        assert_eq!(all_barrier_names().len(), sc_icd::N_BARRIERS);
        let lens = [
            sc_icd::N_CONSTRAINTS_TRANSLATIONAL,
            sc_icd::N_CONSTRAINTS_ATTITUDE,
            sc_icd::N_CONSTRAINTS_ROBOTIC,
        ];
        for s in Subsystem::ALL {
            assert_eq!(constraint_names(s).len(), lens[s.position()], "{s}");
        }
    }

    #[test]
    fn component_lines() {
        let tr = Components::Constraints {
            subsystem: Subsystem::Translational,
            per_second: true,
        };
        assert_eq!(
            components_line(tr).unwrap(),
            "by index: 0 approach_corridor [m/s], 1 collision_avoidance_zone [m²/s]"
        );
        assert_eq!(components_line(Components::One), None);
        assert_eq!(
            components_line(Components::Joints).unwrap(),
            "joints 1..7 in order"
        );
    }
}
