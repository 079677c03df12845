//! Leaving the certified envelope during a run, and the safe mode the layer switches to
//! (docs/SAFETY.md, "Safe mode").
//!
//! The certificate of the attitude filter's line-of-sight and rate rows rests on the
//! target's tumble staying inside the certified envelope ((E1), (E2) of
//! `sc_scenario::envelope`), which the start checks for the declared tumble. During the run
//! the tumble can leave it without anything in the mission declaring so (a collision, an
//! outgassing burst). [`EnvelopeWatch`] checks, at every control step and from knowledge
//! only, the fastest tumble consistent with the estimate `ω̂_T` and its declared error
//! against the same rules; when it breaks one, every stage of the chain is in **safe
//! mode** ([`crate::faults::SAFE_MODE`]):
//!
//! * the translational nominal becomes a radial retreat from the target in the
//!   target-centred, inertially fixed F_R (where the corridor is fixed),
//!   `f_H = sat(m (v_ref − v_H)/T_t)`, `v_ref = v_s r̂_H − ω_H × r_H`
//!   ([`crate::TranslationalFilter::toward_velocity`]), with `v_s` = 0 beyond the hold
//!   range;
//! * the robotic nominal becomes the arm's brake ([`crate::RoboticFilter::brake`]);
//! * the attitude nominal is kept (its filter's rows adapt to the estimated tumble).
//!
//! Every command still goes through its filter. The decision is a function of the
//! observation alone, so every filter process of the partition takes it on the same step
//! as the mission in one process does, without a message between them.

use nalgebra::Vector3;
use sc_core::Observation;
use sc_scenario::{Scenario, TumbleRule};

/// What the safe mode does (`[safety.safe_mode]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SafeModeParams {
    /// `v_s` [m/s].
    pub retreat_speed: f64,
    /// Beyond this distance from the target's CoM the servicer holds [m].
    pub hold_range: f64,
}

/// Checks the target's tumble, from knowledge, against the certified envelope.
#[derive(Debug, Clone)]
pub struct EnvelopeWatch {
    /// The declared scenario (its geometry, bounds and declared spin axis).
    scenario: Scenario,
    /// The declared bound on the error of `ω̂_T` [rad/s].
    rate_error: f64,
    params: SafeModeParams,
}

impl EnvelopeWatch {
    /// From the declared scenario.
    pub fn from_scenario(s: &Scenario) -> Self {
        let mut scenario = s.clone();
        // the watch never reads the world's undeclared events
        scenario.world = None;
        Self {
            rate_error: s.uncertainty_bounds().navigation.target_rate_rad_s.bound(),
            params: SafeModeParams {
                retreat_speed: s.safety.safe_mode.retreat_speed_m_s,
                hold_range: s.safety.safe_mode.hold_range_m,
            },
            scenario,
        }
    }

    /// What the safe mode does.
    pub fn params(&self) -> SafeModeParams {
        self.params
    }

    /// The rule of the envelope the tumble known at `o` breaks (`None`: inside). A
    /// non-finite estimate breaks the envelope too (nothing is known about the tumble).
    pub fn check(&self, o: &Observation) -> Option<TumbleRule> {
        let w = o.omega_t;
        self.check_rate(&[w.x, w.y, w.z], self.rate_error)
    }

    /// The rule broken by the fastest tumble within `error` [rad/s] of `omega_t` [rad/s,
    /// F_T] (the summary checks the true tumble with `error` = 0).
    pub fn check_rate(&self, omega_t: &[f64; 3], error: f64) -> Option<TumbleRule> {
        if !(omega_t.iter().all(|x| x.is_finite()) && error.is_finite()) {
            return Some(TumbleRule::Unknown);
        }
        let tumble = self.scenario.tumble_from_knowledge(omega_t, error);
        self.scenario
            .line_of_sight_envelope_for(&tumble)
            .broken_tumble_rule()
    }

    /// The envelope of the fastest tumble within `error` of `omega_t` (numbers for
    /// reports).
    pub fn envelope_of(&self, omega_t: &[f64; 3], error: f64) -> sc_scenario::LineOfSightEnvelope {
        let tumble = self.scenario.tumble_from_knowledge(omega_t, error);
        self.scenario.line_of_sight_envelope_for(&tumble)
    }

