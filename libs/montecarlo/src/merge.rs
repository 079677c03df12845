//! Shards merged into one campaign ([`merge`]), and one run rerun from its saved
//! scenario and compared with its saved result ([`rerun`]).

use crate::aggregate::{CampaignSummary, Sessions, aggregate};
use crate::campaign::{
    CampaignInfo, McError, PARTITION_DIR, io, json, load_campaign_base, prepare_out, read, run_dir,
    write_base_files,
};
use crate::resume::{derive_run, earlier_sessions};
use crate::run::{self, RunResult, RunTiming};
use sc_mission::{Executed, Executor, InProcess, Job, MissionEnd, Setup, StepRecord};
use sc_scenario::Scenario;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Copies the files of a directory; of its sub-directories every one with `all`, else
/// only the partition reports of a run (not, e.g., a rerun's output).
fn copy_dir(from: &Path, to: &Path, all: bool) -> Result<(), McError> {
    std::fs::create_dir_all(to).map_err(io(to))?;
    for e in std::fs::read_dir(from).map_err(io(from))? {
        let e = e.map_err(io(from))?;
        let p = e.path();
        if p.is_file() {
            std::fs::copy(&p, to.join(e.file_name())).map_err(io(&p))?;
        } else if p.is_dir() && (all || e.file_name() == PARTITION_DIR) {
            copy_dir(&p, &to.join(e.file_name()), true)?;
        }
    }
    Ok(())
}

/// The first shard's campaign, base scenario text and URDF bytes, after checking that
/// every shard belongs to that campaign and that none is `out`.
fn check_shards(dirs: &[PathBuf], out: &Path) -> Result<(CampaignInfo, String, Vec<u8>), McError> {
    let first = dirs
        .first()
        .ok_or_else(|| McError::Invalid("merge: no shard directories given".into()))?;
    let info0: CampaignInfo = json(&first.join("campaign.json"))?;
    let base0 = read(&first.join("base_scenario.toml"))?;
    let urdf0 = std::fs::read(first.join(&info0.urdf)).map_err(io(&first.join(&info0.urdf)))?;
    let out_abs = std::path::absolute(out).unwrap_or(out.to_path_buf());
    for d in dirs {
        if std::path::absolute(d).unwrap_or(d.clone()) == out_abs {
            return Err(McError::Invalid(format!(
                "merge: --out {} is one of the inputs",
                out.display()
            )));
        }
        let info: CampaignInfo = json(&d.join("campaign.json"))?;
        let same = info.seed == info0.seed
            && info.runs == info0.runs
            && info.config == info0.config
            && info.urdf == info0.urdf
            && info.execution == info0.execution
            && info.build == info0.build
            && read(&d.join("base_scenario.toml"))? == base0
            && std::fs::read(d.join(&info.urdf)).map_err(io(&d.join(&info.urdf)))? == urdf0;
        if !same {
            return Err(McError::Invalid(format!(
                "merge: {} belongs to a different campaign than {} (seed, runs, config, scenario, execution mode or build differ)",
                d.display(),
                first.display()
            )));
        }
    }
    Ok((info0, base0, urdf0))
}

/// Copies the runs of the shard `d` into `out`, each once (`seen`: the shard each run
/// came from) and each one of the campaign's `runs`.
fn copy_shard_runs(
    d: &Path,
    out: &Path,
    runs: usize,
    seen: &mut BTreeMap<usize, PathBuf>,
) -> Result<(), McError> {
    let dir = d.join("runs");
    for e in std::fs::read_dir(&dir).map_err(io(&dir))? {
        let e = e.map_err(io(&dir))?;
        let Some(k) = e.file_name().to_str().and_then(|n| n.parse::<usize>().ok()) else {
            continue;
        };
        if let Some(prev) = seen.get(&k) {
            return Err(McError::Invalid(format!(
                "merge: run {k} is in both {} and {}",
                prev.display(),
                d.display()
            )));
        }
        if k >= runs {
            return Err(McError::Invalid(format!(
                "merge: {} holds run {k} outside the campaign's {runs} runs",
                d.display(),
            )));
        }
        copy_dir(&e.path(), &run_dir(out, k), false)?;
        seen.insert(k, d.to_path_buf());
    }
    Ok(())
}

