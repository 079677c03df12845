//! `config/partition.toml`: rate groups, deadlines, clock mode and which executable
//! serves each role. Parsed and validated at start-up; every error is one line.

use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::hosts::Hosts;
use sc_core::{PerSubsystem, Subsystem, SubsystemSet};
use sc_icd::{ROLES, Role};

/// Clock mode of the scheduler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ClockMode {
    /// Next tick as soon as the previous one completed (deterministic).
    LockStep,
    /// Ticks paced on the wall clock at the base period.
    RealTime,
}

/// One rate group.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RateGroup {
    pub name: String,
    /// Period [s].
    pub period_s: f64,
    /// Subsystems (`translational`, `attitude`, `robotic`) in causal order.
    pub members: Vec<String>,
}

/// Executable and placement of a role (`[roles.<name>]`; every key optional: a role
/// the config does not name runs the role table's executable, `sc_icd::ROLES`).
#[derive(Debug, Clone, Default, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RoleExec {
    /// Program: a bare name is looked up next to the launcher's executable (or in
    /// `SC_PARTITION_BIN_DIR`); a path is relative to the config file's directory.
    /// Absent: the role table's executable (`sc-<role>`).
    #[serde(default)]
    pub exec: String,
    /// Extra arguments (before the standard `--config FILE --out DIR`).
    #[serde(default)]
    pub args: Vec<String>,
    /// Do not append `--config FILE --out DIR` (third-party programs read
    /// `SC_PARTITION_CONFIG` / `SC_OUT_DIR` from the environment instead).
    #[serde(default)]
    pub no_standard_args: bool,
    /// SCHED_FIFO priority of this role in real-time mode (1..=99), instead of
    /// `real_time_priority`: e.g. lower for the processes off the causal chain of a
    /// tick, so that they never delay it on a machine with few cores.
    #[serde(default)]
    pub priority: Option<u32>,
    /// CPUs this role may run on in real-time mode (Linux CPU numbers), e.g. the
    /// causal chain of a tick on one core and the rest on another, so that its
    /// hand-overs are same-core switches. Empty/absent = any CPU.
    #[serde(default)]
    pub cpus: Vec<usize>,
    /// The host this role runs on, a name of `[hosts]` (absent: the home host).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub host: Option<String>,
}

/// Per-stage deadlines in real-time mode [ms], every one from the tick (the simulator's
/// receipt of it; the scheduler's stage-deadline watchdog counts from its send).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Deadlines {
    /// The simulator substitutes its own navigation for an estimate missing this long
    /// after it published the measurement (optional: [`DEFAULT_NAVIGATION_MS`]).
    #[serde(default = "default_navigation_ms")]
    pub navigation_ms: f64,
    pub safety_translational_ms: f64,
    pub safety_attitude_ms: f64,
    pub safety_robotic_ms: f64,
    /// The simulator applies fallbacks for safe commands missing at this deadline.
    pub simulator_ms: f64,
}

/// Options of lock-step mode.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LockStep {
    /// Deadlines are multiplied by this in lock-step mode: there a missed deadline
    /// means a hung or dead process, not a slow machine.
    pub deadline_scale: f64,
    /// Flow control: the scheduler sends tick k only when the recorder has taken the
    /// step results up to k − this window, so that the recorder's queues (16 per
    /// service) never fill on a loaded machine and nothing is lost. 1..=14.
    pub recorder_window_ticks: u64,
}

