//! Independent verification of a filter's QP: the same problem, checked by means that
//! share no code with the exact engine ([`crate::engine`]) — the KKT conditions with
//! multipliers recomputed by non-negative least squares over the active rows, and the
//! Clarabel interior-point reference ([`crate::qp::QpEngine`]). Used by the tests and by
//! `safe-capture verify-qp` on every QP a run dumped (`run --dump-qp`).

use crate::barrier::Row;
use crate::qp::{QpDump, QpEngine, QpOutcome, SolverParams};
use nalgebra::{DMatrix, DVector, SVector};

/// A filter's QP `min ‖u − u_nom‖²` s.t. `c_i + a_i·u ≥ 0` for every row (barrier rows
/// first, then the hard rows written the same way).
#[derive(Debug, Clone)]
pub struct Qp {
    pub u_nom: DVector<f64>,
    pub a: Vec<DVector<f64>>,
    pub c: Vec<f64>,
    /// Number of barrier rows (the first `nb`).
    pub nb: usize,
}

impl Qp {
    pub fn from_rows<const M: usize>(
        u_nom: &SVector<f64, M>,
        rows: &[Row<M>],
        hard: &[Row<M>],
    ) -> Self {
        Self {
            u_nom: DVector::from_column_slice(u_nom.as_slice()),
            a: rows
                .iter()
                .chain(hard)
                .map(|r| DVector::from_column_slice(r.a.as_slice()))
                .collect(),
            c: rows.iter().chain(hard).map(|r| r.c).collect(),
            nb: rows.len(),
        }
    }

    /// From a filter's `dump_qp()`: barrier rows `c + a·u ≥ 0`, bounds `g·u ≤ g_max`.
    pub fn from_dump(d: &QpDump) -> Self {
        let mut a: Vec<DVector<f64>> = d
            .rows_a
            .iter()
            .map(|r| DVector::from_column_slice(r))
            .collect();
        let mut c = d.rows_c.clone();
        for (g, gm) in d.bounds_g.iter().zip(&d.bounds_g_max) {
            a.push(-DVector::from_column_slice(g));
            c.push(*gm);
        }
        Self {
            u_nom: DVector::from_column_slice(&d.u_nom),
            a,
            c,
            nb: d.rows_a.len(),
        }
    }

    pub fn m(&self) -> usize {
        self.u_nom.len()
    }

    pub fn phi(&self, i: usize, u: &DVector<f64>) -> f64 {
        self.c[i] + self.a[i].dot(u)
    }

    /// Rows with allowances: `c_i + w_i t_i` for the first rows.
    pub fn relaxed(&self, allowance: &[f64]) -> Self {
        let mut q = self.clone();
        for (i, t) in allowance.iter().enumerate() {
            q.c[i] += t;
        }
        q
    }
}

/// Non-negative least squares `min ‖A λ − b‖, λ ≥ 0` (Lawson–Hanson).
pub fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let n = a.ncols();
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    for _outer in 0..3 * n + 10 {
        let w = a.transpose() * (b - a * &x);
        let cand = (0..n)
            .filter(|&j| !passive[j])
            .max_by(|&i, &j| w[i].partial_cmp(&w[j]).unwrap());
        let Some(j) = cand else { break };
        if w[j] <= 1e-14 * (1.0 + b.norm()) * (1.0 + a.norm()) {
            break;
        }
        passive[j] = true;
        for _inner in 0..3 * n + 10 {
            let idx: Vec<usize> = (0..n).filter(|&k| passive[k]).collect();
            let ap = DMatrix::from_fn(a.nrows(), idx.len(), |r, c| a[(r, idx[c])]);
            let Some(z) = least_squares(&ap, b) else {
                return x;
            };
            if z.iter().all(|v| *v > 0.0) {
                for (k, &i) in idx.iter().enumerate() {
                    x[i] = z[k];
                }
                for k in 0..n {
                    if !passive[k] {
                        x[k] = 0.0;
                    }
                }
                break;
            }
            let mut alpha = 1.0f64;
            for (k, &i) in idx.iter().enumerate() {
                if z[k] <= 0.0 {
                    alpha = alpha.min(x[i] / (x[i] - z[k]));
                }
            }
            for (k, &i) in idx.iter().enumerate() {
                x[i] += alpha * (z[k] - x[i]);
                if x[i] <= 1e-300 {
                    x[i] = 0.0;
                    passive[i] = false;
                }
            }
        }
    }
    x
}

