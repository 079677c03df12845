//! One control step's record, and the telemetry CSV files built from it.
//!
//! * `telemetry.csv` — deterministic: bit-for-bit identical between the in-process run
//!   and the lock-step partition (floats printed in Rust's shortest round-trip form).
//! * `timing.csv` — solve times of the filters, wall clock and the thread's CPU time (not
//!   reproducible by nature).

use nalgebra::Vector3;
use sc_cbf::monitor::Barriers;
use sc_cbf::{AttitudeOutput, RoboticOutput, TranslationalOutput};
use sc_multibody::Vector7;
use sc_sim::{Command, Observation};
use std::io::Write;

/// Everything that happened in one control step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRecord {
    pub step: u64,
    pub t: f64,
    /// Index of the mission phase (0-based, in the scenario's order).
    pub phase: usize,
    /// The TRUE state's observation (the simulator's); the controllers and filters saw
    /// the navigation's estimate, `navigation_error` away from it.
    pub obs: Observation,
    /// The realised navigation errors of this step (`None`: the `exact` profile).
    pub navigation_error: Option<sc_sim::NavigationError>,
    /// Every barrier on knowledge — the navigation's estimate with the declared model,
    /// what the filters act on — in [`crate::constraint_names`] order (`None`: the
    /// `exact` profile, where knowledge is the truth).
    pub knowledge_barriers: Option<Barriers>,
    /// The navigation's estimate was missing or refused and the simulator's own
    /// navigation substituted (`sc_sim::navigation`; `fault::NAVIGATION_REJECTED`).
    pub navigation_rejected: bool,
    /// Nominal commands: force in F_H [N], torque in F_B [N m], joint torques [N m].
    pub f_h_nom: Vector3<f64>,
    pub tau_b_nom: Vector3<f64>,
    pub tau_m_nom: Vector7,
    pub translational: TranslationalOutput,
    pub attitude: AttitudeOutput,
    pub robotic: RoboticOutput,
    /// The command applied to the simulator over the next control period.
    pub applied: Command,
    /// Every barrier at this step, from the true state ([`sc_cbf::monitor`]), in
    /// [`crate::constraint_names`] order — never from a filter's report.
    pub barriers: Barriers,
    /// The smallest value of every barrier over the physics steps since the previous
    /// control step (the state of this step included); at step 0 the values of this step.
    pub barriers_between: Barriers,
}

impl StepRecord {
    /// All barrier values at this step, from the true state, in
    /// [`crate::constraint_names`] order.
    pub fn h(&self) -> Vec<f64> {
        self.barriers.to_vec()
    }

    /// Total safety-layer solve time of this step [µs].
    pub fn solve_time_us(&self) -> [f64; 4] {
        let t = self.translational.report.solve_time_ns as f64 / 1e3;
        let a = self.attitude.report.solve_time_ns as f64 / 1e3;
        let r = self.robotic.report.solve_time_ns as f64 / 1e3;
        [t, a, r, t + a + r]
    }

    /// The CPU time the filters' thread spent in each filter and in all three [µs]: their
    /// own work, without preemption (the wall time is [`Self::solve_time_us`]).
    pub fn solve_cpu_us(&self) -> [f64; 4] {
        let t = self.translational.report.solve_cpu_ns as f64 / 1e3;
        let a = self.attitude.report.solve_cpu_ns as f64 / 1e3;
        let r = self.robotic.report.solve_cpu_ns as f64 / 1e3;
        [t, a, r, t + a + r]
    }

    /// The wall time spent inside the QP solver by each filter and by all three [µs]: the
    /// solves only, without building the rows or certifying the command.
    pub fn qp_time_us(&self) -> [f64; 4] {
        let t = self.translational.report.qp_time_ns as f64 / 1e3;
        let a = self.attitude.report.qp_time_ns as f64 / 1e3;
        let r = self.robotic.report.qp_time_ns as f64 / 1e3;
        [t, a, r, t + a + r]
    }
}

fn push3(cols: &mut Vec<String>, stem: &str, unit: &str) {
    for ax in ["x", "y", "z"] {
        cols.push(format!("{stem}_{ax}{unit}"));
    }
}

