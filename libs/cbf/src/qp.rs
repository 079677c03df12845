//! The Clarabel (interior-point) engine for the filters' QP (paper eqs. "translation_qp",
//! "attitude_qp", "robotic_qp"): the independent second opinion the tests and the
//! verification compare the exact engine ([`crate::engine`]) with. Its settings are
//! `[safety.solver]`; its relaxed problem is the older single-slack one:
//!
//! ```text
//! min_u ‖u − u_nom‖²   s.t.   c_i + a_i·u ≥ 0 (barrier rows),   G u ≤ g (input bounds)
//! ```
//!
//! solved with Clarabel. Clarabel's standard form is `min ½xᵀPx + qᵀx` s.t.
//! `Ax + s = b, s ≥ 0`, so `P = 2I`, `q = −2u_nom`; a barrier row becomes
//! `−σ_i a_i·u + s = σ_i c_i` and a bound row `G_k u + s = g_k`. Each barrier row is
//! scaled by `σ_i = 1/‖a_i‖` (an exactly equivalent row; the constraints of one
//! filter have very different units), rows that cannot bind inside the box are neutralised
//! (see [`QpEngine::solve`]) because Clarabel's own
//! equilibration is switched off: its scaling would be computed once from the set-up data
//! and silently reused by every data update.
//!
//! **Speed without changing results.** Both solvers (hard and relaxed) are built once; every
//! step overwrites `q`, `A` and `b` in place (`update_q`, `update_A`, `update_b`). `A` is
//! stored with a *dense* CSC pattern (explicit zeros kept, `input_sparse_dropzeros =
//! false`), so the pattern never changes and the update is a plain copy. Presolve and
//! equilibration are off (both would forbid or distort updates); the linear solver is
//! single-threaded QDLDL; no time limit. Clarabel restarts its interior-point iteration
//! from its default start on every `solve`, so the result depends only on the current
//! data — never on the history, the thread count or the wall clock.
//!
//! **Skip path.** When `u_nom` already satisfies every barrier row and every bound it is
//! the unique minimiser of the strictly convex cost on the feasible set, and it is
//! returned without calling the solver.
//!
//! **Relaxed problem.** When the hard QP is infeasible or fails, a second problem with one
//! slack `s ≥ 0` on all (scaled) barrier rows, `c̃_i + ã_i·u + s ≥ 0`, and cost
//! `‖u − u_nom‖² + w s²` (`w = safety.solver.slack_weight`) is solved; the bounds stay
//! hard, so the relaxed problem is always feasible.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use serde::{Deserialize, Serialize};

/// Outcome of one QP call.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum QpOutcome {
    /// `u_nom` was feasible and returned unchanged (solver not called).
    Skipped,
    /// Hard QP solved.
    Solved,
    /// Hard QP infeasible or failed; relaxed QP solved.
    Relaxed,
    /// Both problems failed (or the engine could not be built); no solution.
    Failed,
}

/// The solver settings shared by all filters (from `[safety.solver]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SolverParams {
    pub max_iterations: u32,
    /// Clarabel's `tol_gap_abs`, `tol_gap_rel` and `tol_feas`.
    pub tolerance: f64,
    /// Weight `w` of the slack in the relaxed QP.
    pub slack_weight: f64,
}

impl SolverParams {
    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        Self {
            max_iterations: s.safety.solver.max_iterations,
            tolerance: s.safety.solver.tolerance,
            slack_weight: s.safety.solver.slack_weight,
        }
    }

    fn settings(&self) -> DefaultSettings<f64> {
        let mut st = DefaultSettingsBuilder::<f64>::default()
            .build()
            .unwrap_or_default();
        st.verbose = false;
        st.max_iter = self.max_iterations.max(1);
        st.time_limit = f64::INFINITY;
        st.tol_gap_abs = self.tolerance;
        st.tol_gap_rel = self.tolerance;
        st.tol_feas = self.tolerance;
        st.presolve_enable = false;
        st.equilibrate_enable = false;
        st.input_sparse_dropzeros = false;
        st.direct_solve_method = "qdldl".to_string();
        st.max_threads = 1;
        st
    }
}

