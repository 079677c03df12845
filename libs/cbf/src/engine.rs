//! The safety QP of every filter (paper eqs. "translation_qp", "attitude_qp",
//! "robotic_qp"), solved exactly:
//!
//! ```text
//! min_u ‖u − u_nom‖²   s.t.   c_i + a_i·u ≥ 0 (barrier rows),   d_k + g_k·u ≥ 0 (input bounds)
//! ```
//!
//! with the dual active-set solver of `sc-qp` (exact to rounding, allocation-free,
//! deterministic). Clarabel stays in the product as the independent second opinion
//! ([`crate::qp::QpEngine`], used by the tests and the verification mode).
//!
//! * **Skip path.** A nominal command that satisfies every row and bound is the unique
//!   minimiser and is returned unchanged.
//! * **Relaxed problem that cannot be bought.** When the barrier rows cannot all hold
//!   inside the input bounds, each row's allowed violation is chosen lexicographically,
//!   independently of `u_nom`, before the command is: first the least achievable violation
//!   `t₁ = min t` s.t. `c_i + a_i·u + w_i t ≥ 0` for every barrier row, bounds hard (`w_i`
//!   the row's physical scale, so `t` is a fraction of each barrier's braking authority);
//!   the rows that make `t₁` necessary (the support of the LP's optimal dual) keep the
//!   violation `w_i t₁`, every other row must do better: the next round minimises their
//!   common violation with the first rows fixed, and so on until the remaining rows hold
//!   exactly (a lexicographic min-max, at most one round per row). Then the command is the
//!   one nearest `u_nom` among those violating no row by more than its allowance. A large
//!   nominal cannot buy violation, and one infeasible row does not license the others.
//! * **Priorities.** Rows may carry a priority tier ([`Engine::solve_tiered`], 0 first):
//!   the lexicographic relaxation then runs tier by tier, each tier's allowances chosen
//!   with the earlier tiers' fixed and the later tiers ignored, so a row of a later tier
//!   never makes one of an earlier tier give way. The attitude filter puts its rate rows
//!   first (body rates and the boresight's rate: they bound the line of sight's in-sample
//!   motion, and braking the rates is always possible inside the torque box), the line
//!   of sight after them: a lost line of sight cannot drag the body rates with it.

use crate::barrier::Row;
use nalgebra::SVector;
use sc_qp::{ActiveSetQp, Settings, Status};

/// How the command of one solve was produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The nominal satisfied every row and bound.
    Skipped,
    /// The hard QP was solved.
    Solved,
    /// The barrier rows were infeasible: the lexicographic least-violation command.
    Relaxed,
    /// The solver failed (invalid data or its iteration limit): no command.
    Failed,
}

/// The dump's `solver_status` of the exact engine's own solution (its multipliers
/// recorded) and of Clarabel's second opinion (not recorded).
pub const ACTIVE_SET_STATUS: &str = "active_set";
pub const SECOND_OPINION_STATUS: &str = "second_opinion";

/// Most hard rows a filter has (the robotic filter's 2·7 + 6) with room to spare.
pub const MAX_HARD_ROWS: usize = 32;

/// Result of [`Engine::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome<const M: usize> {
    pub kind: Kind,
    /// The command (the nominal for `Skipped`, unchanged input for `Failed`).
    pub u: SVector<f64, M>,
    /// The least violation `t*` of the relaxed problem (0 otherwise).
    pub violation: f64,
    /// Active-set changes (all stages).
    pub iterations: u32,
    /// Multipliers of the barrier rows (0 when skipped; 0 from the second opinion).
    pub row_duals: [f64; 64],
    /// Multipliers of the hard rows, the same convention (`u − u_nom = Σλ_i a_i` over the
    /// barrier and the hard rows as solved; 0 when skipped, relaxed or from the second
    /// opinion).
    pub bound_duals: [f64; MAX_HARD_ROWS],
    /// The active-set solver stopped at its iteration limit (degeneracy or cycling) and
    /// the command is Clarabel's solution of the same hard problem (flagged by the
    /// filters as [`crate::faults::QP_SECOND_OPINION`]).
    pub second_opinion: bool,
}

/// What the engine measured over one filter step ([`Engine::take_tally`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SolverTally {
    /// Wall time spent solving [ns].
    pub qp_ns: u64,
    /// A solve took Clarabel's second opinion.
    pub second_opinion: bool,
}

