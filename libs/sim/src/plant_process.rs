//! A plant in a child process (`safe-capture run --basilisk`, the partition's simulator
//! with `[simulator] plant`): Basilisk propagates the true state, the process that started
//! it keeps everything else (docs/SIMULATOR.md, "Basilisk in the loop").
//!
//! Protocol, one line per message over the child's stdin/stdout, numbers as shortest
//! round-trip decimals (Rust `{:?}`, Python `repr`), so nothing is lost in transit:
//! * `init <41 numbers>` ([`SimState::to_array`]) → `ready`
//! * `step <physics step s> <substeps> <13 numbers: f_B, τ_B, τ_M>` → `substeps` lines
//!   `state <41 numbers>`
//! * `stop` → the child exits.
//!
//! Any other reply, or `error <message>`, ends the run as a simulator failure.

use crate::{Command, Plant, PlantError, SIM_STATE_LEN, SimState};
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::process::{Child, ChildStdin, ChildStdout, Command as Process, Stdio};

pub struct ProcessPlant {
    child: Child,
    stdin: BufWriter<ChildStdin>,
    stdout: BufReader<ChildStdout>,
    what: String,
}

fn numbers(xs: &[f64]) -> String {
    xs.iter()
        .map(|x| format!("{x:?}"))
        .collect::<Vec<_>>()
        .join(" ")
}

impl ProcessPlant {
    /// Starts `program args…`; its stderr goes to ours.
    pub fn spawn(program: &std::path::Path, args: &[String]) -> Result<Self, PlantError> {
        let what = format!("{} {}", program.display(), args.join(" "));
        let mut child = Process::new(program)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .map_err(|e| PlantError(format!("cannot start the plant `{what}`: {e}")))?;
        let stdin = BufWriter::new(child.stdin.take().expect("piped stdin"));
        let stdout = BufReader::new(child.stdout.take().expect("piped stdout"));
        Ok(Self {
            child,
            stdin,
            stdout,
            what,
        })
    }

    fn send(&mut self, line: &str) -> Result<(), PlantError> {
        writeln!(self.stdin, "{line}")
            .and_then(|_| self.stdin.flush())
            .map_err(|e| PlantError(format!("plant `{}` gone: {e}", self.what)))
    }

    fn receive(&mut self) -> Result<String, PlantError> {
        let mut line = String::new();
        match self.stdout.read_line(&mut line) {
            Ok(0) => Err(PlantError(format!("plant `{}` exited", self.what))),
            Ok(_) => {
                let line = line.trim_end().to_string();
                match line.strip_prefix("error ") {
                    Some(e) => Err(PlantError(format!("plant: {e}"))),
                    None => Ok(line),
                }
            }
            Err(e) => Err(PlantError(format!("plant `{}`: {e}", self.what))),
        }
    }
}

impl Plant for ProcessPlant {
    fn start(&mut self, state: &SimState) -> Result<(), PlantError> {
        self.send(&format!("init {}", numbers(&state.to_array())))?;
        match self.receive()?.as_str() {
            "ready" => Ok(()),
            other => Err(PlantError(format!(
                "plant: expected `ready`, got `{other}`"
            ))),
        }
    }

    fn propagate(
        &mut self,
        cmd: &Command,
        physics_step: f64,
        substeps: usize,
    ) -> Result<Vec<SimState>, PlantError> {
        let u = cmd.as_vector();
        self.send(&format!(
            "step {physics_step:?} {substeps} {}",
            numbers(u.as_slice())
        ))?;
        (0..substeps)
            .map(|_| {
                let line = self.receive()?;
                let body = line.strip_prefix("state ").ok_or_else(|| {
                    PlantError(format!("plant: expected `state …`, got `{line}`"))
                })?;
                let v: Vec<f64> = body
                    .split_whitespace()
                    .map(|x| {
                        x.parse::<f64>()
                            .map_err(|e| PlantError(format!("plant: `{x}`: {e}")))
                    })
                    .collect::<Result<_, _>>()?;
                let a: [f64; SIM_STATE_LEN] = v.try_into().map_err(|v: Vec<f64>| {
                    PlantError(format!(
                        "plant: {} numbers in a state, {SIM_STATE_LEN} expected",
                        v.len()
                    ))
                })?;
                Ok(SimState::from_array(&a))
            })
            .collect()
    }
}

impl Drop for ProcessPlant {
    fn drop(&mut self) {
        let _ = self.send("stop");
        // give it a moment to exit, then make sure
        for _ in 0..50 {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