/// The partition configuration file.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PartitionConfig {
    /// Scenario file, relative to this file's directory.
    pub scenario: PathBuf,
    pub clock: ClockMode,
    /// How long the scheduler waits for every process at start-up [s].
    pub handshake_timeout_s: f64,
    /// Stop after this many ticks (0 = run the mission to its end).
    #[serde(default)]
    pub max_ticks: u64,
    /// SCHED_FIFO priority (1..=99) of every process in real-time mode; 0 = the
    /// normal scheduler. Needs CAP_SYS_NICE (or root); refused → a warning.
    #[serde(default)]
    pub real_time_priority: u32,
    /// The longest wake-up latency [µs] the CPUs' idle states may add, requested
    /// from Linux PM QoS (`/dev/cpu_dma_latency`) by the launcher for the whole run
    /// (both clock modes: a lock-step tick waits for a wake-up at every hop too), as
    /// cyclictest does. 0 = idle CPUs poll instead of halting (fastest wake-ups,
    /// burns idle CPU time). Absent = the system's idle states are left alone.
    /// Needs write access to the device (root); refused → a warning.
    #[serde(default)]
    pub cpu_wakeup_latency_us: Option<u32>,
    /// Real-time mode: this long [µs] before each tick the scheduler signals
    /// `PREPARE`, and the simulator, the nominal controllers and the filters rehearse
    /// their step on their latest inputs (publishing nothing), so that the tick finds
    /// their code and data warm in the caches instead of cold after a period asleep.
    /// 0 = off. Must be under half the base period.
    #[serde(default)]
    pub warmup_lead_us: u32,
    pub rate_groups: Vec<RateGroup>,
    pub deadlines: Deadlines,
    pub lock_step: LockStep,
    /// Per role (key: the role's name in `sc_icd::ROLES`); after loading every role has
    /// an entry, with the role table's executable where the file names none.
    #[serde(default)]
    pub roles: BTreeMap<String, RoleExec>,
    /// The simulator role's options (absent: our own simulator propagates).
    #[serde(default)]
    pub simulator: SimulatorOptions,
    /// The run across hosts (absent: every role on this host), `crate::hosts`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hosts: Option<Hosts>,
    /// Directory of the config file (set by [`PartitionConfig::load`]).
    #[serde(skip)]
    pub base_dir: PathBuf,
}

/// `[simulator]`: what propagates the true state behind the simulator role.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SimulatorOptions {
    /// A plant process, program and arguments (paths relative to this file), started by
    /// the simulator role with `--scenario FILE` appended; it propagates the true state
    /// instead of our RK4, while the role keeps the handshake, the admission of safe
    /// commands, the barrier monitor and everything it publishes
    /// (`sc_sim::plant_process`, docs/SIMULATOR.md). Empty: our own simulator.
    #[serde(default)]
    pub plant: Vec<String>,
}

/// A configuration problem, one line naming it.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct ConfigError(pub String);

fn err<T>(msg: impl Into<String>) -> Result<T, ConfigError> {
    Err(ConfigError(msg.into()))
}

/// The validated schedule: per subsystem its period as a multiple of the base period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Schedule {
    /// Base (fastest) period: the simulator's step [s].
    pub base_period_s: f64,
    /// Period of each subsystem's rate group [s].
    pub period_s: PerSubsystem<f64>,
    /// Period of each subsystem's rate group in base ticks.
    pub ratio: PerSubsystem<u64>,
}

impl Schedule {
    /// The subsystems due at tick `k` (their rate group runs).
    pub fn due(&self, k: u64) -> SubsystemSet {
        Subsystem::ALL
            .into_iter()
            .filter(|s| k.is_multiple_of(self.ratio[*s]))
            .collect()
    }

    /// [`Self::due`] as the ICD's `due_mask` bits.
    pub fn due_mask(&self, k: u64) -> u32 {
        self.due(k).bits()
    }
}

/// The navigation deadline of a config that names none [ms]: an estimator answers
/// within a few hundred µs here (docs/PARTITION.md). Like every stage deadline it counts
/// from the tick, so the navigation's share comes out of the translational filter's.
pub const DEFAULT_NAVIGATION_MS: f64 = 10.0;

fn default_navigation_ms() -> f64 {
    DEFAULT_NAVIGATION_MS
}

impl Deadlines {
    /// The stage deadline of the filter of `s` [ms].
    pub fn filter_ms(&self, s: Subsystem) -> f64 {
        match s {
            Subsystem::Translational => self.safety_translational_ms,
            Subsystem::Attitude => self.safety_attitude_ms,
            Subsystem::Robotic => self.safety_robotic_ms,
        }
    }

    /// Every stage deadline with its key, in causal order (the navigation first), the
    /// simulator's last.
    fn keyed(&self) -> [(&'static str, f64); 5] {
        [
            ("deadlines.navigation_ms", self.navigation_ms),
            (
                "deadlines.safety_translational_ms",
                self.safety_translational_ms,
            ),
            ("deadlines.safety_attitude_ms", self.safety_attitude_ms),
            ("deadlines.safety_robotic_ms", self.safety_robotic_ms),
            ("deadlines.simulator_ms", self.simulator_ms),
        ]
    }

    /// Positive and in causal order, strictly (a stage with no time after its input's
    /// deadline could only ever use its fallback).
    fn validate(&self) -> Result<(), ConfigError> {
        let ds = self.keyed();
        if let Some((k, v)) = ds.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
            return err(format!("{k} = {v}: must be > 0"));
        }
        match ds.windows(2).find(|w| w[1].1 <= w[0].1) {
            Some(w) => err(format!(
                "{} = {} is not later than {} = {}: deadlines must follow the causal order, each after the one before",
                w[1].0, w[1].1, w[0].0, w[0].1
            )),
            None => Ok(()),
        }
    }
}

