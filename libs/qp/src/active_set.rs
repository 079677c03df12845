//! The Goldfarb–Idnani dual active-set projection solver (see the crate docs).

use crate::{Settings, Solution, Status, dot, inf_norm};

/// Outcome of the core iteration on the scaled data held in the workspace.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Core {
    Optimal,
    /// `y` holds an (unnormalised) certificate in the scaled rows.
    Infeasible,
    IterationLimit,
}

/// One step's directions for a violated row `p` (Goldfarb–Idnani step 2).
struct Direction<const M: usize> {
    /// `Jᵀ â_p`.
    d: [f64; M],
    /// The primal direction `J₂J₂ᵀ â_p` (in the null space of the active rows).
    z: [f64; M],
    /// `‖z‖²`.
    zz: f64,
    /// The dual direction `R⁻¹ J₁ᵀ â_p` (entries `0..q`).
    r: [f64; M],
    /// Entries of `r` at or below this are zero.
    rtol: f64,
}

/// Dual active-set solver for `min ½‖x − x0‖²  s.t.  a_i·x ≥ b_i` with `x ∈ ℝᴹ` and at most
/// `N ≤ 128` rows. All workspace is inside the struct: build it once, call
/// [`solve`](Self::solve) every control step; no call allocates.
#[derive(Debug, Clone)]
pub struct ActiveSetQp<const M: usize, const N: usize> {
    pub(crate) settings: Settings,
    // ---- the scaled problem ----
    /// Unit rows `â_i = a_i / ‖a_i‖` (zero for zero rows).
    pub(crate) an: [[f64; M]; N],
    /// Row norms `‖a_i‖` (0 for zero rows).
    pub(crate) nu: [f64; N],
    /// The same rows by columns (`at[k][i] = an[i][k]`), for the row scan.
    at: [[f64; N]; M],
    /// Slacks of the last row scan.
    slack: [f64; N],
    /// `b_i / ‖a_i‖` (raw `b_i` for zero rows).
    pub(crate) bn: [f64; N],
    /// `w_i / ‖a_i‖` (raw `w_i` for zero rows); least-violation only.
    pub(crate) wn: [f64; N],
    /// Right-hand side the core iteration works on (scaled rows).
    pub(crate) rhs: [f64; N],
    /// Bit `i`: row `i` is a zero row (never enters the iteration).
    pub(crate) zero: u128,
    /// The caller's rows of the last [`prepare`](Self::prepare), for reuse: a row equal
    /// (bit for bit) to the one before keeps its scaling, only `b` and `w` are rescaled.
    raw: [[f64; M]; N],
    /// `1/‖a_i‖` of `raw[i]` when its scaling may be reused (0: scale again).
    inv: [f64; N],
    /// Rows in use.
    pub(crate) n: usize,
    // ---- the factorisation of the active rows: [â_act[0] … â_act[q−1]] = J[:, ..q] R ----
    /// `J` by columns: `jc[k]` is column `k` (orthogonal `M×M`).
    jc: [[f64; M]; M],
    /// `R` by columns: `rc[k][i] = R(i, k)`, upper triangular `q×q`, positive diagonal.
    rc: [[f64; M]; M],
    /// Row index of each active column.
    act: [usize; M],
    /// Multipliers of the active rows (scaled rows).
    u: [f64; M],
    /// Number of active rows.
    q: usize,
    /// Bit `i`: row `i` is active.
    mask: u128,
    /// Current iterate.
    x: [f64; M],
    /// Certificate in the scaled rows (valid after `Core::Infeasible`).
    pub(crate) y: [f64; N],
    /// Active-set changes in the last core iteration.
    pub(crate) iterations: u32,
}

impl<const M: usize, const N: usize> ActiveSetQp<M, N> {
    /// The active set is a bit mask in a `u128`.
    const SIZE_OK: () = assert!(N <= 128, "ActiveSetQp supports at most 128 rows");

