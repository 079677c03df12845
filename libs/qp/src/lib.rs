//! Exact, allocation-free, deterministic solvers for the small dense QPs of the safety
//! filters.
//!
//! # The projection QP
//!
//! Every safety-filter problem is a Euclidean projection onto a small polytope:
//!
//! ```text
//! minimise ½‖x − x0‖²   subject to   a_i · x ≥ b_i,   i = 0..n      (x ∈ ℝᴹ, n ≤ N ≤ 128)
//! ```
//!
//! [`ActiveSetQp::solve`] solves it with a **dual active-set method of the Goldfarb–Idnani
//! family** (D. Goldfarb, A. Idnani, "A numerically stable dual method for solving strictly
//! convex quadratic programs", Math. Programming 27, 1983; the same family as DAQP, D.
//! Arnström, A. Bemporad, D. Axehill, IEEE TAC 2022), written for the Hessian `H = I`:
//!
//! * Every row is first scaled to unit norm (an exactly equivalent constraint); the slack
//!   `â_i·x − b̂_i` of a scaled row is then the signed Euclidean distance to its half-space,
//!   so "most violated" and every tolerance are scale-free. Multipliers are mapped back to
//!   the caller's scaling at the end (`λ_i = λ̂_i / ‖a_i‖`).
//! * The iterate starts at the unconstrained minimiser `x0` with an empty active set — a
//!   dual-feasible point. Each major step adds the most violated row `p`. The primal step
//!   direction is `z = J₂J₂ᵀ â_p` (projection of `â_p` onto the null space of the active
//!   rows) and the dual direction is `r = R⁻¹J₁ᵀ â_p`, from the factorisation
//!   `[â_j]_{j∈A} = J₁R` with `J = [J₁ J₂]` orthogonal (`M×M`) and `R` upper triangular —
//!   the QR factorisation of the active rows (with `H = I`, Goldfarb–Idnani's `J = L⁻ᵀQ` is
//!   simply `Q`). The step is the smaller of the *full* step `−s_p/‖z‖²` that makes row `p`
//!   active, and the *partial* step at which an active multiplier would turn negative (that
//!   row is dropped, the multiplier of `p` is kept, and the step is retried).
//! * Adding and dropping rows update `J` and `R` by Givens rotations (`O(M²)` each); nothing
//!   is refactorised, nothing is allocated. All workspace lives in the solver struct.
//! * When no row is violated the solution is *refined*: the multipliers of the active set
//!   are recomputed from the KKT system `ÂÂᵀλ̂ = b̂_A − Âx0` (`ÂÂᵀ = RᵀR`) with one step
//!   of iterative refinement, and `x = x0 + Âᵀλ̂` (kept if it is at least as accurate as
//!   the iterated point, which it normally is). The active rows then hold to rounding
//!   (~1e-16 relative) rather than to the accumulated error of the updates, and all rows
//!   are tested once more against the refined point with a tight tolerance (next
//!   section); the iteration resumes if that finds a violated row.
//!
//! ## Degeneracy
//!
//! * **Dependent rows.** A row is added only by a full step, which needs `‖z‖ >
//!   dependence_tol`; so the active rows are always linearly independent and `R` stays
//!   invertible (`|R_kk| > dependence_tol`). A violated row that lies in the span of the
//!   active rows (`‖z‖ ≤ dependence_tol`: duplicates, more than `M` rows through one
//!   vertex, …) gets a pure dual step that drops a blocking row; if no active multiplier
//!   blocks (`r ≤ 0`), the problem is infeasible and `y = e_p − Σ r_j e_j ≥ 0` is a Farkas
//!   certificate (`Σ y_i â_i = z ≈ 0`, `Σ y_i b̂_i = −s_p > 0`).
//! * **Degenerate vertices.** While iterating, a row counts as violated only when its
//!   distance `s_i < −(primal_tol · max(|b̂_i|, ‖x‖∞) + 64ε‖x0‖∞)` (the second term bounds
//!   the rounding the iterate carries from a far-away `x0`), so rows through the current
//!   point are not added. After refinement that rounding lives only in the null space of
//!   the active rows, so the final test scales the `x0` term by the row's component there,
//!   `‖J₂ᵀâ_i‖` (zero when `M` rows are active): with `‖x0‖ = 1e10` the answer still holds
//!   every row to ~1e-12 instead of ~1e-4. A violated row that depends on the active rows with `r ≤ 0` is declared
//!   infeasible only if the data confirm it — `Σ y_i b̂_i > primal_tol · Σ |y_i b̂_i|` for
//!   the certificate `y`, which does not involve the iterate; otherwise the row holds up to
//!   rounding and is set aside until the active set grows. So rounding can neither make
//!   the iteration chase its own noise nor report a false infeasibility.
//! * **Termination / anti-cycling.** Each full step strictly increases the dual objective
//!   (the step is `−s_p/‖z‖² > 0` because `s_p` is below a strictly negative tolerance), and
//!   the point after a full step is the unique minimiser on its active set, so no active set
//!   repeats; between two full steps each partial step removes one row, so there are at most
//!   `M` of them; a row set aside as rounding noise is not picked again until a row is
//!   added. Ties (most violated row, blocking multiplier) are broken by the lowest index,
//!   so the path is deterministic. The iteration limit (default `10·(n + M)`) is a last
//!   resort and is reported as [`Status::IterationLimit`].
//! * **Zero rows** (`a_i = 0`) are never factorised: satisfied when `b_i ≤ 0`, otherwise
//!   the problem is infeasible with certificate `y = e_i`.
//! * **Scales.** Row scaling is removed by the normalisation (tested with row norms from
//!   1e-200 to 1e200, and 1e-6 … 1e6 within one problem); outside 1e±100 the norm is
//!   computed with a max-scaling that neither overflows nor underflows. Non-finite data (or data that overflows when scaled) is
//!   [`Status::InvalidInput`].
//!
//! # The least-violation (phase-1) problem
//!
//! ```text
//! t* = min t   subject to   a_i·x + w_i t ≥ b_i,   t ≥ 0          (w_i ≥ 0)
//! ```
//!
//! Rows with `w_i = 0` are hard (input bounds); rows with `w_i > 0` are the soft barrier rows
//! with their physical weights. [`ActiveSetQp::least_violation`] solves this LP **exactly**
//! by a parametric scheme on the projection solver (a Dinkelbach / Newton iteration on the
//! LP's dual, with Farkas certificates as dual points):
//!
//! 1. Start from `t₀ = max(0, max b_i/w_i over rows with a_i = 0, w_i > 0)`.
//! 2. Solve the projection QP of the origin onto `P(t) = {x : a_i·x ≥ b_i − w_i t}`. If it
//!    is feasible, stop: `t` is optimal (see below).
//! 3. Otherwise the solver returns a Farkas certificate `y ≥ 0`, `Σ y_i a_i = 0`,
//!    `Σ y_i (b_i − w_i t) > 0`. For every feasible `(x, t')`, `Σ y_i (a_i·x + w_i t') ≥
//!    Σ y_i b_i`, so `t' ≥ Σ y_i b_i / Σ y_i w_i =: t_y > t` — a lower bound that is strictly
//!    larger than the current `t`. If `Σ y_i w_i = 0` the certificate involves hard rows only
//!    and the hard rows alone are infeasible ([`Status::Infeasible`]). Otherwise set `t = t_y`
//!    and go to 2.
//!
//! *Exactness:* when step 2 finds `P(t)` feasible, `t` is both attained by a primal point
//! and equal to the dual value of the LP-dual-feasible point `y / Σ y_i w_i` (or `t = t₀`,
//! which is a lower bound on its own), so `t = t*` by weak duality — it is the value of an
//! exact vertex, computed by the formula `Σ y_i b_i / Σ y_i w_i` from the supporting rows,
//! not an interior-point tolerance. The returned [`LeastViolation::dual`] is that dual point,
//! so callers and tests can verify optimality themselves. *Finiteness:* each certificate is
//! determined by the active set and the added row of the projection solver (finitely many
//! combinations), and `t` increases strictly, so no certificate repeats. In practice it
//! takes 2–7 projections; each after the first starts warm from the previous active set
//! (its multipliers recomputed for the new right-hand side and negative ones dropped: a
//! dual-feasible start), which saves about a third of the work. The remaining inexactness
//! is that of the projections themselves: `P(t)` is declared feasible within `primal_tol`
//! (1e-12 relative), and a certificate's `Σ y_i a_i` is zero only to within
//! `dependence_tol` (in practice ~1e-16: exactly dependent rows), which bounds how far `t`
//! can overshoot `t*`.
//!
//! The projection used inside `least_violation` is always that of the origin, so `t*` does
//! not depend on `x0` at all — a large nominal input cannot "buy" violation.
//! [`ActiveSetQp::lexicographic`] then projects `x0` onto `P(t*)` (the second stage); if,
//! by rounding, that projection finds `P(t*)` infeasible, the same iteration continues from
//! `t*` (by at least `primal_tol`-sized steps), and the `t` actually used is returned.
//!
//! This method was chosen over a tableau simplex because it reuses the exact, degeneracy-
//! hardened projection solver (no second pivoting code with its own anti-cycling rules), it
//! needs no extra workspace whose size would depend on `N + M` (not expressible with stable
//! const generics), and it is deterministic and allocation-free for the same reasons as the
//! projection.
//!
//! # Determinism and allocation
//!
//! The solvers use no heap, no threads, no clocks and no hash maps; every loop runs in index
//! order and every tie is broken by the lowest index, so the same inputs give the same output
//! bits (on the same target and build).

