//! Shared test support: a deterministic generator, Clarabel as the independent reference,
//! and KKT / certificate checks computed from the caller's (unscaled) data.
#![allow(dead_code)]
// Index loops mirror the linear algebra.
#![allow(clippy::needless_range_loop)]

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use sc_qp::{LeastViolation, Solution, Status};

/// SplitMix64: deterministic, no dependencies.
#[derive(Clone)]
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
    pub fn normal(&mut self) -> f64 {
        // Box–Muller
        let u1 = self.unit().max(1e-300);
        let u2 = self.unit();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
    pub fn vec(&mut self, m: usize) -> Vec<f64> {
        (0..m).map(|_| self.normal()).collect()
    }
    pub fn shuffle<T>(&mut self, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            let j = self.below(i + 1);
            v.swap(i, j);
        }
    }
}

/// A problem in the caller's form: `min ½‖x − x0‖²  s.t.  a_i·x ≥ b_i`, with weights `w`
/// for the least-violation problems.
#[derive(Clone, Debug)]
pub struct Problem {
    pub m: usize,
    pub x0: Vec<f64>,
    pub a: Vec<Vec<f64>>,
    pub b: Vec<f64>,
    pub w: Vec<f64>,
}

impl Problem {
    pub fn new(x0: Vec<f64>) -> Self {
        Self {
            m: x0.len(),
            x0,
            a: vec![],
            b: vec![],
            w: vec![],
        }
    }
    pub fn row(&mut self, a: Vec<f64>, b: f64) {
        self.row_w(a, b, 0.0);
    }
    pub fn row_w(&mut self, a: Vec<f64>, b: f64, w: f64) {
        assert_eq!(a.len(), self.m);
        self.a.push(a);
        self.b.push(b);
        self.w.push(w);
    }
    /// `±x_j ≥ −limit` for every j.
    pub fn boxed(&mut self, limit: f64) {
        for j in 0..self.m {
            for s in [1.0, -1.0] {
                let mut a = vec![0.0; self.m];
                a[j] = s;
                self.row(a, -limit);
            }
        }
    }
    pub fn n(&self) -> usize {
        self.a.len()
    }
    pub fn shuffle(&mut self, rng: &mut Rng) {
        let mut idx: Vec<usize> = (0..self.n()).collect();
        rng.shuffle(&mut idx);
        self.a = idx.iter().map(|&i| self.a[i].clone()).collect();
        self.b = idx.iter().map(|&i| self.b[i]).collect();
        self.w = idx.iter().map(|&i| self.w[i]).collect();
    }
    /// The arrays the solver takes (rows beyond `n` are garbage on purpose: they must be
    /// ignored).
    pub fn arrays<const M: usize, const N: usize>(
        &self,
    ) -> ([f64; M], [[f64; M]; N], [f64; N], [f64; N]) {
        assert_eq!(self.m, M);
        assert!(self.n() <= N);
        let mut x0 = [0.0; M];
        x0.copy_from_slice(&self.x0);
        let mut a = [[f64::NAN; M]; N];
        let mut b = [f64::NAN; N];
        let mut w = [f64::NAN; N];
        for i in 0..self.n() {
            a[i].copy_from_slice(&self.a[i]);
            b[i] = self.b[i];
            w[i] = self.w[i];
        }
        (x0, a, b, w)
    }
    pub fn row_norm(&self, i: usize) -> f64 {
        norm(&self.a[i])
    }
    /// Scale of the problem: `max(1, ‖x0‖∞, max |b_i|/‖a_i‖)`.
    pub fn scale(&self) -> f64 {
        let mut s = 1.0f64.max(inf(&self.x0));
        for i in 0..self.n() {
            let nu = self.row_norm(i);
            if nu > 0.0 {
                s = s.max(self.b[i].abs() / nu);
            }
        }
        s
    }
    /// The same problem with `b_i − w_i t`.
    pub fn relaxed(&self, t: f64) -> Problem {
        let mut p = self.clone();
        for i in 0..p.n() {
            p.b[i] = self.b[i] - self.w[i] * t;
            p.w[i] = 0.0;
        }
        p
    }
}

pub fn dot(u: &[f64], v: &[f64]) -> f64 {
    u.iter().zip(v).map(|(a, b)| a * b).sum()
}
/// Euclidean norm without overflow or underflow of the squares.
pub fn norm(v: &[f64]) -> f64 {
    let m = inf(v);
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    m * v.iter().map(|e| (e / m) * (e / m)).sum::<f64>().sqrt()
}
pub fn inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, e| m.max(e.abs()))
}