    /// A solver with its workspace for problems of `M` variables and up to `N` rows.
    pub fn new(settings: Settings) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::SIZE_OK;
        Self {
            settings,
            an: [[0.0; M]; N],
            at: [[0.0; N]; M],
            slack: [0.0; N],
            nu: [0.0; N],
            bn: [0.0; N],
            wn: [0.0; N],
            rhs: [0.0; N],
            zero: 0,
            raw: [[0.0; M]; N],
            inv: [0.0; N],
            n: 0,
            jc: [[0.0; M]; M],
            rc: [[0.0; M]; M],
            act: [0; M],
            u: [0.0; M],
            q: 0,
            mask: 0,
            x: [0.0; M],
            y: [0.0; N],
            iterations: 0,
        }
    }

    /// The settings in use.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Projects `x0` onto `{x : a_i·x ≥ b_i, i < n}`; rows `n..N` of `a` and `b` are ignored.
    ///
    /// Never panics and never allocates; see [`Solution`] for the outputs and [`Status`] for
    /// the outcomes.
    pub fn solve(
        &mut self,
        x0: &[f64; M],
        a: &[[f64; M]; N],
        b: &[f64; N],
        n: usize,
    ) -> Solution<M, N> {
        if n > N || !x0.iter().all(|v| v.is_finite()) || !self.prepare(a, b, None, n) {
            return Solution::empty(Status::InvalidInput, *x0);
        }
        for i in 0..n {
            if self.zero >> i & 1 == 1 && self.bn[i] > 0.0 {
                let mut s = Solution::empty(Status::Infeasible, *x0);
                s.certificate[i] = 1.0;
                return s;
            }
        }
        self.rhs[..n].copy_from_slice(&self.bn[..n]);
        let c = self.core(x0, self.max_iterations(), false);
        self.solution(c)
    }

    pub(crate) fn max_iterations(&self) -> u32 {
        self.settings
            .max_iterations
            .unwrap_or(10 * (self.n + M) as u32)
    }

    /// Scales rows `0..n` to unit norm into the workspace. `false` for non-finite data (or
    /// data that overflows when scaled) and negative weights.
    pub(crate) fn prepare(
        &mut self,
        a: &[[f64; M]; N],
        b: &[f64; N],
        w: Option<&[f64; N]>,
        n: usize,
    ) -> bool {
        self.n = n;
        self.zero = 0;
        for i in 0..n {
            let wi = w.map_or(0.0, |w| w[i]);
            if !b[i].is_finite() || !wi.is_finite() || wi < 0.0 {
                return false;
            }
            if !self.prepare_row(i, &a[i], b[i], wi) {
                return false;
            }
        }
        true
    }

    /// Scales row `i` (`a_i·x ≥ b_i`, weight `w_i`) into the workspace, reusing its
    /// scaling when the row is the one of the last call. `false` for non-finite data or
    /// data that overflows when scaled.
    #[inline(always)]
    fn prepare_row(&mut self, i: usize, row: &[f64; M], bi: f64, wi: f64) -> bool {
        if self.inv[i] > 0.0 && same_bits(row, &self.raw[i]) {
            // the same row as last time: its unit row and norm are in place; the
            // right-hand side and weight scale exactly as in `scale_row`
            let inv = self.inv[i];
            self.bn[i] = bi * inv;
            self.wn[i] = wi * inv;
            return self.bn[i].is_finite() && self.wn[i].is_finite();
        }
        self.inv[i] = 0.0;
        if !row.iter().all(|v| v.is_finite()) {
            return false;
        }
        let m = inf_norm(row);
        if m == 0.0 {
            self.zero |= 1 << i;
            self.an[i] = [0.0; M];
            for k in 0..M {
                self.at[k][i] = 0.0;
            }
            self.nu[i] = 0.0;
            self.bn[i] = bi;
            self.wn[i] = wi;
            return true;
        }
        if (1e-100..=1e100).contains(&m) {
            self.scale_row(i, row, bi, wi);
        } else {
            self.scale_row_extreme(i, row, m, bi, wi);
        }
        if !self.nu[i].is_finite() || !self.bn[i].is_finite() || !self.wn[i].is_finite() {
            self.inv[i] = 0.0;
            return false;
        }
        true
    }

    /// Row `i` to unit norm when its largest entry `m` lies in `[1e-100, 1e100]`: the
    /// squares can neither overflow nor underflow to a wrong norm. The scaling is kept
    /// for reuse when finite.
    #[inline(always)]
    fn scale_row(&mut self, i: usize, row: &[f64; M], bi: f64, wi: f64) {
        let mut s = 0.0;
        for &v in row {
            s += v * v;
        }
        let nu = s.sqrt();
        let inv = 1.0 / nu;
        for k in 0..M {
            self.an[i][k] = row[k] * inv;
            self.at[k][i] = self.an[i][k];
        }
        self.nu[i] = nu;
        self.bn[i] = bi * inv;
        self.wn[i] = wi * inv;
        if inv.is_finite() && nu.is_finite() {
            self.raw[i] = *row;
            self.inv[i] = inv;
        }
    }

    /// Row `i` to unit norm when its largest entry `m` is huge or tiny: `‖a‖ = m·h` with
    /// `h = ‖a/m‖ ∈ [1, √M]`, no overflow or underflow.
    #[inline(always)]
    fn scale_row_extreme(&mut self, i: usize, row: &[f64; M], m: f64, bi: f64, wi: f64) {
        let mut s = 0.0;
        for &v in row {
            let v = v / m;
            s += v * v;
        }
        let h = s.sqrt();
        for k in 0..M {
            self.an[i][k] = (row[k] / m) / h;
            self.at[k][i] = self.an[i][k];
        }
        self.nu[i] = m * h;
        self.bn[i] = (bi / m) / h;
        self.wn[i] = (wi / m) / h;
    }

    /// The dual active-set iteration from `x0` on `an`, `rhs` (rows `0..n`, zero rows
    /// skipped).
    ///
    /// With `warm`, the iteration starts from the active set left by the previous call
    /// (on the same rows, with another right-hand side): see [`warm_start`](Self::warm_start).
    pub(crate) fn core(&mut self, x0: &[f64; M], max_iter: u32, warm: bool) -> Core {
        self.iterations = 0;
        if warm {
            self.warm_start(x0);
        } else {
            self.cold_start(x0);
        }
        // The iterate carries the rounding of the steps that brought it from x0: a few ulps
        // of ‖x0‖ (however far x0 is), on top of the relative tolerance of the rows.
        let x0_noise = 64.0 * f64::EPSILON * inf_norm(x0);
        // Rows found to be violated only by rounding (dependent on the active rows, and the
        // data say they hold): not picked again until the active set grows.
        let mut noise: u128 = 0;
        // `tight`: the loose test has passed once and x was refined; from then on rows are
        // tested against the refined point's own rounding. `fresh`: refined, no step since.
        let (mut tight, mut fresh) = (false, false);
        loop {
            // Step 1: the most violated row (distances: the rows have unit norm).
            let p = self.most_violated(self.zero | self.mask | noise, x0_noise, tight);
            if p == usize::MAX {
                if fresh {
                    return Core::Optimal;
                }
                self.refine(x0);
                tight = true;
                fresh = true;
                continue;
            }
            fresh = false;
            // Step 2: move towards satisfying row p, dropping blocking rows on the way.
            if let Some(end) = self.satisfy(p, max_iter, &mut noise) {
                return end;
            }
        }
    }

    /// The start without an active set: `x = x0`, `J = I`, `R` empty.
    #[inline(always)]
    fn cold_start(&mut self, x0: &[f64; M]) {
        self.q = 0;
        self.mask = 0;
        self.x = *x0;
        for k in 0..M {
            self.jc[k] = [0.0; M];
            self.jc[k][k] = 1.0;
            self.rc[k] = [0.0; M];
        }
    }

    /// Step 2 of the iteration for the violated row `p`: full or partial steps until `p`
    /// joins the active set (`None`, `noise` cleared), or `p` is found to hold up to
    /// rounding (`None`, `p` added to `noise`), or the iteration ends (`Some`: the rows are
    /// infeasible, or the iteration limit is reached).
    #[inline(always)]
    fn satisfy(&mut self, p: usize, max_iter: u32, noise: &mut u128) -> Option<Core> {
        // the multiplier row p has gathered so far
        let mut up = 0.0;
        loop {
            if self.iterations >= max_iter {
                return Some(Core::IterationLimit);
            }
            self.iterations += 1;
            let q = self.q;
            let dir = self.step_direction(p);
            let (t1, kdrop) = self.dual_step(&dir.r, dir.rtol);
            let t2 = if dir.zz.sqrt() > self.settings.dependence_tol {
                let sp = dot(&self.an[p], &self.x) - self.rhs[p];
                -sp / dir.zz
            } else {
                f64::INFINITY
            };
            if kdrop == usize::MAX && t2 == f64::INFINITY {
                if self.dependent_row_fails(p, &dir.r, dir.rtol) {
                    return Some(Core::Infeasible);
                }
                // Row p holds up to rounding: fold the multiplier it gathered into the
                // active rows it depends on (â_p = Σ r_j â_j) and set it aside.
                for j in 0..q {
                    self.u[j] = (self.u[j] + up * dir.r[j]).max(0.0);
                }
                *noise |= 1 << p;
                return None;
            }
            let t = t1.min(t2);
            if t2 != f64::INFINITY {
                for i in 0..M {
                    self.x[i] += t * dir.z[i];
                }
            }
            for j in 0..q {
                self.u[j] = (self.u[j] - t * dir.r[j]).max(0.0);
            }
            up += t;
            if t2 <= t1 {
                self.add(p, dir.d, up);
                *noise = 0;
                return None;
            }
            self.u[kdrop] = 0.0;
            self.drop(kdrop);
        }
    }

    /// The step direction for row `p`: `d = Jᵀ â_p`, the primal direction
    /// `z = J₂J₂ᵀ â_p` with `‖z‖² = Σ_{k≥q} d_k²`, and the dual direction `r = R⁻¹ J₁ᵀ â_p`
    /// with its tolerance.
    #[inline(always)]
    fn step_direction(&self, p: usize) -> Direction<M> {
        let q = self.q;
        let mut d = [0.0; M];
        for (k, dk) in d.iter_mut().enumerate() {
            *dk = dot(&self.jc[k], &self.an[p]);
        }
        let mut z = [0.0; M];
        let mut zz = 0.0;
        for k in q..M {
            zz += d[k] * d[k];
            for i in 0..M {
                z[i] += d[k] * self.jc[k][i];
            }
        }
        let mut r = d;
        self.r_solve(&mut r);
        let rtol = self.settings.dual_tol * (1.0 + inf_norm(&r[..q]));
        Direction { d, z, zz, r, rtol }
    }

    /// The longest dual step `t1 = min u_j / r_j` over `r_j > rtol` and the active
    /// position that blocks it (`usize::MAX` and `∞` if none).
    #[inline(always)]
    fn dual_step(&self, r: &[f64; M], rtol: f64) -> (f64, usize) {
        let mut t1 = f64::INFINITY;
        let mut kdrop = usize::MAX;
        for j in 0..self.q {
            if r[j] > rtol {
                let ratio = self.u[j] / r[j];
                if ratio < t1 {
                    t1 = ratio;
                    kdrop = j;
                }
            }
        }
        (t1, kdrop)
    }

    /// Row `p` depends on the active rows with no blocking row: `â_p = Σ r_j â_j` with
    /// `r ≤ 0`, so `y = e_p − Σ r_j e_j ≥ 0` has `Σ y_i â_i ≈ 0` and, the active rows being
    /// tight, `s_p = −Σ y_i b̂_i`. Decides from the data (free of the iterate's rounding)
    /// whether row p really fails; if so `y` holds the certificate.
    ///
    /// Entries of r within the dual tolerance are zero (as for the steps): rounding noise
    /// must not put weight on a row (for the least-violation iteration, noise on a soft
    /// row would fake `Σ y_i w_i > 0`).
    #[inline(always)]
    fn dependent_row_fails(&mut self, p: usize, r: &[f64; M], rtol: f64) -> bool {
        let q = self.q;
        let yj = |rj: f64| if -rj > rtol { -rj } else { 0.0 };
        let mut yb = self.rhs[p];
        let mut mag = self.rhs[p].abs();
        for j in 0..q {
            yb += yj(r[j]) * self.rhs[self.act[j]];
            mag += yj(r[j]) * self.rhs[self.act[j]].abs();
        }
        if yb > self.settings.primal_tol * mag {
            self.y[..self.n].fill(0.0);
            self.y[p] = 1.0;
            for j in 0..q {
                self.y[self.act[j]] = yj(r[j]);
            }
            return true;
        }
        false
    }

    /// A dual-feasible start from the current active set for the current right-hand side:
    /// the minimiser with the active rows as equalities has multipliers
    /// `RᵀR λ̂ = b̂_A − Â x0`; while one is negative the most negative row is dropped (each
    /// counted as an iteration). The result — the equality-constrained minimiser with
    /// `λ̂ ≥ 0` — is the minimiser on its active set, which is all the method needs.
    fn warm_start(&mut self, x0: &[f64; M]) {
        loop {
            let q = self.q;
            let mut lam = [0.0; M];
            for j in 0..q {
                let i = self.act[j];
                lam[j] = self.rhs[i] - dot(&self.an[i], x0);
            }
            self.rt_solve(&mut lam);
            self.r_solve(&mut lam);
            let mut jmin = usize::MAX;
            let mut vmin = 0.0;
            for j in 0..q {
                if lam[j] < vmin {
                    vmin = lam[j];
                    jmin = j;
                }
            }
            if jmin == usize::MAX {
                self.x = *x0;
                for j in 0..q {
                    self.u[j] = lam[j];
                    let row = &self.an[self.act[j]];
                    for k in 0..M {
                        self.x[k] += lam[j] * row[k];
                    }
                }
                return;
            }
            self.iterations += 1;
            self.drop(jmin);
        }
    }

    /// The row with the most negative distance among those violated beyond tolerance, not
    /// in `skip`; `usize::MAX` if none.
    ///
    /// Loose test (while iterating): `s_i < −(primal_tol · max(|b̂_i|, ‖x‖∞) + x0_noise)`,
    /// covering the rounding the iterate gathered on its way from `x0`. Tight test (after
    /// [`refine`](Self::refine)): the refined point's rounding from a far `x0` lies in the
    /// null space of the active rows only, so the `x0` term is scaled by `‖J₂ᵀ â_i‖`, the
    /// row's component in that null space (zero when `M` rows are active).
    fn most_violated(&mut self, skip: u128, x0_noise: f64, tight: bool) -> usize {
        let ptol = self.settings.primal_tol;
        let sx = inf_norm(&self.x);
        let n = self.n;
        // slacks of all rows, by columns (vectorises across rows); the same summation
        // order as `dot`
        let slack = &mut self.slack[..n];
        slack.fill(0.0);
        for k in 0..M {
            let xk = self.x[k];
            for (s, &a) in slack.iter_mut().zip(&self.at[k][..n]) {
                *s += a * xk;
            }
        }
        for (s, &r) in slack.iter_mut().zip(&self.rhs[..n]) {
            *s -= r;
        }
        let mut p = usize::MAX;
        let mut worst = 0.0;
        for i in 0..n {
            if skip >> i & 1 == 1 {
                continue;
            }
            let s = self.slack[i];
            let base = ptol * self.rhs[i].abs().max(sx);
            if s >= -base || (p != usize::MAX && s >= worst) {
                continue;
            }
            let violated = if s < -(base + x0_noise) {
                true
            } else if !tight {
                false
            } else {
                let mut nn = 0.0;
                for k in self.q..M {
                    let c = dot(&self.jc[k], &self.an[i]);
                    nn += c * c;
                }
                s < -(base + x0_noise * nn.sqrt())
            };
            if violated {
                p = i;
                worst = s;
            }
        }
        p
    }

    /// Appends row `p` (with `d = Jᵀ â_p`) to the factorisation.
    fn add(&mut self, p: usize, mut d: [f64; M], up: f64) {
        let q = self.q;
        // Rotate d[q..] into d[q], and J's columns along.
        for k in (q + 1..M).rev() {
            let Some((c, s, h)) = givens(d[k - 1], d[k]) else {
                continue;
            };
            d[k - 1] = h;
            d[k] = 0.0;
            rotate_columns(&mut self.jc, k - 1, k, c, s);
        }
        if d[q] < 0.0 {
            d[q] = -d[q];
            for v in self.jc[q].iter_mut() {
                *v = -*v;
            }
        }
        self.rc[q] = [0.0; M];
        self.rc[q][..=q].copy_from_slice(&d[..=q]);
        self.act[q] = p;
        self.u[q] = up;
        self.mask |= 1 << p;
        self.q = q + 1;
    }

    /// Removes the active row at position `l` and restores `R` to triangular form.
    fn drop(&mut self, l: usize) {
        let q = self.q;
        self.mask &= !(1u128 << self.act[l]);
        for k in l..q - 1 {
            self.rc[k] = self.rc[k + 1];
            self.act[k] = self.act[k + 1];
            self.u[k] = self.u[k + 1];
        }
        self.rc[q - 1] = [0.0; M];
        // Columns l..q−2 are Hessenberg now: zero their sub-diagonal by rotations of rows
        // (k, k+1) of R, applied to columns (k, k+1) of J so that J R is unchanged.
        for k in l..q - 1 {
            let Some((c, s, _)) = givens(self.rc[k][k], self.rc[k][k + 1]) else {
                self.rc[k][k + 1] = 0.0;
                continue;
            };
            for col in k..q - 1 {
                let (x, y) = (self.rc[col][k], self.rc[col][k + 1]);
                self.rc[col][k] = c * x + s * y;
                self.rc[col][k + 1] = -s * x + c * y;
            }
            self.rc[k][k + 1] = 0.0;
            rotate_columns(&mut self.jc, k, k + 1, c, s);
        }
        // (The rotated diagonal entries are hypotenuses, so R keeps a positive diagonal.)
        self.q = q - 1;
    }

    /// `v[..q] ← R⁻¹ v[..q]`.
    fn r_solve(&self, v: &mut [f64; M]) {
        for i in (0..self.q).rev() {
            let mut s = v[i];
            for k in i + 1..self.q {
                s -= self.rc[k][i] * v[k];
            }
            v[i] = s / self.rc[i][i];
        }
    }

    /// `v[..q] ← R⁻ᵀ v[..q]`.
    fn rt_solve(&self, v: &mut [f64; M]) {
        for i in 0..self.q {
            let mut s = v[i];
            for k in 0..i {
                s -= self.rc[i][k] * v[k];
            }
            v[i] = s / self.rc[i][i];
        }
    }

    /// Worst error of `x` on the scaled rows: violation of any row, or distance from an
    /// active row's boundary.
    fn kkt_error(&self, x: &[f64; M]) -> f64 {
        let mut e = 0.0f64;
        for i in 0..self.n {
            if self.zero >> i & 1 == 1 {
                continue;
            }
            let s = dot(&self.an[i], x) - self.rhs[i];
            e = e.max(if self.mask >> i & 1 == 1 { s.abs() } else { -s });
        }
        e
    }

    /// Recomputes the multipliers and `x` of the final active set from its KKT system
    /// (`RᵀR λ̂ = b̂_A − Â x0`, `x = x0 + Âᵀλ̂`) with one step of iterative refinement, and
    /// keeps the result when it is at least as accurate as the iterated point.
    fn refine(&mut self, x0: &[f64; M]) {
        let q = self.q;
        if q == 0 && same_bits(&self.x, x0) {
            // no active row and the iterate is x0 itself: the refined point is x0 again
            return;
        }
        let mut lam = [0.0; M];
        for j in 0..q {
            let i = self.act[j];
            lam[j] = self.rhs[i] - dot(&self.an[i], x0);
        }
        self.rt_solve(&mut lam);
        self.r_solve(&mut lam);
        let mut xr = *x0;
        for j in 0..q {
            let row = &self.an[self.act[j]];
            for k in 0..M {
                xr[k] += lam[j] * row[k];
            }
        }
        let mut dl = [0.0; M];
        for j in 0..q {
            let i = self.act[j];
            dl[j] = self.rhs[i] - dot(&self.an[i], &xr);
        }
        self.rt_solve(&mut dl);
        self.r_solve(&mut dl);
        for j in 0..q {
            lam[j] += dl[j];
            let row = &self.an[self.act[j]];
            for k in 0..M {
                xr[k] += dl[j] * row[k];
            }
        }
        if lam.iter().chain(xr.iter()).all(|v| v.is_finite())
            && self.kkt_error(&xr) <= self.kkt_error(&self.x)
        {
            self.x = xr;
            for j in 0..q {
                self.u[j] = lam[j].max(0.0);
            }
        }
    }

    /// Builds the caller-facing solution from the state after [`core`](Self::core).
    pub(crate) fn solution(&mut self, c: Core) -> Solution<M, N> {
        let mut s = Solution::empty(Status::Optimal, self.x);
        s.iterations = self.iterations;
        match c {
            Core::Optimal | Core::IterationLimit => {
                if c == Core::IterationLimit {
                    s.status = Status::IterationLimit;
                }
                s.x = self.x;
                for j in 0..self.q {
                    let i = self.act[j];
                    s.lambda[i] = self.u[j] / self.nu[i];
                }
                s.active = self.mask;
            }
            Core::Infeasible => {
                s.status = Status::Infeasible;
                self.certificate(&mut s.certificate);
            }
        }
        s
    }

    /// The certificate `y` of the last `Core::Infeasible` in the caller's scaling, with
    /// `Σ y_i ‖a_i‖ = 1`.
    pub(crate) fn certificate(&self, out: &mut [f64; N]) {
        let total: f64 = self.y[..self.n].iter().sum();
        for i in 0..self.n {
            out[i] = if self.y[i] > 0.0 {
                self.y[i] / total / self.nu[i]
            } else {
                0.0
            };
        }
    }
}

