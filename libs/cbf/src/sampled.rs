//! Sampled-data barrier rows: conditions that hold **between** samples under a
//! zero-order hold of length `T`, not only at the sampling instants.
//!
//! The paper's conditions (eqs. "CBF rel deg 1" and "CBF rel deg 2") constrain the
//! derivative at the sample only; under a held input the state drifts inside the sample
//! and ε is the only margin. Here every row is derived from a one-sample prediction with
//! bounds on how much the barrier's highest derivative can change inside the sample
//! (after Breeden & Panagou, "Autonomous Spacecraft Attitude Reorientation Using Robust
//! Sampled-Data CBFs", JGCD 46(10), 2023). docs/SAFETY.md has the derivation; in short:
//!
//! **Relative degree two** (`ḧ = a + b·u` at the sample, the paper's position-level
//! barriers). With `φ = a + b·u` the true `ḧ(t_k + s)` stays in
//! `[φ − M₂ − M₃ s, φ + M₂ + M₃ s]` for `s ∈ [0, T]`, where `M₂` bounds what the model does
//! not know at the sample (e.g. a downstream subsystem's reaction) and `M₃` bounds the
//! rate of change of `ḧ` over everything reachable in one sample. Integrating the lower
//! bound gives `ḣ(s) ≥ v(s)`, `h(s) ≥ p(s)` and the row requires
//!
//! * (C1) `p(s) ≥ 0` for all `s ∈ [0, T]` — the barrier itself holds inside the sample;
//! * (C2) `H(p(T), v(T)) ≥ e^{−γT} H(h, ḣ)` with the paper's auxiliary (braking) barrier
//!   `H(h, ḣ) = h + |ḣ| ḣ / (2μ)` — the next sample is again in the braking-safe set, and
//!   `H` decays at most like the paper's `α(H) = γH` (or, far inside the set, like a
//!   steeper class-K function: [`Decay`]).
//!
//! `H` is increasing in both arguments and `p`, `v` increase with `φ`, so both become
//! `φ ≥ φ_req`: one affine row `b·u ≥ φ_req − a`. Unlike the paper's row (whose input
//! gain `|ḣ| ∂ḧ/∂u / μ` vanishes at `ḣ = 0`) its gain is `∂ḧ/∂u` itself. It is feasible
//! wherever the subsystem can brake the barrier at `φ = μ + M₂ + M₃T` (see
//! [`braking_requirement`]): that command keeps `p ≥ 0` and does not decrease `H`.
//!
//! **Relative degree one** (`ḣ = a + b·u`, the rate limits): with the true `ḣ` in
//! `[φ − D − J s, …]`, `h(T) ≥ h + (φ − D)T − ½JT²`, concave in `s`, so requiring the
//! exact discretisation of the paper's `ḣ ≥ −γh + ε` at `s = T` keeps `h ≥ 0` on the
//! whole sample: `φ ≥ D + ½JT + (e^{−γT}(h − ε/γ) + ε/γ − h)/T`.

use crate::barrier::Row;
use nalgebra::SVector;

/// The paper's auxiliary barrier `H = h + |ḣ| ḣ / (2μ)`.
pub fn braking_barrier(h: f64, hdot: f64, mu: f64) -> f64 {
    h + hdot.abs() * hdot / (2.0 * mu)
}

/// How much (C2) lets `H` decay in one sample: the discrete form of a class-K function
/// that is the paper's `α(H) = γH` up to a knee `H_k` and steeper above it,
/// `κ(H) = e^{−γT} min(H, H_k) + e^{−γ_in T} max(H − H_k, 0)`.
///
/// With `H_k = ∞` ([`Decay::linear`]) this is the paper's `e^{−γT} H`. For `γ_in ≥ γ ≥ 0`,
/// `κ(0) = 0`, `κ` is increasing and `κ(H) ≤ H` on `H ≥ 0`: the braking command (which
/// does not decrease `H`) still meets (C2), `{h ≥ 0, H ≥ 0}` stays invariant, and wherever
/// `H ≤ H_k` — everywhere near the boundary — the row is exactly the paper's. Above the
/// knee, far inside the set, `H` may fall faster: there a barrier whose input gain
/// vanishes (the line of sight near its cone's axis) need not be braked for a decay that
/// cannot threaten it (docs/SAFETY.md, "Line of sight").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decay {
    /// γ [1/s] of `α(H) = γH` below the knee (the paper's γ_h).
    pub gamma: f64,
    /// `H_k` [unit of h]; `f64::INFINITY`: no knee.
    pub knee: f64,
    /// γ_in [1/s] above the knee, `≥ γ`.
    pub gamma_inner: f64,
}