/// Clarabel's tolerances for the reference solutions, tried in turn until one gives
/// `Solved` (else the first "almost solved" point). Near-degenerate rows (tiny multipliers λ) keep an interior-point slack of
/// about μ/λ: at 1e-12 that reached 2e-8 on a random 7×34 problem with λ̂ = 2e-4 (2e-10 at
/// 1e-14); but at 1e-14 Clarabel often ends "almost solved". If no tolerance gives
/// `Solved`, the last "almost solved" point is returned: callers still compare it at their
/// full tolerance (on the LPs where this happens it agrees with the exact t* to ~1e-12).
/// On rare, highly degenerate problems Clarabel reaches its iteration limit at every
/// tolerance; callers then skip the comparison (`prop_assume!`: proptest fails if that
/// becomes frequent).
pub const CLARABEL_TOLS: [f64; 4] = [1e-14, 1e-13, 1e-12, 1e-10];

pub fn clarabel_settings(tol: f64) -> DefaultSettings<f64> {
    let mut st = DefaultSettingsBuilder::<f64>::default()
        .build()
        .expect("settings");
    st.verbose = false;
    st.max_iter = 400;
    st.tol_gap_abs = tol;
    st.tol_gap_rel = tol;
    st.tol_feas = tol;
    st.tol_ktratio = tol;
    st.max_threads = 1;
    st
}

fn dense_csc(rows: &[Vec<f64>], cols: usize) -> CscMatrix<f64> {
    let nr = rows.len();
    let colptr = (0..=cols).map(|j| j * nr).collect();
    let rowval = (0..cols).flat_map(|_| 0..nr).collect();
    let mut nzval = Vec::with_capacity(nr * cols);
    for j in 0..cols {
        for r in rows {
            nzval.push(r[j]);
        }
    }
    CscMatrix::new(nr, cols, colptr, rowval, nzval)
}

pub struct Reference {
    pub status: SolverStatus,
    pub x: Vec<f64>,
    /// The Clarabel tolerance this result was obtained with.
    pub tol: f64,
}

impl Reference {
    /// How far the reference can be trusted, relative to the problem scale: 1e-9 when
    /// Clarabel solved it at 1e-12 or tighter; otherwise (solved only at 1e-10, or "almost
    /// solved" with its reduced tolerances) 1e-6. Exactness itself is checked by the
    /// certificates (KKT, LP dual), not by this comparison.
    pub fn trust(&self) -> f64 {
        if self.status == SolverStatus::Solved && self.tol <= 1e-12 {
            1e-9
        } else {
            1e-6
        }
    }
}

fn clarabel(p_diag: &[f64], q: &[f64], rows: &[Vec<f64>], rhs: &[f64]) -> Reference {
    let k = q.len();
    let p = CscMatrix::new(
        k,
        k,
        (0..=k)
            .map(|j| if p_diag.is_empty() { 0 } else { j })
            .collect(),
        if p_diag.is_empty() {
            vec![]
        } else {
            (0..k).collect()
        },
        p_diag.to_vec(),
    );
    let a = dense_csc(rows, k);
    let cones = [SupportedConeT::NonnegativeConeT(rows.len())];
    let mut almost: Option<Reference> = None;
    let mut last = None;
    for tol in CLARABEL_TOLS {
        let mut solver =
            DefaultSolver::new(&p, q, &a, rhs, &cones, clarabel_settings(tol)).expect("clarabel");
        solver.solve();
        let r = Reference {
            status: solver.solution.status,
            x: solver.solution.x.clone(),
            tol,
        };
        match r.status {
            SolverStatus::Solved => return r,
            SolverStatus::AlmostSolved if almost.is_none() => almost = Some(r),
            _ => last = Some(r),
        }
    }
    almost.or(last).expect("at least one tolerance")
}

