//! Every output names the build that wrote it: `--version` gives the crate version and
//! the git commit embedded by build.rs, and a run's summary.json carries both as
//! `version` and `git_commit`, and so does a Monte Carlo campaign's.

use serde_json::Value;
use std::process::Command;

mod common;
use common::{cli, root, short_scenario, tmp};

/// The commit as build.rs embedded it for this build (the test is built by the same
/// build script as the binary).
const COMMIT: &str = env!("SC_GIT_COMMIT");

/// A commit as build.rs writes it: "unknown", or a short hex hash with an optional
/// "-dirty".
fn is_commit(s: &str) -> bool {
    if s == "unknown" {
        return true;
    }
    let hash = s.strip_suffix("-dirty").unwrap_or(s);
    hash.len() >= 4 && hash.chars().all(|c| c.is_ascii_hexdigit())
}

#[test]
fn version_names_the_commit() {
    assert!(is_commit(COMMIT), "{COMMIT}");
    assert!(!is_commit("") && !is_commit("zz12345") && !is_commit("abc1234-clean"));
    for args in [&["--version"][..], &["run", "--version"]] {
        let out = Command::new(env!("CARGO_BIN_EXE_safe-capture"))
            .args(args)
            .output()
            .unwrap();
        assert!(out.status.success(), "{args:?}");
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(
            text.contains(&format!("{} ({COMMIT})", env!("CARGO_PKG_VERSION"))),
            "{args:?}: {text}"
        );
    }
}

#[test]
fn run_summary_names_version_and_commit() {
    let d = tmp("build-info");
    let scenario = short_scenario(&d, 5.0);
    let out = Command::new(env!("CARGO_BIN_EXE_safe-capture"))
        .current_dir(root())
        .args([
            "run",
            "--quiet",
            "--no-compare",
            "--no-figures",
            "--scenario",
        ])
        .arg(&scenario)
        .arg("--out")
        .arg(d.join("o"))
        .output()
        .unwrap();
    // a 5 s mission times out; what matters here is the summary it writes
    let s: Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("o/summary.json")).unwrap_or_else(|e| {
            panic!(
                "no summary.json ({e}): {}",
                String::from_utf8_lossy(&out.stderr)
            )
        }),
    )
    .unwrap();
    assert_eq!(s["version"], env!("CARGO_PKG_VERSION"), "{s}");
    assert_eq!(s["git_commit"], COMMIT, "{s}");
}

#[test]
fn campaign_summary_names_version_and_commit() {
    let d = tmp("build-info-mc");
    let scenario = short_scenario(&d, 1.0);
    let out = d.join("c");
    let o = cli(
        &[
            "montecarlo",
            "--runs",
            "1",
            "--jobs",
            "1",
            "-q",
            "--scenario",
            scenario.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert_ne!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["version"], env!("CARGO_PKG_VERSION"), "{s}");
    assert_eq!(s["git_commit"], COMMIT, "{s}");
}
