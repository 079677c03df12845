//! safe-capture run from any working directory (issue #16): the defaults find the
//! shipped config/ and scripts/ in the installation; paths the user gives stay relative
//! to the user's working directory.

mod common;
use common::*;
use std::process::{Command, Output};

/// A mission short enough for a quick run [s].
const SHORT_MISSION_S: f64 = 2.0;

/// Ticks of a short launch.
const SHORT_TICKS: &str = "20";

/// The CLI run in `cwd` (not the checkout), with the partition's executables of this build.
fn cli_in(cwd: &std::path::Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_safe-capture"));
    c.current_dir(cwd)
        .args(args)
        .env("SC_PARTITION_BIN_DIR", partition_bin_dir())
        .env_remove("SAFE_CAPTURE_HOME");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

#[test]
fn the_defaults_resolve_against_the_installation_not_the_working_directory() {
    let _cpu = exclusive();
    let d = tmp("anywhere");
    // the default scenario, and a relative --out in the working directory
    let o = cli_in(
        &d,
        &["run", "-q", "--no-figures", "--no-compare", "--out", "r"],
        &[],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(d.join("r/summary.json").is_file(), "{}", text(&o));
    // the default Monte Carlo config and a relative --scenario of the user's
    short_scenario(&d, SHORT_MISSION_S);
    let o = cli_in(
        &d,
        &[
            "montecarlo",
            "--runs",
            "1",
            "-q",
            "--scenario",
            "scenario.toml",
            "--out",
            "m",
        ],
        &[],
    );
    assert_eq!(
        o.status.code(),
        Some(1),
        "short missions do not capture: {}",
        text(&o)
    );
    assert!(d.join("m/summary.json").is_file(), "{}", text(&o));
    // the default partition config
    let o = cli_in(
        &d,
        &["launch", "--max-ticks", SHORT_TICKS, "--out", "p"],
        &[],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(d.join("p/summary.json").is_file(), "{}", text(&o));
    // a relative path the user gives is the user's: not found in the installation
    let o = cli_in(&d, &["run", "--scenario", "config/scenario.toml"], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("cannot read config/scenario.toml"),
        "{}",
        text(&o)
    );
}

#[test]
fn safe_capture_home_names_the_installation() {
    let d = tmp("home-env");
    let home = d.join("elsewhere");
    let o = cli_in(
        &d,
        &["run", "--out", "r"],
        &[("SAFE_CAPTURE_HOME", home.to_str().unwrap())],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let want = format!(
        "cannot read {}",
        home.join("config/scenario.toml").display()
    );
    assert!(text(&o).contains(&want), "{}", text(&o));
    assert!(!d.join("r").exists());
}