/// Clarabel on `min ½‖x − x0‖²  s.t.  a_i·x ≥ b_i` (rows given as `−a_i·x ≤ −b_i`).
///
/// The rows are handed over scaled to unit norm (an exactly equivalent constraint): with the
/// raw 1e-6…1e6 row scales Clarabel stops at ~1e-7 accuracy or reports "almost
/// infeasible", which would test Clarabel rather than this crate. Zero rows are dropped
/// (callers only pass feasible problems here).
pub fn clarabel_qp(p: &Problem) -> Reference {
    let q: Vec<f64> = p.x0.iter().map(|v| -v).collect();
    let mut rows = Vec::new();
    let mut rhs = Vec::new();
    for i in 0..p.n() {
        let nu = p.row_norm(i);
        if nu == 0.0 {
            continue;
        }
        rows.push(p.a[i].iter().map(|v| -v / nu).collect());
        rhs.push(-p.b[i] / nu);
    }
    clarabel(&vec![1.0; p.m], &q, &rows, &rhs)
}

/// Clarabel on the LP `min t  s.t.  a_i·x + w_i t ≥ b_i, t ≥ 0`; `x` is `(x, t)`.
pub fn clarabel_lp(p: &Problem) -> Reference {
    let m = p.m;
    let mut q = vec![0.0; m + 1];
    q[m] = 1.0;
    let mut rows = Vec::new();
    let mut rhs = Vec::new();
    for i in 0..p.n() {
        // unit-scaled rows, as in `clarabel_qp`
        let nu = p.row_norm(i).max(p.w[i]);
        if nu == 0.0 {
            continue;
        }
        let mut r: Vec<f64> = p.a[i].iter().map(|v| -v / nu).collect();
        r.push(-p.w[i] / nu);
        rows.push(r);
        rhs.push(-p.b[i] / nu);
    }
    let mut r = vec![0.0; m + 1];
    r[m] = -1.0;
    rows.push(r);
    rhs.push(0.0);
    clarabel(&[], &q, &rows, &rhs)
}

pub fn objective(p: &Problem, x: &[f64]) -> f64 {
    0.5 * x
        .iter()
        .zip(&p.x0)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
}

/// KKT of the projection at `s` in the caller's scaling, to `tol` relative to the problem
/// scale: primal feasibility (distances), λ ≥ 0 and zero off the active set,
/// complementarity (active rows on their boundary), stationarity `x − x0 = Σ λ_i a_i`.
/// Stationarity is a sum of terms of size `λ̂_i = λ_i‖a_i‖`; at a degenerate vertex with a
/// nearly dependent active set these can be far larger than the scale, and the sum then
/// carries their rounding: the residual is measured against `max(scale, Σ λ̂_i)`.
/// Likewise the point of an ill-conditioned active set is only determined to about
/// `ε·cond(Â)·scale`, so distances are checked to `scale · max(tol, 16ε·cond(Â))`
/// (`cond(Â)` of the unit-scaled active rows; for well-conditioned sets this is `tol`).
pub fn check_kkt<const M: usize, const N: usize>(
    p: &Problem,
    s: &Solution<M, N>,
    tol: f64,
) -> Result<(), String> {
    if s.status != Status::Optimal {
        return Err(format!("status {:?}", s.status));
    }
    let scale = p.scale().max(inf(&s.x));
    let terms = (0..p.n()).fold(0.0, |acc, i| acc + s.lambda[i] * p.row_norm(i));
    let act: Vec<usize> = (0..p.n()).filter(|&i| s.active >> i & 1 == 1).collect();
    let ptol = tol.max(16.0 * f64::EPSILON * gram_cond(p, &act).sqrt());
    let mut stat: Vec<f64> = (0..M).map(|k| s.x[k] - p.x0[k]).collect();
    for i in 0..p.n() {
        let nu = p.row_norm(i);
        let lam = s.lambda[i];
        if lam.is_nan() || lam < 0.0 {
            return Err(format!("λ_{i} = {lam}"));
        }
        if nu == 0.0 {
            if p.b[i] > 0.0 {
                return Err(format!("zero row {i} with b > 0 but Optimal"));
            }
            continue;
        }
        let dist = (dot(&p.a[i], &s.x) - p.b[i]) / nu;
        if dist < -ptol * scale {
            return Err(format!("row {i} violated: distance {dist:e}"));
        }
        let active = s.active >> i & 1 == 1;
        if !active && lam != 0.0 {
            return Err(format!("inactive row {i} has λ = {lam}"));
        }
        if active && dist.abs() > ptol * scale {
            return Err(format!("active row {i} off its boundary by {dist:e}"));
        }
        if lam * nu * dist.abs() > ptol * scale * scale.max(terms) {
            return Err(format!(
                "complementarity row {i}: λ‖a‖ = {} d = {dist:e}",
                lam * nu
            ));
        }
        for k in 0..M {
            stat[k] -= lam * p.a[i][k];
        }
    }
    let r = inf(&stat);
    if r.is_nan() || r > tol * scale.max(terms) {
        return Err(format!(
            "stationarity residual {r:e} (scale {scale:e}, Σ λ̂ {terms:e})"
        ));
    }
    Ok(())
}