/// The last QP a filter handed to its solver, in the filter's own (unscaled) form —
/// for `--dump-qp` and offline checks. Filled by the filters' exact engine
/// ([`crate::engine::LastProblem::dump`]) or by the Clarabel reference engine
/// ([`QpEngine::dump`]); the two differ in the multipliers' convention and in `slack`,
/// as noted per field.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct QpDump {
    /// Cost `‖u − u_nom‖²` (`P = 2I`, `q = −2 u_nom`).
    pub u_nom: Vec<f64>,
    /// Barrier rows `c_i + a_i·u ≥ 0`: `a_i` (row-major).
    pub rows_a: Vec<Vec<f64>>,
    pub rows_c: Vec<f64>,
    /// Hard rows (input bounds, contracts) as `G u ≤ g`.
    pub bounds_g: Vec<Vec<f64>>,
    pub bounds_g_max: Vec<f64>,
    /// Returned solution (before the filter's last-line clamp).
    pub solution: Vec<f64>,
    /// Multipliers λ_i ≥ 0 of the barrier rows. Exact engine: `u − u_nom = Σλ_i a_i −
    /// Σμ_k g_k` (the cost `½‖u − u_nom‖²`); Clarabel engine: `2(u − u_nom) = Σλ_i a_i − Gᵀμ`.
    pub row_duals: Vec<f64>,
    /// Multipliers μ_k ≥ 0 of the hard rows (exact engine: of the hard solve, zero when
    /// skipped, relaxed or from the second opinion).
    pub bound_duals: Vec<f64>,
    /// Exact engine: the largest allowance `t*` of the relaxed problem (a fraction of the
    /// rows' weights); Clarabel engine: the slack of its relaxed problem. 0 otherwise.
    pub slack: f64,
    pub outcome: Option<QpOutcome>,
    /// "active_set" (exact engine) or Clarabel's status of the last solver call.
    pub solver_status: String,
    /// Clarabel's status of the hard QP ("" from the exact engine or when skipped).
    pub hard_status: String,
    pub iterations: u32,
}

/// Result of [`QpEngine::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QpResult {
    pub outcome: QpOutcome,
    /// Interior-point iterations (hard + relaxed).
    pub iterations: u32,
    /// Slack of the relaxed problem.
    pub slack: f64,
}

/// Dense-pattern CSC with `rows × cols`, all entries stored.
fn dense_csc(rows: usize, cols: usize) -> CscMatrix<f64> {
    let colptr = (0..=cols).map(|j| j * rows).collect();
    let rowval = (0..cols).flat_map(|_| 0..rows).collect();
    CscMatrix::new(rows, cols, colptr, rowval, vec![0.0; rows * cols])
}

/// Diagonal CSC (upper triangle of P).
fn diag_csc(d: &[f64]) -> CscMatrix<f64> {
    let n = d.len();
    CscMatrix::new(n, n, (0..=n).collect(), (0..n).collect(), d.to_vec())
}

fn accepted(st: SolverStatus) -> bool {
    matches!(st, SolverStatus::Solved | SolverStatus::AlmostSolved)
}

/// One filter's QP: `m` inputs, `nb` barrier rows, `ng` bound rows. All buffers are
/// allocated once in [`QpEngine::new`]; [`QpEngine::solve`] does not allocate.
pub struct QpEngine {
    m: usize,
    nb: usize,
    ng: usize,
    hard: Option<DefaultSolver<f64>>,
    relaxed: Option<DefaultSolver<f64>>,
    // hard problem data (column-major A)
    q_h: Vec<f64>,
    a_h: Vec<f64>,
    b_h: Vec<f64>,
    // relaxed problem data
    q_r: Vec<f64>,
    a_r: Vec<f64>,
    b_r: Vec<f64>,
    scale: Vec<f64>,
    neutral: Vec<bool>,
    /// Bound on ‖u‖∞ over the input box.
    u_inf: f64,
    // last problem (unscaled, row-major) for the dump
    last_u_nom: Vec<f64>,
    last_rows_a: Vec<f64>,
    last_rows_c: Vec<f64>,
    last_g: Vec<f64>,
    last_g_max: Vec<f64>,
    last_x: Vec<f64>,
    last_row_duals: Vec<f64>,
    last_bound_duals: Vec<f64>,
    last_status: Option<SolverStatus>,
    last_hard_status: Option<SolverStatus>,
    last: Option<QpResult>,
    skip_enabled: bool,
}

