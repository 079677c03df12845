//! Output, report, status and fault flags shared by the three filters, plus the input
//! validation helpers.

use crate::barrier::Row;
use nalgebra::{SVector, Vector3};
use sc_models::quat::{self, Quat};
use serde::{Deserialize, Serialize};

/// Fault flags (`FilterReport::faults`, a `u32` bitset). Stable: telemetry stores them.
pub mod faults {
    /// The state (or a parameter carried with it, e.g. the inertia) is non-finite or
    /// cannot be evaluated; the backup command is used (zero when the state itself cannot
    /// be trusted).
    pub const INVALID_STATE: u32 = 1 << 0;
    /// The nominal command was non-finite or beyond `NOMINAL_RANGE × bound`: the QP ran on
    /// the subsystem's substitute nominal.
    pub const INVALID_NOMINAL: u32 = 1 << 1;
    /// The upstream coupling ξ is non-finite or out of range; the backup command is used
    /// (the certificate cannot be computed without the coupling).
    pub const INVALID_COUPLING: u32 = 1 << 2;
    /// The barrier rows could not all hold inside the input bounds: the lexicographic
    /// least-violation command (`FilterReport::violation` > 0). The state is outside the
    /// certified set (docs/SAFETY.md).
    pub const QP_INFEASIBLE_RELAXED: u32 = 1 << 3;
    /// The solver failed (invalid data, iteration limit): the backup braking law was used.
    pub const QP_FAILED_FALLBACK: u32 = 1 << 4;
    /// Set by callers: the upstream safe command was missing (the upstream backup command
    /// was used as ξ).
    pub const UPSTREAM_MISSING: u32 = 1 << 5;
    /// The last-line clamp to the input bounds changed the command by more than 1e-9.
    pub const OUTPUT_CLAMPED: u32 = 1 << 6;
    /// No nominal command arrived (silent, dead or late controller): the QP ran on the
    /// subsystem's substitute nominal.
    pub const NOMINAL_MISSING: u32 = 1 << 7;
    /// The exact active-set solver stopped at its iteration limit (degeneracy or cycling)
    /// and Clarabel's solution of the same QP is the command (it holds every row to 1e-9
    /// of the input bound); without one the backup law is used
    /// ([`QP_FAILED_FALLBACK`]).
    pub const QP_SECOND_OPINION: u32 = 1 << 8;
    /// No command is certified for the declared errors (a declared uncertainty): the
    /// command is the solution of the rows with the largest feasible share `λ` of the
    /// declared margins, `FilterReport::violation = 1 − λ` (`λ = 0`: the nominal model's
    /// rows). Only the translational filter degrades so (docs/SAFETY.md).
    pub const MARGINS_DEGRADED: u32 = 1 << 9;
    /// The run has left the certified envelope (the tumble known at this step breaks a
    /// rule of it, `crate::safe_mode`): the layer is in safe mode — the translational
    /// nominal is the retreat, the robotic nominal the arm's brake, each still filtered.
    pub const SAFE_MODE: u32 = 1 << 10;
    /// All flags, for masks.
    pub const ALL: u32 = (1 << 11) - 1;

    /// Names of the flags in bit order.
    pub const NAMES: [&str; 11] = [
        "invalid_state",
        "invalid_nominal",
        "invalid_coupling",
        "qp_infeasible_relaxed",
        "qp_failed_fallback",
        "upstream_missing",
        "output_clamped",
        "nominal_missing",
        "qp_second_opinion",
        "margins_degraded",
        "safe_mode",
    ];
}

/// Whether the step's command is certified for every declared error: solved (or skipped,
/// the nominal meeting every row) and not on degraded margins
/// ([`faults::MARGINS_DEGRADED`], reported with status solved).
pub fn certified<const N: usize>(r: &FilterReport<N>) -> bool {
    matches!(r.status, FilterStatus::Solved | FilterStatus::Skipped)
        && r.faults & faults::MARGINS_DEGRADED == 0
}

/// A nominal command is rejected when `‖u_nom‖∞ > NOMINAL_RANGE × bound` (it would only be
/// clipped anyway, and astronomically large costs ruin the solver's conditioning).
pub const NOMINAL_RANGE: f64 = 1e3;
/// The QP's box is shrunk by this relative margin so that the solver's feasibility
/// tolerance (1e-8) never pushes the solution beyond the true bound; the last-line clamp
/// then only acts on genuine faults.
pub const BOX_MARGIN: f64 = 1e-7;
/// A constraint is reported active when `Φ(u) ≤ ACTIVE_TOL · max(1, ‖∂Φ/∂u‖)`.
pub const ACTIVE_TOL: f64 = 1e-6;
/// Changes of the last-line clamp above this are flagged [`faults::OUTPUT_CLAMPED`].
pub const CLAMP_FLAG_TOL: f64 = 1e-9;
/// Accepted deviation of a quaternion's norm from 1 (it is renormalised).
pub const QUAT_NORM_TOL: f64 = 1e-3;