/// Copies every shard's runs into `out` and checks that they cover the campaign's
/// `runs` ([`missing_runs`]); the shards' sessions (wall time summed, host loads in shard
/// order).
fn copy_runs(dirs: &[PathBuf], out: &Path, info: &CampaignInfo) -> Result<Sessions, McError> {
    let mut seen: BTreeMap<usize, PathBuf> = BTreeMap::new();
    let mut sessions = Sessions::default();
    for d in dirs {
        copy_shard_runs(d, out, info.runs, &mut seen)?;
        let (wall, load) = earlier_sessions(d);
        sessions.wall_time_s += wall;
        sessions.host_load.extend(load);
    }
    let missing: Vec<usize> = (0..info.runs).filter(|k| !seen.contains_key(k)).collect();
    if !missing.is_empty() {
        return Err(McError::Invalid(missing_runs(dirs, info, &missing)));
    }
    Ok(sessions)
}

/// Up to ten numbers of a list, then how many more.
fn some_of(ks: &[usize]) -> String {
    let shown: Vec<String> = ks.iter().take(10).map(usize::to_string).collect();
    match ks.len() {
        n if n > 10 => format!("{} and {} more", shown.join(", "), n - 10),
        _ => shown.join(", "),
    }
}

/// What `merge` says when runs are missing: per shard of the campaign's sharding, the
/// runs it lacks and the command that completes it — `--resume` on a shard that was given
/// (a task that failed, timed out or was pre-empted), the shard's own command for one
/// that was not.
fn missing_runs(dirs: &[PathBuf], info: &CampaignInfo, missing: &[usize]) -> String {
    let n = info.shard.map_or(1, |[_, n]| n);
    let mut lines = vec![format!(
        "merge: {} of {} runs missing",
        missing.len(),
        info.runs
    )];
    for i in 0..n {
        let ks: Vec<usize> = missing.iter().copied().filter(|k| k % n == i).collect();
        if ks.is_empty() {
            continue;
        }
        let given = dirs.iter().find(|d| {
            json::<CampaignInfo>(&d.join("campaign.json"))
                .is_ok_and(|c| c.shard.map_or(n == 1, |s| s == [i, n]))
        });
        lines.push(match given {
            Some(d) => format!(
                "shard {i}/{n} ({}) lacks runs {}: complete it with `safe-capture montecarlo --resume --out {}`, then merge again",
                d.display(),
                some_of(&ks),
                d.display()
            ),
            None => format!(
                "shard {i}/{n} was not given (runs {}): run it with `{}`, then merge it too",
                some_of(&ks),
                shard_command(dirs, info, i, n)
            ),
        });
    }
    lines.join("; ")
}

/// The command that runs shard `i/n` of the campaign the shards `dirs` belong to, from
/// the first shard's copies of the base scenario and the dispersions, into a sibling
/// folder `shard-<i>`.
fn shard_command(dirs: &[PathBuf], info: &CampaignInfo, i: usize, n: usize) -> String {
    let first = &dirs[0];
    let out = first
        .parent()
        .map_or(PathBuf::from(format!("shard-{i}")), |p| {
            p.join(format!("shard-{i}"))
        });
    let mut cmd = format!(
        "safe-capture montecarlo --runs {} --seed {} --shard {i}/{n} --scenario {} --config {}",
        info.runs,
        info.seed,
        first.join("base_scenario.toml").display(),
        first.join("montecarlo.toml").display()
    );
    if info.execution == sc_mission::Execution::Partition {
        cmd += " --mode partition";
    }
    if let Some(u) = &info.uncertainty {
        cmd += &format!(" --uncertainty {u}");
    }
    cmd + &format!(" --out {}", out.display())
}

