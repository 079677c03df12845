//! `--resume`: completing an interrupted campaign in place. Its complete runs are
//! verified against their re-derivation (seed, dispersion, scenario) and kept, the
//! others run again; the campaign must be the same (parameters, base scenario, URDF,
//! execution, build).

use crate::campaign::{
    CampaignInfo, McError, PARTIAL_SUFFIX, campaign_info, io, json, read, run_dir,
};
use crate::host::HostLoad;
use crate::run::{self, CampaignBase, RunResult, RunTiming, TraceError};
use crate::sample::{Dispersion, SampleError, run_seed, sample};
use std::path::{Path, PathBuf};

/// Refuses to resume the campaign in `out` with another campaign's parameters; one line
/// naming every difference.
pub(crate) fn check_resume(
    out: &Path,
    info: &CampaignInfo,
    urdf: &[u8],
    base_text: &str,
) -> Result<(), McError> {
    let saved = campaign_info(out).map_err(|e| McError::Invalid(format!("--resume: {e}")))?;
    let shard = |s: Option<[usize; 2]>| s.map_or("none".into(), |[i, n]| format!("{i}/{n}"));
    let mut diff = Vec::new();
    if saved.seed != info.seed {
        diff.push(format!("seed {} (not {})", saved.seed, info.seed));
    }
    if saved.runs != info.runs {
        diff.push(format!("{} runs (not {})", saved.runs, info.runs));
    }
    if saved.shard != info.shard {
        diff.push(format!(
            "shard {} (not {})",
            shard(saved.shard),
            shard(info.shard)
        ));
    }
    if saved.config != info.config {
        diff.push("another dispersion config".into());
    }
    if saved.execution != info.execution {
        diff.push(format!(
            "execution {:?} (not {:?})",
            saved.execution, info.execution
        ));
    }
    if saved.build != info.build {
        let name = |b: &Option<sc_mission::build::BuildInfo>| {
            b.as_ref().map_or("an unrecorded build".into(), |b| {
                format!("build {} ({})", b.version, b.git_commit)
            })
        };
        diff.push(format!(
            "runs of {} (this is {})",
            name(&saved.build),
            name(&info.build)
        ));
    }
    let saved_urdf = std::fs::read(out.join(&saved.urdf)).ok();
    if saved.urdf != info.urdf || saved_urdf.as_deref() != Some(urdf) {
        diff.push("another servicer URDF".into());
    }
    if std::fs::read_to_string(out.join("base_scenario.toml"))
        .ok()
        .as_deref()
        != Some(base_text)
    {
        diff.push("another base scenario".into());
    }
    if diff.is_empty() {
        return Ok(());
    }
    Err(McError::Invalid(format!(
        "--resume: {} holds another campaign: {}; resume it with its own parameters (omitted ones are taken from its campaign.json) or choose another --out",
        out.display(),
        diff.join(", ")
    )))
}

/// Run `k`'s seed and, unless sampling fails, its dispersion and the text of its
/// dispersed scenario, re-derived from the campaign.
pub(crate) fn derive_run(
    base: &CampaignBase,
    k: usize,
) -> (u64, Result<(Dispersion, String), SampleError>) {
    let seed = run_seed(base.seed, k);
    let derived = sample(&base.config, &base.scenario, seed)
        .map(|d| (d, run::run_scenario(base, &d, seed).to_toml_string()));
    (seed, derived)
}

/// Why a saved run does not verify (it runs again).
#[derive(Debug, thiserror::Error)]
enum VerifyError {
    #[error(transparent)]
    Unreadable(#[from] McError),
    #[error("result.json holds run {run} with seed {seed}, not run {k} with seed {derived}")]
    OtherRun {
        run: usize,
        seed: u64,
        k: usize,
        derived: u64,
    },
    #[error("the saved dispersion differs from the re-derived one")]
    Dispersion,
    #[error("scenario.toml differs from the re-derived dispersed scenario")]
    Scenario,
    #[error("sampling fails ({0}) but the saved run has a dispersion")]
    SampledNothing(SampleError),
    #[error("{}: {error}", .path.display())]
    Trace { path: PathBuf, error: TraceError },
}

/// Checks the saved run `k` of the campaign in `dir` without running it: `result.json`
/// names run k with its derived seed, the dispersion and `scenario.toml` are the
/// re-derived ones, and the trace and the timing of a completed run read back.
fn verify_saved_run(base: &CampaignBase, dir: &Path, k: usize) -> Result<(), VerifyError> {
    let d = run_dir(dir, k);
    let result: RunResult = json(&d.join("result.json"))?;
    let (seed, derived) = derive_run(base, k);
    if result.run != k || result.seed != seed {
        return Err(VerifyError::OtherRun {
            run: result.run,
            seed: result.seed,
            k,
            derived: seed,
        });
    }
    match derived {
        Ok((disp, text)) => {
            if result.dispersion != Some(disp) {
                return Err(VerifyError::Dispersion);
            }
            if read(&d.join("scenario.toml"))? != text {
                return Err(VerifyError::Scenario);
            }
        }
        Err(e) => {
            if !result.failed() || result.dispersion.is_some() {
                return Err(VerifyError::SampledNothing(e));
            }
        }
    }
    let tp = d.join("trace.csv");
    if tp.is_file() {
        run::parse_trace(&read(&tp)?).map_err(|error| VerifyError::Trace { path: tp, error })?;
    }
    if !result.failed() {
        json::<RunTiming>(&d.join("timing.json"))?;
    }
    Ok(())
}

/// Prepares a resume of the campaign in `out`: removes the runs being written when it
/// stopped, keeps the complete runs of `indices` that verify ([`verify_saved_run`]; the
/// others are removed, with a note on stderr) and returns the runs still to do.
pub(crate) fn runs_to_resume(
    out: &Path,
    base: &CampaignBase,
    indices: &[usize],
) -> Result<Vec<usize>, McError> {
    let runs = out.join("runs");
    std::fs::create_dir_all(&runs).map_err(io(&runs))?;
    for e in std::fs::read_dir(&runs).map_err(io(&runs))? {
        let p = e.map_err(io(&runs))?.path();
        if p.is_dir()
            && p.file_name()
                .is_some_and(|n| n.to_string_lossy().ends_with(PARTIAL_SUFFIX))
        {
            std::fs::remove_dir_all(&p).map_err(io(&p))?;
        }
    }
    let mut todo = Vec::new();
    for &k in indices {
        let d = run_dir(out, k);
        if !d.exists() {
            todo.push(k);
            continue;
        }
        if let Err(why) = verify_saved_run(base, out, k) {
            // not `eprintln!`: a closed stderr must not stop the campaign
            use std::io::Write as _;
            let _ = writeln!(
                std::io::stderr().lock(),
                "resume: run {k} in {} does not verify ({why}); running it again",
                d.display()
            );
            std::fs::remove_dir_all(&d).map_err(io(&d))?;
            todo.push(k);
        }
    }
    Ok(todo)
}

/// Wall time and host load of the earlier sessions of the campaign in `dir`, from its
/// `summary.json` (none if it has none).
pub(crate) fn earlier_sessions(dir: &Path) -> (f64, Vec<HostLoad>) {
    let Ok(v) = json::<serde_json::Value>(&dir.join("summary.json")) else {
        return (0.0, Vec::new());
    };
    let wall = v.get("wall_time_s").and_then(|w| w.as_f64()).unwrap_or(0.0);
    let load = v
        .get("host_load")
        .cloned()
        .and_then(|l| serde_json::from_value(l).ok())
        .unwrap_or_default();
    (wall, load)
}
