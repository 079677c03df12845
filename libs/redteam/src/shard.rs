//! A red-team campaign split into shards and merged again (`redteam --shard i/N`,
//! `redteam merge`), and completed after it was stopped (`redteam --resume`): the contract
//! of the Monte Carlo's shards. Every case's result is recorded in its folder as it
//! finishes (`cases/<case>/result.json`), the campaign in `campaign.json`; a merge
//! rebuilds every output from the recorded results with the function an unsharded
//! campaign uses ([`crate::report::write`]), so the two agree byte for byte but for the
//! wall-clock columns.

use crate::campaign::{CaseError, CaseResult};
use crate::strategy::{CaseLabel, Target};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The campaign's description in every red-team output folder.
pub const CAMPAIGN_FILE: &str = "campaign.json";
/// A case's recorded result, in its folder `cases/<case>/`.
pub const RESULT_FILE: &str = "result.json";

/// `campaign.json`: what the shards of one campaign share, and which shard this is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignInfo {
    /// The build that ran the cases: shards of different builds are not merged.
    pub build: sc_mission::build::BuildInfo,
    /// `[i, n]` for shard i of n (0-based); absent for a whole or merged campaign.
    pub shard: Option<[usize; 2]>,
    /// Every case of the whole campaign, in report order (a shard runs every n-th).
    pub cases: Vec<String>,
    /// The command's own options (without `--out`, `--shard`, `--jobs`, `--resume`,
    /// `--force`, `--quiet`) and the folder it ran in: what runs a shard again.
    pub options: Vec<String>,
    pub cwd: PathBuf,
    /// The cases run through the process partition.
    pub partition: bool,
    /// The report's paragraph on how the cases ran.
    pub how: String,
    /// The scenario the cases ran (its text, the declared uncertainty included) and every
    /// barrier's scale in the report's normalised margins.
    pub scenario: String,
    pub scales: Vec<f64>,
}

/// A case's recorded outcome: its result, or why it could not run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recorded {
    pub case: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub result: Option<CaseResult>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// Why shards could not be merged, or a campaign not read.
#[derive(Debug, thiserror::Error)]
pub enum ShardError {
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("merge: {0}")]
    Invalid(String),
    #[error("{0}")]
    Missing(String),
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> ShardError + '_ {
    move |e| ShardError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// The case named `name` (`<target>/<strategy>`).
pub fn label(name: &str) -> Option<CaseLabel> {
    let (target, strategy) = name.split_once('/')?;
    Some(CaseLabel {
        target: Target::parse(target)?,
        strategy: strategy.to_string(),
    })
}

/// Writes `campaign.json` into `dir`.
pub fn write_info(dir: &Path, info: &CampaignInfo) -> Result<(), ShardError> {
    let path = dir.join(CAMPAIGN_FILE);
    let text =
        serde_json::to_string_pretty(info).map_err(|e| ShardError::Invalid(e.to_string()))?;
    std::fs::write(&path, text + "\n").map_err(io_err(&path))
}

/// Reads `campaign.json` of `dir`.
pub fn read_info(dir: &Path) -> Result<CampaignInfo, ShardError> {
    let path = dir.join(CAMPAIGN_FILE);
    let text = std::fs::read_to_string(&path).map_err(io_err(&path))?;
    serde_json::from_str(&text).map_err(|e| ShardError::Io {
        path,
        message: e.to_string(),
    })
}

/// Records case `case`'s outcome in `out/cases/<case>/result.json`.
pub fn record(
    out: &Path,
    case: &CaseLabel,
    r: &Result<CaseResult, CaseError>,
) -> Result<(), ShardError> {
    let dir = out.join("cases").join(case.dir_name());
    std::fs::create_dir_all(&dir).map_err(io_err(&dir))?;
    let rec = Recorded {
        case: case.name(),
        result: r.as_ref().ok().cloned(),
        error: r.as_ref().err().map(ToString::to_string),
    };
    let text =
        serde_json::to_string_pretty(&rec).map_err(|e| ShardError::Invalid(e.to_string()))?;
    // written apart and renamed: a case killed mid-write leaves no half a result
    let (tmp, path) = (dir.join("result.json.partial"), dir.join(RESULT_FILE));
    std::fs::write(&tmp, text + "\n").map_err(io_err(&tmp))?;
    std::fs::rename(&tmp, &path).map_err(io_err(&path))
}