#![forbid(unsafe_code)]
// Index loops mirror the linear algebra (rows, columns, active positions) of the method.
#![allow(clippy::needless_range_loop)]
#![warn(missing_docs)]

mod active_set;
mod phase1;

pub use active_set::ActiveSetQp;

/// Outcome of a solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Status {
    /// Solved: `x` is the minimiser (or `t` the minimum) to the stated tolerances.
    Optimal,
    /// The constraints cannot all hold; `certificate` proves it (Farkas).
    Infeasible,
    /// The iteration limit was reached before optimality (a last resort; never expected for
    /// a well-posed problem with the default settings).
    IterationLimit,
    /// Non-finite data, `n > N`, negative weights, or data that overflows when the rows are
    /// scaled to unit norm.
    InvalidInput,
}

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Limit on active-set changes (adds + drops) per projection; `None` means
    /// `10·(n + M)`.
    pub max_iterations: Option<u32>,
    /// Limit on the projections of the least-violation iteration; `None` means
    /// `2·(n + M) + 4`.
    pub max_outer_iterations: Option<u32>,
    /// A unit-scaled row is violated when its signed distance is below
    /// `−(primal_tol · max(|b̂_i|, ‖x‖∞) + 64 ε ‖x0‖∞)` (`ε` = machine epsilon: the
    /// iterate's rounding after the steps from `x0`).
    pub primal_tol: f64,
    /// A row whose unit normal is within this distance of the span of the active normals is
    /// treated as dependent on them (never factorised).
    pub dependence_tol: f64,
    /// Entries of the dual direction `r` with `r_j ≤ dual_tol · (1 + ‖r‖∞)` are treated as
    /// non-positive (they cannot block a step).
    pub dual_tol: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            max_iterations: None,
            max_outer_iterations: None,
            primal_tol: 1e-12,
            dependence_tol: 1e-10,
            dual_tol: 1e-14,
        }
    }
}

