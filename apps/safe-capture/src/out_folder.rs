//! The command line's side of the output-folder policy ([`sc_mission::out_dir`]): the
//! help of `--out` and `--force`, the same for every command that writes a folder.

use anyhow::Context;
use sc_mission::out_dir::Staged;
use std::path::Path;

/// `--help` of every command's `--out` folder, with what the command says of its
/// default (e.g. `" (default: B/compare)"`).
#[macro_export]
macro_rules! out_help {
    () => {
        $crate::out_help!("")
    };
    ($default:literal) => {
        concat!("Output folder", $default, ". Written as DIR.incomplete, which replaces DIR as a whole when the command finishes (a failed run's partial output stays in DIR.incomplete; DIR is then unchanged). A non-empty DIR that safe-capture did not write (no .safe-capture file in it) is refused with exit 2 unless --force"
        )
    };
}

/// `--help` of every command's `--force`.
pub const FORCE_HELP: &str = "Replace the --out folder even if safe-capture did not write it (its contents are deleted; the command lists them first)";

/// Starts writing the output folder `out` of `command` ([`Staged::begin`]).
pub fn stage(out: &Path, command: &str, force: bool) -> anyhow::Result<Staged> {
    let staged = Staged::begin(out, command, force)?;
    say_what_force_replaces(out, command, force);
    Ok(staged)
}

/// Entries of a forced folder named before it is replaced.
const LISTED_ENTRIES: usize = 10;

/// With `--force` over a folder safe-capture did not write, says on stderr what it held
/// (its first entries by name and their count): the command replaces it when it
/// finishes, and the user should not learn that from a missing file.
fn say_what_force_replaces(out: &Path, command: &str, force: bool) {
    if !force || !out.is_dir() || sc_mission::out_dir::is_ours(out) {
        return;
    }
    let Ok(rd) = std::fs::read_dir(out) else {
        return;
    };
    let mut names: Vec<String> = rd
        .flatten()
        .map(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            if e.path().is_dir() { n + "/" } else { n }
        })
        .collect();
    if names.is_empty() {
        return;
    }
    names.sort();
    let more = names.len().saturating_sub(LISTED_ENTRIES);
    names.truncate(LISTED_ENTRIES);
    errln!(
        "{command}: --force: {} was not written by safe-capture; it is replaced when the command finishes, with its {} {}: {}{}",
        out.display(),
        names.len() + more,
        if names.len() + more == 1 {
            "entry"
        } else {
            "entries"
        },
        names.join(", "),
        if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        }
    );
}

/// [`stage`] for a command that reads `inputs`: an `out` that is or holds one of them
/// is refused, even with --force ([`Staged::begin_with_inputs`]).
pub fn stage_reading(
    out: &Path,
    command: &str,
    force: bool,
    inputs: &[&Path],
) -> anyhow::Result<Staged> {
    let staged = Staged::begin_with_inputs(out, command, force, inputs)?;
    say_what_force_replaces(out, command, force);
    Ok(staged)
}

/// `--resume` of a campaign that never reached `out`: quit at once by a second signal,
/// or killed (a cluster's task pre-empted or timed out without a grace period) — its
/// runs are still in the staging folder `out.incomplete`. An empty or absent `out`
/// takes it over (the campaign then completes there); anything else in `out` is left
/// alone and the command says how to resume the staging folder itself.
pub fn adopt_staging(out: &Path, command: &str) -> anyhow::Result<()> {
    let mut staging = out.to_path_buf().into_os_string();
    staging.push(sc_mission::out_dir::INCOMPLETE_SUFFIX);
    let staging = std::path::PathBuf::from(staging);
    if out.join("campaign.json").is_file() || !staging.join("campaign.json").is_file() {
        return Ok(());
    }
    if let Some(pid) = sc_mission::out_dir::writer_alive(&staging) {
        anyhow::bail!(
            "--resume: {} is still being written by process {pid}; stop it first, or wait for it",
            staging.display()
        );
    }
    let empty = std::fs::read_dir(out).map_or(true, |mut d| d.next().is_none());
    if !empty {
        anyhow::bail!(
            "--resume: {} holds no campaign, but {} holds one that was quit before it was complete: resume it with --resume --out {}",
            out.display(),
            staging.display(),
            staging.display()
        );
    }
    if out.exists() {
        std::fs::remove_dir(out).with_context(|| format!("--resume: {}", out.display()))?;
    }
    std::fs::rename(&staging, out).with_context(|| {
        format!(
            "--resume: moving {} to {}",
            staging.display(),
            out.display()
        )
    })?;
    errln!(
        "{command}: resuming the campaign that was stopped before it reached {} (from {})",
        out.display(),
        staging.display()
    );
    Ok(())
}
