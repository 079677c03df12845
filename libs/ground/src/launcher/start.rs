//! The start of a run: the effective config every process reads (absolute paths, the
//! options' overrides) and one process per role of the role table, each with its log.

use super::{BIN_DIR_ENV, LaunchError, LaunchOptions, abs};
use sc_bus::RunScope;
use sc_flight::config::PartitionConfig;
use sc_icd::{ROLES, Role};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

/// The config `opts` names, with the options' overrides applied (scenario, clock,
/// ticks, deadline scale, role executables); paths still relative to its directory.
pub fn configured(opts: &LaunchOptions) -> Result<PartitionConfig, LaunchError> {
    let mut cfg = PartitionConfig::load(&opts.config)?;
    if let Some(sc) = &opts.scenario {
        cfg.scenario = abs(sc);
    }
    if let Some(c) = opts.clock {
        cfg.clock = c;
    }
    if let Some(n) = opts.max_ticks {
        cfg.max_ticks = n;
    }
    if let Some(d) = opts.deadline_scale {
        cfg.lock_step.deadline_scale = d;
    }
    for (role, exec, args) in &opts.role_override {
        let unknown = || LaunchError::UnknownRole {
            role: role.clone(),
            known: sc_icd::roles::names().collect::<Vec<_>>().join(", "),
        };
        Role::named(role).ok_or_else(unknown)?;
        let e = cfg.roles.get_mut(role).ok_or_else(unknown)?;
        e.exec = exec.clone();
        e.args = args.clone();
    }
    Ok(cfg)
}

/// A file argument relative to the config directory `base` made absolute (options and
/// names that are not files there are left alone).
fn absolute_arg(a: &mut String, base: &Path, is_file_name: bool) {
    if !a.starts_with('-') && is_file_name && !Path::new(a).is_absolute() && base.join(&*a).exists()
    {
        *a = base.join(&*a).display().to_string();
    }
}

/// Clears `out` of an earlier run's outputs and writes the effective config into it
/// (absolute paths: what every process reads); returns it and its path.
pub(super) fn prepare(
    opts: &LaunchOptions,
    out: &Path,
) -> Result<(PartitionConfig, PathBuf), LaunchError> {
    let mut cfg = configured(opts)?;
    super::clean::clear_previous_run(out);
    std::fs::create_dir_all(out.join("logs")).map_err(|e| LaunchError::io(out, e))?;
    let base = abs(&cfg.base_dir);
    cfg.scenario = base.join(&cfg.scenario);
    for e in cfg.roles.values_mut() {
        e.exec = resolve_exec(&e.exec, &base, &opts.bin_dir)
            .display()
            .to_string();
        // arguments that name files relative to the config directory
        for a in e.args.iter_mut() {
            let file = a.contains('/');
            absolute_arg(a, &base, file);
        }
    }
    // the plant's program and files, relative to the config directory like a role's
    for (i, a) in cfg.simulator.plant.iter_mut().enumerate() {
        let file = i == 0 || a.contains('/');
        absolute_arg(a, &base, file);
    }
    cfg.validate()?;
    let eff = out.join("partition.effective.toml");
    let text = toml::to_string(&cfg)
        .map_err(|e| LaunchError::Output(format!("serialising the effective config: {e}")))?;
    std::fs::write(&eff, text).map_err(|e| LaunchError::io(&eff, e))?;
    Ok((cfg, eff))
}

/// A started process of the run.
pub(super) struct Started {
    pub role: &'static str,
    pub child: Child,
}

/// Starts the process of every role of `host` (every role on one host, `""`) in the
/// table's order, each with its log; stops at the first that cannot start (or whose log
/// cannot be opened) and says why.
pub(super) fn spawn_roles(
    cfg: &PartitionConfig,
    host: &str,
    link_pid: Option<u32>,
    eff: &Path,
    out: &Path,
    run: &RunScope,
) -> (Vec<Started>, Option<SpawnError>) {
    let mut procs = Vec::new();
    for role in ROLES
        .iter()
        .map(|r| r.name)
        .filter(|r| cfg.host_of(r) == host)
    {
        match spawn_role(cfg, role, link_pid, eff, out, run) {
            Ok(child) => procs.push(Started { role, child }),
            // the processes already running are torn down, not left behind
            Err(why) => return (procs, Some(why)),
        }
    }
    (procs, None)
}