/// Bit-for-bit equality (so `-0.0 ≠ 0.0`; the cached rows never hold a NaN: a row with one
/// is refused before it is cached).
#[inline]
fn same_bits<const M: usize>(u: &[f64; M], v: &[f64; M]) -> bool {
    u.iter()
        .zip(v)
        .fold(true, |same, (x, y)| same & (x.to_bits() == y.to_bits()))
}

/// The rotation `(c, s)` with `c·a + s·b = h ≥ 0`, `−s·a + c·b = 0`; `None` when `b` is
/// negligible. Every entry rotated here is a coordinate of a unit vector (`|a|, |b| ≤ 1`),
/// so the squares cannot overflow; they underflow only when both entries are below
/// ~1e-154, where the rotation is skipped (its effect would be below rounding).
#[inline]
fn givens(a: f64, b: f64) -> Option<(f64, f64, f64)> {
    if b == 0.0 {
        return None;
    }
    let h = (a * a + b * b).sqrt();
    if h == 0.0 || !h.is_finite() {
        return None;
    }
    Some((a / h, b / h, h))
}

/// Columns `(k, l) ← (c·col_k + s·col_l, −s·col_k + c·col_l)`.
#[inline]
fn rotate_columns<const M: usize>(j: &mut [[f64; M]; M], k: usize, l: usize, c: f64, s: f64) {
    for i in 0..M {
        let (x, y) = (j[k][i], j[l][i]);
        j[k][i] = c * x + s * y;
        j[l][i] = -s * x + c * y;
    }
}
