//! The exact least-violation (phase-1) solver and the lexicographic problem, as a
//! parametric iteration on the projection solver (see the crate docs).

use crate::active_set::Core;
use crate::{ActiveSetQp, LeastViolation, Solution, Status};

impl<const M: usize, const N: usize> ActiveSetQp<M, N> {
    /// The least violation
    ///
    /// ```text
    /// t* = min t   s.t.   a_i·x + w_i t ≥ b_i  (i < n),   t ≥ 0
    /// ```
    ///
    /// with `w_i ≥ 0`: rows with `w_i = 0` are hard (e.g. input bounds), rows with `w_i > 0`
    /// soft with their weights. `t*` is exact (the ratio `Σ y_i b_i / Σ y_i w_i` of an
    /// optimal LP-dual point `y`, returned in [`LeastViolation::dual`]); the status is
    /// `Infeasible` only if the hard rows alone are infeasible. `t*` does not depend on any
    /// nominal point: the internal projections are those of the origin.
    pub fn least_violation(
        &mut self,
        a: &[[f64; M]; N],
        b: &[f64; N],
        w: &[f64; N],
        n: usize,
    ) -> LeastViolation<N> {
        let mut lv = LeastViolation {
            status: Status::InvalidInput,
            t: 0.0,
            dual: [0.0; N],
            certificate: [0.0; N],
            outer_iterations: 0,
            iterations: 0,
        };
        if n > N || !self.prepare(a, b, Some(w), n) {
            return lv;
        }
        // Zero rows: `0 ≥ b_i` (hard) or `w_i t ≥ b_i` (a lower bound on t).
        let mut t = 0.0;
        for i in 0..n {
            if self.zero >> i & 1 == 0 {
                continue;
            }
            let (bi, wi) = (self.bn[i], self.wn[i]);
            if wi == 0.0 {
                if bi > 0.0 {
                    lv.status = Status::Infeasible;
                    lv.certificate[i] = 1.0;
                    return lv;
                }
            } else if bi / wi > t {
                t = bi / wi;
                lv.dual = [0.0; N];
                lv.dual[i] = 1.0 / wi;
            }
        }
        self.parametric(&[0.0; M], t, false, &mut lv);
        lv
    }

    /// The lexicographic relaxed problem: first `t*` as in
    /// [`least_violation`](Self::least_violation), then the projection of `x0` onto
    /// `{x : a_i·x ≥ b_i − w_i t*}` (the point nearest `x0` among those with violation at
    /// most `t*`). The returned [`LeastViolation::t`] is the `t` of that second stage (equal
    /// to the first stage's unless rounding made `P(t*)` look empty, in which case it was
    /// raised by a certificate step, of the order of `primal_tol`). The solution's `lambda`
    /// are the multipliers of the rows `a_i·x ≥ b_i − w_i t`.
    pub fn lexicographic(
        &mut self,
        x0: &[f64; M],
        a: &[[f64; M]; N],
        b: &[f64; N],
        w: &[f64; N],
        n: usize,
    ) -> (LeastViolation<N>, Solution<M, N>) {
        if !x0.iter().all(|v| v.is_finite()) {
            let lv = LeastViolation {
                status: Status::InvalidInput,
                t: 0.0,
                dual: [0.0; N],
                certificate: [0.0; N],
                outer_iterations: 0,
                iterations: 0,
            };
            return (lv, Solution::empty(Status::InvalidInput, *x0));
        }
        let mut lv = self.least_violation(a, b, w, n);
        if lv.status != Status::Optimal {
            let mut s = Solution::empty(lv.status, *x0);
            s.certificate = lv.certificate;
            return (lv, s);
        }
        // Stage 2 starts cold: its x is then exactly the projection `solve` would compute
        // on P(t*), independent of the path the first stage took.
        let c = self.parametric(x0, lv.t, false, &mut lv);
        let mut s = self.solution(c);
        if lv.status == Status::Infeasible {
            s.certificate = lv.certificate;
        }
        (lv, s)
    }

