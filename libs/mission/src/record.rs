//! One control step's record, and the telemetry CSV files built from it.
//!
//! * `telemetry.csv` — deterministic: bit-for-bit identical between the in-process run
//!   and the lock-step partition (floats printed in Rust's shortest round-trip form).
//! * `timing.csv` — wall-clock solve times of the filters (not reproducible by nature).

use nalgebra::Vector3;
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
    pub obs: Observation,
    /// Nominal commands: force in F_H [N], torque in F_B [N m], joint torques [N m].
    pub f_h_nom: Vector3<f64>,
    pub tau_b_nom: Vector3<f64>,
    pub tau_m_nom: Vector7,
    pub translational: TranslationalOutput,
    pub attitude: AttitudeOutput,
    pub robotic: RoboticOutput,
    /// The command applied to the simulator over the next control period.
    pub applied: Command,
}

impl StepRecord {
    /// All barrier values in [`crate::constraint_names`] order.
    pub fn h(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(51);
        v.extend(self.translational.report.h);
        v.extend(self.attitude.report.h);
        v.extend(self.robotic.report.h);
        v
    }

    /// Total safety-layer solve time of this step [µs].
    pub fn solve_time_us(&self) -> [f64; 4] {
        let t = self.translational.report.solve_time_ns as f64 / 1e3;
        let a = self.attitude.report.solve_time_ns as f64 / 1e3;
        let r = self.robotic.report.solve_time_ns as f64 / 1e3;
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
    for f in ["translational", "attitude", "robotic"] {
        c.push(format!("{f}_status"));
        c.push(format!("{f}_iterations"));
        c.push(format!("{f}_active"));
        c.push(format!("{f}_faults"));
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
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
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
    r.h().into_iter().for_each(&mut f);
    for (status, iters, active, faults) in [
        (
            r.translational.report.status,
            r.translational.report.iterations,
            r.translational.report.active,
            r.translational.report.faults,
        ),
        (
            r.attitude.report.status,
            r.attitude.report.iterations,
            r.attitude.report.active,
            r.attitude.report.faults,
        ),
        (
            r.robotic.report.status,
            r.robotic.report.iterations,
            r.robotic.report.active,
            r.robotic.report.faults,
        ),
    ] {
        v.push((status as u8).to_string());
        v.push(iters.to_string());
        v.push(active.to_string());
        v.push(faults.to_string());
    }
    v.join(",")
}

/// Formats one record as a `timing.csv` line.
pub fn timing_line(r: &StepRecord) -> String {
    let t = r.solve_time_us();
    format!("{},{},{},{},{},{}", r.step, r.t, t[0], t[1], t[2], t[3])
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