/// Columns of `telemetry.csv`, in order. Frames: `_h` Hill, `_r` reference, `_b` base;
/// quaternions scalar-first; SI units in the names.
pub fn telemetry_columns() -> Vec<String> {
    let mut c: Vec<String> = vec!["step".into(), "t_s".into(), "phase".into()];
    push3(&mut c, "r_h", "_m");
    push3(&mut c, "v_h", "_m_s");
    push3(&mut c, "r_r", "_m");
    push3(&mut c, "v_r", "_m_s");
    push3(&mut c, "com_r", "_m");
    push3(&mut c, "com_v_r", "_m_s");
    push3(&mut c, "com_h", "_m");
    push3(&mut c, "com_v_h", "_m_s");
    for i in 0..4 {
        c.push(format!("q{i}_rb"));
    }
    push3(&mut c, "omega_b", "_rad_s");
    for i in 1..=7 {
        c.push(format!("theta_{i}_rad"));
    }
    for i in 1..=7 {
        c.push(format!("theta_dot_{i}_rad_s"));
    }
    for i in 0..4 {
        c.push(format!("q{i}_rt"));
    }
    push3(&mut c, "omega_t", "_rad_s");
    push3(&mut c, "sync_error_b", "_rad_s");
    c.push("grasp_distance_m".into());
    push3(&mut c, "ee_r", "_m");
    push3(&mut c, "grasp_r", "_m");
    push3(&mut c, "f_h_nom", "_n");
    push3(&mut c, "tau_b_nom", "_nm");
    for i in 1..=7 {
        c.push(format!("tau_m_nom_{i}_nm"));
    }
    push3(&mut c, "f_h_safe", "_n");
    push3(&mut c, "f_b_applied", "_n");
    push3(&mut c, "tau_b_applied", "_nm");
    for i in 1..=7 {
        c.push(format!("tau_m_applied_{i}_nm"));
    }
    for n in crate::constraint_names() {
        c.push(format!("h_{n}"));
    }
    for n in crate::constraint_names() {
        c.push(format!("hmin_{n}"));
    }
    for f in ["translational", "attitude", "robotic"] {
        c.push(format!("{f}_status"));
        c.push(format!("{f}_iterations"));
        c.push(format!("{f}_active"));
        c.push(format!("{f}_faults"));
        c.push(format!("{f}_violation"));
    }
    c
}

