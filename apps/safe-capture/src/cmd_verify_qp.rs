//! `safe-capture verify-qp`: every QP a run dumped, checked independently of the engine
//! that solved it (`sc_cbf::verify`).

use anyhow::Context;
use sc_cbf::QpOutcome;
use sc_cbf::qp::QpDump;
use sc_cbf::verify::{Check, check, input_bound};
use std::collections::BTreeMap;
use std::io::BufRead;
use std::path::PathBuf;
use std::process::ExitCode;

/// Checks every hard QP of a `run --dump-qp FILE` (JSON lines) independently of the exact
/// active-set engine that solved it: feasibility of its solution (the largest row
/// violation) and its distance to an exact reference — Clarabel's interior-point solution
/// of the same data, its active set then solved in exact linear algebra and accepted only
/// as a KKT point of the whole problem (`sc_cbf::verify::exact_reference`) — both judged.
/// Where no exact reference is found, the distance to Clarabel's own solution is judged
/// with its looser tolerance (the count is printed). For information, the KKT
/// stationarity residual with multipliers recomputed by non-negative least squares over
/// the rows active at the engine's solution; and the dump's own multipliers, which must
/// certify the solution (stationarity, sign and complementarity with the dumped rows and
/// bounds; the exact engine's own solutions, not Clarabel's second opinion). Lengths are
/// relative to the filter's input bound.
///
/// Prints per filter: QPs checked, largest relative violation, stationarity residual,
/// distance to the exact reference and to Clarabel, and the step of each largest value.
///
/// Exit codes: 0 every check within the tolerances, 1 a check beyond them, 2 bad
/// arguments or an unreadable dump.
#[derive(clap::Args)]
pub struct Args {
    /// The dump written by `safe-capture run --dump-qp FILE`.
    #[arg(value_name = "DUMP.jsonl")]
    dump: PathBuf,
    /// Largest accepted row violation at the solution, relative to the input bound.
    #[arg(long, value_name = "REL", default_value_t = 1e-9)]
    feasibility_tolerance: f64,
    /// Largest accepted distance to the exact reference, relative to the input bound.
    #[arg(long, value_name = "REL", default_value_t = 1e-9)]
    exact_tolerance: f64,
    /// Largest accepted distance to Clarabel's solution where no exact reference was
    /// found, relative to the input bound (an interior-point method at tolerance 1e-11
    /// agrees to about this).
    #[arg(long, value_name = "REL", default_value_t = 1e-6)]
    clarabel_tolerance: f64,
    /// Largest accepted residual of the dump's own multipliers (stationarity, sign,
    /// complementarity; `sc_cbf::verify::dual_residual`), relative to the input bound.
    #[arg(long, value_name = "REL", default_value_t = 1e-9)]
    certificate_tolerance: f64,
}

/// The exact reference must be a KKT point to this (relative to the input bound): rows
/// hold and the stationarity residual is below it — rounding of a 7 × 64 problem.
const EXACT_KKT_TOLERANCE: f64 = 1e-11;

/// Rows within this distance of their boundary (relative to the input bound) count as
/// active when the multipliers are recomputed: the engine keeps a rounding room of this
/// order between a solution and its rows.
const ACTIVE_TOLERANCE: f64 = 1e-7;

#[derive(serde::Deserialize)]
struct Line {
    filter: String,
    step: u64,
    qp: QpDump,
}

#[derive(Default)]
struct Worst {
    checked: usize,
    clarabel_failed: usize,
    violation: (f64, u64),
    stationarity: (f64, u64),
    /// The dump's own multipliers: how far from certifying the solution
    /// (`sc_cbf::verify::dual_residual`), over the exact engine's own solutions.
    certificate: (f64, u64),
    clarabel: (f64, u64),
    exact: (f64, u64),
    /// QPs without an exact reference: their distance to Clarabel (judged instead).
    inexact: usize,
    /// QPs whose exact reference was built on the solution's own active set (Clarabel
    /// failed or its active set gave no KKT point).
    from_solution: usize,
    inexact_clarabel: (f64, u64),
    /// QPs judged against an exact reference.
    exact_n: usize,
}

fn raise(slot: &mut (f64, u64), v: f64, step: u64) {
    if v > slot.0 || v.is_nan() {
        *slot = (v, step);
    }
}