impl Decay {
    /// The paper's `α(H) = γH` everywhere.
    pub fn linear(gamma: f64) -> Self {
        Self {
            gamma,
            knee: f64::INFINITY,
            gamma_inner: gamma,
        }
    }

    /// `κ(H)` for a sample of length `t` [s].
    pub fn target(&self, big_h: f64, t: f64) -> f64 {
        self.at(t).target(big_h)
    }

    /// The decay over a sample of length `t` [s], its exponentials computed once (a
    /// filter builds dozens of rows with the same `γ` and `T`).
    pub fn at(&self, t: f64) -> DecayAt {
        let below = (-self.gamma * t).exp();
        DecayAt {
            below,
            // without a knee the inner factor is never used: one exponential, not two
            inner: if self.knee == f64::INFINITY {
                below
            } else {
                (-self.gamma_inner * t).exp()
            },
            knee: self.knee,
        }
    }
}

/// [`Decay`] for one sample length: `e^{−γT}`, `e^{−γ_in T}` and the knee.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecayAt {
    below: f64,
    inner: f64,
    knee: f64,
}

impl DecayAt {
    /// `κ(H) = e^{−γT} min(H, H_k) + e^{−γ_in T} max(H − H_k, 0)`.
    pub fn target(&self, big_h: f64) -> f64 {
        if big_h <= self.knee {
            self.below * big_h
        } else {
            self.below * self.knee + self.inner * (big_h - self.knee)
        }
    }
}

/// Bounds on the model's error inside one sample of a relative-degree-two barrier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleBounds {
    /// Sample length `T` [s].
    pub period: f64,
    /// `M₂`: bound on the part of `ḧ` unknown at the sample [unit of h / s²].
    pub m2: f64,
    /// `M₃`: bound on `|d ḧ / dt|` over one sample [unit of h / s³].
    pub m3: f64,
}

/// Terms of a relative-degree-two barrier at the sample: `h`, `ḣ`, and `ḧ = a + b·u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelDeg2<const M: usize> {
    pub h: f64,
    pub hdot: f64,
    /// `ḧ` at `u = 0` (drift, explicit time dependence, known coupling ξ).
    pub a: f64,
    /// `∂ḧ/∂u`.
    pub b: SVector<f64, M>,
}

/// Terms of a relative-degree-one barrier at the sample: `h` and `ḣ = a + b·u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelDeg1<const M: usize> {
    pub h: f64,
    pub a: f64,
    pub b: SVector<f64, M>,
}

impl<const M: usize> From<crate::barrier::RelDegTwo<M>> for RelDeg2<M> {
    fn from(t: crate::barrier::RelDegTwo<M>) -> Self {
        Self {
            h: t.h,
            hdot: t.hdot,
            a: t.hddot_drift,
            b: t.hddot_u,
        }
    }
}

impl<const M: usize> From<crate::barrier::RelDegOne<M>> for RelDeg1<M> {
    fn from(t: crate::barrier::RelDegOne<M>) -> Self {
        Self {
            h: t.h,
            a: t.hdot_drift,
            b: t.hdot_u,
        }
    }
}

/// Smallest `a` such that `h + ḣ s + ½ a s² ≥ 0` for all `s ∈ (0, T]`. For `h < 0`
/// (already outside) only the end of the sample is required (recover within one sample).
fn c1_requirement(h: f64, hdot: f64, t: f64) -> f64 {
    let a_end = -2.0 * (h + hdot * t) / (t * t);
    if h < 0.0 || hdot >= 0.0 || a_end <= 0.0 || -hdot / a_end >= t {
        return a_end;
    }
    if h == 0.0 {
        // h = 0 while decreasing: outside the braking set, nothing keeps h(s) ≥ 0 just
        // after the sample; require the end of the sample
        return a_end;
    }
    a_end.max(hdot * hdot / (2.0 * h))
}

/// Smallest `ψ = φ − M₂` with `H(P0 + ½T²ψ, V0 + Tψ) ≥ κ` (`H` increasing in `ψ`).
fn c2_requirement(p0: f64, v0: f64, t: f64, mu: f64, kappa: f64) -> f64 {
    // at v = 0 (ψ0 = −V0/T) H equals P0 − ½T V0
    let h_at_switch = p0 - 0.5 * t * v0;
    let c = h_at_switch - kappa;
    let half_t = 0.5 * t;
    let w = if c <= 0.0 {
        // root on the v ≥ 0 branch: w²/(2μ) + (T/2) w + c = 0, w ≥ 0
        let d = -2.0 * c / mu;
        mu * d / (half_t + (half_t * half_t + d).sqrt())
    } else {
        // root on the v < 0 branch: −w²/(2μ) + (T/2) w + c = 0, w < 0
        let d = 2.0 * c / mu;
        -2.0 * c / (half_t + (half_t * half_t + d).sqrt())
    };
    (w - v0) / t
}

