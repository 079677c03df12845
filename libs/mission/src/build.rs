//! Which build produced an output: the `version` and `git_commit` every summary.json
//! carries (`safe-capture run`, the partition's recorder, a Monte Carlo campaign).
//!
//! The commit is embedded at build time by the *binaries* (`apps/safe-capture/build.rs`,
//! shared by `apps/partition`), not by this library: a library whose build script read
//! git would recompile everything downstream of it at every commit. Each binary
//! registers its build once at start ([`register`]); the summaries read it from here
//! ([`current`]), so the field names and values are the same in every output of a
//! process.

use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// `git_commit` when the commit of the build is not known: a process that did not
/// [`register`] (a library's own tests), or a binary built without git or `.git`
/// (e.g. from a tarball).
pub const UNKNOWN_COMMIT: &str = "unknown";

/// The build of the running program.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct BuildInfo {
    /// The crate version (the workspace's), e.g. "0.1.0".
    pub version: String,
    /// Short commit hash of the build, with "-dirty" when the work tree had changes,
    /// or [`UNKNOWN_COMMIT`].
    pub git_commit: String,
}

static REGISTERED: OnceLock<BuildInfo> = OnceLock::new();

/// Records the build of this process (call once, first thing in `main`). A second call
/// is ignored: the first registration stands.
pub fn register(version: &str, git_commit: &str) {
    let _ = REGISTERED.set(BuildInfo {
        version: version.into(),
        git_commit: git_commit.into(),
    });
}

/// The registered build, or this library's version with [`UNKNOWN_COMMIT`].
pub fn current() -> BuildInfo {
    REGISTERED.get().cloned().unwrap_or_else(|| BuildInfo {
        version: env!("CARGO_PKG_VERSION").into(),
        git_commit: UNKNOWN_COMMIT.into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registration_is_returned_and_first_one_stands() {
        // one test only touches the process-wide registration
        assert_eq!(current().git_commit, UNKNOWN_COMMIT);
        assert_eq!(current().version, env!("CARGO_PKG_VERSION"));
        register("9.9.9", "abc1234-dirty");
        register("0.0.0", "other");
        assert_eq!(
            current(),
            BuildInfo {
                version: "9.9.9".into(),
                git_commit: "abc1234-dirty".into()
            }
        );
    }
}