impl PartitionConfig {
    /// Reads and validates a config file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ConfigError(format!("{}: {e}", path.display())))?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_toml_str(&text, &base)
            .map_err(|e| ConfigError(format!("{}: {}", path.display(), e.0)))
    }

    /// Parses and validates config text; relative paths resolve against `base_dir`.
    pub fn from_toml_str(text: &str, base_dir: &Path) -> Result<Self, ConfigError> {
        let mut c: PartitionConfig = toml::from_str(text).map_err(|e| {
            ConfigError(
                e.to_string()
                    .lines()
                    .filter(|l| !l.trim().is_empty())
                    .collect::<Vec<_>>()
                    .join(" "),
            )
        })?;
        c.base_dir = base_dir.to_path_buf();
        c.validate()?;
        c.fill_role_defaults();
        Ok(c)
    }

    /// The scenario path, resolved.
    pub fn scenario_path(&self) -> PathBuf {
        if self.scenario.is_absolute() {
            self.scenario.clone()
        } else {
            self.base_dir.join(&self.scenario)
        }
    }

    /// A deadline [s] of the given stage in the configured clock mode.
    pub fn deadline_s(&self, ms: f64) -> f64 {
        let scale = match self.clock {
            ClockMode::LockStep => self.lock_step.deadline_scale,
            ClockMode::RealTime => 1.0,
        };
        ms * scale / 1e3
    }

    /// SCHED_FIFO priority of `role` in real-time mode (0 = normal scheduling).
    pub fn priority_of(&self, role: &str) -> u32 {
        if self.real_time_priority == 0 {
            return 0;
        }
        self.roles
            .get(role)
            .and_then(|e| e.priority)
            .unwrap_or(self.real_time_priority)
    }

    /// Checks the schedule and roles.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_timing()?;
        self.validate_real_time()?;
        self.deadlines.validate()?;
        self.validate_roles()?;
        self.schedule().map(|_| ())
    }

    /// The handshake timeout and the lock-step options.
    fn validate_timing(&self) -> Result<(), ConfigError> {
        if !(self.handshake_timeout_s.is_finite() && self.handshake_timeout_s > 0.0) {
            return err(format!(
                "handshake_timeout_s = {}: must be > 0",
                self.handshake_timeout_s
            ));
        }
        if !(self.lock_step.deadline_scale.is_finite() && self.lock_step.deadline_scale >= 1.0) {
            return err(format!(
                "lock_step.deadline_scale = {}: must be >= 1",
                self.lock_step.deadline_scale
            ));
        }
        if !(1..=14).contains(&self.lock_step.recorder_window_ticks) {
            return err(format!(
                "lock_step.recorder_window_ticks = {}: must be 1..=14 (below the subscriber buffer of 16)",
                self.lock_step.recorder_window_ticks
            ));
        }
        Ok(())
    }

    /// Priorities, PM QoS and the pre-tick warm-up of real-time mode.
    fn validate_real_time(&self) -> Result<(), ConfigError> {
        if self.real_time_priority > 99 {
            return err(format!(
                "real_time_priority = {}: must be 0 (off) or 1..=99",
                self.real_time_priority
            ));
        }
        if let Some(us) = self.cpu_wakeup_latency_us
            && us > 1_000_000
        {
            return err(format!(
                "cpu_wakeup_latency_us = {us}: must be 0..=1000000 (µs; remove the key to leave the system alone)"
            ));
        }
        if let Some(base) = self
            .rate_groups
            .iter()
            .map(|g| g.period_s)
            .filter(|p| p.is_finite() && *p > 0.0)
            .reduce(f64::min)
            && f64::from(self.warmup_lead_us) >= base * 1e6 / 2.0
        {
            return err(format!(
                "warmup_lead_us = {}: must be under half the base period ({} µs)",
                self.warmup_lead_us,
                base * 1e6 / 2.0
            ));
        }
        Ok(())
    }

    /// Every `[roles.<name>]` names a role of the table, with a sane placement.
    fn validate_roles(&self) -> Result<(), ConfigError> {
        if let Some(k) = self.roles.keys().find(|k| Role::named(k).is_none()) {
            let known: Vec<&str> = sc_icd::roles::names().collect();
            return err(format!(
                "roles.{k}: unknown role (known: {})",
                known.join(", ")
            ));
        }
        for (r, e) in &self.roles {
            if let Some(p) = e.priority
                && !(1..=99).contains(&p)
            {
                return err(format!("roles.{r}.priority = {p}: must be 1..=99"));
            }
            if let Some(c) = e.cpus.iter().find(|c| **c >= 1024) {
                return err(format!("roles.{r}.cpus: CPU {c} is out of range (0..1024)"));
            }
        }
        let role_hosts = self
            .roles
            .iter()
            .map(|(r, e)| (r.as_str(), e.host.as_deref()));
        match &self.hosts {
            Some(h) => h.validate(role_hosts),
            None => crate::hosts::check_no_host(role_hosts),
        }
    }

    /// The host `role` runs on (`""` in a run on one host).
    pub fn host_of(&self, role: &str) -> &str {
        let Some(h) = &self.hosts else { return "" };
        self.roles
            .get(role)
            .and_then(|e| e.host.as_deref())
            .unwrap_or(&h.home)
    }

    /// Whether the run crosses hosts (`[hosts]`).
    pub fn across_hosts(&self) -> bool {
        self.hosts.is_some()
    }

    /// Every role of the table gets an entry; an empty `exec` is the table's executable.
    fn fill_role_defaults(&mut self) {
        for r in &ROLES {
            let e = self.roles.entry(r.name.to_string()).or_default();
            if e.exec.trim().is_empty() {
                e.exec = r.exec.to_string();
            }
        }
    }

    /// The schedule of the rate groups (validated).
    pub fn schedule(&self) -> Result<Schedule, ConfigError> {
        if self.rate_groups.is_empty() {
            return err("rate_groups: empty (at least one group with all three subsystems)");
        }
        let mut period = PerSubsystem([None; 3]);
        for g in &self.rate_groups {
            g.assign(&mut period)?;
        }
        let period = PerSubsystem::from_fn(|s| period[s]);
        let period = match Subsystem::ALL.into_iter().find(|s| period[*s].is_none()) {
            Some(s) => return err(format!("rate_groups: subsystem `{s}` is in no group")),
            None => period.map(|p| p.unwrap_or(f64::NAN)),
        };
        downstream_not_slower(&period)?;
        let base = period.0.iter().cloned().fold(f64::INFINITY, f64::min);
        let mut ratio = PerSubsystem([1u64; 3]);
        for s in Subsystem::ALL {
            let r = period[s] / base;
            let ri = r.round();
            if (r - ri).abs() > 1e-6 || ri < 1.0 {
                return err(format!(
                    "rate groups: period {} s of `{s}` is not an integer multiple of the base period {} s",
                    period[s], base
                ));
            }
            ratio[s] = ri as u64;
        }
        nested(&period, &ratio)?;
        Ok(Schedule {
            base_period_s: base,
            period_s: period,
            ratio,
        })
    }
}