impl<const M: usize> RelDeg2<M> {
    /// `φ_req`: the smallest `ḧ` at the sample for which (C1) and (C2) hold, with braking
    /// authority `μ` in `H` and class-K gain `γ`.
    pub fn phi_required(&self, bounds: &SampleBounds, mu: f64, gamma: f64) -> f64 {
        self.phi_required_with(bounds, mu, &Decay::linear(gamma))
    }

    /// [`Self::phi_required`] with the decay of (C2) given by `decay`.
    pub fn phi_required_with(&self, bounds: &SampleBounds, mu: f64, decay: &Decay) -> f64 {
        self.phi_required_at(bounds, mu, &decay.at(bounds.period))
    }

    /// [`Self::phi_required_with`] with the decay already evaluated for `bounds.period`.
    pub fn phi_required_at(&self, bounds: &SampleBounds, mu: f64, decay: &DecayAt) -> f64 {
        phi_required_of(self.h, self.hdot, bounds, mu, decay)
    }

    /// The row `b·u + (a − φ_req) ≥ 0`.
    pub fn row(&self, bounds: &SampleBounds, mu: f64, gamma: f64) -> Row<M> {
        self.row_with(bounds, mu, &Decay::linear(gamma))
    }

    /// [`Self::row`] with the decay of (C2) given by `decay`.
    pub fn row_with(&self, bounds: &SampleBounds, mu: f64, decay: &Decay) -> Row<M> {
        self.row_at(bounds, mu, &decay.at(bounds.period))
    }

    /// [`Self::row_with`] with the decay already evaluated for `bounds.period`.
    pub fn row_at(&self, bounds: &SampleBounds, mu: f64, decay: &DecayAt) -> Row<M> {
        Row {
            a: self.b,
            c: self.a - self.phi_required_at(bounds, mu, decay),
        }
    }
}

/// [`RelDeg2::phi_required_at`] from the barrier's value `h` and rate `ḣ` alone: the
/// requirement does not depend on the row's normal, so a filter that re-evaluates its rows
/// for other in-sample bounds needs only these offsets.
pub fn phi_required_of(h: f64, hd: f64, bounds: &SampleBounds, mu: f64, decay: &DecayAt) -> f64 {
    let t = bounds.period;
    let c1 = bounds.m2 + bounds.m3 * t / 3.0 + c1_requirement(h, hd, t);
    let kappa = decay.target(braking_barrier(h, hd, mu));
    let p0 = h + hd * t - bounds.m3 * t * t * t / 6.0;
    let v0 = hd - 0.5 * bounds.m3 * t * t;
    let c2 = bounds.m2 + c2_requirement(p0, v0, t, mu, kappa);
    c1.max(c2)
}

/// What a filter does not know of a barrier's state at the sample: the true `h` and `ḣ`
/// lie within `h` and `hdot` of the estimate's (the navigation's and the model's errors
/// through the barrier's gradients; docs/SAFETY.md, "Measurement-robust rows").
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StateUncertainty {
    /// `δh` [unit of h].
    pub h: f64,
    /// `δḣ` [unit of h / s].
    pub hdot: f64,
}

impl StateUncertainty {
    /// Nothing unknown: the rows are the estimate's own, bit for bit.
    pub fn is_zero(&self) -> bool {
        self.h == 0.0 && self.hdot == 0.0
    }
}