/// Columns of `timing.csv`.
pub fn timing_columns() -> Vec<String> {
    [
        "step",
        "t_s",
        "translational_us",
        "attitude_us",
        "robotic_us",
        "total_us",
        "translational_cpu_us",
        "attitude_cpu_us",
        "robotic_cpu_us",
        "total_cpu_us",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

/// Columns of `navigation.csv` (written when the scenario declares an uncertainty, or a
/// navigation's estimate was refused): whether the step's estimate was refused and the
/// simulator's own navigation substituted (`navigation_rejected`, 0/1), the realised
/// navigation errors of each control step (`nav_err_*`, each against the truth at the
/// measurement's time, docs/UNCERTAINTY.md) and every barrier on knowledge (`hk_*`: the
/// estimate with the declared model — what the filters saw; `h_*` in `telemetry.csv` is
/// the truth's). Without a declared uncertainty the errors and barriers on knowledge are
/// empty (knowledge is the truth).
pub fn knowledge_columns() -> Vec<String> {
    let mut c: Vec<String> = vec!["step".into(), "t_s".into(), "navigation_rejected".into()];
    c.extend(
        sc_sim::uncertainty::NAVIGATION_ERROR_NAMES
            .iter()
            .map(|n| format!("nav_err_{n}")),
    );
    c.extend(crate::constraint_names().iter().map(|n| format!("hk_{n}")));
    c
}

/// One record as a `navigation.csv` line.
pub fn knowledge_line(r: &StepRecord) -> String {
    let mut v: Vec<String> = vec![
        r.step.to_string(),
        r.t.to_string(),
        u8::from(r.navigation_rejected).to_string(),
    ];
    let n_err = sc_sim::uncertainty::NAVIGATION_ERROR_NAMES.len();
    match r.navigation_error {
        Some(e) => v.extend(e.values().iter().map(|x| x.to_string())),
        None => v.extend(std::iter::repeat_n(String::new(), n_err)),
    }
    match r.knowledge_barriers {
        Some(h) => v.extend(h.iter().map(|x| x.to_string())),
        None => v.extend(std::iter::repeat_n(String::new(), sc_cbf::monitor::N_ALL)),
    }
    v.join(",")
}

/// Whether `records` have anything for `navigation.csv`: knowledge apart from the truth
/// (a declared uncertainty) or a refused estimate.
fn has_knowledge(records: &[StepRecord]) -> bool {
    records
        .iter()
        .any(|r| r.navigation_error.is_some() || r.navigation_rejected)
}

/// Writes `navigation.csv` at `path` when the records have knowledge apart from the
/// truth (a declared uncertainty) or a refused estimate; nothing otherwise. `safe-capture
/// run` and the partition's recorder write it with this one function.
pub fn write_knowledge(path: &std::path::Path, records: &[StepRecord]) -> std::io::Result<()> {
    use std::io::Write;
    if !has_knowledge(records) {
        return Ok(());
    }
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "{}", knowledge_columns().join(","))?;
    for r in records {
        writeln!(f, "{}", knowledge_line(r))?;
    }
    f.flush()
}

/// Reads `navigation.csv` (written by [`write_knowledge`]) back into `records`, the
/// steps of the same run's telemetry: each line's navigation errors and barriers on
/// knowledge go to the record of its step, bit for bit.
pub fn read_knowledge(text: &str, records: &mut [StepRecord]) -> Result<(), TelemetryError> {
    const FILE: &str = "navigation.csv";
    let mut names = knowledge_columns();
    let mut lines = text.lines();
    let header = lines.next();
    // a file written before the refusal flag (0e6ee4a) has no `navigation_rejected`
    let flagged = header == Some(names.join(",").as_str());
    if !flagged {
        names.retain(|n| n != "navigation_rejected");
        if header != Some(names.join(",").as_str()) {
            return Err(TelemetryError::Header { file: FILE });
        }
    }
    let mut rows = 0;
    for (i, line) in lines.enumerate() {
        let n = i + 2;
        let mut c = Fields::new(FILE, n, line, &names)?;
        let step: u64 = c.parse("a step")?;
        let t: f64 = c.parse("a time")?;
        let r = records
            .get_mut(i)
            .filter(|r| r.step == step && same_bits(r.t, t))
            .ok_or(TelemetryError::KnowledgeStep { line: n, step })?;
        r.navigation_rejected = flagged
            && match c.parse::<u8>("0 or 1")? {
                0 => false,
                1 => true,
                v => return Err(c.invalid(&v.to_string(), "0 or 1")),
            };
        r.navigation_error = c
            .optional::<10>("a number")?
            .map(|e| sc_sim::uncertainty::NavigationError::from_values(&e));
        r.knowledge_barriers = c.optional::<{ sc_cbf::monitor::N_ALL }>("a number")?;
        rows += 1;
    }
    if rows != records.len() {
        return Err(TelemetryError::KnowledgeRows {
            rows,
            steps: records.len(),
        });
    }
    Ok(())
}

/// Formats one record as a `telemetry.csv` line (without newline).
pub fn telemetry_line(r: &StepRecord) -> String {
    let o = &r.obs;
    let mut v: Vec<String> = vec![r.step.to_string(), r.t.to_string(), r.phase.to_string()];
    let mut f = |x: f64| v.push(x.to_string());
    o.r_h.iter().for_each(|x| f(*x));
    o.v_h.iter().for_each(|x| f(*x));
    o.r_r.iter().for_each(|x| f(*x));
    o.v_r.iter().for_each(|x| f(*x));
    o.com_r.iter().for_each(|x| f(*x));
    o.com_v_r.iter().for_each(|x| f(*x));
    o.com_h.iter().for_each(|x| f(*x));
    o.com_v_h.iter().for_each(|x| f(*x));
    o.q_rb.iter().for_each(|x| f(*x));
    o.omega_b.iter().for_each(|x| f(*x));
    o.theta.iter().for_each(|x| f(*x));
    o.theta_dot.iter().for_each(|x| f(*x));
    o.q_rt.iter().for_each(|x| f(*x));
    o.omega_t.iter().for_each(|x| f(*x));
    o.sync_error().iter().for_each(|x| f(*x));
    f(o.grasp_distance());
    o.ee_r.iter().for_each(|x| f(*x));
    o.grasp_r.iter().for_each(|x| f(*x));
    r.f_h_nom.iter().for_each(|x| f(*x));
    r.tau_b_nom.iter().for_each(|x| f(*x));
    r.tau_m_nom.iter().for_each(|x| f(*x));
    r.translational.u.iter().for_each(|x| f(*x));
    r.applied.force_b.iter().for_each(|x| f(*x));
    r.applied.torque_b.iter().for_each(|x| f(*x));
    r.applied.tau.iter().for_each(|x| f(*x));
    r.barriers.iter().for_each(|x| f(*x));
    r.barriers_between.iter().for_each(|x| f(*x));
    for (status, iters, active, faults, violation) in [
        (
            r.translational.report.status,
            r.translational.report.iterations,
            r.translational.report.active,
            r.translational.report.faults,
            r.translational.report.violation,
        ),
        (
            r.attitude.report.status,
            r.attitude.report.iterations,
            r.attitude.report.active,
            r.attitude.report.faults,
            r.attitude.report.violation,
        ),
        (
            r.robotic.report.status,
            r.robotic.report.iterations,
            r.robotic.report.active,
            r.robotic.report.faults,
            r.robotic.report.violation,
        ),
    ] {
        v.push((status as u8).to_string());
        v.push(iters.to_string());
        v.push(active.to_string());
        v.push(faults.to_string());
        v.push(violation.to_string());
    }
    v.join(",")
}

/// Formats one record as a `timing.csv` line.
pub fn timing_line(r: &StepRecord) -> String {
    let t = r.solve_time_us();
    let c = r.solve_cpu_us();
    format!(
        "{},{},{},{},{},{},{},{},{},{}",
        r.step, r.t, t[0], t[1], t[2], t[3], c[0], c[1], c[2], c[3]
    )
}

/// Writes `telemetry.csv` and `timing.csv` as records arrive.
pub struct TelemetryWriter<W: Write> {
    telemetry: W,
    timing: W,
}

impl<W: Write> TelemetryWriter<W> {
    /// Starts both files with their headers.
    pub fn new(mut telemetry: W, mut timing: W) -> std::io::Result<Self> {
        writeln!(telemetry, "{}", telemetry_columns().join(","))?;
        writeln!(timing, "{}", timing_columns().join(","))?;
        Ok(Self { telemetry, timing })
    }

    /// Appends one record.
    pub fn write(&mut self, r: &StepRecord) -> std::io::Result<()> {
        writeln!(self.telemetry, "{}", telemetry_line(r))?;
        writeln!(self.timing, "{}", timing_line(r))
    }

    /// Flushes both files.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.telemetry.flush()?;
        self.timing.flush()
    }
}