/// Merges shard directories into `out`: checks that they belong to the same campaign and
/// cover every run exactly once, copies the runs and aggregates. `wall_time_s` of the
/// result is the sum of the shards'.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<CampaignSummary, McError> {
    let (info0, base0, urdf0) = check_shards(dirs, out)?;
    let info0_sharding = info0.clone();
    prepare_out(out)?;
    let info = CampaignInfo {
        shard: None,
        ..info0
    };
    write_base_files(out, &info, &urdf0, &base0)?;
    let sessions = copy_runs(dirs, out, &info0_sharding)?;
    aggregate(out, &sessions)
}

/// A rerun of one run and how it compares with the saved one.
pub struct Rerun {
    pub scenario: Scenario,
    pub records: Vec<StepRecord>,
    pub end: MissionEnd,
    pub result: RunResult,
    pub timing: RunTiming,
    /// Empty when the rerun reproduced the saved dispersion, scenario and result exactly.
    pub differences: Vec<String>,
}

/// The saved `result.json` of run `k` of the campaign in `dir` (text and parsed).
fn saved_result(dir: &Path, k: usize) -> Result<(String, RunResult), McError> {
    let info: CampaignInfo = json(&dir.join("campaign.json"))?;
    if k >= info.runs {
        return Err(McError::Invalid(format!(
            "--run {k}: the campaign has runs 0..{}",
            info.runs
        )));
    }
    let saved_path = run_dir(dir, k).join("result.json");
    if !saved_path.is_file() {
        return Err(McError::Invalid(format!(
            "run {k} is not in {} (another shard?)",
            dir.display()
        )));
    }
    Ok((read(&saved_path)?, json(&saved_path)?))
}

/// Reruns run `k` of the campaign in `dir` from its saved scenario and compares the
/// re-derived seed and dispersion, the scenario text and the result with the saved ones.
pub fn rerun(dir: &Path, k: usize) -> Result<Rerun, McError> {
    let base = load_campaign_base(dir)?;
    let (saved_text, saved) = saved_result(dir, k)?;
    let rd = run_dir(dir, k);
    let mut differences = Vec::new();
    let (seed, derived) = derive_run(&base, k);
    if seed != saved.seed {
        differences.push(format!("seed: saved {}, derived {seed}", saved.seed));
    }
    let (d, text) = derived?;
    let saved_scenario = read(&rd.join("scenario.toml"))?;
    if text != saved_scenario {
        differences
            .push("scenario.toml: re-derived dispersed scenario differs from the saved one".into());
    }
    let scenario = Scenario::from_toml_str(&saved_scenario, &rd)
        .map_err(|e| McError::Setup(format!("{}: {e}", rd.join("scenario.toml").display())))?;
    let setup =
        Setup::from_scenario(scenario.clone()).map_err(|e| McError::Setup(e.to_string()))?;
    let Executed { records, end } = InProcess.execute(Job::new(setup))?;
    let (metrics, _trace, timing) = run::measure(
        &scenario,
        &records,
        &end,
        base.config.output.trace_every_steps,
    );
    let result = RunResult {
        run: k,
        seed,
        status: "ok".into(),
        error: None,
        dispersion: Some(d),
        metrics: Some(metrics),
    };
    let new_text =
        serde_json::to_string_pretty(&result).map_err(|e| McError::Invalid(e.to_string()))? + "\n";
    if new_text != saved_text {
        differences.push(if saved.failed() {
            format!(
                "result: the saved run failed ({}), the rerun completed",
                saved.error.as_deref().unwrap_or("")
            )
        } else {
            "result.json: rerun result differs from the saved one".into()
        });
    }
    Ok(Rerun {
        scenario,
        records,
        end,
        result,
        timing,
        differences,
    })
}
