//! Where the shipped files are (config/, scripts/): the installation, not the working
//! directory, so that `safe-capture run` works from any folder. The default of every
//! option that names a shipped file resolves here; a path the user gives stays relative
//! to the user's working directory.

use std::path::{Path, PathBuf};

/// Environment variable naming the installation (the folder holding config/ and
/// scripts/), e.g. for a binary copied out of the checkout.
pub const HOME_ENV: &str = "SAFE_CAPTURE_HOME";

/// A file every installation holds: how a folder is recognised as one.
const LANDMARK: &str = sc_scenario::DEFAULT_SCENARIO;

/// How many folders above the executable's are searched (target/release/safe-capture
/// and target/debug/deps/… sit two and three below the checkout).
const SEARCH_DEPTH: usize = 4;

/// The installation: `SAFE_CAPTURE_HOME` if set, else the first folder above the
/// executable that holds config/scenario.toml; `None` when neither (the defaults then
/// stay relative to the working directory).
pub fn installation() -> Option<PathBuf> {
    if let Some(h) = std::env::var_os(HOME_ENV) {
        return Some(PathBuf::from(h));
    }
    let exe = std::env::current_exe().ok()?;
    let exe = std::fs::canonicalize(&exe).unwrap_or(exe);
    exe.ancestors()
        .skip(1)
        .take(SEARCH_DEPTH)
        .find(|d| d.join(LANDMARK).is_file())
        .map(Path::to_path_buf)
}

/// A shipped file, `rel` to the installation (e.g. "config/partition.toml").
pub fn shipped(rel: &str) -> PathBuf {
    match installation() {
        Some(h) => h.join(rel),
        None => PathBuf::from(rel),
    }
}