/// The QP of one filter: `M` inputs, at most `N` rows (barrier rows + bound rows).
pub struct Engine<const M: usize, const N: usize> {
    qp: ActiveSetQp<M, N>,
    a: [[f64; M]; N],
    b: [f64; N],
    w: [f64; N],
    tier: [u8; N],
    skip_enabled: bool,
    /// Wall time spent in [`Self::solve_tiered`] since the last [`Self::take_qp_ns`] [ns].
    qp_ns: u64,
    /// A solve since the last [`Self::take_second_opinion`] took Clarabel's second
    /// opinion (then no further one is taken before the next call: one per filter step).
    second_opinion: bool,
}

impl<const M: usize, const N: usize> Default for Engine<M, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const M: usize, const N: usize> Engine<M, N> {
    pub fn new() -> Self {
        Self::with_settings(Settings::default())
    }

    /// With the active-set solver's settings (tests: a small iteration limit exercises
    /// the second opinion).
    pub fn with_settings(settings: Settings) -> Self {
        Self {
            qp: ActiveSetQp::new(settings),
            a: [[0.0; M]; N],
            b: [0.0; N],
            w: [0.0; N],
            tier: [0; N],
            skip_enabled: true,
            qp_ns: 0,
            second_opinion: false,
        }
    }

    /// Verification only: with `false` the solver runs even for a feasible nominal.
    pub fn set_skip_enabled(&mut self, on: bool) {
        self.skip_enabled = on;
    }

    /// Verification only: the active-set solver's settings (it keeps no state between
    /// solves, so replacing it changes nothing else).
    pub fn set_settings(&mut self, settings: Settings) {
        self.qp = ActiveSetQp::new(settings);
    }

    /// The wall time spent solving since the last call [ns] (and restarts the count).
    pub fn take_qp_ns(&mut self) -> u64 {
        std::mem::take(&mut self.qp_ns)
    }

    /// Whether a solve since the last call took Clarabel's second opinion (and resets).
    pub fn take_second_opinion(&mut self) -> bool {
        std::mem::take(&mut self.second_opinion)
    }

    /// The solver's time and second-opinion flag since the last call (and resets both):
    /// what one filter step spent in its solves.
    pub fn take_tally(&mut self) -> SolverTally {
        SolverTally {
            qp_ns: self.take_qp_ns(),
            second_opinion: self.take_second_opinion(),
        }
    }

    /// Solves for `u_nom` with barrier `rows` (physical weights `weights`, > 0) and hard
    /// `bounds`. Never panics: too many rows or non-finite data give [`Kind::Failed`].
    pub fn solve(
        &mut self,
        u_nom: &SVector<f64, M>,
        rows: &[Row<M>],
        weights: &[f64],
        bounds: &[Row<M>],
    ) -> Outcome<M> {
        self.solve_tiered(u_nom, rows, weights, &[], bounds)
    }

    /// [`Self::solve`] with a priority tier per barrier row (0 first; `tiers` empty: all
    /// rows in tier 0). Only the relaxed problem depends on the tiers.
    pub fn solve_tiered(
        &mut self,
        u_nom: &SVector<f64, M>,
        rows: &[Row<M>],
        weights: &[f64],
        tiers: &[u8],
        bounds: &[Row<M>],
    ) -> Outcome<M> {
        self.solve_inner(u_nom, rows, weights, tiers, bounds, true)
    }

    /// The hard problem only: the command when every row and bound can hold (`Skipped` or
    /// `Solved`), `None` otherwise — no relaxation is computed (for a caller that would
    /// discard it and try other rows).
    pub fn solve_hard(
        &mut self,
        u_nom: &SVector<f64, M>,
        rows: &[Row<M>],
        bounds: &[Row<M>],
    ) -> Option<Outcome<M>> {
        let out = self.solve_inner(u_nom, rows, &[], &[], bounds, false);
        matches!(out.kind, Kind::Skipped | Kind::Solved).then_some(out)
    }