/// Why `telemetry.csv` and `timing.csv` could not be read back ([`parse_telemetry`]):
/// each names the file and the line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TelemetryError {
    #[error("{file}: the header is not this version's columns")]
    Header { file: &'static str },
    #[error("{file} line {line}: {found} fields, the header has {expected}")]
    FieldCount {
        file: &'static str,
        line: usize,
        found: usize,
        expected: usize,
    },
    #[error("{file} line {line}: `{column}` = `{value}` is not {what}")]
    Field {
        file: &'static str,
        line: usize,
        column: String,
        value: String,
        what: &'static str,
    },
    #[error("{file} line {line}: solve time {us} us is not a finite number >= 0")]
    SolveTime {
        file: &'static str,
        line: usize,
        us: f64,
    },
    #[error(
        "{file} line {line}: {column} does not match the state it derives from (a corrupt file or another version)"
    )]
    Derived {
        file: &'static str,
        line: usize,
        column: &'static str,
    },
    #[error("{file} line {line}: filter status {value} is not one of 0..=3")]
    Status {
        file: &'static str,
        line: usize,
        value: u8,
    },
    #[error("timing.csv: ends before step {step} (telemetry.csv line {line})")]
    TimingEnds { step: u64, line: usize },
    #[error(
        "timing.csv line {line}: step {timing_step} at t = {timing_t} s, telemetry.csv has step {step} at t = {t} s"
    )]
    StepMismatch {
        line: usize,
        timing_step: u64,
        timing_t: f64,
        step: u64,
        t: f64,
    },
    #[error(
        "telemetry.csv line {line}: read {read} of {columns} columns (the reader is out of step with telemetry_columns)"
    )]
    OutOfStep {
        line: usize,
        read: usize,
        columns: usize,
    },
    #[error("timing.csv: more rows than the {rows} of telemetry.csv")]
    TimingLonger { rows: usize },
    #[error("navigation.csv line {line}: step {step} is not the step of telemetry.csv's row")]
    KnowledgeStep { line: usize, step: u64 },
    #[error("navigation.csv: {rows} rows for the {steps} steps of telemetry.csv")]
    KnowledgeRows { rows: usize, steps: usize },
}