/// `min ‖A z − b‖` by SVD with two rounds of iterative refinement: nalgebra's SVD alone
/// loses digits when the columns' norms differ by orders of magnitude (rows of `1/m` beside
/// unit bound rows: a relative error of 2e-4 measured).
fn least_squares(a: &DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    let svd = a.clone().svd(true, true);
    let mut z = svd.solve(b, 1e-14).ok()?;
    for _ in 0..2 {
        let r = b - a * &z;
        z += svd.solve(&r, 1e-14).ok()?;
    }
    Some(z)
}

/// KKT residuals of `u` for `qp`, with multipliers computed here (NNLS over the rows
/// active within `act_tol` in distance): `(max row violation in distance, stationarity
/// residual ‖(u − u_nom) − Σ λ_i a_i‖, multipliers)`. The multipliers are those of the ½
/// cost `½‖u − u_nom‖²`.
pub fn kkt(qp: &Qp, u: &DVector<f64>, act_tol: f64) -> (f64, f64, Vec<f64>) {
    let mut viol = 0.0f64;
    let mut act = Vec::new();
    for i in 0..qp.a.len() {
        let n = qp.a[i].norm();
        let d = if n > 0.0 { qp.phi(i, u) / n } else { qp.c[i] };
        viol = viol.max(-d);
        if n > 0.0 && d <= act_tol {
            act.push(i);
        }
    }
    let g = u - &qp.u_nom;
    let mut lam = vec![0.0; qp.a.len()];
    if act.is_empty() {
        return (viol, g.norm(), lam);
    }
    let a = DMatrix::from_fn(qp.m(), act.len(), |r, c| qp.a[act[c]][r]);
    let l = nnls(&a, &g);
    for (k, &i) in act.iter().enumerate() {
        lam[i] = l[k];
    }
    ((viol), (a * l - g).norm(), lam)
}

/// Clarabel's solution of `qp` through the crate's independent reference engine
/// [`QpEngine`] (barrier rows as rows, hard rows as bounds; tight tolerances). `u_inf`
/// bounds `‖u‖∞` on the hard rows' feasible set.
pub fn clarabel(qp: &Qp, u_inf: f64) -> Option<DVector<f64>> {
    let m = qp.m();
    let (nb, ng) = (qp.nb, qp.a.len() - qp.nb);
    let params = SolverParams {
        max_iterations: 200,
        tolerance: 1e-11,
        slack_weight: 1e6,
    };
    let mut eng = QpEngine::new(m, nb, ng, u_inf, &params);
    eng.set_skip_enabled(false);
    let rows_a: Vec<f64> = qp.a[..nb].iter().flat_map(|a| a.iter().copied()).collect();
    let g: Vec<f64> = qp.a[nb..]
        .iter()
        .flat_map(|a| a.iter().map(|x| -x))
        .collect();
    let mut u = vec![0.0; m];
    let r = eng.solve(
        qp.u_nom.as_slice(),
        &rows_a,
        &qp.c[..nb],
        &g,
        &qp.c[nb..],
        &mut u,
    );
    (r.outcome == QpOutcome::Solved).then(|| DVector::from_vec(u))
}