/// [`phi_required_of`] for **every** true state consistent with the estimate `(h, ḣ)`:
/// the true `(h_t, ḣ_t)` lies in the box `|h_t − h| ≤ δh`, `|ḣ_t − ḣ| ≤ δḣ` and (by the
/// induction the rows keep) in the braking-safe set `S = {h ≥ 0, H ≥ 0}`.
///
/// * The braking requirement `β = μ + M₂ + M₃T` meets (C1) and (C2) from every state of
///   `S` ([`braking_requirement`]), so it bounds the requirement of every consistent state.
/// * If the low corner `(h − δh, ḣ − δḣ)` is in `S`, the whole box is: (C1)'s requirement
///   falls with `h` and `ḣ`, (C2)'s margin `G = H(p(T), v(T)) − κ(H(h, ḣ))` rises with `h`
///   (`∂H/∂p = 1 ≥ κ'`) and falls with `ḣ` by at most
///   `(|ḣ| − |v(T)|)/μ − T ≤ (T|ψ| + ½M₃T²)/μ − T` per unit (`ψ = φ − M₂`, `|ψ| ≤ ψ_max`),
///   so the low corner's requirement with `κ` raised by that deficit over `2δḣ` covers
///   the box.
///
/// With the low corner in `S` the result is the smaller of the two. Otherwise, while the
/// high corner is in `S`, the truth may be on `S`'s boundary: `β`, which brakes every
/// state of `S` and so every consistent one — also when the estimate itself is outside
/// `S`, where its own requirement (a recovery `S`'s states do not need) may exceed `β`
/// (test `in_the_middle_case_beta_holds_for_every_consistent_truth`). When even the high
/// corner is outside `S`, no consistent state is in it and the row asks for the worst
/// one's recovery: the low corner's requirement, at least `β` and the estimate's own. So
/// the robust row is never looser than the estimate's row wherever the estimate is in `S`
/// or no consistent state is (test `a_robust_row_is_never_looser_than_the_estimates`).
/// With nothing unknown it is [`phi_required_of`] itself.
pub fn phi_required_known(
    h: f64,
    hd: f64,
    unknown: &StateUncertainty,
    bounds: &SampleBounds,
    mu: f64,
    decay: &DecayAt,
    psi_max: f64,
) -> f64 {
    if unknown.is_zero() {
        return phi_required_of(h, hd, bounds, mu, decay);
    }
    let beta = braking_requirement(bounds, mu);
    let (h_lo, hd_lo) = (h - unknown.h, hd - unknown.hdot);
    let in_set = |h: f64, hd: f64| h >= 0.0 && braking_barrier(h, hd, mu) >= 0.0;
    if in_set(h_lo, hd_lo) {
        return low_corner_requirement(h_lo, hd_lo, unknown, bounds, mu, decay, psi_max).min(beta);
    }
    if in_set(h + unknown.h, hd + unknown.hdot) {
        // the truth may be anywhere in S: β brakes every state of S (an estimate outside
        // S may ask more for its own recovery, which no consistent truth needs)
        return beta;
    }
    // no consistent state is in S: recover the worst one (and never ask less than β or
    // the estimate's own row)
    low_corner_requirement(h_lo, hd_lo, unknown, bounds, mu, decay, psi_max)
        .max(beta)
        .max(phi_required_of(h, hd, bounds, mu, decay))
}

/// The low corner's requirement with (C2)'s target raised by the rate's deficit over
/// `2δḣ` ([`phi_required_known`]).
fn low_corner_requirement(
    h_lo: f64,
    hd_lo: f64,
    unknown: &StateUncertainty,
    bounds: &SampleBounds,
    mu: f64,
    decay: &DecayAt,
    psi_max: f64,
) -> f64 {
    let t = bounds.period;
    let per_unit = ((t * psi_max.abs() + 0.5 * bounds.m3 * t * t) / mu - t).max(0.0);
    let deficit = 2.0 * unknown.hdot * per_unit;
    let c1 = bounds.m2 + bounds.m3 * t / 3.0 + c1_requirement(h_lo, hd_lo, t);
    let kappa = decay.target(braking_barrier(h_lo, hd_lo, mu)) + deficit;
    let p0 = h_lo + hd_lo * t - bounds.m3 * t * t * t / 6.0;
    let v0 = hd_lo - 0.5 * bounds.m3 * t * t;
    let c2 = bounds.m2 + c2_requirement(p0, v0, t, mu, kappa);
    c1.max(c2)
}

/// [`hdot_required_of`] for every true `h_t` with `|h_t − h| ≤ δh`, `h_t ≥ 0`: the
/// requirement falls with `h`, so it is the lowest consistent value's — never above the
/// estimate's own, and unclamped when no consistent value is `≥ 0`.
pub fn hdot_required_known(h: f64, delta_h: f64, bounds: &RateBounds, decay: &RateDecay) -> f64 {
    if delta_h == 0.0 {
        return hdot_required_of(h, bounds, decay);
    }
    let lowest = if h + delta_h < 0.0 {
        h - delta_h
    } else {
        (h - delta_h).max(0.0).min(h)
    };
    hdot_required_of(lowest, bounds, decay)
}

/// [`RelDeg1::hdot_required_at`] from the barrier's value `h` alone.
pub fn hdot_required_of(h: f64, bounds: &RateBounds, decay: &RateDecay) -> f64 {
    let t = bounds.period;
    bounds.d + 0.5 * bounds.j * t + (decay.target(h) - h) / t
}