impl Worst {
    /// Adds the check `c` of the QP of `step`, lengths relative to the input bound `u_inf`.
    fn add(&mut self, c: &Check, certificate: Option<f64>, u_inf: f64, step: u64) {
        self.checked += 1;
        if let Some(r) = certificate {
            raise(&mut self.certificate, r / u_inf, step);
        }
        raise(&mut self.violation, c.violation / u_inf, step);
        raise(&mut self.stationarity, c.stationarity / u_inf, step);
        match c.clarabel_distance {
            Some(d) => raise(&mut self.clarabel, d / u_inf, step),
            None => self.clarabel_failed += 1,
        }
        self.from_solution += usize::from(c.exact_from_solution);
        match (c.exact_distance, c.clarabel_distance) {
            (Some(d), _) => {
                self.exact_n += 1;
                raise(&mut self.exact, d / u_inf, step)
            }
            (None, Some(d)) => {
                self.inexact += 1;
                raise(&mut self.inexact_clarabel, d / u_inf, step);
            }
            (None, None) => {}
        }
    }

    /// Every check within the tolerances of `a`.
    fn within(&self, a: &Args) -> bool {
        let kkt_ok = self.violation.0 <= a.feasibility_tolerance
            && self.certificate.0 <= a.certificate_tolerance;
        let exact_ok = self.exact.0 <= a.exact_tolerance;
        // a QP without any reference (Clarabel failed, no KKT point found) is not verified
        let unverified = self.checked - self.exact_n;
        let cl_ok = self.inexact_clarabel.0 <= a.clarabel_tolerance && unverified == self.inexact;
        kkt_ok && exact_ok && cl_ok
    }
}

/// Checks every solved QP of the dump; the worst values per filter.
fn check_dump(a: &Args) -> anyhow::Result<BTreeMap<String, Worst>> {
    let file = std::fs::File::open(&a.dump)
        .with_context(|| format!("cannot open {}", a.dump.display()))?;
    let mut worst: BTreeMap<String, Worst> = BTreeMap::new();
    for (n, line) in std::io::BufReader::new(file).lines().enumerate() {
        let line = line.with_context(|| format!("reading {}", a.dump.display()))?;
        let l: Line = serde_json::from_str(&line)
            .with_context(|| format!("{} line {}", a.dump.display(), n + 1))?;
        if l.qp.outcome != Some(QpOutcome::Solved) {
            continue;
        }
        let u_inf = input_bound(&l.qp, 1.0);
        let m = l.qp.u_nom.len().max(1) as f64;
        let c = check(
            &l.qp,
            u_inf * m.sqrt(),
            ACTIVE_TOLERANCE * u_inf,
            EXACT_KKT_TOLERANCE * u_inf,
        );
        let certificate = (l.qp.solver_status == sc_cbf::engine::ACTIVE_SET_STATUS)
            .then(|| sc_cbf::verify::dual_residual(&l.qp));
        worst
            .entry(l.filter)
            .or_default()
            .add(&c, certificate, u_inf, l.step);
    }
    Ok(worst)
}

/// The line of filter `f`'s worst values and verdict.
fn filter_line(f: &str, w: &Worst, ok: bool) {
    outln!(
        "{f:<14} {:>6} QPs  violation {:.1e} (step {})  stationarity {:.1e} (step {})  dumped duals {:.1e} (step {})  distance to exact {:.1e} (step {}) on {}  to Clarabel {:.1e} (step {}){}{}  {}",
        w.checked,
        w.violation.0,
        w.violation.1,
        w.stationarity.0,
        w.stationarity.1,
        w.certificate.0,
        w.certificate.1,
        w.exact.0,
        w.exact.1,
        w.exact_n,
        w.clarabel.0,
        w.clarabel.1,
        if w.inexact > 0 {
            format!(
                ", no exact reference for {} (to Clarabel {:.1e}, step {})",
                w.inexact, w.inexact_clarabel.0, w.inexact_clarabel.1
            )
        } else {
            String::new()
        },
        match (w.clarabel_failed, w.from_solution) {
            (0, 0) => String::new(),
            (f, s) => format!(
                ", Clarabel failed on {f}, exact reference from the solution's own active set on {s}"
            ),
        },
        if ok { "ok" } else { "BEYOND TOLERANCE" }
    );
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let worst = check_dump(&a)?;
    let mut ok = true;
    for (f, w) in &worst {
        let within = w.within(&a);
        ok &= within;
        filter_line(f, w, within);
    }
    let total: usize = worst.values().map(|w| w.checked).sum();
    let exact: usize = worst.values().map(|w| w.exact_n).sum();
    outln!(
        "verify-qp: {total} solved QPs checked, {exact} against an exact reference (relative to the input bound: violation <= {:e}, dumped duals <= {:e}, distance to exact <= {:e}, to Clarabel where none <= {:e}): {}",
        a.feasibility_tolerance,
        a.certificate_tolerance,
        a.exact_tolerance,
        a.clarabel_tolerance,
        if ok { "all within" } else { "NOT all within" }
    );
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