/// Bit-for-bit equality of two floats (NaN equals NaN).
fn same_bits(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// The comma-separated fields of one CSV line, read in order.
struct Fields<'a> {
    file: &'static str,
    line: usize,
    names: &'a [String],
    fields: Vec<&'a str>,
    next: usize,
}

impl<'a> Fields<'a> {
    fn new(
        file: &'static str,
        line: usize,
        text: &'a str,
        names: &'a [String],
    ) -> Result<Self, TelemetryError> {
        let fields: Vec<&str> = text.split(',').collect();
        if fields.len() != names.len() {
            return Err(TelemetryError::FieldCount {
                file,
                line,
                found: fields.len(),
                expected: names.len(),
            });
        }
        Ok(Self {
            file,
            line,
            names,
            fields,
            next: 0,
        })
    }

    /// The next `N` fields as numbers, or `None` when all of them are empty.
    fn optional<const N: usize>(
        &mut self,
        what: &'static str,
    ) -> Result<Option<[f64; N]>, TelemetryError> {
        let at = self.next;
        if self.fields[at..at + N].iter().all(|f| f.is_empty()) {
            self.next += N;
            return Ok(None);
        }
        let mut v = [0.0; N];
        for x in &mut v {
            *x = self.parse(what)?;
        }
        Ok(Some(v))
    }

    /// The error for the value `v` of the last field read, which is not `what`.
    fn invalid(&self, v: &str, what: &'static str) -> TelemetryError {
        TelemetryError::Field {
            file: self.file,
            line: self.line,
            column: self.names[self.next - 1].clone(),
            value: v.to_string(),
            what,
        }
    }

    fn raw(&mut self) -> (&'a str, &'a str) {
        let i = self.next;
        self.next += 1;
        (self.fields[i], self.names[i].as_str())
    }

    fn parse<T: std::str::FromStr>(&mut self, what: &'static str) -> Result<T, TelemetryError> {
        let (v, name) = self.raw();
        v.parse().map_err(|_| TelemetryError::Field {
            file: self.file,
            line: self.line,
            column: name.to_string(),
            value: v.to_string(),
            what,
        })
    }

    fn f(&mut self) -> Result<f64, TelemetryError> {
        self.parse("a number")
    }

    fn array<const N: usize>(&mut self) -> Result<[f64; N], TelemetryError> {
        let mut a = [0.0; N];
        for x in a.iter_mut() {
            *x = self.f()?;
        }
        Ok(a)
    }

    fn v3(&mut self) -> Result<Vector3<f64>, TelemetryError> {
        Ok(Vector3::from(self.array::<3>()?))
    }

    fn v7(&mut self) -> Result<Vector7, TelemetryError> {
        Ok(Vector7::from(self.array::<7>()?))
    }

    /// A solve time written in µs (of whole ns, see [`timing_line`]) back in ns.
    fn ns(&mut self) -> Result<u64, TelemetryError> {
        let us = self.f()?;
        if !(us.is_finite() && us >= 0.0) {
            return Err(TelemetryError::SolveTime {
                file: self.file,
                line: self.line,
                us,
            });
        }
        Ok((us * 1e3).round() as u64)
    }

    /// A derived column (`column`) checked against the state it comes from.
    fn check(&self, column: &'static str, ok: bool) -> Result<(), TelemetryError> {
        if ok {
            Ok(())
        } else {
            Err(TelemetryError::Derived {
                file: self.file,
                line: self.line,
                column,
            })
        }
    }

    /// One filter's report: status, iterations, active set, faults, violation (the
    /// solve times come from `timing.csv`).
    fn report<const N: usize>(
        &mut self,
        r: &mut sc_cbf::FilterReport<N>,
    ) -> Result<(), TelemetryError> {
        r.status = status_of(self.parse("a filter status")?, self.file, self.line)?;
        r.iterations = self.parse("an iteration count")?;
        r.active = self.parse("an active-set bitset")?;
        r.faults = self.parse("a fault bitset")?;
        r.violation = self.f()?;
        Ok(())
    }
}