impl QpEngine {
    /// Builds both Clarabel solvers once. A solver that cannot be built is `None`, and
    /// every solve then reports [`QpOutcome::Failed`] (the filter falls back).
    /// `u_inf` bounds `‖u‖∞` on the input box (used to condition the rows).
    pub fn new(m: usize, nb: usize, ng: usize, u_inf: f64, params: &SolverParams) -> Self {
        let rows_h = nb + ng;
        let rows_r = nb + ng + 1;
        let cones_h = [SupportedConeT::NonnegativeConeT(rows_h)];
        let cones_r = [SupportedConeT::NonnegativeConeT(rows_r)];
        let p_h = diag_csc(&vec![2.0; m]);
        let mut pr = vec![2.0; m + 1];
        pr[m] = 2.0 * params.slack_weight;
        let p_r = diag_csc(&pr);
        let a_h = dense_csc(rows_h, m);
        let a_r = dense_csc(rows_r, m + 1);
        let hard = DefaultSolver::new(
            &p_h,
            &vec![0.0; m],
            &a_h,
            &vec![1.0; rows_h],
            &cones_h,
            params.settings(),
        )
        .ok()
        .filter(|s| s.is_data_update_allowed());
        let relaxed = DefaultSolver::new(
            &p_r,
            &vec![0.0; m + 1],
            &a_r,
            &vec![1.0; rows_r],
            &cones_r,
            params.settings(),
        )
        .ok()
        .filter(|s| s.is_data_update_allowed());
        Self {
            m,
            nb,
            ng,
            hard,
            relaxed,
            q_h: vec![0.0; m],
            a_h: vec![0.0; rows_h * m],
            b_h: vec![0.0; rows_h],
            q_r: vec![0.0; m + 1],
            a_r: vec![0.0; rows_r * (m + 1)],
            b_r: vec![0.0; rows_r],
            scale: vec![1.0; nb],
            neutral: vec![false; nb],
            u_inf,
            last_u_nom: vec![0.0; m],
            last_rows_a: vec![0.0; nb * m],
            last_rows_c: vec![0.0; nb],
            last_g: vec![0.0; ng * m],
            last_g_max: vec![0.0; ng],
            last_x: vec![0.0; m],
            last_row_duals: vec![0.0; nb],
            last_bound_duals: vec![0.0; ng],
            last_status: None,
            last_hard_status: None,
            last: None,
            skip_enabled: true,
        }
    }

    /// Verification only: with `false` the solver runs even for a feasible nominal (the
    /// result then equals the skip path's up to the solver tolerance).
    pub fn set_skip_enabled(&mut self, on: bool) {
        self.skip_enabled = on;
    }

    /// Number of inputs, barrier rows, bound rows.
    pub fn dims(&self) -> (usize, usize, usize) {
        (self.m, self.nb, self.ng)
    }

