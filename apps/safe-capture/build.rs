// Embeds the git commit of the build as the environment variable `SC_GIT_COMMIT`:
// the short hash of HEAD, with "-dirty" when `git status --porcelain` lists any change
// (untracked files included: they may be part of the build), or "unknown" when git or
// the repository is missing (a build from a tarball). `apps/partition/build.rs`
// includes this file, so every binary of the workspace says the same.
//
// The script reruns when HEAD or the branch it points to moves (a commit, a checkout),
// not at every build: "-dirty" is the state of the tree when it last ran.

use std::path::{Path, PathBuf};
use std::process::Command;

/// What the build says when it cannot tell its commit.
const UNKNOWN: &str = "unknown";

/// The trimmed standard output of `git -C dir args…`, or None if git is missing or fails.
fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(args)
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    String::from_utf8(out.stdout)
        .ok()
        .map(|s| s.trim().to_string())
}

/// Asks cargo to rerun this script when `git_path` (a path inside the git directory, as
/// git names it) changes; only for files that exist, as a missing one would rerun it at
/// every build.
fn rerun_if_changed(dir: &Path, git_path: &str) {
    if let Some(p) = git(dir, &["rev-parse", "--git-path", git_path]) {
        let p = dir.join(p);
        if p.is_file() {
            println!("cargo:rerun-if-changed={}", p.display());
        }
    }
}

fn main() {
    let dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    // without rerun-if-changed lines, cargo would rerun at any change of the package
    println!("cargo:rerun-if-changed=build.rs");
    let commit = match git(&dir, &["rev-parse", "--short", "HEAD"]) {
        Some(hash) if !hash.is_empty() => {
            rerun_if_changed(&dir, "HEAD");
            if let Some(branch) = git(&dir, &["symbolic-ref", "-q", "HEAD"]) {
                rerun_if_changed(&dir, &branch);
            }
            rerun_if_changed(&dir, "packed-refs");
            // a status git cannot give is not a clean tree
            let clean = git(&dir, &["status", "--porcelain"]).is_some_and(|s| s.is_empty());
            if clean { hash } else { hash + "-dirty" }
        }
        _ => UNKNOWN.to_string(),
    };
    println!("cargo:rustc-env=SC_GIT_COMMIT={commit}");
}