fn status_of(
    value: u8,
    file: &'static str,
    line: usize,
) -> Result<sc_cbf::FilterStatus, TelemetryError> {
    use sc_cbf::FilterStatus as S;
    [S::Skipped, S::Solved, S::Relaxed, S::Fallback]
        .into_iter()
        .find(|s| *s as u8 == value)
        .ok_or(TelemetryError::Status { file, line, value })
}

/// Rebuilds the records of a run from its `telemetry.csv` and `timing.csv` (as written
/// by [`TelemetryWriter`], by `safe-capture run` or the partition's recorder), e.g. to
/// measure a run that executed in other processes.
///
/// Everything the files hold comes back with the same bits (floats are written in
/// shortest round-trip form, solve times in µs of whole ns), hence so does everything
/// [`crate::summarize`] reads. With `filtered` (the filters were in the loop) the
/// attitude and robotic filters' safe commands are the applied ones and the
/// translational one's actuated force is the applied force; without, they are NaN.
/// `obs.grasp_b` is recomputed from the attitude and positions
/// ([`Observation::grasp_in_base`]), the derived columns (synchronisation error, grasp
/// distance) are checked against the state they come from. Not in the files, so NaN:
/// the filters' own barrier values and CBF conditions (the records' barriers are the
/// monitor's, which the files hold), the Hill frame's attitude and rates,
/// the mean motion, the target's angular acceleration, the grasping point's velocity
/// and acceleration, the end-effector in F_B and its velocity.
pub fn parse_telemetry(
    telemetry: &str,
    timing: &str,
    filtered: bool,
) -> Result<Vec<StepRecord>, TelemetryError> {
    let tel_names = telemetry_columns();
    let tim_names = timing_columns();
    let mut tel = telemetry.lines();
    let mut tim = timing.lines();
    if tel.next() != Some(tel_names.join(",").as_str()) {
        return Err(TelemetryError::Header {
            file: "telemetry.csv",
        });
    }
    if tim.next() != Some(tim_names.join(",").as_str()) {
        return Err(TelemetryError::Header { file: "timing.csv" });
    }
    let mut out = Vec::new();
    for (i, line) in tel.enumerate() {
        let n = i + 2;
        let mut c = Fields::new("telemetry.csv", n, line, &tel_names)?;
        let mut record = read_record(&mut c, filtered)?;
        // solve times from the same step of timing.csv
        let tl = tim.next().ok_or(TelemetryError::TimingEnds {
            step: record.step,
            line: n,
        })?;
        let mut tc = Fields::new("timing.csv", n, tl, &tim_names)?;
        read_solve_times(&mut tc, &mut record)?;
        if c.next != tel_names.len() {
            return Err(TelemetryError::OutOfStep {
                line: n,
                read: c.next,
                columns: tel_names.len(),
            });
        }
        out.push(record);
    }
    if tim.next().is_some_and(|l| !l.is_empty()) {
        return Err(TelemetryError::TimingLonger { rows: out.len() });
    }
    Ok(out)
}