/// How the command of one filter call was produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[repr(u8)]
pub enum FilterStatus {
    /// The nominal command satisfied every row and bound and was returned unchanged.
    Skipped = 0,
    /// The CBF-QP was solved.
    Solved = 1,
    /// The relaxed QP was solved (see [`faults::QP_INFEASIBLE_RELAXED`]).
    Relaxed = 2,
    /// The bounded fallback command was used (see the fault flags for why).
    #[default]
    Fallback = 3,
}

/// Per-call report of a filter with `N` constraints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterReport<const N: usize> {
    /// Barrier values `h_i` (NaN when the state is invalid).
    pub h: [f64; N],
    /// CBF conditions `Φ_i` (or `φ_i`) at the returned command (NaN when not computable).
    pub phi: [f64; N],
    /// Bit `i` set when constraint `i` is active (`Φ_i ≤ ACTIVE_TOL·max(1,‖∂Φ_i/∂u‖)`).
    pub active: u64,
    pub status: FilterStatus,
    /// Solver iterations (active-set changes, all stages).
    pub iterations: u32,
    /// Wall time of the whole filter call [ns] — nondeterministic, like the next field.
    pub solve_time_ns: u64,
    /// CPU time the calling thread spent in the filter call [ns] (`CLOCK_THREAD_CPUTIME_ID`):
    /// the filter's own work, without the time the thread was preempted.
    pub solve_cpu_ns: u64,
    /// Wall time spent inside the QP solver [ns]: every solve of the call (certification
    /// and verification rounds included), without building the rows — nondeterministic.
    pub qp_time_ns: u64,
    /// [`faults`] bitset.
    pub faults: u32,
    /// Least violation `t*` of the relaxed problem (0 otherwise), as a fraction of each
    /// barrier's braking authority (docs/SAFETY.md) — except for a translational step
    /// degraded under declared errors: `1 − λ`, the share of the declared margins given
    /// up (`TranslationalFilter::solve_degraded`).
    pub violation: f64,
}

impl<const N: usize> Default for FilterReport<N> {
    fn default() -> Self {
        Self {
            h: [f64::NAN; N],
            phi: [f64::NAN; N],
            active: 0,
            status: FilterStatus::Fallback,
            iterations: 0,
            solve_time_ns: 0,
            solve_cpu_ns: 0,
            qp_time_ns: 0,
            faults: 0,
            violation: 0.0,
        }
    }
}

/// A filter's defined output when its input cannot even be built (a state the model
/// cannot evaluate): zero command, status `Fallback`, flag [`faults::INVALID_STATE`].
pub fn invalid_state_output<const M: usize, const N: usize>() -> FilterOutput<M, N> {
    let mut report = FilterReport::default();
    report.faults |= faults::INVALID_STATE;
    FilterOutput {
        u: SVector::zeros(),
        actuated: SVector::zeros(),
        report,
    }
}

/// CPU time consumed by the calling thread so far [ns] (`CLOCK_THREAD_CPUTIME_ID`; 0 if the
/// clock is unavailable). Differences of two readings measure a call's own work.
pub fn thread_cpu_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return 0;
    }
    (ts.tv_sec as u64)
        .saturating_mul(1_000_000_000)
        .saturating_add(ts.tv_nsec as u64)
}

impl<const N: usize> FilterReport<N> {
    /// Every field except the solve time, as bits — for determinism checks.
    pub fn deterministic_bits(&self) -> Vec<u64> {
        let mut v: Vec<u64> = self.h.iter().map(|x| x.to_bits()).collect();
        v.extend(self.phi.iter().map(|x| x.to_bits()));
        v.extend([
            self.active,
            self.status as u64,
            self.iterations as u64,
            self.faults as u64,
            self.violation.to_bits(),
        ]);
        v
    }
}

/// Safe command of a filter with `M` inputs and `N` constraints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterOutput<const M: usize, const N: usize> {
    /// The safe command in the filter's frame (`f_H`, `τ_B`, `τ_M`).
    pub u: SVector<f64, M>,
    /// The command in the actuator frame: `f_B = R_BH f_H` for the translational filter,
    /// `u` itself for the others.
    pub actuated: SVector<f64, M>,
    pub report: FilterReport<N>,
}

