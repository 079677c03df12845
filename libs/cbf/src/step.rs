//! One filter step, written once for the three filters (paper eqs. "translation_qp",
//! "attitude_qp", "robotic_qp"; docs/SAFETY.md, "The promise").
//!
//! Every step of every filter is the same sequence; only the parts marked *own* differ
//! between the filters ([`FilterStep`]):
//!
//! 1. **Prepare** (*own*): validate the input and build the barrier terms and rows. An
//!    input that cannot be prepared gets the filter's bounded refusal command, flagged
//!    [`faults::INVALID_STATE`] or [`faults::INVALID_COUPLING`].
//! 2. **Resolve the nominal**: a missing or invalid nominal is replaced by the substitute
//!    nominal, the filter's braking law (*own*) — the QP still runs.
//! 3. **Solve** (*own*): the filter's QP on its rows, with its certificate or verification;
//!    it ends in [`conclude`] with the rows it solved with.
//! 4. **Conclude**: record the solved problem (`--dump-qp`), map how the command came
//!    about to the report's status and fault flags, brake when no solver produced a
//!    command, clamp to the input bounds as the last line of defence (in the filter's
//!    actuator frame, *own*), and evaluate the certifying rows at the command.
//!
//! [`filter_with`] times the whole step (wall clock, the thread's CPU clock, the solver's
//! own time).

use crate::barrier::Row;
use crate::common::{self, FilterOutput, FilterReport, FilterStatus, clamp_box, faults};
use crate::engine::{Kind, LastProblem, Outcome, SolverTally};
use nalgebra::SVector;
use std::time::Instant;

/// Why a filter's input cannot be prepared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Invalid {
    /// The state (or a model term carried with it) is non-finite or out of range.
    State,
    /// The upstream coupling ξ is non-finite or out of range.
    Coupling,
}

impl Invalid {
    /// The report's fault flag.
    fn flag(&self) -> u32 {
        match self {
            Invalid::State => faults::INVALID_STATE,
            Invalid::Coupling => faults::INVALID_COUPLING,
        }
    }
}

/// What the filter's QP step produced, as the shared conclusion needs it: how the command
/// came about, the problem it was solved with (recorded for `--dump-qp`) and the rows that
/// certify it (the first `N` are evaluated into the report).
pub(crate) struct Solved<'a, const M: usize> {
    pub outcome: &'a Outcome<M>,
    /// The barrier rows the command was solved with, and their weights.
    pub rows: &'a [Row<M>],
    pub weights: &'a [f64],
    /// The hard rows it was solved with (input bounds, contracts, caps).
    pub hard: &'a [Row<M>],
    /// The barrier rows that certify the command, in report order.
    pub certifying: &'a [Row<M>],
}

/// What one filter of `M` inputs and `N` barriers brings to the shared step.
pub(crate) trait FilterStep<const M: usize, const N: usize> {
    /// Everything the filter needs at one control step.
    type Input;
    /// The validated input with its barrier terms and rows.
    type Prepared;
    /// The bound `‖u‖∞ ≤ bound` of its commands (in its actuator frame).
    fn bound(&self) -> f64;

    /// The solver's time and second-opinion flag since the last call (and resets both).
    fn take_tally(&mut self) -> SolverTally;

    /// Where the last problem is recorded.
    fn last_problem(&mut self) -> &mut LastProblem<M>;

    /// Validates the input and builds the barrier terms and rows.
    fn prepare(&self, x: &Self::Input) -> Result<Self::Prepared, Invalid>;

    /// The bounded command for an input that cannot be prepared.
    fn refused(&self, x: &Self::Input) -> SVector<f64, M>;

    /// The barrier values `h_i` in report order.
    fn barrier_values(p: &Self::Prepared) -> [f64; N];

    /// The braking law: the substitute nominal, and the command when no solver can
    /// produce one.
    fn braking_law(&self, x: &Self::Input, p: &Self::Prepared) -> SVector<f64, M>;

    /// The command when no solver produced one: the braking law, unless the filter
    /// keeps a contract with the other filters that its brake must keep too.
    fn emergency(&self, x: &Self::Input, p: &Self::Prepared) -> SVector<f64, M> {
        self.braking_law(x, p)
    }

    /// The filter's own QP step on the resolved nominal `u_nom` (its rows, its certificate
    /// or verification), handed to [`conclude`] with the rows it was solved with — kept
    /// where the filter built them, so that nothing large is copied.
    fn solve_qp(
        &mut self,
        x: &Self::Input,
        p: &Self::Prepared,
        u_nom: &SVector<f64, M>,
        report: &mut FilterReport<N>,
    ) -> Actuated<M>;