    /// From `t`, project `x0` onto `P(t)`; while it is empty, raise `t` to the lower bound
    /// given by the Farkas certificate. Leaves the workspace in the state of the last
    /// projection.
    ///
    /// Each projection after the first starts warm from the previous one's active set (the
    /// rows are the same, only the right-hand side moves); `warm` says whether the first
    /// one may start from the state the workspace holds.
    fn parametric(
        &mut self,
        x0: &[f64; M],
        mut t: f64,
        mut warm: bool,
        lv: &mut LeastViolation<N>,
    ) -> Core {
        let n = self.n;
        let max_outer = self
            .settings
            .max_outer_iterations
            .unwrap_or(2 * (n + M) as u32 + 4);
        let max_iter = self.max_iterations();
        loop {
            if lv.outer_iterations >= max_outer {
                lv.status = Status::IterationLimit;
                lv.t = t;
                return Core::IterationLimit;
            }
            lv.outer_iterations += 1;
            self.relax_rhs(t);
            let c = self.core(x0, max_iter, warm);
            warm = true;
            lv.iterations += self.iterations;
            match c {
                Core::Optimal => {
                    lv.status = Status::Optimal;
                    lv.t = t;
                    return c;
                }
                Core::IterationLimit => {
                    lv.status = Status::IterationLimit;
                    lv.t = t;
                    return c;
                }
                Core::Infeasible => {}
            }
            match self.raise_t(t, lv) {
                Ok(tn) => t = tn,
                Err(end) => return end,
            }
        }
    }

    /// The right-hand side of `P(t)`: `b̂_i − ŵ_i t` (0 for zero rows).
    #[inline(always)]
    fn relax_rhs(&mut self, t: f64) {
        for i in 0..self.n {
            self.rhs[i] = if self.zero >> i & 1 == 1 {
                0.0
            } else {
                self.bn[i] - self.wn[i] * t
            };
        }
    }

    /// After `P(t)` was found empty: the lower bound on `t` from the Farkas certificate `y`
    /// (with the LP-dual point in `lv.dual`), or the end of the iteration (`Err`, with
    /// `lv`'s status set): the hard rows alone are infeasible, or the bound is not finite.
    #[inline(always)]
    fn raise_t(&mut self, t: f64, lv: &mut LeastViolation<N>) -> Result<f64, Core> {
        let n = self.n;
        // Σ y_i (â_i·x + ŵ_i t') ≥ Σ y_i b̂_i with Σ y_i â_i = 0  ⇒  t' ≥ yᵀb̂ / yᵀŵ.
        let (mut yw, mut yb, mut yr) = (0.0, 0.0, 0.0);
        for i in 0..n {
            yw += self.y[i] * self.wn[i];
            yb += self.y[i] * self.bn[i];
            yr += self.y[i] * self.rhs[i];
        }
        if yw <= 0.0 {
            // Only hard rows in the certificate: the hard rows alone are infeasible.
            lv.status = Status::Infeasible;
            lv.t = t;
            lv.dual = [0.0; N];
            self.certificate(&mut lv.certificate);
            return Err(Core::Infeasible);
        }
        let mut tn = yb / yw;
        if tn.partial_cmp(&t) != Some(core::cmp::Ordering::Greater) {
            // Rounding in yᵀb̂: the same bound from the current residual instead.
            tn = t + yr / yw;
            if tn.partial_cmp(&t) != Some(core::cmp::Ordering::Greater) {
                tn = t.next_up();
            }
        }
        if !tn.is_finite() {
            lv.status = Status::IterationLimit;
            lv.t = t;
            return Err(Core::IterationLimit);
        }
        for i in 0..n {
            lv.dual[i] = if self.y[i] > 0.0 {
                self.y[i] / yw / self.nu[i]
            } else {
                0.0
            };
        }
        Ok(tn)
    }
}