/// Result of [`ActiveSetQp::solve`] (and the second stage of
/// [`ActiveSetQp::lexicographic`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solution<const M: usize, const N: usize> {
    /// Outcome.
    pub status: Status,
    /// The minimiser when `Optimal`; otherwise the last iterate (`x0` for invalid input).
    pub x: [f64; M],
    /// Multipliers `λ_i ≥ 0` in the caller's row scaling: `x − x0 = Σ λ_i a_i`; zero for
    /// inactive rows.
    pub lambda: [f64; N],
    /// Bit `i` is set when row `i` is in the final active set.
    pub active: u128,
    /// Active-set changes (adds + drops).
    pub iterations: u32,
    /// When `Infeasible`: a Farkas certificate `y ≥ 0` with `Σ y_i a_i ≈ 0` and
    /// `Σ y_i b_i > 0`, scaled so that `Σ y_i ‖a_i‖ = 1` (or `y = e_i` for a zero row
    /// `a_i = 0` with `b_i > 0`). Zero otherwise.
    pub certificate: [f64; N],
}

impl<const M: usize, const N: usize> Solution<M, N> {
    fn empty(status: Status, x: [f64; M]) -> Self {
        Self {
            status,
            x,
            lambda: [0.0; N],
            active: 0,
            iterations: 0,
            certificate: [0.0; N],
        }
    }
}

/// Result of [`ActiveSetQp::least_violation`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeastViolation<const N: usize> {
    /// `Optimal`, `Infeasible` (the hard rows alone are infeasible), `IterationLimit` (an
    /// iteration limit, or `t` would overflow) or `InvalidInput`.
    pub status: Status,
    /// The least violation `t* ≥ 0` when `Optimal`; the last lower bound otherwise.
    pub t: f64,
    /// When `Optimal`: an optimal point of the LP dual in the caller's scaling, `y ≥ 0`,
    /// `Σ y_i a_i ≈ 0`, and (when `t > 0`) `Σ y_i w_i = 1`, `Σ y_i b_i = t*`. All zero when
    /// `t* = 0` (the multiplier of `t ≥ 0` carries the cost).
    pub dual: [f64; N],
    /// When `Infeasible`: a Farkas certificate of the hard rows (`w_i = 0`), as in
    /// [`Solution::certificate`].
    pub certificate: [f64; N],
    /// Projections solved.
    pub outer_iterations: u32,
    /// Active-set changes over all projections.
    pub iterations: u32,
}

/// `‖v‖∞`.
#[inline]
fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, &e| m.max(e.abs()))
}

/// `u · v` in index order.
#[inline]
fn dot<const M: usize>(u: &[f64; M], v: &[f64; M]) -> f64 {
    let mut s = 0.0;
    for k in 0..M {
        s += u[k] * v[k];
    }
    s
}