    /// The last line of defence: the command inside the input bounds in the actuator frame
    /// — `(u, actuated, flagged)` with `flagged` when the clamp changed it. By default the
    /// box `‖u‖∞ ≤ bound` on `u` itself.
    fn actuate(&self, _p: &Self::Prepared, u: SVector<f64, M>) -> Actuated<M> {
        let (u, clamped) = clamp_box(&u, self.bound());
        Actuated {
            u,
            actuated: u,
            clamped,
        }
    }
}

/// A command after the last-line clamp.
pub(crate) struct Actuated<const M: usize> {
    /// In the filter's frame.
    pub u: SVector<f64, M>,
    /// In the actuator frame.
    pub actuated: SVector<f64, M>,
    /// The clamp changed it ([`faults::OUTPUT_CLAMPED`]).
    pub clamped: bool,
}

/// One timed filter step on the nominal `nominal` (`None`: missing).
pub(crate) fn filter_with<F, const M: usize, const N: usize>(
    f: &mut F,
    x: &F::Input,
    nominal: Option<&SVector<f64, M>>,
) -> FilterOutput<M, N>
where
    F: FilterStep<M, N>,
{
    let t0 = Instant::now();
    // the thread's CPU clock inside the wall interval: CPU ≤ wall
    let c0 = common::thread_cpu_ns();
    let mut report = FilterReport::<N>::default();
    f.take_tally();
    let out = step(f, x, nominal, &mut report);
    report.solve_cpu_ns = common::thread_cpu_ns().saturating_sub(c0);
    // (the second-opinion flag comes from the outcome whose command is used)
    report.qp_time_ns = f.take_tally().qp_ns;
    report.solve_time_ns = t0.elapsed().as_nanos().min(u64::MAX as u128) as u64;
    FilterOutput {
        u: out.u,
        actuated: out.actuated,
        report,
    }
}

/// Prepare, resolve the nominal, solve, conclude.
fn step<F, const M: usize, const N: usize>(
    f: &mut F,
    x: &F::Input,
    nominal: Option<&SVector<f64, M>>,
    report: &mut FilterReport<N>,
) -> Actuated<M>
where
    F: FilterStep<M, N>,
{
    // (borrowed, not moved out: the prepared rows are large)
    let prepared = f.prepare(x);
    let p = match &prepared {
        Ok(p) => p,
        Err(why) => {
            report.faults |= why.flag();
            report.status = FilterStatus::Fallback;
            let u = f.refused(x);
            return Actuated {
                u,
                actuated: u,
                clamped: false,
            };
        }
    };
    report.h = F::barrier_values(p);
    let (u_nom, flag) = common::resolve_nominal(nominal, f.bound(), || f.braking_law(x, p));
    report.faults |= flag;
    f.solve_qp(x, p, &u_nom, report)
}

/// The end of every filter's QP step: records the problem, reports how the command came
/// about, brakes when no solver produced one, clamps and evaluates the certifying rows.
pub(crate) fn conclude<F, const M: usize, const N: usize>(
    f: &mut F,
    x: &F::Input,
    p: &F::Prepared,
    u_nom: &SVector<f64, M>,
    s: Solved<'_, M>,
    report: &mut FilterReport<N>,
) -> Actuated<M>
where
    F: FilterStep<M, N>,
{
    let out = s.outcome;
    f.last_problem()
        .record(u_nom, s.rows, s.weights, s.hard, out);
    report.iterations = out.iterations;
    report.violation = out.violation;
    if out.second_opinion {
        report.faults |= faults::QP_SECOND_OPINION;
    }
    let mut u = out.u;
    report.status = match out.kind {
        Kind::Skipped => FilterStatus::Skipped,
        Kind::Solved => FilterStatus::Solved,
        Kind::Relaxed => {
            report.faults |= faults::QP_INFEASIBLE_RELAXED;
            FilterStatus::Relaxed
        }
        Kind::Failed => {
            report.faults |= faults::QP_FAILED_FALLBACK;
            u = f.emergency(x, p);
            FilterStatus::Fallback
        }
    };
    let out = f.actuate(p, u);
    if out.clamped {
        report.faults |= faults::OUTPUT_CLAMPED;
    }
    common::evaluate_rows(s.certifying, &out.u, report);
    out
}