    fn solve_inner(
        &mut self,
        u_nom: &SVector<f64, M>,
        rows: &[Row<M>],
        weights: &[f64],
        tiers: &[u8],
        bounds: &[Row<M>],
        relax: bool,
    ) -> Outcome<M> {
        let mut out = Outcome {
            kind: Kind::Failed,
            u: *u_nom,
            violation: 0.0,
            iterations: 0,
            row_duals: [0.0; 64],
            bound_duals: [0.0; MAX_HARD_ROWS],
            second_opinion: false,
        };
        let nb = rows.len();
        let n = nb + bounds.len();
        let weights_ok = weights.len() == nb || (!relax && weights.is_empty());
        if n > N || !weights_ok || nb > 64 || !(tiers.is_empty() || tiers.len() == nb) {
            return out;
        }
        if self.skip_enabled && rows.iter().chain(bounds).all(|r| r.phi(u_nom) >= 0.0) {
            out.kind = Kind::Skipped;
            return out;
        }
        // the solver's own time: from here (a skipped step costs the row test above only)
        let t0 = std::time::Instant::now();
        self.solve_rows(&mut out, rows, weights, tiers, bounds, relax);
        self.qp_ns = self
            .qp_ns
            .saturating_add(t0.elapsed().as_nanos().min(u64::MAX as u128) as u64);
        out
    }

    /// The solver on rows already checked by [`Self::solve_inner`].
    fn solve_rows(
        &mut self,
        out: &mut Outcome<M>,
        rows: &[Row<M>],
        weights: &[f64],
        tiers: &[u8],
        bounds: &[Row<M>],
        relax: bool,
    ) {
        let u_nom = out.u;
        let nb = rows.len();
        let n = nb + bounds.len();
        for (i, r) in rows.iter().chain(bounds).enumerate() {
            self.a[i].copy_from_slice(r.a.as_slice());
            self.b[i] = -r.c;
            self.w[i] = if i < nb {
                weights.get(i).copied().unwrap_or(0.0)
            } else {
                0.0
            };
            self.tier[i] = if i < nb {
                tiers.get(i).copied().unwrap_or(0)
            } else {
                0
            };
        }
        let x0: [f64; M] = std::array::from_fn(|j| u_nom[j]);
        let hard = self.qp.solve(&x0, &self.a, &self.b, n);
        out.iterations = hard.iterations;
        match hard.status {
            Status::Optimal => {
                out.kind = Kind::Solved;
                out.u = SVector::from(hard.x);
                out.row_duals[..nb].copy_from_slice(&hard.lambda[..nb]);
                let nh = (n - nb).min(MAX_HARD_ROWS);
                out.bound_duals[..nh].copy_from_slice(&hard.lambda[nb..nb + nh]);
            }
            Status::Infeasible if !relax => {}
            Status::Infeasible => {
                if let Some((sol, t, iters)) = self.relaxed(&x0, nb, n) {
                    out.kind = Kind::Relaxed;
                    out.u = SVector::from(sol.x);
                    out.violation = t;
                    out.row_duals[..nb].copy_from_slice(&sol.lambda[..nb]);
                    out.iterations += iters;
                }
            }
            // degeneracy or cycling: Clarabel solves the same hard problem (allocates; a
            // fault path, so at most once between two `take_second_opinion` calls — once
            // per filter step), its answer accepted only if it holds every row
            Status::IterationLimit if !self.second_opinion => {
                if let Some(u) = second_opinion(&u_nom, rows, bounds) {
                    out.kind = Kind::Solved;
                    out.u = u;
                    out.second_opinion = true;
                    self.second_opinion = true;
                }
            }
            Status::IterationLimit | Status::InvalidInput => {}
        }
        if !out.u.iter().all(|x| x.is_finite()) {
            out.kind = Kind::Failed;
            out.u = u_nom;
        }
    }
}

/// Rows hold at the second opinion's command to this much of the input bound (Clarabel's
/// tolerance is 1e-11; its point is pulled into the box by the filter's last clamp).
const SECOND_OPINION_FEASIBILITY: f64 = 1e-9;

/// Clarabel's solution of the hard problem (`None` when it fails, or when its point
/// violates a row by more than [`SECOND_OPINION_FEASIBILITY`] of the input bound).
fn second_opinion<const M: usize>(
    u_nom: &SVector<f64, M>,
    rows: &[Row<M>],
    bounds: &[Row<M>],
) -> Option<SVector<f64, M>> {
    let qp = crate::verify::Qp::from_rows(u_nom, rows, bounds);
    // the box's half-width: the largest c/‖a‖ of the bound rows (each a ≥ 0 half-space)
    let half = bounds
        .iter()
        .filter_map(|r| {
            let n = r.a.norm();
            (n > 0.0 && r.c.is_finite()).then(|| r.c.abs() / n)
        })
        .fold(0.0f64, f64::max);
    if half <= 0.0 {
        return None;
    }
    let u = crate::verify::clarabel(&qp, half * (M as f64).sqrt())?;
    let u = SVector::<f64, M>::from_iterator(u.iter().copied());
    // in distance: φ/‖a‖ (a zero row holds when its constant does)
    let tol = SECOND_OPINION_FEASIBILITY * half;
    let holds = rows.iter().chain(bounds).all(|r| {
        let n = r.a.norm();
        if n > 0.0 {
            r.phi(&u) / n >= -tol
        } else {
            r.c >= 0.0
        }
    });
    (u.iter().all(|x| x.is_finite()) && holds).then_some(u)
}