/// The `ḧ` a command must produce at the sample to brake a relative-degree-two barrier
/// in every state of the braking-safe set `{h ≥ 0, H ≥ 0}`: `μ + M₂ + M₃T`. A subsystem
/// whose bounded input can produce it for all its barriers at once keeps every row
/// feasible (docs/SAFETY.md, "Feasibility").
pub fn braking_requirement(bounds: &SampleBounds, mu: f64) -> f64 {
    mu + bounds.m2 + bounds.m3 * bounds.period
}

/// Bounds inside one sample of a relative-degree-one barrier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateBounds {
    /// Sample length `T` [s].
    pub period: f64,
    /// `D`: bound on the part of `ḣ` unknown at the sample [unit of h / s].
    pub d: f64,
    /// `J`: bound on `|ḧ|` over one sample [unit of h / s²].
    pub j: f64,
}

/// The exact discretisation of the paper's `ḣ ≥ −γh + ε` over a sample of length `T`:
/// `h(T) ≥ e^{−γT}(h − ε/γ) + ε/γ`, its exponential computed once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateDecay {
    e: f64,
    floor: f64,
}

impl RateDecay {
    /// For class-K gain `γ` [1/s], margin `ε` and sample length `t` [s].
    pub fn new(gamma: f64, eps: f64, t: f64) -> Self {
        Self {
            e: (-gamma * t).exp(),
            floor: if gamma > 0.0 { eps / gamma } else { 0.0 },
        }
    }

    /// The least `h(T)` allowed from `h`.
    pub fn target(&self, h: f64) -> f64 {
        self.e * (h - self.floor) + self.floor
    }
}

impl<const M: usize> RelDeg1<M> {
    /// `ḣ` required at the sample: `D + ½JT + (e^{−γT}(h − ε/γ) + ε/γ − h)/T`.
    pub fn hdot_required(&self, bounds: &RateBounds, gamma: f64, eps: f64) -> f64 {
        self.hdot_required_at(bounds, &RateDecay::new(gamma, eps, bounds.period))
    }

    /// [`Self::hdot_required`] with the decay already evaluated for `bounds.period`.
    pub fn hdot_required_at(&self, bounds: &RateBounds, decay: &RateDecay) -> f64 {
        hdot_required_of(self.h, bounds, decay)
    }

    /// The row `b·u + (a − ḣ_req) ≥ 0`.
    pub fn row(&self, bounds: &RateBounds, gamma: f64, eps: f64) -> Row<M> {
        self.row_at(bounds, &RateDecay::new(gamma, eps, bounds.period))
    }

