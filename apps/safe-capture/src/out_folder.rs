//! The command line's side of the output-folder policy ([`sc_mission::out_dir`]): the
//! help of `--out` and `--force`, the same for every command that writes a folder.

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
