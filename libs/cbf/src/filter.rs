//! What every safety filter of the layer is (paper Sec. "Method"): a small QP that
//! minimally changes its nominal command so that its barriers stay non-negative, built
//! from the known state and the upstream safe commands (the coupling ξ), with a backup
//! command for when nothing better is known.
//!
//! [`SafetyFilter`] is implemented by the three filters of the paper
//! ([`crate::TranslationalFilter`], [`crate::AttitudeFilter`], [`crate::RoboticFilter`]);
//! the typed causal chain ([`crate::chain`]) and the conformance suite
//! (`tests/conformance.rs`) are written once against it.

use crate::common::FilterOutput;
use crate::qp::QpDump;
use nalgebra::{SVector, Vector3};
use sc_core::{Observation, Subsystem};
use sc_multibody::Robot;

/// The upstream safe commands a filter takes as its known coupling ξ (paper eq.
/// "control-affine system"): what acts on the base while the filter's own command acts.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Coupling {
    /// The actuated base force `f_B` [N, F_B] (the translational filter's `actuated`):
    /// ξ_att and part of ξ_rob.
    pub force_b: Vector3<f64>,
    /// The base torque `τ_B` [N m, F_B] (the attitude filter's command): part of ξ_rob.
    pub torque_b: Vector3<f64>,
}

/// A CBF-QP safety filter of `M` inputs and `N` barriers.
///
/// Every call is deterministic and memoryless: the same input gives bit-identical
/// commands and reports (except the timings), whatever came before. A filter never
/// panics, never outputs a non-finite command and never one outside its input bounds.
pub trait SafetyFilter<const M: usize, const N: usize> {
    /// The subsystem it keeps safe.
    const SUBSYSTEM: Subsystem;
    /// Its barriers' stable names, in report order.
    const NAMES: [&'static str; N];
    /// Everything it needs at one control step.
    type Input;

    /// Its input at the known state `o` with the upstream commands `xi`, evaluated with
    /// the servicer model `model`. `None` when the model cannot be evaluated at that state
    /// (the filter's [`Self::invalid_state`] output applies).
    fn input(&self, model: &Robot, o: &Observation, xi: &Coupling) -> Option<Self::Input>;

    /// One filter step on the nominal command (`None`: missing — the QP then runs on the
    /// filter's substitute nominal, its braking law), timed.
    fn filter_with(
        &mut self,
        x: &Self::Input,
        nominal: Option<&SVector<f64, M>>,
    ) -> FilterOutput<M, N>;

    /// The defined output when the input cannot be built (a state the model cannot
    /// evaluate): zero command, status `Fallback`, flagged [`crate::faults::INVALID_STATE`].
    fn invalid_state(&self) -> FilterOutput<M, N> {
        crate::common::invalid_state_output()
    }

    /// The last QP handed to the solver (for `--dump-qp` and offline checks).
    fn dump_qp(&self) -> QpDump;

    /// Verification only: with `false` the solver runs even for a feasible nominal.
    fn set_skip_enabled(&mut self, on: bool);

    /// Verification only: the exact solver's settings (small iteration limits reach the
    /// second opinion and the braking law on demand).
    fn set_solver_settings(&mut self, settings: sc_qp::Settings);

    /// The bound `‖actuated‖∞ ≤ bound` of every command it outputs.
    fn input_bound(&self) -> f64;

    /// The command when nothing better is known: the safety QP on the substitute nominal.
    fn backup(&mut self, x: &Self::Input) -> FilterOutput<M, N> {
        self.filter_with(x, None)
    }

    /// One stage of the causal chain: the input at `o` with the upstream commands `xi`,
    /// then the filter on `nominal` — or [`Self::invalid_state`] when the input cannot be
    /// built.
    fn stage(
        &mut self,
        model: &Robot,
        o: &Observation,
        xi: &Coupling,
        nominal: Option<&SVector<f64, M>>,
    ) -> FilterOutput<M, N> {
        match self.input(model, o, xi) {
            Some(x) => self.filter_with(&x, nominal),
            None => self.invalid_state(),
        }
    }
}