/// Farkas certificate check: `y ≥ 0`, `‖Σ y_i a_i‖ ≤ tol · Σ y_i ‖a_i‖` and
/// `Σ y_i b_i > 0` (strictly, and above the rounding level of the sum).
pub fn check_certificate(p: &Problem, y: &[f64], tol: f64) -> Result<(), String> {
    let mut ay = vec![0.0; p.m];
    let mut yb = 0.0;
    let mut mass = 0.0;
    let mut bmass = 0.0;
    for i in 0..p.n() {
        if y[i].is_nan() || y[i] < 0.0 {
            return Err(format!("y_{i} = {}", y[i]));
        }
        for k in 0..p.m {
            ay[k] += y[i] * p.a[i][k];
        }
        yb += y[i] * p.b[i];
        mass += y[i] * p.row_norm(i);
        bmass += (y[i] * p.b[i]).abs();
    }
    for (i, &v) in y.iter().enumerate().skip(p.n()) {
        if v != 0.0 {
            return Err(format!("y_{i} = {v} beyond n"));
        }
    }
    if mass == 0.0 && yb <= 0.0 {
        return Err("empty certificate".into());
    }
    let r = norm(&ay);
    if r.is_nan() || r > tol * mass.max(f64::MIN_POSITIVE) {
        return Err(format!("‖Aᵀy‖ = {r:e} (Σ y‖a‖ = {mass:e})"));
    }
    if yb.is_nan() || yb <= 1e-12 * bmass || yb <= 0.0 {
        return Err(format!("bᵀy = {yb:e} not positive (Σ|y b| = {bmass:e})"));
    }
    Ok(())
}

/// LP-dual optimality of `lv.t` for `min t s.t. a x + w t ≥ b, t ≥ 0`: `y ≥ 0`,
/// `Σ y a ≈ 0`, and either `t = 0` (with `y = 0`) or `Σ y w = 1`, `Σ y b = t`.
pub fn check_lp_dual<const N: usize>(
    p: &Problem,
    lv: &LeastViolation<N>,
    tol: f64,
) -> Result<(), String> {
    if lv.status != Status::Optimal {
        return Err(format!("status {:?}", lv.status));
    }
    if lv.t.is_nan() || lv.t < 0.0 {
        return Err(format!("t = {}", lv.t));
    }
    let mut ay = vec![0.0; p.m];
    let (mut yw, mut yb, mut mass) = (0.0, 0.0, 0.0);
    for i in 0..p.n() {
        let y = lv.dual[i];
        if y.is_nan() || y < 0.0 {
            return Err(format!("dual y_{i} = {y}"));
        }
        for k in 0..p.m {
            ay[k] += y * p.a[i][k];
        }
        yw += y * p.w[i];
        yb += y * p.b[i];
        mass += y * (p.row_norm(i) + p.w[i]);
    }
    if lv.t == 0.0 {
        return if mass == 0.0 {
            Ok(())
        } else {
            Err("t = 0 with a nonzero dual".into())
        };
    }
    if (yw - 1.0).abs() > tol {
        return Err(format!("Σ y w = {yw}"));
    }
    if norm(&ay) > tol * mass {
        return Err(format!("‖Σ y a‖ = {:e}", norm(&ay)));
    }
    if (yb - lv.t).abs() > tol * lv.t.max(1.0) {
        return Err(format!("Σ y b = {yb} vs t = {}", lv.t));
    }
    Ok(())
}

