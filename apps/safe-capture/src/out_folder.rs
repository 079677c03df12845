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
pub const FORCE_HELP: &str =
    "Replace the --out folder even if safe-capture did not write it (its contents are deleted)";

/// Starts writing the output folder `out` of `command` ([`Staged::begin`]).
pub fn stage(out: &Path, command: &str, force: bool) -> anyhow::Result<Staged> {
    Ok(Staged::begin(out, command, force)?)
}

/// [`stage`] for a command that reads `inputs`: an `out` that is or holds one of them
/// is refused, even with --force ([`Staged::begin_with_inputs`]).
pub fn stage_reading(
    out: &Path,
    command: &str,
    force: bool,
    inputs: &[&Path],
) -> anyhow::Result<Staged> {
    Ok(Staged::begin_with_inputs(out, command, force, inputs)?)
}
