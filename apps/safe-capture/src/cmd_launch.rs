//! `safe-capture launch`: the mission as a process partition (logic in sc-ground).

use sc_ground::executor::{failure_reason, partner_overrides};
use sc_ground::launcher::configured;
use sc_ground::preflight::preflight;
use sc_ground::{ClockMode, LaunchOptions, LaunchReport, launch};
use sc_mission::out_dir::Staged;
use sc_redteam::{CaseLabel, HostilePartners};
use std::path::PathBuf;
use std::process::ExitCode;

/// Runs the mission with every module in its own process (iceoryx2), from
/// config/partition.toml: starts every process, waits for all to be ready, runs
/// the mission, tears everything down. Writes the same telemetry.csv, timing.csv,
/// summary.json and figures (of its own closed loop; no nominal-only comparison: the
/// partition runs the mission once) as `run`, plus recording.mcap, latency.csv,
/// logs/<role>.log.
///
/// While the mission runs, one line every 10 s on stderr says how many steps were
/// recorded (`launch: 412 steps recorded after 41 s`).
///
/// Before anything starts, the config, the scenario it names, every role's program,
/// partner scripts and the simulator's plant program are checked as `safe-capture
/// check` does: a problem is one line naming the role or key, the cause and the fix.
///
/// Exit codes, the mission's verdict: 0 captured safely, 1 the mission ended (or
/// --max-ticks stopped it) but not captured safely. The infrastructure's (no mission
/// result; the run's output stays in OUT.incomplete): 2 bad configuration or arguments
/// (nothing was started), 3 a process failed (did not start, crashed, was killed or
/// hung) or the run was interrupted (SIGINT/SIGTERM: "interrupted after N ticks"), 4
/// every process ended well but flight-side samples were lost in transport.
#[derive(clap::Args)]
pub struct Args {
    /// Partition config.
    #[arg(long, value_name = "FILE", default_value_os_t = crate::home::shipped("config/partition.toml"))]
    config: PathBuf,
    #[arg(long, value_name = "DIR", default_value = "out/partition", help = crate::out_help!())]
    out: PathBuf,
    #[arg(long, help = crate::out_folder::FORCE_HELP)]
    force: bool,
    /// Skip the figures.
    #[arg(long)]
    no_figures: bool,
    #[command(flatten)]
    figures: crate::figure_format::FigureFormatArg,
    /// Pace ticks on the wall clock instead of lock-step.
    #[arg(long)]
    real_time: bool,
    /// Stop after N ticks (0 = to the end of the mission). A run stopped before the
    /// mission ended says "stopped after N ticks" and exits 1 (no capture).
    #[arg(long, value_name = "N")]
    max_ticks: Option<u64>,
    /// Red team: a hostile partner process (scripts/python/hostile_nominal.py) in place
    /// of the nominal controller(s) of a target, `<target>/<strategy>`, e.g.
    /// `attitude/spin:-y+burst:40` or `all/random:1+hang:300` (`safe-capture redteam
    /// --partition --list` lists the campaign's cases).
    #[arg(long, value_name = "CASE")]
    hostile: Option<String>,
    /// --hostile: Python interpreter with the iceoryx2 package (default: $SC_PYTHON,
    /// else scripts/.venv/bin/python).
    #[arg(long, value_name = "PY", default_value_os_t = crate::redteam_partition::default_python())]
    python: PathBuf,
    /// --hostile: the hostile partner script.
    #[arg(
        long,
        value_name = "FILE",
        default_value_os_t = crate::home::shipped("scripts/python/hostile_nominal.py")
    )]
    partner: PathBuf,
    /// A run across hosts (the config's `[hosts]`, docs/PARTITION.md "Across hosts"): start
    /// the roles of this host and its end of the link (default: the home host, which
    /// runs the scheduler, simulator and recorder and writes the mission's outputs).
    #[arg(long, value_name = "NAME")]
    host: Option<String>,
    /// The run's id (its iceoryx2 prefix). Across hosts every host's launch takes the
    /// same one: the home host's launch prints the command for the others (default: a
    /// fresh one; required with --host for a host other than the home host).
    #[arg(long, value_name = "ID")]
    run_id: Option<String>,
}