impl<const M: usize, const N: usize> Engine<M, N> {
    /// The lexicographic min-max relaxation of the barrier rows `0..nb` (see the module
    /// documentation): returns the command, the largest allowance `t₁` (the violation
    /// reported) and the iterations. `None` when a stage fails.
    fn relaxed(
        &mut self,
        x0: &[f64; M],
        nb: usize,
        n: usize,
    ) -> Option<(sc_qp::Solution<M, N>, f64, u32)> {
        let mut allowed = Allowances {
            fixed: [false; N],
            allowance: [0.0; N],
        };
        let mut iterations = 0;
        let mut worst = 0.0f64;
        let last_tier = (0..nb).map(|i| self.tier[i]).max().unwrap_or(0);
        for tier in 0..=last_tier {
            if !(0..nb).any(|i| self.tier[i] == tier) {
                continue;
            }
            iterations += self.relax_tier(tier, nb, n, &mut allowed, &mut worst)?;
        }
        // the command nearest the nominal among those within the allowances
        let mut b = self.b;
        for (i, bi) in b.iter_mut().enumerate().take(n) {
            *bi = self.b[i] - allowed.offset(&self.w, i);
        }
        let sol = self.qp.solve(x0, &self.a, &b, n);
        iterations += sol.iterations;
        (sol.status == Status::Optimal).then_some((sol, worst, iterations))
    }

    /// The rounds of one priority tier: each round the least common violation `t` of the
    /// tier's rows not yet fixed (the earlier tiers' and this tier's fixed rows held to
    /// their allowances, the later tiers' rows left out); the rows that make `t` necessary
    /// (the support of the LP's optimal dual) are fixed at `t`, until the rest hold
    /// exactly. Raises `worst` to every round's `t`; returns the iterations, `None` when an
    /// LP fails.
    fn relax_tier(
        &mut self,
        tier: u8,
        nb: usize,
        n: usize,
        allowed: &mut Allowances<N>,
        worst: &mut f64,
    ) -> Option<u32> {
        let in_tier = |i: usize| i < nb && self.tier[i] == tier;
        let mut a = self.a;
        let mut b = self.b;
        let mut w = [0.0; N];
        let mut iterations = 0;
        for _ in 0..nb {
            for i in 0..n {
                // rows of later tiers are left out (a row that always holds)
                let later = i < nb && self.tier[i] > tier;
                a[i] = if later { [0.0; M] } else { self.a[i] };
                let soft = in_tier(i) && !allowed.fixed[i];
                w[i] = if soft { self.w[i] } else { 0.0 };
                b[i] = if later {
                    -1.0
                } else {
                    self.b[i] - allowed.offset(&self.w, i)
                };
            }
            let lv = self.qp.least_violation(&a, &b, &w, n);
            iterations += lv.iterations;
            if lv.status != Status::Optimal {
                return None;
            }
            if lv.t <= 0.0 {
                break;
            }
            *worst = worst.max(lv.t);
            // rounding must not make the fixed rows' set empty: a relative 1e-9 of room
            let t = lv.t * (1.0 + 1e-9) + 1e-12;
            let supporting = |i: usize| lv.dual[i] > 0.0;
            if !(0..nb).any(|i| in_tier(i) && !allowed.fixed[i] && supporting(i)) {
                // a degenerate dual: give every remaining row of the tier the same allowance
                allowed.fix(t, in_tier);
            } else {
                allowed.fix(t, |i| in_tier(i) && supporting(i));
            }
            if (0..nb).filter(|i| in_tier(*i)).all(|i| allowed.fixed[i]) {
                break;
            }
        }
        Some(iterations)
    }
}

/// The allowances of the lexicographic relaxation: row `i`, once fixed, may be violated
/// by `w_i · allowance_i`.
struct Allowances<const N: usize> {
    fixed: [bool; N],
    allowance: [f64; N],
}