/// Starts one role's process with its log and the run's environment.
fn spawn_role(
    cfg: &PartitionConfig,
    role: &str,
    link_pid: Option<u32>,
    eff: &Path,
    out: &Path,
    run: &RunScope,
) -> Result<Child, SpawnError> {
    let e = &cfg.roles[role];
    let log = open_log(out, role)?;
    let mut cmd = Command::new(&e.exec);
    cmd.args(&e.args);
    if !e.no_standard_args {
        cmd.arg("--config").arg(eff).arg("--out").arg(out);
    }
    if let Some(hosts) = &cfg.hosts {
        cmd.env(sc_flight::hosts::ACROSS_HOSTS_ENV, "1");
        if cfg.host_of(role) != hosts.home {
            cmd.env(sc_flight::hosts::AWAY_FROM_HOME_ENV, "1");
        }
    }
    if let Some(pid) = link_pid {
        cmd.env(sc_flight::process::LINK_PID_ENV, pid.to_string());
    }
    cmd.env(sc_bus::RUN_ID_ENV, run.run_id())
        .env(sc_flight::process::CONFIG_ENV, eff)
        .env(sc_flight::process::OUT_ENV, out)
        .env(sc_flight::process::ROLE_ENV, role)
        .stdin(Stdio::null())
        .stdout(log.0)
        .stderr(log.1);
    cmd.spawn().map_err(|source| SpawnError::Exec {
        role: role.to_string(),
        exec: e.exec.clone(),
        source,
    })
}

/// The link's program (apps/link), found like a role's bare executable name.
pub const LINK_EXEC: &str = "sc-link";

/// Starts this host's end of the link of a run across hosts (`sc-link`, iceoryx2's Zenoh
/// tunnel scoped to the run): it listens on `host`'s endpoint and connects to every
/// other host's; its log is `logs/link.log`.
pub(super) fn spawn_link(
    cfg: &PartitionConfig,
    host: &str,
    bin_dir: &Option<PathBuf>,
    out: &Path,
    run: &RunScope,
) -> Result<Option<Child>, SpawnError> {
    let Some(hosts) = &cfg.hosts else {
        return Ok(None);
    };
    let role = "link";
    let log = open_log(out, role)?;
    let exec = resolve_exec(LINK_EXEC, &abs(&cfg.base_dir), bin_dir);
    let mut cmd = Command::new(&exec);
    cmd.arg("--run-id").arg(run.run_id());
    if let Some(own) = hosts.link.get(host) {
        cmd.arg("--listen").arg(own);
    }
    for other in hosts.others(host) {
        cmd.arg("--connect").arg(other);
    }
    // in real time the link carries the causal chain: it must not wait behind the roles
    if cfg.clock == sc_flight::ClockMode::RealTime && cfg.real_time_priority > 0 {
        cmd.arg("--priority")
            .arg(cfg.real_time_priority.to_string());
    }
    cmd.stdin(Stdio::null()).stdout(log.0).stderr(log.1);
    cmd.spawn().map(Some).map_err(|source| SpawnError::Exec {
        role: role.to_string(),
        exec: exec.display().to_string(),
        source,
    })
}

/// `logs/<name>.log` of the run, twice: the process's stdout and stderr.
fn open_log(out: &Path, name: &str) -> Result<(std::fs::File, std::fs::File), SpawnError> {
    let path = out.join("logs").join(format!("{name}.log"));
    std::fs::File::create(&path)
        .and_then(|l| Ok((l.try_clone()?, l)))
        .map_err(|source| SpawnError::Log {
            role: name.to_string(),
            path: path.display().to_string(),
            source,
        })
}

/// Why a role's process could not be started.
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    #[error("cannot open the log of role `{role}` ({path}): {source}")]
    Log {
        role: String,
        path: String,
        source: std::io::Error,
    },
    #[error("cannot start role `{role}` ({exec}): {source}")]
    Exec {
        role: String,
        exec: String,
        source: std::io::Error,
    },
}

/// The executable a role's `exec` names: a path relative to the config directory
/// `base_dir`, or a bare name looked up in `bin_dir`, `SC_PARTITION_BIN_DIR` and the
/// launcher's own directory; a bare name found in none of them is returned as is
/// (then `PATH` decides).
pub fn resolve_exec(exec: &str, base_dir: &Path, bin_dir: &Option<PathBuf>) -> PathBuf {
    if exec.contains('/') {
        let p = PathBuf::from(exec);
        return if p.is_absolute() { p } else { base_dir.join(p) };
    }
    let mut dirs: Vec<PathBuf> = Vec::new();
    if let Some(d) = bin_dir {
        dirs.push(d.clone());
    }
    if let Some(d) = std::env::var_os(BIN_DIR_ENV) {
        dirs.push(PathBuf::from(d));
    }
    if let Ok(me) = std::env::current_exe()
        && let Some(d) = me.parent()
    {
        dirs.push(d.to_path_buf());
        if d.file_name().is_some_and(|n| n == "deps")
            && let Some(pd) = d.parent()
        {
            dirs.push(pd.to_path_buf());
        }
    }
    for d in dirs {
        let c = d.join(exec);
        if c.is_file() {
            return c;
        }
    }
    PathBuf::from(exec)
}