/// A feasible random problem: a feasible point `xf`, rows with random normals (of random
/// scale when `wild`), some through `xf`, the input box `±x_j ≥ −limit`, and `x0` pushed out
/// so that several rows are active. `n_rows` random rows plus `2M` box rows.
pub fn random_feasible(rng: &mut Rng, m: usize, n_rows: usize, wild: bool) -> Problem {
    let limit = rng.range(1.0, 10.0);
    let xf: Vec<f64> = (0..m).map(|_| rng.range(-0.8, 0.8) * limit).collect();
    let dir = rng.vec(m);
    let push = rng.range(0.5, 20.0) * limit / norm(&dir);
    let x0: Vec<f64> = (0..m).map(|k| xf[k] + push * dir[k]).collect();
    let mut p = Problem::new(x0);
    for _ in 0..n_rows {
        let mut a = rng.vec(m);
        // many rows facing x0 so they bind
        if dot(&a, &dir) > 0.0 && rng.chance(0.7) {
            a.iter_mut().for_each(|v| *v = -*v);
        }
        let sc = if wild {
            10f64.powf(rng.range(-6.0, 6.0))
        } else {
            rng.range(0.2, 5.0)
        };
        a.iter_mut().for_each(|v| *v *= sc);
        let slack = if rng.chance(0.25) {
            0.0
        } else {
            rng.range(0.0, 2.0) * limit
        };
        let b = dot(&a, &xf) - slack * norm(&a);
        p.row(a, b);
    }
    p.boxed(limit);
    p.shuffle(rng);
    p
}

/// 1-norm condition number of the Gram matrix `ÂÂᵀ` of the unit-scaled rows `rows`
/// (Gauss–Jordan with partial pivoting; ∞ when singular).
pub fn gram_cond(p: &Problem, rows: &[usize]) -> f64 {
    let q = rows.len();
    if q == 0 {
        return 1.0;
    }
    let unit: Vec<Vec<f64>> = rows
        .iter()
        .map(|&i| p.a[i].iter().map(|v| v / p.row_norm(i)).collect())
        .collect();
    let g: Vec<Vec<f64>> = (0..q)
        .map(|i| (0..q).map(|j| dot(&unit[i], &unit[j])).collect())
        .collect();
    let norm1 = |m: &Vec<Vec<f64>>| {
        (0..q)
            .map(|j| (0..q).map(|i| m[i][j].abs()).sum::<f64>())
            .fold(0.0f64, f64::max)
    };
    let mut a = g.clone();
    let mut inv: Vec<Vec<f64>> = (0..q)
        .map(|i| (0..q).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect();
    for c in 0..q {
        let piv = (c..q)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        if a[piv][c].abs() < 1e-300 {
            return f64::INFINITY;
        }
        a.swap(c, piv);
        inv.swap(c, piv);
        let d = a[c][c];
        for j in 0..q {
            a[c][j] /= d;
            inv[c][j] /= d;
        }
        for i in 0..q {
            if i != c {
                let f = a[i][c];
                for j in 0..q {
                    a[i][j] -= f * a[c][j];
                    inv[i][j] -= f * inv[c][j];
                }
            }
        }
    }
    norm1(&g) * norm1(&inv)
}

/// Hard box and a few hard rows (feasible at `xf`), soft rows with weights 10^U(−1, 1); in
/// most cases the soft rows are contradictory (normals summing to zero), so `t* > 0`.
pub fn random_lv(rng: &mut Rng, m: usize, soft: usize, hard: usize, contradict: bool) -> Problem {
    let limit = rng.range(1.0, 10.0);
    let xf: Vec<f64> = (0..m).map(|_| rng.range(-0.8, 0.8) * limit).collect();
    let mut p = Problem::new(rng.vec(m).iter().map(|v| v * 3.0 * limit).collect());
    p.boxed(limit);
    for _ in 0..hard {
        let a = rng.vec(m);
        let b = dot(&a, &xf) - rng.range(0.0, 1.0) * norm(&a);
        p.row(a, b);
    }
    let c: Vec<f64> = (0..m).map(|_| rng.range(-2.0, 2.0) * limit).collect();
    let mut sum = vec![0.0; m];
    for k in 0..soft {
        let a = if contradict && k + 1 == soft {
            sum.iter().map(|v: &f64| -v).collect()
        } else {
            rng.vec(m)
        };
        for j in 0..m {
            sum[j] += a[j];
        }
        let sc = rng.range(0.1, 10.0);
        let a: Vec<f64> = a.iter().map(|v| v * sc).collect();
        let b = dot(&a, &c) + rng.range(-0.5, 1.0) * norm(&a);
        let w = 10f64.powf(rng.range(-1.0, 1.0));
        p.row_w(a, b, w);
    }
    p.shuffle(rng);
    p
}

/// Property-test cases: 300, or `PROPTEST_CASES` from the environment (for longer runs).
pub fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300)
}