impl<const N: usize> Allowances<N> {
    /// How far row `i`'s offset is relaxed: `w_i · allowance_i` once fixed, else 0.
    fn offset(&self, w: &[f64; N], i: usize) -> f64 {
        if self.fixed[i] {
            w[i] * self.allowance[i]
        } else {
            0.0
        }
    }

    /// Fixes the allowance `t` of every row not yet fixed that `which` selects.
    fn fix(&mut self, t: f64, which: impl Fn(usize) -> bool) {
        for i in 0..N {
            if !self.fixed[i] && which(i) {
                self.fixed[i] = true;
                self.allowance[i] = t;
            }
        }
    }
}

/// The last problem a filter handed to its engine and what came out — for `--dump-qp`
/// and offline checks. The buffers are allocated once, so recording does not allocate.
#[derive(Debug, Clone)]
pub struct LastProblem<const M: usize> {
    pub u_nom: SVector<f64, M>,
    pub rows: Vec<Row<M>>,
    pub weights: Vec<f64>,
    pub hard: Vec<Row<M>>,
    pub u: SVector<f64, M>,
    pub kind: Option<Kind>,
    pub violation: f64,
    pub iterations: u32,
    pub row_duals: Vec<f64>,
    pub bound_duals: Vec<f64>,
    /// The command is Clarabel's second opinion (its multipliers are not recorded).
    pub second_opinion: bool,
}

impl<const M: usize> LastProblem<M> {
    /// Empty, with room for `rows` barrier rows and `hard` bound rows.
    pub fn with_capacity(rows: usize, hard: usize) -> Self {
        Self {
            u_nom: SVector::zeros(),
            rows: Vec::with_capacity(rows),
            weights: Vec::with_capacity(rows),
            hard: Vec::with_capacity(hard),
            u: SVector::zeros(),
            kind: None,
            violation: 0.0,
            iterations: 0,
            row_duals: Vec::with_capacity(rows),
            bound_duals: Vec::with_capacity(hard),
            second_opinion: false,
        }
    }

    /// Records a solve.
    pub fn record(
        &mut self,
        u_nom: &SVector<f64, M>,
        rows: &[Row<M>],
        weights: &[f64],
        hard: &[Row<M>],
        out: &Outcome<M>,
    ) {
        self.u_nom = *u_nom;
        self.rows.clear();
        self.rows.extend_from_slice(rows);
        self.weights.clear();
        self.weights.extend_from_slice(weights);
        self.hard.clear();
        self.hard.extend_from_slice(hard);
        self.u = out.u;
        self.kind = Some(out.kind);
        self.violation = out.violation;
        self.iterations = out.iterations;
        self.row_duals.clear();
        self.row_duals
            .extend_from_slice(&out.row_duals[..rows.len().min(64)]);
        self.second_opinion = out.second_opinion;
        self.bound_duals.clear();
        self.bound_duals
            .extend_from_slice(&out.bound_duals[..hard.len().min(MAX_HARD_ROWS)]);
    }

    /// As a [`crate::QpDump`] (allocates).
    pub fn dump(&self) -> crate::QpDump {
        use crate::QpOutcome;
        crate::QpDump {
            u_nom: self.u_nom.iter().copied().collect(),
            rows_a: self
                .rows
                .iter()
                .map(|r| r.a.iter().copied().collect())
                .collect(),
            rows_c: self.rows.iter().map(|r| r.c).collect(),
            bounds_g: self
                .hard
                .iter()
                .map(|r| r.a.iter().map(|x| -x).collect())
                .collect(),
            bounds_g_max: self.hard.iter().map(|r| r.c).collect(),
            solution: self.u.iter().copied().collect(),
            row_duals: self.row_duals.clone(),
            bound_duals: self.bound_duals.clone(),
            slack: self.violation,
            outcome: self.kind.map(|k| match k {
                Kind::Skipped => QpOutcome::Skipped,
                Kind::Solved => QpOutcome::Solved,
                Kind::Relaxed => QpOutcome::Relaxed,
                Kind::Failed => QpOutcome::Failed,
            }),
            solver_status: if self.second_opinion {
                SECOND_OPINION_STATUS
            } else {
                ACTIVE_SET_STATUS
            }
            .into(),
            hard_status: String::new(),
            iterations: self.iterations,
        }
    }
}