/// Case `case`'s recorded outcome in `out`, if it finished there.
pub fn recorded(out: &Path, case: &CaseLabel) -> Option<Result<CaseResult, CaseError>> {
    let path = out.join("cases").join(case.dir_name()).join(RESULT_FILE);
    let rec: Recorded = serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()?;
    if rec.case != case.name() {
        return None;
    }
    match (rec.result, rec.error) {
        (Some(r), _) => Some(Ok(r)),
        // a case stopped by a signal did not finish (an older build recorded it)
        (None, Some(e)) if e == "interrupted" => None,
        (None, Some(e)) => Some(Err(CaseError::Recorded(e))),
        (None, None) => None,
    }
}

/// The wall time a campaign folder's `summary.json` reports [s] (0 when unreadable).
fn wall_s(dir: &Path) -> f64 {
    std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| v["wall_s"].as_f64())
        .unwrap_or(0.0)
}

/// The merge of shards: the whole campaign's cases with their recorded outcomes, and the
/// shards' wall time summed.
pub struct Merged {
    pub info: CampaignInfo,
    pub cases: Vec<CaseLabel>,
    pub results: Vec<Result<CaseResult, CaseError>>,
    pub wall_s: f64,
}

/// Checks that `dirs` are shards of one campaign (everything but the shard the same, the
/// same N) and none is `out`; their descriptions.
fn check_shards(dirs: &[PathBuf], out: &Path) -> Result<Vec<CampaignInfo>, ShardError> {
    let first = dirs
        .first()
        .ok_or_else(|| ShardError::Invalid("no shard folders given".into()))?;
    let out_abs = std::path::absolute(out).unwrap_or(out.to_path_buf());
    let infos = dirs
        .iter()
        .map(|d| read_info(d))
        .collect::<Result<Vec<_>, _>>()?;
    let n = |i: &CampaignInfo| i.shard.map_or(1, |[_, n]| n);
    for (k, (d, info)) in dirs.iter().zip(&infos).enumerate() {
        if let Some(j) = (0..k).find(|&j| infos[j].shard == info.shard) {
            return Err(ShardError::Invalid(format!(
                "{} and {} are the same shard",
                dirs[j].display(),
                d.display()
            )));
        }
        if std::path::absolute(d).unwrap_or(d.clone()) == out_abs {
            return Err(ShardError::Invalid(format!(
                "--out {} is one of the inputs",
                out.display()
            )));
        }
        // the folder a shard ran in counts: relative paths in its options name files there
        let same = CampaignInfo {
            shard: infos[0].shard,
            ..info.clone()
        } == infos[0]
            && n(info) == n(&infos[0]);
        if !same {
            return Err(ShardError::Invalid(format!(
                "{} belongs to a different campaign than {} (cases, options, the folder it ran in, scenario, build or number of shards differ)",
                d.display(),
                first.display()
            )));
        }
    }
    Ok(infos)
}

/// Merges red-team shard folders: every case of the campaign from the shard that ran it.
/// Cases missing are named per shard with the command that completes each.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<Merged, ShardError> {
    let infos = check_shards(dirs, out)?;
    let info = CampaignInfo {
        shard: None,
        ..infos[0].clone()
    };
    let n = infos[0].shard.map_or(1, |[_, n]| n);
    let mut cases = Vec::new();
    let mut results = Vec::new();
    let mut missing: Vec<(usize, String)> = Vec::new();
    for (k, name) in info.cases.iter().enumerate() {
        let case = label(name).ok_or_else(|| ShardError::Invalid(format!("case `{name}`")))?;
        let shard = [k % n, n];
        let found = dirs
            .iter()
            .zip(&infos)
            .filter(|(_, i)| i.shard.is_none_or(|s| s == shard))
            .find_map(|(d, _)| recorded(d, &case));
        match found {
            Some(r) => results.push(r),
            None => missing.push((k % n, name.clone())),
        }
        cases.push(case);
    }
    if !missing.is_empty() {
        return Err(ShardError::Missing(missing_cases(
            dirs, &infos, &info, n, &missing,
        )));
    }
    let wall_s = dirs.iter().map(|d| wall_s(d)).sum();
    Ok(Merged {
        info,
        cases,
        results,
        wall_s,
    })
}