/// An exact reference from Clarabel's point `u_c`: the rows within `act_tol` (distance) of
/// their boundary at `u_c` are taken as equalities and `u_nom` is projected onto their
/// intersection in exact linear algebra (SVD of the active rows' Gram matrix,
/// rank-revealing, so dependent rows are allowed). While that is no KKT point the guess is
/// corrected — the row with the most negative multiplier leaves, else the most violated
/// row joins — for a bounded number of rounds. A projection is accepted only as a KKT
/// point of the whole problem — every row holds within `tol` in distance, and `u − u_nom`
/// is a non-negative combination of the rows active at it to within `tol` (NNLS) — which
/// makes it *the* optimum (the cost is strictly convex); `None` when no round gives one.
/// Shares no code with the engine that is checked.
pub fn exact_reference(
    qp: &Qp,
    u_c: &DVector<f64>,
    act_tol: f64,
    tol: f64,
) -> Option<DVector<f64>> {
    // unit rows (the same half-spaces): the Gram matrix and NNLS see no row scaling
    let mut unit = qp.clone();
    for (a, c) in unit.a.iter_mut().zip(unit.c.iter_mut()) {
        let norm = a.norm();
        if norm > 0.0 {
            *a /= norm;
            *c /= norm;
        }
    }
    let qp = &unit;
    let m = qp.m();
    let n = qp.a.len();
    let dist = |i: usize, u: &DVector<f64>| {
        if qp.a[i].norm() > 0.0 {
            qp.phi(i, u)
        } else {
            qp.c[i]
        }
    };
    let mut act: Vec<usize> = (0..n)
        .filter(|&i| qp.a[i].norm() > 0.0 && dist(i, u_c).abs() <= act_tol)
        .collect();
    for _ in 0..2 * (n + m) {
        // u = u_nom + A⁺(−c_A − A u_nom), the rows A of the guess as equalities, and the
        // multipliers λ = (Aᵀ)⁺(u − u_nom) — both by SVD of A itself (never of AᵀA, whose
        // condition is the square: at a vertex with σ_min = 4e-5 that cost 5e-8)
        let (u, lam) = if act.is_empty() {
            (qp.u_nom.clone(), DVector::zeros(0))
        } else {
            let a = DMatrix::from_fn(act.len(), m, |r, c| qp.a[act[r]][c]);
            let rhs = DVector::from_fn(act.len(), |k, _| -qp.c[act[k]]) - &a * &qp.u_nom;
            let eps = 1e-13 * a.norm().max(f64::MIN_POSITIVE);
            let delta = a.clone().svd(true, true).solve(&rhs, eps).ok()?;
            let lam = a.transpose().svd(true, true).solve(&delta, eps).ok()?;
            (&qp.u_nom + delta, lam)
        };
        if !u.iter().all(|v| v.is_finite()) {
            return None;
        }
        let worst = (0..n)
            .map(|i| (dist(i, &u), i))
            .fold((f64::INFINITY, 0), |w, d| if d.0 < w.0 { d } else { w });
        let (_, stationarity, _) = kkt(qp, &u, tol);
        if worst.0 >= -tol && stationarity <= tol {
            return Some(u);
        }
        let most_negative = (0..lam.len())
            .filter(|&k| lam[k] < 0.0)
            .min_by(|&x, &y| lam[x].total_cmp(&lam[y]));
        match most_negative {
            Some(k) => {
                act.remove(k);
            }
            None if worst.0 < -tol && !act.contains(&worst.1) => act.push(worst.1),
            None => return None,
        }
    }
    None
}

/// What [`check`] found for one solved QP, relative to `u_inf` where a length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Check {
    /// Largest row violation at the engine's solution, in distance (`−(c + a·u)/‖a‖`) [u].
    pub violation: f64,
    /// Stationarity residual `‖(u − u_nom) − Σ λ_i a_i‖` with NNLS multipliers [u].
    pub stationarity: f64,
    /// `‖u − u_Clarabel‖∞`, `None` when Clarabel did not solve it [u].
    pub clarabel_distance: Option<f64>,
    /// `‖u − u_exact‖∞` to [`exact_reference`] built on Clarabel's active set — or, when
    /// Clarabel failed or that gave no KKT point, on the rows active at `u` itself (still
    /// accepted only as a KKT point) — `None` when neither gave one [u].
    pub exact_distance: Option<f64>,
    /// The exact reference came from the rows active at `u`, not from Clarabel's.
    pub exact_from_solution: bool,
}