/// One line of `telemetry.csv` (see [`parse_telemetry`]) as a record without its solve
/// times.
fn read_record(c: &mut Fields, filtered: bool) -> Result<StepRecord, TelemetryError> {
    let nan3 = Vector3::from_element(f64::NAN);
    let nan7 = Vector7::from_element(f64::NAN);
    let step: u64 = c.parse("a step number")?;
    let t = c.f()?;
    let phase: usize = c.parse("a phase index")?;
    let obs = read_observation(c, step, t)?;
    let f_h_nom = c.v3()?;
    let tau_b_nom = c.v3()?;
    let tau_m_nom = c.v7()?;
    let f_h_safe = c.v3()?;
    let applied = Command {
        force_b: c.v3()?,
        torque_b: c.v3()?,
        tau: c.v7()?,
    };
    let mut translational = sc_cbf::TranslationalOutput {
        u: f_h_safe,
        actuated: if filtered { applied.force_b } else { nan3 },
        report: Default::default(),
    };
    let mut attitude = sc_cbf::AttitudeOutput {
        u: if filtered { applied.torque_b } else { nan3 },
        actuated: if filtered { applied.torque_b } else { nan3 },
        report: Default::default(),
    };
    let mut robotic = sc_cbf::RoboticOutput {
        u: if filtered { applied.tau } else { nan7 },
        actuated: if filtered { applied.tau } else { nan7 },
        report: Default::default(),
    };
    let mut barriers = [0.0; sc_cbf::monitor::N_ALL];
    for h in barriers.iter_mut() {
        *h = c.f()?;
    }
    let mut barriers_between = [0.0; sc_cbf::monitor::N_ALL];
    for h in barriers_between.iter_mut() {
        *h = c.f()?;
    }
    c.report(&mut translational.report)?;
    c.report(&mut attitude.report)?;
    c.report(&mut robotic.report)?;
    Ok(StepRecord {
        step,
        t,
        phase,
        obs,
        navigation_error: None,
        knowledge_barriers: None,
        // not in the telemetry: the live summary and the simulator's log have it
        navigation_rejected: false,
        f_h_nom,
        tau_b_nom,
        tau_m_nom,
        translational,
        attitude,
        robotic,
        applied,
        barriers,
        barriers_between,
    })
}

/// The state columns of a `telemetry.csv` line (after step, time and phase) as the
/// observation of step `step` at `t`, the derived columns checked against it.
fn read_observation(c: &mut Fields, step: u64, t: f64) -> Result<Observation, TelemetryError> {
    let nan3 = Vector3::from_element(f64::NAN);
    let r_h = c.v3()?;
    let v_h = c.v3()?;
    let r_r = c.v3()?;
    let v_r = c.v3()?;
    let com_r = c.v3()?;
    let com_v_r = c.v3()?;
    let com_h = c.v3()?;
    let com_v_h = c.v3()?;
    let q_rb = c.array::<4>()?;
    let omega_b = c.v3()?;
    let theta = c.v7()?;
    let theta_dot = c.v7()?;
    let q_rt = c.array::<4>()?;
    let omega_t = c.v3()?;
    let sync_error = c.v3()?;
    let grasp_distance = c.f()?;
    let ee_r = c.v3()?;
    let grasp_r = c.v3()?;
    let obs = Observation {
        step,
        t,
        r_h,
        v_h,
        r_r,
        v_r,
        q_hr: [f64::NAN; 4],
        omega_h: nan3,
        omega_dot_h: nan3,
        mean_motion: f64::NAN,
        q_rb,
        omega_b,
        theta,
        theta_dot,
        q_rt,
        omega_t,
        omega_dot_t: nan3,
        grasp_r,
        grasp_v_r: nan3,
        grasp_a_r: nan3,
        grasp_b: Observation::grasp_in_base(&q_rb, &r_r, &grasp_r),
        ee_b: nan3,
        ee_r,
        ee_v_r: nan3,
        com_h,
        com_v_h,
        com_r,
        com_v_r,
    };
    let s = obs.sync_error();
    c.check(
        "sync_error_b",
        (0..3).all(|k| same_bits(s[k], sync_error[k])),
    )?;
    c.check(
        "grasp_distance_m",
        same_bits(obs.grasp_distance(), grasp_distance),
    )?;
    Ok(obs)
}

/// The solve times of `r` from its line of `timing.csv` (the same step at the same time).
fn read_solve_times(tc: &mut Fields, r: &mut StepRecord) -> Result<(), TelemetryError> {
    let tstep: u64 = tc.parse("a step number")?;
    let tt = tc.f()?;
    if tstep != r.step || !same_bits(tt, r.t) {
        return Err(TelemetryError::StepMismatch {
            line: tc.line,
            timing_step: tstep,
            timing_t: tt,
            step: r.step,
            t: r.t,
        });
    }
    r.translational.report.solve_time_ns = tc.ns()?;
    r.attitude.report.solve_time_ns = tc.ns()?;
    r.robotic.report.solve_time_ns = tc.ns()?;
    tc.ns()?; // total_us
    r.translational.report.solve_cpu_ns = tc.ns()?;
    r.attitude.report.solve_cpu_ns = tc.ns()?;
    r.robotic.report.solve_cpu_ns = tc.ns()?;
    Ok(())
}