fn read_json(path: &std::path::Path) -> Option<serde_json::Value> {
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

/// The ticks the scheduler ran (its scheduler.json).
fn ticks_run(scheduler: Option<&serde_json::Value>) -> Option<u64> {
    scheduler?["ticks"].as_u64()
}

/// How the mission ended, in words: its end from summary.json ("captured at t = 125.4
/// s"), except a run that --max-ticks stopped before the mission's end (summary.json
/// says "stopped": "stopped after 50 ticks (--max-ticks) at t = 4.9 s, before the
/// mission ended").
fn outcome(summary: Option<&serde_json::Value>, scheduler: Option<&serde_json::Value>) -> String {
    let Some(s) = summary else {
        return "no summary".into();
    };
    let end = s["end"].as_str().unwrap_or("no end");
    let t = s["final_time_s"].as_f64().unwrap_or(f64::NAN);
    let by_max_ticks = scheduler.is_some_and(|s| s["end"] == "max_ticks");
    if by_max_ticks && end == (sc_mission::MissionEnd::Stopped { t }).name() {
        format!(
            "stopped after {} ticks (--max-ticks) at t = {t:.1} s, before the mission ended",
            ticks_run(scheduler).map_or("?".into(), |n| n.to_string())
        )
    } else {
        format!("{end} at t = {t:.1} s")
    }
}

/// The reason a partner gave for its first step without a valid command: the SDK's line
/// `<label>: tick N (t = … s): no valid command: <reason>` in `logs/<role>.log`
/// (scripts/python/sc_partner/process.py); `None` when the log has none.
fn first_invalid(logs: &std::path::Path, role: &str) -> Option<String> {
    const MARK: &str = ": no valid command: ";
    let log = std::fs::read_to_string(logs.join(format!("{role}.log"))).ok()?;
    let line = log.lines().find(|l| l.contains(MARK))?;
    let reason = &line[line.find(MARK)? + MARK.len()..];
    Some(reason.trim().to_string())
}

/// The figures of `run` from the partition's own telemetry (its closed loop), into
/// `out/figures`; without a nominal-only comparison (the partition ran the mission
/// once — `run --replay-nominals` would draw an open-loop replay, not the partners').
fn write_figures(out: &std::path::Path, scenario: &std::path::Path) -> anyhow::Result<()> {
    let read = |f: &str| {
        std::fs::read_to_string(out.join(f))
            .map_err(|e| anyhow::anyhow!("{}: {e}", out.join(f).display()))
    };
    let records = sc_mission::parse_telemetry(&read("telemetry.csv")?, &read("timing.csv")?, true)
        .map_err(|e| anyhow::anyhow!("{}: {e}", out.join("telemetry.csv").display()))?;
    let scenario = sc_scenario::Scenario::load(scenario)?;
    sc_plots::run_figures(&out.join("figures"), &scenario, &records, None)?;
    Ok(())
}

/// The launcher's codes from this one on are the infrastructure's (a process failed,
/// samples lost): the run is no mission result.
const INFRASTRUCTURE_FAILURE: i32 = 3;

/// The launch options of the arguments, the hostile partner processes of `--hostile`
/// in place of their nominal controllers (checked that the script understands the case).
fn options(a: &Args) -> anyhow::Result<(LaunchOptions, Option<(HostilePartners, CaseLabel)>)> {
    let mut opts = LaunchOptions {
        config: a.config.clone(),
        out: PathBuf::new(),
        clock: a.real_time.then_some(ClockMode::RealTime),
        max_ticks: a.max_ticks,
        host: a.host.clone(),
        run_id: a.run_id.clone(),
        ..Default::default()
    };
    let Some(h) = &a.hostile else {
        return Ok((opts, None));
    };
    let case = crate::redteam_partition::parse_hostile(h)?;
    // a config that does not load is named before the partner's interpreter
    sc_ground::PartitionConfig::load(&a.config)?;
    let p = crate::redteam_partition::hostile_partners(&a.python, &a.partner)?;
    opts.role_override = partner_overrides(&p.processes(&case));
    Ok((opts, Some((p, case))))
}

/// Reports a run that gave no mission result (the partial output kept apart) and its
/// exit code.
fn infrastructure_failure(
    a: &Args,
    rep: &LaunchReport,
    staged: Staged,
    scheduler: Option<&serde_json::Value>,
) -> ExitCode {
    let out = staged.path().to_path_buf();
    // no mission result: say why, in one line; the partial output is kept apart
    let what = if rep.interrupted {
        format!(
            "interrupted by SIGINT/SIGTERM{} (exit {}), no mission result",
            ticks_run(scheduler)
                .map(|n| format!(" after {n} ticks"))
                .unwrap_or_default(),
            rep.code
        )
    } else {
        format!(
            "infrastructure failure (exit {}), no mission result: {}",
            rep.code,
            failure_reason(rep, &out)
        )
    };
    let kept = staged.abandon();
    outln!(
        "partition: {what}; wall {:.2} s -> {} (partial output; {} not replaced)",
        rep.wall_s,
        kept.as_deref().unwrap_or(&out).display(),
        a.out.display()
    );
    ExitCode::from(rep.code.clamp(0, 255) as u8)
}

/// Across hosts: the host this launch runs and whether it is the home host; the run id
/// every host's launch shares (a fresh one at home when none was given), and the
/// command that starts each other host's side, said before anything starts.
fn across_hosts(
    a: &Args,
    cfg: &sc_ground::PartitionConfig,
    opts: &mut LaunchOptions,
) -> anyhow::Result<Option<bool>> {
    let Some(hosts) = &cfg.hosts else {
        if let Some(h) = &a.host {
            anyhow::bail!(
                "--host {h}: {} has no [hosts] (a run on one host)",
                a.config.display()
            );
        }
        return Ok(None);
    };
    let host = a.host.clone().unwrap_or_else(|| hosts.home.clone());
    if !hosts.link.contains_key(&host) {
        anyhow::bail!(
            "--host {host}: not a host of {}'s hosts.link ({})",
            a.config.display(),
            hosts.names().join(", ")
        );
    }
    let home = host == hosts.home;
    if !home {
        anyhow::ensure!(
            a.run_id.is_some(),
            "--host {host} is not the home host {:?}: give the home launch's --run-id (it prints it)",
            hosts.home
        );
        return Ok(Some(false));
    }
    let id = match &a.run_id {
        Some(id) => id.clone(),
        None => format!("run-{}-{}", std::process::id(), sc_icd::monotonic_ns()),
    };
    opts.run_id = Some(id.clone());
    Ok(Some(true))
}

/// Says, once every check passed, the command that starts each other host's side: with
/// `--real-time` as here, and `--hostile` only for a host that runs a replaced role.
fn say_other_hosts_of_launch(a: &Args, cfg: &sc_ground::PartitionConfig, opts: &LaunchOptions) {
    let (Some(hosts), Some(id)) = (&cfg.hosts, &opts.run_id) else {
        return;
    };
    let home = &hosts.home;
    for other in hosts.names().into_iter().filter(|h| h != home) {
        let mut extra = Vec::new();
        if a.real_time {
            extra.push("--real-time".to_string());
        }
        let replaced_there = opts
            .role_override
            .iter()
            .any(|(r, _, _)| cfg.host_of(r) == other);
        if let (Some(case), true) = (&a.hostile, replaced_there) {
            extra.extend(["--hostile".to_string(), shell_word(case)]);
            extra.extend([
                "--python".to_string(),
                shell_word(&a.python.display().to_string()),
            ]);
            extra.extend([
                "--partner".to_string(),
                shell_word(&a.partner.display().to_string()),
            ]);
        }
        say_other_hosts(&a.config, hosts, home, Some(other), id, &extra);
    }
}

/// `w` as one word of a POSIX shell command line (quoted when it has to be).
fn shell_word(w: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "/._-:+=,@%".contains(c);
    if !w.is_empty() && w.chars().all(plain) {
        w.to_string()
    } else {
        format!("'{}'", w.replace('\'', "'\\''"))
    }
}

/// Says, for each host but `host`, the command that starts its side of run `id`.
pub fn say_other_hosts(
    config: &std::path::Path,
    hosts: &sc_flight::hosts::Hosts,
    host: &str,
    only: Option<&str>,
    id: &str,
    extra: &[String],
) {
    let config = std::path::absolute(config).unwrap_or_else(|_| config.to_path_buf());
    let config = shell_word(&config.display().to_string());
    let id = shell_word(id);
    let extra: String = extra.iter().map(|e| format!(" {e}")).collect();
    for other in hosts
        .names()
        .into_iter()
        .filter(|h| *h != host && only.is_none_or(|o| o == *h))
    {
        outln!(
            "launch: host {host} of {}; start host {other} with: safe-capture launch --config {config} --host {other} --run-id {id}{extra}",
            hosts.link.len(),
        );
    }
}

/// The end of a launch away from the home host: its processes and link, no mission result.
fn away_end(a: &Args, rep: &LaunchReport, staged: Staged) -> anyhow::Result<ExitCode> {
    let failed: Vec<&str> = rep
        .exits
        .iter()
        .chain(rep.link.as_ref())
        .filter(|e| !e.ended_well() && !e.killed_by_launcher)
        .map(|e| e.role.as_str())
        .collect();
    if rep.code != 0 {
        return Ok(infrastructure_failure(a, rep, staged, None));
    }
    staged.commit()?;
    outln!(
        "partition (host {}): {} processes ended well, failed: [{}]; shm leftovers: {}; wall {:.2} s -> {} (the mission's outputs are the home host's)",
        rep.host.as_deref().unwrap_or("?"),
        rep.exits.len(),
        failed.join(", "),
        rep.leftovers.len(),
        rep.wall_s,
        a.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let (mut opts, partners) = options(&a)?;
    // nothing starts unless the scenario and every program are there
    let cfg = configured(&opts)?;
    let home = across_hosts(&a, &cfg, &mut opts)?.unwrap_or(true);
    preflight(&cfg, &opts.bin_dir).map_err(|e| anyhow::anyhow!("{}: {e}", a.config.display()))?;
    if let Some((p, case)) = &partners {
        crate::redteam_partition::check_case(p, &a.config, case)?;
    }
    a.figures.check()?;
    // the processes write into the staging folder; it replaces --out once they are done
    let staged = crate::out_folder::stage(&a.out, "launch", a.force)?;
    let out = staged.path().to_path_buf();
    opts.out = out.clone();
    if home {
        say_other_hosts_of_launch(&a, &cfg, &opts);
    }
    let rep = launch(&opts)?;
    if !home {
        return away_end(&a, &rep, staged);
    }
    let scheduler = read_json(&out.join("scheduler.json"));
    if rep.code >= INFRASTRUCTURE_FAILURE {
        return Ok(infrastructure_failure(&a, &rep, staged, scheduler.as_ref()));
    }
    let failed: Vec<String> = rep
        .exits
        .iter()
        .filter(|e| !e.ended_well())
        .map(|e| e.role.clone())
        .collect();
    let summary = read_json(&out.join("summary.json"));
    if !a.no_figures {
        write_figures(&out, &cfg.scenario_path())?;
        a.figures.export_dir(&out.join("figures"))?;
    }
    staged.commit()?;
    // a declared uncertainty: the realised errors against the declared bounds, and what
    // the margins do not cover (as `run` says it)
    let uncertainty = summary
        .as_ref()
        .and_then(|s| serde_json::from_value::<sc_mission::Summary>(s.clone()).ok())
        .and_then(|s| s.uncertainty);
    if let Some(u) = uncertainty {
        outln!("{}", u.line());
    }
    let logs = a.out.join("logs");
    let verdict = summary
        .as_ref()
        .and_then(|s| serde_json::from_value::<sc_mission::Summary>(s.clone()).ok())
        .map(|s| {
            format!(
                "; {}",
                s.verdict_after_end(&|role| first_invalid(&logs, role))
            )
        })
        .unwrap_or_default();
    outln!(
        "partition: {}{verdict}; {} processes, failed: [{}]; shm leftovers: {}; wall {:.2} s -> {}",
        outcome(summary.as_ref(), scheduler.as_ref()),
        rep.exits.len(),
        failed.join(", "),
        rep.leftovers.len(),
        rep.wall_s,
        a.out.display()
    );
    Ok(ExitCode::from(rep.code.clamp(0, 255) as u8))
}

#[cfg(test)]
mod tests {
    use super::{outcome, shell_word};
    use serde_json::json;

    #[test]
    fn the_other_hosts_command_quotes_what_the_shell_would_split() {
        assert_eq!(shell_word("/work/config/p.toml"), "/work/config/p.toml");
        assert_eq!(shell_word("/my configs/p.toml"), "'/my configs/p.toml'");
        assert_eq!(shell_word("it's"), "'it'\\''s'");
        assert_eq!(shell_word(""), "''");
    }

    #[test]
    fn a_run_stopped_by_max_ticks_is_no_timeout() {
        let s = json!({"end": "stopped", "final_time_s": 4.9});
        let stopped = json!({"end": "max_ticks", "ticks": 50});
        assert_eq!(
            outcome(Some(&s), Some(&stopped)),
            "stopped after 50 ticks (--max-ticks) at t = 4.9 s, before the mission ended"
        );
        // the mission's own end stays its end, --max-ticks or not
        let timeout = json!({"end": "timeout", "final_time_s": 240.0});
        assert_eq!(
            outcome(Some(&timeout), Some(&stopped)),
            "timeout at t = 240.0 s"
        );
        let captured = json!({"end": "captured", "final_time_s": 125.4});
        assert_eq!(
            outcome(Some(&captured), Some(&stopped)),
            "captured at t = 125.4 s"
        );
        // stopped by the scheduler for another reason: its own word
        let aborted = json!({"end": "aborted", "ticks": 12});
        assert_eq!(outcome(Some(&s), Some(&aborted)), "stopped at t = 4.9 s");
        assert_eq!(outcome(None, None), "no summary");
    }
}