    /// The safe mode's reference velocity of the CoM in F_H [m/s] at `r_h` [m, F_H] with
    /// F_H turning at `omega_h` [rad/s, F_H]: `v_s r̂` in the target-centred, inertially
    /// fixed F_R — where the corridor is fixed — inside the hold range, at rest in F_R
    /// beyond it; in F_H that is `v_s r̂_H − ω_H × r_H` (zero at the target's centre or for
    /// a non-finite state).
    pub fn retreat_velocity(&self, r_h: &Vector3<f64>, omega_h: &Vector3<f64>) -> Vector3<f64> {
        let range = r_h.norm();
        if !(range.is_finite() && range > 0.0 && omega_h.iter().all(|w| w.is_finite())) {
            return Vector3::zeros();
        }
        let radial = if range < self.params.hold_range {
            r_h * (self.params.retreat_speed / range)
        } else {
            Vector3::zeros()
        };
        radial - omega_h.cross(r_h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn watch() -> EnvelopeWatch {
        let s = Scenario::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../config/scenario.toml"
        )))
        .unwrap();
        EnvelopeWatch::from_scenario(&s)
    }

    /// The Monte Carlo's fastest tumble (0.12 rad/s about the declared axis) known with the
    /// `realistic` profile's rate error (1e-3 rad/s), in any direction within it, is inside:
    /// no false alarm; 0.13 rad/s is outside (the limit is 0.1241), and so is a tumble off
    /// the declared principal axis by more than the error, or one not known at all.
    #[test]
    fn the_envelope_watch_tells_the_campaigns_tumbles_from_faster_ones() {
        let w = watch();
        let e = 1e-3;
        for across in [[0.0, 0.0], [e, 0.0], [0.0, -e], [0.7 * e, 0.7 * e]] {
            assert_eq!(w.check_rate(&[-0.12, across[0], across[1]], e), None);
        }
        assert_eq!(w.check_rate(&[0.0; 3], e), None);
        assert_eq!(w.check_rate(&[-0.13, 0.0, 0.0], e), Some(TumbleRule::Sync));
        assert_eq!(w.check_rate(&[-0.124, 0.0, 0.0], e), Some(TumbleRule::Sync));
        assert!(w.check_rate(&[-0.08, 0.05, 0.0], e).is_some());
        for bad in [f64::NAN, f64::INFINITY] {
            assert_eq!(w.check_rate(&[bad, 0.0, 0.0], e), Some(TumbleRule::Unknown));
            assert_eq!(w.check_rate(&[0.0; 3], bad), Some(TumbleRule::Unknown));
        }
    }

    /// The retreat: `v_s` radially in F_R inside the hold range, at rest in F_R beyond it,
    /// nothing for a state it cannot use.
    #[test]
    fn the_retreat_is_radial_in_the_inertial_frame_and_stops_at_the_hold_range() {
        let w = watch();
        let p = w.params();
        let omega_h = Vector3::new(0.0, 0.0, 1e-3);
        let r = Vector3::new(-3.0, 4.0, 0.0);
        let v = w.retreat_velocity(&r, &omega_h);
        // in F_R (v_H + ω_H × r_H): radial, at the retreat speed
        let v_r = v + omega_h.cross(&r);
        assert!((v_r - r * (p.retreat_speed / 5.0)).norm() < 1e-15);
        let far = r * (p.hold_range / 5.0 * 1.01);
        assert!((w.retreat_velocity(&far, &omega_h) + omega_h.cross(&far)).norm() < 1e-15);
        for bad in [Vector3::zeros(), Vector3::new(f64::NAN, 0.0, 0.0)] {
            assert_eq!(w.retreat_velocity(&bad, &omega_h), Vector3::zeros());
        }
        assert_eq!(
            w.retreat_velocity(&r, &Vector3::new(f64::INFINITY, 0.0, 0.0)),
            Vector3::zeros()
        );
    }
}