/// What `merge` says when cases are missing: per shard, the cases it lacks and the
/// command that completes it.
fn missing_cases(
    dirs: &[PathBuf],
    infos: &[CampaignInfo],
    info: &CampaignInfo,
    n: usize,
    missing: &[(usize, String)],
) -> String {
    let mut lines = vec![format!(
        "redteam merge: {} of {} cases missing",
        missing.len(),
        info.cases.len()
    )];
    for i in 0..n {
        let names: Vec<&str> = missing
            .iter()
            .filter(|(s, _)| *s == i)
            .map(|(_, c)| c.as_str())
            .collect();
        if names.is_empty() {
            continue;
        }
        let shown = match names.len() {
            l if l > 10 => format!("{} and {} more", names[..10].join(", "), l - 10),
            _ => names.join(", "),
        };
        let given = dirs
            .iter()
            .zip(infos)
            .find(|(_, c)| c.shard.map_or(n == 1, |s| s == [i, n]));
        lines.push(match given {
            Some((d, _)) => format!(
                "shard {i}/{n} ({}) lacks {shown}: complete it with `safe-capture redteam --resume --out {}`, then merge again",
                d.display(),
                d.display()
            ),
            None => {
                let out = dirs[0]
                    .parent()
                    .map_or(PathBuf::from(format!("shard-{i}")), |p| p.join(format!("shard-{i}")));
                format!(
                    "shard {i}/{n} was not given ({shown}): run it in {} with `safe-capture redteam {} --shard {i}/{n} --out {}`, then merge it too",
                    info.cwd.display(),
                    info.options.join(" "),
                    out.display()
                )
            }
        });
    }
    lines.join("; ")
}

/// The command's own options from its arguments after `redteam`: without the per-shard
/// and output ones (`--out`, `--shard`, `--jobs`/`-j`, `--resume`, `--force`, `--quiet`/`-q`).
pub fn campaign_options(args: &[String]) -> Vec<String> {
    let with_value = ["--out", "--shard", "--jobs", "-j"];
    let alone = ["--resume", "--force", "--quiet", "-q"];
    let mut out = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if with_value.contains(&a.as_str()) {
            it.next();
        } else if alone.contains(&a.as_str())
            || with_value
                .iter()
                .any(|o| a.starts_with(&format!("{o}=")) || (*o == "-j" && a.starts_with("-j")))
        {
            continue;
        } else {
            out.push(a.clone());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_campaign_options_leave_out_what_is_set_per_shard() {
        let args: Vec<String> = [
            "--seeds",
            "2",
            "--out",
            "x",
            "-j",
            "2",
            "--shard=1/4",
            "-q",
            "--partition",
            "-j3",
            "--cases",
            "all/huge",
            "--jobs=4",
            "--force",
            "--resume",
            "--out=y",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        assert_eq!(
            campaign_options(&args),
            ["--seeds", "2", "--partition", "--cases", "all/huge"]
        );
    }

    #[test]
    fn case_names_read_back_as_labels() {
        let c = label("robotic/toward:theta_dot_max_7").unwrap();
        assert_eq!(c.name(), "robotic/toward:theta_dot_max_7");
        let p = label("attitude/spin:-y+burst:40").unwrap();
        assert_eq!(p.strategy, "spin:-y+burst:40");
        assert!(label("nobody/huge").is_none() && label("huge").is_none());
    }
}