impl RateGroup {
    /// Gives this group's members its period, checking each is a known subsystem, in no
    /// other group and in causal order.
    fn assign(&self, period: &mut PerSubsystem<Option<f64>>) -> Result<(), ConfigError> {
        if !(self.period_s.is_finite() && self.period_s > 0.0) {
            return err(format!(
                "rate group `{}`: period_s = {} must be > 0",
                self.name, self.period_s
            ));
        }
        let mut last: Option<Subsystem> = None;
        for m in &self.members {
            let Some(s) = Subsystem::parse(m) else {
                return err(format!(
                    "rate group `{}`: unknown member `{m}` (known: translational, attitude, robotic)",
                    self.name
                ));
            };
            if period[s].is_some() {
                return err(format!(
                    "rate group `{}`: `{m}` is already in another group",
                    self.name
                ));
            }
            if let Some(l) = last.filter(|l| s < *l) {
                return err(format!(
                    "rate group `{}`: members must be in causal order translational → attitude → robotic, `{m}` comes after `{l}`",
                    self.name
                ));
            }
            last = Some(s);
            period[s] = Some(self.period_s);
        }
        Ok(())
    }
}

/// A downstream filter runs at least as fast as its upstream one (paper Sec. "Method").
fn downstream_not_slower(period: &PerSubsystem<f64>) -> Result<(), ConfigError> {
    for s in Subsystem::ALL {
        let Some(u) = s.upstream() else { continue };
        if period[s] > period[u] * (1.0 + 1e-9) {
            return err(format!(
                "rate groups: the {s} filter (period {} s) is slower than its upstream {u} filter (period {} s); a downstream filter must run at least as fast as its upstream one",
                period[s], period[u]
            ));
        }
    }
    Ok(())
}