    /// [`Self::row`] with the decay already evaluated for `bounds.period`.
    pub fn row_at(&self, bounds: &RateBounds, decay: &RateDecay) -> Row<M> {
        Row {
            a: self.b,
            c: self.a - self.hdot_required_at(bounds, decay),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_draws::lcg;
    use nalgebra::Vector1;

    /// The worst case the row guards against: ḧ(s) = φ − M₂ − M₃ s, integrated exactly.
    fn worst(x: &RelDeg2<1>, b: &SampleBounds, phi: f64, s: f64) -> (f64, f64) {
        let a = phi - b.m2;
        (
            x.h + x.hdot * s + 0.5 * a * s * s - b.m3 * s * s * s / 6.0,
            x.hdot + a * s - 0.5 * b.m3 * s * s,
        )
    }

    /// A random μ, sample bounds and a state inside `{h ≥ 0, H ≥ 0}` (terms with `b = 1`).
    fn random_state(seed: &mut u64) -> (f64, SampleBounds, RelDeg2<1>) {
        let mut r = || lcg(seed);
        let mu = 0.001 + r();
        let b = SampleBounds {
            period: 0.01 + 0.2 * r(),
            m2: 0.1 * r(),
            m3: r() * r(),
        };
        let hdot = 2.0 * r() - 1.0;
        let h = hdot.min(0.0).powi(2) / (2.0 * mu) + r() * r();
        let x = RelDeg2 {
            h,
            hdot,
            a: 0.0,
            b: Vector1::new(1.0),
        };
        (mu, b, x)
    }

    /// Under the worst case for `φ`, `h ≥ 0` all through the sample and `H(T) ≥ κ`.
    fn assert_worst_case_holds(x: &RelDeg2<1>, b: &SampleBounds, mu: f64, phi: f64, kappa: f64) {
        for k in 0..=200 {
            let s = b.period * k as f64 / 200.0;
            let (p, _) = worst(x, b, phi, s);
            assert!(
                p >= -1e-12 * (1.0 + x.h),
                "h({s}) = {p} (h {}, hdot {})",
                x.h,
                x.hdot
            );
        }
        let (p, v) = worst(x, b, phi, b.period);
        assert!(
            braking_barrier(p, v, mu) >= kappa - 1e-9 * (1.0 + kappa.abs()),
            "H(T) = {} < {kappa}",
            braking_barrier(p, v, mu)
        );
    }

    #[test]
    fn rel_deg_two_row_keeps_h_and_next_braking_barrier_on_the_worst_case() {
        let mut seed = 1;
        for _ in 0..20000 {
            let (mu, b, x) = random_state(&mut seed);
            let gamma = 2.0 * lcg(&mut seed);
            let phi = x.phi_required(&b, mu, gamma);
            assert!(phi.is_finite());
            let kappa = (-gamma * b.period).exp() * braking_barrier(x.h, x.hdot, mu);
            assert_worst_case_holds(&x, &b, mu, phi, kappa);
            // feasible by braking: the requirement never exceeds μ + M₂ + M₃T
            assert!(
                phi <= braking_requirement(&b, mu) + 1e-9,
                "phi_req {phi} > braking {}",
                braking_requirement(&b, mu)
            );
        }
    }

    #[test]
    fn a_knee_only_relaxes_the_row_above_it_and_keeps_the_set_invariant() {
        let mut seed = 3;
        for _ in 0..20000 {
            let (mu, b, x) = random_state(&mut seed);
            let mut r = || lcg(&mut seed);
            let gamma = 2.0 * r();
            let decay = Decay {
                gamma,
                knee: r() * r(),
                gamma_inner: gamma + 20.0 * r(),
            };
            let big_h = braking_barrier(x.h, x.hdot, mu);
            let kappa = decay.target(big_h, b.period);
            assert!((0.0..=big_h).contains(&kappa), "κ({big_h}) = {kappa}");
            let linear = x.phi_required(&b, mu, gamma);
            let phi = x.phi_required_with(&b, mu, &decay);
            // never stricter than the paper's decay, and the same up to the knee
            assert!(phi <= linear + 1e-12, "{phi} > {linear}");
            if big_h <= decay.knee {
                assert_eq!(phi, linear);
            }
            // the worst case still keeps h ≥ 0 inside the sample and H(T) ≥ κ(H) ≥ 0
            assert_worst_case_holds(&x, &b, mu, phi, kappa);
        }
    }

    /// Measurement-robust rows: every true state in the estimate's box and in the set
    /// keeps (C1) and (C2) under the worst case of a command that meets the estimate's
    /// robust row — at the requirement itself (or the least command the subsystem can
    /// produce, `ψ = −ψ_max`) and at the largest, `ψ = ψ_max`.
    #[test]
    fn a_robust_row_holds_for_every_true_state_consistent_with_the_estimate() {
        let mut seed = 11;
        let mut boxed = 0;
        for _ in 0..4000 {
            let (mu, b, truth) = random_state(&mut seed);
            let mut r = || lcg(&mut seed);
            let unknown = StateUncertainty {
                h: 0.3 * r() * r(),
                hdot: 0.3 * r() * r(),
            };
            // an estimate whose box holds the truth
            let est_h = truth.h + unknown.h * (2.0 * r() - 1.0);
            let est_hd = truth.hdot + unknown.hdot * (2.0 * r() - 1.0);
            let gamma = 2.0 * r();
            let decay = Decay::linear(gamma);
            let psi_max = braking_requirement(&b, mu) + 2.0 * r();
            let phi = phi_required_known(
                est_h,
                est_hd,
                &unknown,
                &b,
                mu,
                &decay.at(b.period),
                psi_max,
            );
            assert!(phi.is_finite());
            // an estimate in S asks no more than braking (outside it, its own recovery)
            if braking_barrier(est_h, est_hd, mu) >= 0.0 && est_h >= 0.0 {
                assert!(phi <= braking_requirement(&b, mu) + 1e-12);
            }
            if braking_barrier(est_h - unknown.h, est_hd - unknown.hdot, mu) >= 0.0 {
                boxed += 1;
            }
            let kappa = decay.target(braking_barrier(truth.h, truth.hdot, mu), b.period);
            // the commands a subsystem can produce: |φ − M₂| ≤ ψ_max
            for phi_u in [phi.max(b.m2 - psi_max), (psi_max + b.m2).max(phi)] {
                assert_worst_case_holds(&truth, &b, mu, phi_u, kappa);
            }
        }
        // both branches were exercised
        assert!(boxed > 400 && boxed < 3600, "{boxed}");
    }

    /// Wherever the estimate is in `S`, or no state of its box is (far outside), the robust
    /// requirement is at least the estimate's own; in between (the estimate outside `S`,
    /// its box's high corner in it) it is `β`, which may be less than the estimate's own
    /// recovery and is sound there (`in_the_middle_case_beta_holds_for_every_consistent_truth`).
    /// The rate row's is at least the estimate's own everywhere.
    #[test]
    fn a_robust_row_is_never_looser_than_the_estimates() {
        let mut seed = 13;
        let in_set = |h: f64, hd: f64, mu: f64| h >= 0.0 && braking_barrier(h, hd, mu) >= 0.0;
        let (mut inside, mut between, mut beyond) = (0, 0, 0);
        for _ in 0..20000 {
            let (mu, b, x) = random_state(&mut seed);
            let mut r = || lcg(&mut seed);
            // anywhere: shifted by up to ±1 in h and ±1 in ḣ from a state of S
            let (h, hd) = (x.h + 2.0 * r() - 1.0, x.hdot + 2.0 * r() - 1.0);
            let unknown = StateUncertainty {
                h: 0.3 * r(),
                hdot: 0.3 * r(),
            };
            let d = Decay::linear(2.0 * r()).at(b.period);
            let psi_max = braking_requirement(&b, mu) + r();
            let robust = phi_required_known(h, hd, &unknown, &b, mu, &d, psi_max);
            let own = phi_required_of(h, hd, &b, mu, &d);
            if in_set(h, hd, mu) || !in_set(h + unknown.h, hd + unknown.hdot, mu) {
                if in_set(h, hd, mu) {
                    inside += 1;
                } else {
                    beyond += 1;
                }
                // (below the least `φ` a command can produce, `M₂ − ψ_max`, no row binds)
                let floor = b.m2 - psi_max;
                assert!(
                    robust.max(floor) >= own.max(floor) - 1e-12,
                    "h {h} hd {hd} {unknown:?}: {robust} < {own}"
                );
            } else {
                between += 1;
                assert_eq!(
                    robust,
                    braking_requirement(&b, mu),
                    "h {h} hd {hd} {unknown:?}"
                );
            }
            let rate = RateBounds {
                period: b.period,
                d: 0.1 * r(),
                j: r(),
            };
            let rd = RateDecay::new(2.0 * r(), 0.0, b.period);
            assert!(
                hdot_required_known(h, unknown.h, &rate, &rd) >= hdot_required_of(h, &rate, &rd)
            );
        }
        eprintln!("estimate in S {inside}, between {between}, no consistent state in S {beyond}");
        // every part of the domain was exercised
        assert!(
            inside > 1000 && between > 1000 && beyond > 1000,
            "{inside} {between} {beyond}"
        );
    }

    /// The middle case of [`phi_required_known`]: the estimate outside `S`, its box's high
    /// corner in it. The row asks `β` — less than the estimate's own recovery on many of
    /// these draws — and every true state of the box that is in `S` (on `S`'s boundary
    /// and inside it) keeps (C1) and (C2) under the worst case of every command that
    /// meets it, at the requirement and at the largest, `ψ = ψ_max`.
    #[test]
    fn in_the_middle_case_beta_holds_for_every_consistent_truth() {
        let mut seed = 17;
        let in_set = |h: f64, hd: f64, mu: f64| h >= 0.0 && braking_barrier(h, hd, mu) >= 0.0;
        let (mut cases, mut looser, mut truths) = (0, 0, 0);
        while cases < 2000 {
            let (mu, b, x) = random_state(&mut seed);
            let mut r = || lcg(&mut seed);
            let unknown = StateUncertainty {
                h: 0.3 * r(),
                hdot: 0.3 * r(),
            };
            // an estimate below a state of S, within the box of it: the high corner is in S
            let (est_h, est_hd) = (x.h - unknown.h * r(), x.hdot - unknown.hdot * r());
            if in_set(est_h, est_hd, mu) || in_set(est_h - unknown.h, est_hd - unknown.hdot, mu) {
                continue;
            }
            cases += 1;
            let gamma = 2.0 * r();
            let decay = Decay::linear(gamma);
            let d = decay.at(b.period);
            let beta = braking_requirement(&b, mu);
            let psi_max = beta + 2.0 * r();
            let phi = phi_required_known(est_h, est_hd, &unknown, &b, mu, &d, psi_max);
            assert_eq!(phi, beta);
            if phi_required_of(est_h, est_hd, &b, mu, &d) > beta {
                looser += 1;
            }
            // the truths: x itself, then states of the box on S's boundary (k < 4) and
            // inside it
            for k in 0..20 {
                let (h_t, hd_t) = if k == 0 {
                    (x.h, x.hdot)
                } else {
                    let hd_t = est_hd + unknown.hdot * (2.0 * r() - 1.0);
                    // the least h of S at this rate, within the box
                    let h_min = if hd_t < 0.0 {
                        hd_t * hd_t / (2.0 * mu)
                    } else {
                        0.0
                    };
                    let lo = h_min.max(est_h - unknown.h);
                    let hi = est_h + unknown.h;
                    if lo > hi {
                        continue;
                    }
                    let at = if k < 4 { 0.0 } else { r() };
                    (lo + (hi - lo) * at, hd_t)
                };
                assert!(in_set(h_t, hd_t, mu), "{h_t} {hd_t}");
                truths += 1;
                let truth = RelDeg2 {
                    h: h_t,
                    hdot: hd_t,
                    a: 0.0,
                    b: Vector1::new(1.0),
                };
                let kappa = decay.target(braking_barrier(h_t, hd_t, mu), b.period);
                for phi_u in [phi.max(b.m2 - psi_max), (psi_max + b.m2).max(phi)] {
                    assert_worst_case_holds(&truth, &b, mu, phi_u, kappa);
                }
            }
        }
        eprintln!(
            "{cases} estimates, {looser} with their own requirement above β, {truths} truths"
        );
        // the case the fix is for: the estimate's own requirement above β
        assert!(looser > 200, "{looser} of {cases}");
        assert!(truths > 20000, "{truths}");
    }

    #[test]
    fn nothing_unknown_is_the_estimates_own_row() {
        let mut seed = 5;
        for _ in 0..1000 {
            let (mu, b, x) = random_state(&mut seed);
            let d = Decay::linear(1.0).at(b.period);
            assert_eq!(
                phi_required_known(x.h, x.hdot, &StateUncertainty::default(), &b, mu, &d, 1.0)
                    .to_bits(),
                phi_required_of(x.h, x.hdot, &b, mu, &d).to_bits()
            );
        }
    }

    #[test]
    fn rel_deg_two_requirement_is_tight_for_the_braking_barrier() {
        // no margins, γ = 0, moving towards the boundary exactly at the stopping distance:
        // the row must ask for exactly μ (brake now), and a little less must fail (C2).
        let mu = 0.5;
        let hdot: f64 = -0.4;
        let x = RelDeg2 {
            h: hdot * hdot / (2.0 * mu),
            hdot,
            a: 0.0,
            b: Vector1::new(1.0),
        };
        let b = SampleBounds {
            period: 0.1,
            m2: 0.0,
            m3: 0.0,
        };
        let phi = x.phi_required(&b, mu, 0.0);
        assert!((phi - mu).abs() < 1e-12, "{phi}");
    }

    #[test]
    fn row_gain_does_not_vanish_at_zero_rate() {
        let x = RelDeg2 {
            h: 0.0,
            hdot: 0.0,
            a: -0.3,
            b: Vector1::new(2.0),
        };
        let b = SampleBounds {
            period: 0.1,
            m2: 0.01,
            m3: 0.1,
        };
        let row = x.row(&b, 1.0, 1.0);
        assert_eq!(row.a[0], 2.0);
        // at rest on the boundary the command must produce at least the margins
        assert!(
            row.c <= -0.3 - (0.01 + 0.1 * 0.1 / 3.0) + 1e-15,
            "{}",
            row.c
        );
    }

    #[test]
    fn rel_deg_one_row_holds_over_the_sample() {
        let mut seed = 7;
        for _ in 0..20000 {
            let mut r = || lcg(&mut seed);
            let x = RelDeg1 {
                h: r() * r(),
                a: 0.0,
                b: Vector1::new(1.0),
            };
            let b = RateBounds {
                period: 0.01 + 0.2 * r(),
                d: 0.1 * r(),
                j: r(),
            };
            let (gamma, eps) = (2.0 * r(), 0.01 * r());
            let req = x.hdot_required(&b, gamma, eps);
            // worst case ḣ(s) = req − D − J s
            for k in 0..=100 {
                let s = b.period * k as f64 / 100.0;
                let h = x.h + (req - b.d) * s - 0.5 * b.j * s * s;
                assert!(h >= -1e-12, "h({s}) = {h}");
            }
            let e = (-gamma * b.period).exp();
            let h_t = x.h + (req - b.d) * b.period - 0.5 * b.j * b.period * b.period;
            let floor = eps / gamma;
            assert!(h_t >= e * (x.h - floor) + floor - 1e-12);
        }
    }
}