/// Checks the solution `d.solution` of the hard QP in `d` (KKT with recomputed multipliers,
/// rows active within `act_tol` in distance; the distance to Clarabel's solution; and the
/// distance to the exact reference on Clarabel's active set, KKT-checked to `exact_tol`).
/// `u_inf` bounds `‖u‖∞` over the hard rows.
pub fn check(d: &QpDump, u_inf: f64, act_tol: f64, exact_tol: f64) -> Check {
    let qp = Qp::from_dump(d);
    let u = DVector::from_column_slice(&d.solution);
    let (violation, stationarity, _) = kkt(&qp, &u, act_tol);
    let reference = clarabel(&qp, u_inf);
    let clarabel_distance = reference.as_ref().map(|v| (v - &u).amax());
    let from_clarabel = reference.and_then(|v| exact_reference(&qp, &v, act_tol, exact_tol));
    let exact_from_solution = from_clarabel.is_none();
    let exact_distance = from_clarabel
        .or_else(|| exact_reference(&qp, &u, act_tol, exact_tol))
        .map(|v| (v - &u).amax());
    Check {
        violation,
        stationarity,
        clarabel_distance,
        exact_distance,
        exact_from_solution: exact_from_solution && exact_distance.is_some(),
    }
}

/// How far the dump's own multipliers are from certifying its solution, the largest of:
/// the stationarity residual `‖(u − u_nom) − Σλ_i a_i + Σμ_k g_k‖∞` (the exact engine's
/// convention, [`QpDump::row_duals`]), a negative multiplier's pull `−λ_i‖a_i‖`, and the
/// complementarity `min(λ_i‖a_i‖, slack_i/‖a_i‖)` (a pull on a row that is not active)
/// [u]. 0 for the exact certificate.
pub fn dual_residual(d: &QpDump) -> f64 {
    let m = d.solution.len();
    let mut r: Vec<f64> = (0..m).map(|j| d.solution[j] - d.u_nom[j]).collect();
    let mut worst = 0.0f64;
    let dot = |a: &[f64]| a.iter().zip(&d.solution).map(|(x, y)| x * y).sum::<f64>();
    let norm = |a: &[f64]| {
        a.iter()
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt()
            .max(f64::MIN_POSITIVE)
    };
    for ((lam, a), c) in d.row_duals.iter().zip(&d.rows_a).zip(&d.rows_c) {
        for j in 0..m {
            r[j] -= lam * a[j];
        }
        let (pull, slack) = (lam * norm(a), (c + dot(a)) / norm(a));
        worst = worst.max(-pull).max(pull.min(slack.abs()));
    }
    for ((mu, g), gm) in d.bound_duals.iter().zip(&d.bounds_g).zip(&d.bounds_g_max) {
        for j in 0..m {
            r[j] += mu * g[j];
        }
        let (pull, slack) = (mu * norm(g), (gm - dot(g)) / norm(g));
        worst = worst.max(-pull).max(pull.min(slack.abs()));
    }
    r.iter().fold(worst, |w, x| w.max(x.abs()))
}

/// The scale of the filter's inputs: the largest half-width `g_max/‖g‖` of its hard rows
/// (the input bound for a box, also a rotated one); `fallback` when there is none. A box
/// rotated in `m` dimensions bounds `‖u‖∞` by `√m` times this.
pub fn input_bound(d: &QpDump, fallback: f64) -> f64 {
    d.bounds_g
        .iter()
        .zip(&d.bounds_g_max)
        .filter_map(|(g, gm)| {
            let n = g.iter().map(|x| x * x).sum::<f64>().sqrt();
            (n > 0.0 && gm.is_finite()).then(|| gm.abs() / n)
        })
        .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))
        .unwrap_or(fallback)
}