    /// Solves the QP. `rows_a` is `nb × m` row-major, `g` is `ng × m` row-major; all data
    /// must be finite (the filters validate before calling). The minimiser is written to
    /// `u_out` (unchanged on [`QpOutcome::Failed`]).
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &mut self,
        u_nom: &[f64],
        rows_a: &[f64],
        rows_c: &[f64],
        g: &[f64],
        g_max: &[f64],
        u_out: &mut [f64],
    ) -> QpResult {
        let (m, nb, ng) = (self.m, self.nb, self.ng);
        let dims_ok = u_nom.len() == m
            && rows_a.len() == nb * m
            && rows_c.len() == nb
            && g.len() == ng * m
            && g_max.len() == ng
            && u_out.len() == m;
        self.last_status = None;
        self.last_hard_status = None;
        self.last_row_duals.iter_mut().for_each(|x| *x = 0.0);
        self.last_bound_duals.iter_mut().for_each(|x| *x = 0.0);
        if !dims_ok {
            return self.finish(QpOutcome::Failed, 0, 0.0);
        }
        self.last_u_nom.copy_from_slice(u_nom);
        self.last_rows_a.copy_from_slice(rows_a);
        self.last_rows_c.copy_from_slice(rows_c);
        self.last_g.copy_from_slice(g);
        self.last_g_max.copy_from_slice(g_max);

        // Skip path: u_nom feasible ⇒ unique minimiser.
        if Self::feasible(m, u_nom, rows_a, rows_c, g, g_max) && self.skip_enabled {
            u_out.copy_from_slice(u_nom);
            self.last_x.copy_from_slice(u_nom);
            return self.finish(QpOutcome::Skipped, 0, 0.0);
        }
        let hard_infeasible = self.condition_rows(rows_a, rows_c);
        self.fill_hard(u_nom, rows_a, rows_c, g, g_max);
        let mut iterations = 0;
        if !hard_infeasible && let Some(r) = self.solve_hard(u_out, &mut iterations) {
            return r;
        }
        self.fill_relaxed();
        if let Some(r) = self.solve_relaxed(u_out, &mut iterations) {
            return r;
        }
        self.finish(QpOutcome::Failed, iterations, 0.0)
    }

    /// Records and returns the result of a solve.
    fn finish(&mut self, outcome: QpOutcome, iterations: u32, slack: f64) -> QpResult {
        let r = QpResult {
            outcome,
            iterations,
            slack,
        };
        self.last = Some(r);
        r
    }

    /// `u_nom` satisfies every barrier row and every bound.
    fn feasible(
        m: usize,
        u_nom: &[f64],
        rows_a: &[f64],
        rows_c: &[f64],
        g: &[f64],
        g_max: &[f64],
    ) -> bool {
        let nb = rows_c.len();
        let ng = g_max.len();
        (0..nb).all(|i| {
            let a = &rows_a[i * m..(i + 1) * m];
            rows_c[i] + dot(a, u_nom) >= 0.0
        }) && (0..ng).all(|k| dot(&g[k * m..(k + 1) * m], u_nom) <= g_max[k])
    }

    /// Row conditioning. With `‖u‖∞ ≤ U` on the box, `|a·u| ≤ ‖a‖₁U =: reach`. A row with
    /// `c ≥ reach` can never bind inside the box and is replaced by the neutral row
    /// `0·u ≥ −1` (its multiplier is 0); a row with `c < −reach` cannot be met anywhere in
    /// the box, so the hard QP is infeasible and only the relaxed one is solved (that row
    /// scaled to unit violation). Every other row is scaled by `σ = 1/‖a‖`, so all
    /// right-hand sides stay of the order of `U` (Clarabel stalls on rows like
    /// `0·u ≥ −10⁸` that a near-zero `‖a‖` would otherwise produce). Returns whether the
    /// hard QP is infeasible.
    fn condition_rows(&mut self, rows_a: &[f64], rows_c: &[f64]) -> bool {
        let m = self.m;
        let mut hard_infeasible = false;
        for i in 0..self.nb {
            let a = &rows_a[i * m..(i + 1) * m];
            let c = rows_c[i];
            let reach = a.iter().map(|x| x.abs()).sum::<f64>() * self.u_inf;
            if c >= reach {
                self.scale[i] = 0.0;
                self.neutral[i] = true;
            } else if c < -reach {
                hard_infeasible = true;
                self.neutral[i] = false;
                self.scale[i] = 1.0 / (-c).max(1e-300);
            } else {
                self.neutral[i] = false;
                self.scale[i] = 1.0 / dot(a, a).sqrt();
            }
        }
        hard_infeasible
    }

    /// The hard problem's data: `q = −2u_nom`, the scaled barrier rows `−σ_i a_i` and the
    /// bound rows `G` (column-major), `b = [σ_i c_i (1 if neutral); g]`.
    fn fill_hard(
        &mut self,
        u_nom: &[f64],
        rows_a: &[f64],
        rows_c: &[f64],
        g: &[f64],
        g_max: &[f64],
    ) {
        let (m, nb, ng) = (self.m, self.nb, self.ng);
        let rows_h = nb + ng;
        for j in 0..m {
            self.q_h[j] = -2.0 * u_nom[j];
            for i in 0..nb {
                self.a_h[j * rows_h + i] = -self.scale[i] * rows_a[i * m + j];
            }
            for k in 0..ng {
                self.a_h[j * rows_h + nb + k] = g[k * m + j];
            }
        }
        for (i, &c) in rows_c.iter().enumerate() {
            self.b_h[i] = if self.neutral[i] {
                1.0
            } else {
                self.scale[i] * c
            };
        }
        self.b_h[nb..].copy_from_slice(g_max);
    }

    /// The hard problem with Clarabel; `Some` when it is solved (the minimiser in `u_out`).
    fn solve_hard(&mut self, u_out: &mut [f64], iterations: &mut u32) -> Option<QpResult> {
        let (nb, ng) = (self.nb, self.ng);
        let s = self.hard.as_mut()?;
        let upd = s.update_q(&self.q_h).is_ok()
            && s.update_A(&self.a_h).is_ok()
            && s.update_b(&self.b_h).is_ok();
        if !upd {
            return None;
        }
        s.solve();
        let sol = &s.solution;
        *iterations += sol.iterations;
        self.last_status = Some(sol.status);
        self.last_hard_status = Some(sol.status);
        if !(accepted(sol.status) && sol.x.iter().all(|x| x.is_finite())) {
            return None;
        }
        u_out.copy_from_slice(&sol.x);
        self.last_x.copy_from_slice(&sol.x);
        for i in 0..nb {
            self.last_row_duals[i] = sol.z[i] * self.scale[i];
        }
        self.last_bound_duals.copy_from_slice(&sol.z[nb..nb + ng]);
        Some(self.finish(QpOutcome::Solved, *iterations, 0.0))
    }

    /// The relaxed problem's data, `x = [u; s]`: the hard problem's columns, then the slack
    /// column (`−s` on the non-neutral barrier rows, 0 on the bounds, `−s ≤ 0` last).
    fn fill_relaxed(&mut self) {
        let (m, nb, ng) = (self.m, self.nb, self.ng);
        let rows_h = nb + ng;
        let rows_r = rows_h + 1;
        for j in 0..m {
            self.q_r[j] = self.q_h[j];
            for i in 0..rows_h {
                self.a_r[j * rows_r + i] = self.a_h[j * rows_h + i];
            }
            self.a_r[j * rows_r + rows_h] = 0.0;
        }
        self.q_r[m] = 0.0;
        let sc = m * rows_r;
        for i in 0..rows_r {
            let on = (i < nb && !self.neutral[i]) || i == rows_h;
            self.a_r[sc + i] = if on { -1.0 } else { 0.0 };
        }
        self.b_r[..rows_h].copy_from_slice(&self.b_h);
        self.b_r[rows_h] = 0.0;
    }

    /// The relaxed problem with Clarabel; `Some` when it is solved (the command in `u_out`).
    fn solve_relaxed(&mut self, u_out: &mut [f64], iterations: &mut u32) -> Option<QpResult> {
        let (m, nb, ng) = (self.m, self.nb, self.ng);
        let s = self.relaxed.as_mut()?;
        let upd = s.update_q(&self.q_r).is_ok()
            && s.update_A(&self.a_r).is_ok()
            && s.update_b(&self.b_r).is_ok();
        if !upd {
            return None;
        }
        s.solve();
        let sol = &s.solution;
        *iterations += sol.iterations;
        self.last_status = Some(sol.status);
        if !(accepted(sol.status) && sol.x.iter().all(|x| x.is_finite())) {
            return None;
        }
        u_out.copy_from_slice(&sol.x[..m]);
        self.last_x.copy_from_slice(&sol.x[..m]);
        for i in 0..nb {
            self.last_row_duals[i] = sol.z[i] * self.scale[i];
        }
        self.last_bound_duals.copy_from_slice(&sol.z[nb..nb + ng]);
        let slack = sol.x[m].max(0.0);
        Some(self.finish(QpOutcome::Relaxed, *iterations, slack))
    }

    /// The last problem and its solution (allocates; not for the hot path).
    pub fn dump(&self) -> QpDump {
        let (m, nb, ng) = (self.m, self.nb, self.ng);
        QpDump {
            u_nom: self.last_u_nom.clone(),
            rows_a: (0..nb)
                .map(|i| self.last_rows_a[i * m..(i + 1) * m].to_vec())
                .collect(),
            rows_c: self.last_rows_c.clone(),
            bounds_g: (0..ng)
                .map(|k| self.last_g[k * m..(k + 1) * m].to_vec())
                .collect(),
            bounds_g_max: self.last_g_max.clone(),
            solution: self.last_x.clone(),
            row_duals: self.last_row_duals.clone(),
            bound_duals: self.last_bound_duals.clone(),
            slack: self.last.map(|r| r.slack).unwrap_or(0.0),
            outcome: self.last.map(|r| r.outcome),
            solver_status: self
                .last_status
                .map(|s| format!("{s:?}"))
                .unwrap_or_default(),
            hard_status: self
                .last_hard_status
                .map(|s| format!("{s:?}"))
                .unwrap_or_default(),
            iterations: self.last.map(|r| r.iterations).unwrap_or(0),
        }
    }

    /// Multipliers λ_i of the barrier rows of the last solve (0 when skipped).
    pub fn row_duals(&self) -> &[f64] {
        &self.last_row_duals
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