/// Longest hold in base periods: a group's filter is woken by its own inputs, not by
/// every state, so the states of the base periods between its ticks queue up in its
/// subscriber buffer (16 samples, `process::qos`) and must not overflow it.
pub const MAX_RATIO: u64 = 15;

/// Every group's period divides its upstream group's (when an upstream command is due,
/// its downstream one is too, so a held downstream command never meets a new upstream
/// one), and none holds longer than [`MAX_RATIO`] base periods.
fn nested(period: &PerSubsystem<f64>, ratio: &PerSubsystem<u64>) -> Result<(), ConfigError> {
    for s in Subsystem::ALL {
        if ratio[s] > MAX_RATIO {
            return err(format!(
                "rate groups: `{s}` is held {} base periods (period {} s); at most {MAX_RATIO}: its filter's state queue holds 16",
                ratio[s], period[s]
            ));
        }
        let Some(u) = s.upstream() else { continue };
        if !ratio[u].is_multiple_of(ratio[s]) {
            return err(format!(
                "rate groups: the period {} s of `{u}` is not an integer multiple of the period {} s of its downstream `{s}`: a new {u} command would meet a held {s} command certified against the previous one",
                period[u], period[s]
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn text(groups: &str) -> String {
        let mut s = String::from(
            "scenario = \"scenario.toml\"\nclock = \"lock_step\"\nhandshake_timeout_s = 30\n",
        );
        s += groups;
        s += "\n[deadlines]\nsafety_translational_ms = 40\nsafety_attitude_ms = 60\nsafety_robotic_ms = 80\nsimulator_ms = 90\n[lock_step]\ndeadline_scale = 20\nrecorder_window_ticks = 8\n";
        for r in sc_icd::roles::names() {
            s += &format!("[roles.{r}]\nexec = \"sc-{r}\"\n");
        }
        s
    }

    #[test]
    fn default_schedule_all_at_once() {
        let c = PartitionConfig::from_toml_str(
            &text("[[rate_groups]]\nname = \"control\"\nperiod_s = 0.1\nmembers = [\"translational\", \"attitude\", \"robotic\"]\n"),
            Path::new("."),
        )
        .unwrap();
        let s = c.schedule().unwrap();
        assert_eq!(s.ratio.0, [1, 1, 1]);
        assert_eq!(s.due_mask(7), 7);
    }

    #[test]
    fn multi_rate_due_masks() {
        let c = PartitionConfig::from_toml_str(
            &text("[[rate_groups]]\nname = \"t\"\nperiod_s = 0.2\nmembers = [\"translational\"]\n[[rate_groups]]\nname = \"a\"\nperiod_s = 0.1\nmembers = [\"attitude\"]\n[[rate_groups]]\nname = \"r\"\nperiod_s = 0.02\nmembers = [\"robotic\"]\n"),
            Path::new("."),
        )
        .unwrap();
        let s = c.schedule().unwrap();
        assert_eq!(s.ratio.0, [10, 5, 1]);
        assert_eq!(s.due_mask(0), 7);
        assert_eq!(s.due_mask(5), 6);
        assert_eq!(s.due_mask(3), 4);
    }

    #[test]
    fn downstream_slower_than_upstream_is_rejected() {
        let e = PartitionConfig::from_toml_str(
            &text("[[rate_groups]]\nname = \"fast\"\nperiod_s = 0.1\nmembers = [\"translational\", \"attitude\"]\n[[rate_groups]]\nname = \"slow\"\nperiod_s = 0.2\nmembers = [\"robotic\"]\n"),
            Path::new("."),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("robotic filter (period 0.2 s) is slower than its upstream attitude filter"),
            "{e}"
        );
        assert!(!e.contains('\n'));
    }

    #[test]
    fn bad_configs_give_one_line_errors() {
        for (g, want) in [
            (
                "[[rate_groups]]\nname = \"x\"\nperiod_s = 0.1\nmembers = [\"attitude\", \"translational\", \"robotic\"]\n",
                "causal order",
            ),
            (
                "[[rate_groups]]\nname = \"x\"\nperiod_s = 0.1\nmembers = [\"translational\", \"attitude\"]\n",
                "in no group",
            ),
            (
                "[[rate_groups]]\nname = \"x\"\nperiod_s = -1\nmembers = [\"translational\", \"attitude\", \"robotic\"]\n",
                "must be > 0",
            ),
            (
                "[[rate_groups]]\nname = \"x\"\nperiod_s = 0.1\nmembers = [\"translational\", \"attitude\", \"robot\"]\n",
                "unknown member",
            ),
            (
                "[[rate_groups]]\nname = \"t\"\nperiod_s = 0.15\nmembers = [\"translational\"]\n[[rate_groups]]\nname = \"r\"\nperiod_s = 0.1\nmembers = [\"attitude\", \"robotic\"]\n",
                "integer multiple",
            ),
            (
                "[[rate_groups]]\nname = \"t\"\nperiod_s = 0.3\nmembers = [\"translational\"]\n[[rate_groups]]\nname = \"a\"\nperiod_s = 0.2\nmembers = [\"attitude\"]\n[[rate_groups]]\nname = \"r\"\nperiod_s = 0.1\nmembers = [\"robotic\"]\n",
                "is not an integer multiple of the period 0.2 s of its downstream `attitude`",
            ),
            (
                "[[rate_groups]]\nname = \"t\"\nperiod_s = 1.6\nmembers = [\"translational\"]\n[[rate_groups]]\nname = \"r\"\nperiod_s = 0.1\nmembers = [\"attitude\", \"robotic\"]\n",
                "held 16 base periods",
            ),
            ("rate_groups = 3\n", "invalid type"),
        ] {
            let e = PartitionConfig::from_toml_str(&text(g), Path::new("."))
                .unwrap_err()
                .to_string();
            assert!(e.contains(want), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn real_time_and_flow_control_keys_are_validated() {
        let ok = text(
            "[[rate_groups]]\nname = \"c\"\nperiod_s = 0.1\nmembers = [\"translational\", \"attitude\", \"robotic\"]\n",
        );
        let c = PartitionConfig::from_toml_str(
            &ok.replace(
                "[roles.recorder]\nexec = \"sc-recorder\"\n",
                "[roles.recorder]\nexec = \"sc-recorder\"\ncpus = [0]\npriority = 40\n",
            )
            .replace(
                "handshake_timeout_s = 30\n",
                "handshake_timeout_s = 30\nreal_time_priority = 50\ncpu_wakeup_latency_us = 0\nwarmup_lead_us = 1000\n",
            ),
            Path::new("."),
        )
        .unwrap();
        assert_eq!(c.warmup_lead_us, 1000);
        assert_eq!(c.priority_of("recorder"), 40);
        assert_eq!(c.priority_of("simulator"), 50);
        assert_eq!(c.roles["recorder"].cpus, vec![0]);
        assert_eq!(c.cpu_wakeup_latency_us, Some(0));
        for (from, to, want) in [
            (
                "recorder_window_ticks = 8",
                "recorder_window_ticks = 0",
                "recorder_window_ticks = 0: must be 1..=14",
            ),
            (
                "recorder_window_ticks = 8",
                "recorder_window_ticks = 16",
                "recorder_window_ticks = 16: must be 1..=14",
            ),
            (
                "[roles.recorder]\nexec = \"sc-recorder\"\n",
                "[roles.recorder]\nexec = \"sc-recorder\"\npriority = 0\n",
                "roles.recorder.priority = 0: must be 1..=99",
            ),
            (
                "[roles.recorder]\nexec = \"sc-recorder\"\n",
                "[roles.recorder]\nexec = \"sc-recorder\"\ncpus = [4096]\n",
                "roles.recorder.cpus: CPU 4096 is out of range",
            ),
            (
                "handshake_timeout_s = 30\n",
                "handshake_timeout_s = 30\ncpu_wakeup_latency_us = 2000000\n",
                "cpu_wakeup_latency_us = 2000000: must be 0..=1000000",
            ),
            (
                "handshake_timeout_s = 30\n",
                "handshake_timeout_s = 30\nwarmup_lead_us = 50000\n",
                "warmup_lead_us = 50000: must be under half the base period (50000 µs)",
            ),
        ] {
            assert!(ok.contains(from), "{from}");
            let e = PartitionConfig::from_toml_str(&ok.replace(from, to), Path::new("."))
                .unwrap_err()
                .to_string();
            assert!(e.contains(want), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }
}