/// `v · min(1, limit/‖v‖∞)`: saturation that keeps the direction (zero if not finite).
pub fn sat_inf<const M: usize>(v: &SVector<f64, M>, limit: f64) -> SVector<f64, M> {
    if !v.iter().all(|x| x.is_finite()) {
        return SVector::zeros();
    }
    let m = v.amax();
    if m > limit && m > 0.0 {
        v * (limit / m)
    } else {
        *v
    }
}

/// Clamps every component to `[−limit, limit]`; returns the clamped vector and whether
/// any component moved by more than [`CLAMP_FLAG_TOL`]. Non-finite components become 0.
pub fn clamp_box<const M: usize>(v: &SVector<f64, M>, limit: f64) -> (SVector<f64, M>, bool) {
    let mut out = *v;
    let mut flagged = false;
    for x in out.iter_mut() {
        let c = if x.is_finite() {
            x.clamp(-limit, limit)
        } else {
            0.0
        };
        if !x.is_finite() || (c - *x).abs() > CLAMP_FLAG_TOL {
            flagged = true;
        }
        *x = c;
    }
    (out, flagged)
}

/// All components finite.
pub fn finite<const R: usize, const C: usize>(m: &nalgebra::SMatrix<f64, R, C>) -> bool {
    // on the magnitudes' bits (every finite one is below infinity's), without early exit,
    // so that it vectorises
    const MAGNITUDE: u64 = !(1 << 63);
    let inf = f64::INFINITY.to_bits();
    m.as_slice()
        .iter()
        .fold(true, |ok, x| ok & (x.to_bits() & MAGNITUDE < inf))
}

/// All components finite and `‖v‖₂ ≤ max`.
pub fn in_range3(v: &Vector3<f64>, max: f64) -> bool {
    finite(v) && v.norm() <= max
}

/// A finite quaternion with `|‖q‖ − 1| ≤ QUAT_NORM_TOL`, renormalised.
pub fn unit_quat(q: &Quat) -> Option<Quat> {
    if !q.iter().all(|x| x.is_finite()) {
        return None;
    }
    let n = quat::norm(q);
    if (n - 1.0).abs() > QUAT_NORM_TOL {
        return None;
    }
    quat::normalized(q)
}

/// A nominal command is valid when finite and `‖u‖∞ ≤ NOMINAL_RANGE × bound`.
pub fn nominal_valid<const M: usize>(u: &SVector<f64, M>, bound: f64) -> bool {
    finite(u) && u.amax() <= NOMINAL_RANGE * bound
}

/// The nominal the QP runs on: the given one when valid, else `substitute`, with the flag
/// saying why ([`faults::INVALID_NOMINAL`], [`faults::NOMINAL_MISSING`]).
pub fn resolve_nominal<const M: usize>(
    given: Option<&SVector<f64, M>>,
    bound: f64,
    substitute: impl FnOnce() -> SVector<f64, M>,
) -> (SVector<f64, M>, u32) {
    match given {
        Some(u) if nominal_valid(u, bound) => (*u, 0),
        Some(_) => (substitute(), faults::INVALID_NOMINAL),
        None => (substitute(), faults::NOMINAL_MISSING),
    }
}

/// Input-bound rows `limit (1 − BOX_MARGIN) ∓ u_k ≥ 0` of a box `‖u‖∞ ≤ limit`.
pub fn box_rows<const M: usize>(limit: f64) -> Vec<Row<M>> {
    let l = limit * (1.0 - BOX_MARGIN);
    let mut v = Vec::with_capacity(2 * M);
    for k in 0..M {
        for sign in [-1.0, 1.0] {
            let mut a = SVector::<f64, M>::zeros();
            a[k] = sign;
            v.push(Row { a, c: l });
        }
    }
    v
}

/// Fills `phi` and the active mask from the first `N` rows (the barrier rows in report
/// order) at the returned command.
pub fn evaluate_rows<const M: usize, const N: usize>(
    rows: &[Row<M>],
    u: &SVector<f64, M>,
    report: &mut FilterReport<N>,
) {
    report.active = 0;
    for (i, r) in rows.iter().enumerate().take(N) {
        let phi = r.phi(u);
        report.phi[i] = phi;
        if phi <= ACTIVE_TOL * r.a.norm().max(1.0) {
            report.active |= 1u64 << i;
        }
    }
}
