//! `safe-capture redteam --partition` and `launch --hostile`: the red team through the
//! process partition, with hostile partner processes (`scripts/python/hostile_nominal.py`,
//! strategies in `sc_redteam::partners`) in place of the nominal controllers.
//!
//! Per case: `sc_ground::launch` with the user's partition config, the campaign's
//! scenario, lock-step, a run id of its own and output in `cases/<case>/`; the hostile
//! process replaces the nominal role(s) of the case's target. The recorder's telemetry is
//! read back into step records (`montecarlo_partition::read_run`: every tick recorded, no
//! sample of a flight-side service missing) and measured by `sc_redteam::campaign::measure`
//! — every barrier from the simulator's true state at every physics step, every applied
//! command checked — exactly as in process.

use crate::montecarlo_partition::read_run;
use anyhow::Context;
use sc_ground::launcher::interrupted;
use sc_ground::{ClockMode, LaunchOptions, launch};
use sc_mission::Setup;
use sc_redteam::partners::roles;
use sc_redteam::{CaseLabel, CaseResult};
use std::path::{Path, PathBuf};

/// The hostile partner process and how the partition runs it.
pub struct Partners {
    /// Python interpreter with the `iceoryx2` package.
    pub python: PathBuf,
    /// `hostile_nominal.py`.
    pub script: PathBuf,
    /// Partition config (schedule, deadlines, the other roles' executables).
    pub config: PathBuf,
    /// The scenario every process runs (the campaign's).
    pub scenario: PathBuf,
    /// Stop each run after this many ticks (0: the whole mission).
    pub max_ticks: u64,
    /// Lock-step deadlines as a multiple of the real-time ones.
    pub deadline_scale: Option<f64>,
    /// Lock-step (deterministic) or real time (the isolation measured on the clock).
    pub clock: ClockMode,
}

/// `scripts/.venv/bin/python` unless `SC_PYTHON` names another interpreter.
pub fn default_python() -> PathBuf {
    std::env::var_os("SC_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate::home::shipped("scripts/.venv/bin/python"))
}

fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

impl Partners {
    /// Checks that the interpreter imports iceoryx2 and the script exists.
    pub fn new(
        python: &Path,
        script: &Path,
        config: &Path,
        scenario: &Path,
        max_ticks: u64,
        deadline_scale: Option<f64>,
        clock: ClockMode,
    ) -> anyhow::Result<Self> {
        let ok = std::process::Command::new(python)
            .args(["-c", "import iceoryx2"])
            .output()
            .map(|o| o.status.success());
        if ok.ok() != Some(true) {
            anyhow::bail!(
                "--python {}: cannot run it or it cannot import iceoryx2 (create the venv with scripts/setup.sh or pass --python)",
                python.display()
            );
        }
        if !script.is_file() {
            anyhow::bail!("--partner {}: no such file", script.display());
        }
        Ok(Self {
            python: absolute(python),
            script: absolute(script),
            config: config.to_path_buf(),
            scenario: absolute(scenario),
            max_ticks,
            deadline_scale,
            clock,
        })
    }

    fn args(&self, role: &str, strategy: &str) -> Vec<String> {
        vec![
            self.script.display().to_string(),
            "--role".into(),
            role.into(),
            "--strategy".into(),
            strategy.into(),
        ]
    }

    /// Asks the script whether it understands the case (`--check`), before any run.
    pub fn check(&self, case: &CaseLabel) -> anyhow::Result<()> {
        for role in roles(case.target) {
            let out = std::process::Command::new(&self.python)
                .args(self.args(role, &case.strategy))
                .args(["--check", "--config"])
                .arg(&self.config)
                .output()
                .with_context(|| format!("running {}", self.python.display()))?;
            if !out.status.success() {
                anyhow::bail!(
                    "case {}: {}",
                    case.name(),
                    String::from_utf8_lossy(&out.stderr).trim()
                );
            }
        }
        Ok(())
    }

    /// The role overrides that put the hostile process in place of the case's nominals.
    pub fn overrides(&self, case: &CaseLabel) -> Vec<(String, String, Vec<String>)> {
        roles(case.target)
            .iter()
            .map(|role| {
                (
                    format!("nominal_{role}"),
                    self.python.display().to_string(),
                    self.args(role, &case.strategy),
                )
            })
            .collect()
    }

    /// Launch options of one run of `case` into `out` (run id `<tag>`).
    pub fn options(&self, case: &CaseLabel, out: &Path, tag: &str) -> LaunchOptions {
        LaunchOptions {
            config: self.config.clone(),
            out: out.to_path_buf(),
            run_id: Some(tag.into()),
            clock: Some(self.clock),
            max_ticks: Some(self.max_ticks),
            deadline_scale: match self.clock {
                ClockMode::LockStep => self.deadline_scale,
                _ => None,
            },
            scenario: Some(self.scenario.clone()),
            role_override: self.overrides(case),
            quiet: true,
            ..Default::default()
        }
    }

    /// Runs one case through the partition and measures it.
    pub fn run_case(
        &self,
        setup: &Setup,
        case: &CaseLabel,
        out: &Path,
        tag: &str,
    ) -> Result<CaseResult, String> {
        if interrupted() {
            return Err("interrupted".into());
        }
        let rep = launch(&self.options(case, out, tag))
            .map_err(|e| format!("partition: {}", e.to_string().replace('\n', " ")))?;
        if let Some(e) = &rep.error {
            return Err(format!("partition: {e} (exit code {})", rep.code));
        }
        if !rep.leftovers.is_empty() {
            return Err(format!(
                "partition: {} files left in /dev/shm: {:?}",
                rep.leftovers.len(),
                rep.leftovers
            ));
        }
        // Our own processes must end well; the hostile ones may crash or hang (the
        // launcher kills a hung one at teardown).
        let hostile: Vec<String> = roles(case.target)
            .iter()
            .map(|r| format!("nominal_{r}"))
            .collect();
        let failed: Vec<String> = rep
            .exits
            .iter()
            .filter(|e| !hostile.contains(&e.role))
            .filter(|e| !e.ended_well())
            .map(|e| format!("{} ({:?}/{:?})", e.role, e.code, e.signal))
            .collect();
        if !failed.is_empty() {
            return Err(format!(
                "partition: flight-side processes failed: {}; see {}",
                failed.join(", "),
                out.join("logs").display()
            ));
        }
        let services: Vec<String> = roles(case.target)
            .iter()
            .map(|r| format!("safe_capture/nominal/{r}"))
            .collect();
        let may_miss: Vec<&str> = services.iter().map(String::as_str).collect();
        let (records, end) = read_run(out, &may_miss)?;
        Ok(sc_redteam::campaign::measure(setup, case, &records, &end))
    }
}

/// Parses `--hostile <target>/<strategy>` of `launch`.
pub fn parse_hostile(s: &str) -> anyhow::Result<CaseLabel> {
    sc_redteam::partners::parse_partition_case(s)
        .map_err(anyhow::Error::msg)
        .context("--hostile")
}
