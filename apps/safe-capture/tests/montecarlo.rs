//! `safe-capture montecarlo` (campaign, rerun, merge, injected failure, --mode partition)
//! and the figures of `safe-capture run`, on short missions.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sc-mc-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The default scenario with a short duration (absolute URDF path), in `dir`.
fn short_scenario(dir: &Path, duration: f64) -> PathBuf {
    let text = std::fs::read_to_string(root().join("config/scenario.toml")).unwrap();
    let urdf = std::path::absolute(root().join("config/servicer.urdf")).unwrap();
    let text = text
        .replace("duration_s = 240.0", &format!("duration_s = {duration:?}"))
        .replace(
            "urdf = \"servicer.urdf\"",
            &format!("urdf = \"{}\"", urdf.display()),
        );
    assert!(text.contains(&format!("duration_s = {duration:?}")));
    let p = dir.join("scenario.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn cli(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_safe-capture"));
    c.current_dir(root()).args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn campaign_rerun_and_merge_from_the_command_line() {
    let d = tmp("cli");
    let sc = short_scenario(&d, 2.0);
    let sc = sc.to_str().unwrap();
    let out = d.join("c");
    let o = cli(
        &[
            "montecarlo",
            "--runs",
            "3",
            "--seed",
            "5",
            "--jobs",
            "2",
            "--scenario",
            sc,
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    // 2 s missions do not capture: exit code 1, but the campaign is complete
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("3 runs (seed 5): 3 safe, 0 captured, 0 failed"),
        "{}",
        text(&o)
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    for k in [
        "runs",
        "safe_runs",
        "captured_runs",
        "failed_runs",
        "worst",
        "solve_time_us",
        "wall_time_s",
    ] {
        assert!(s.get(k).is_some(), "summary.json lacks {k}");
    }
    for f in ["geomean", "p50", "p99", "max"] {
        assert!(s["solve_time_us"]["total"][f].as_f64().unwrap() > 0.0);
    }
    assert!(s["worst"]["approach_corridor"]["run"].is_u64());
    for f in [
        "runs.csv",
        "runs_timing.csv",
        "report.md",
        "figures/runtime.svg",
        "figures/trajectories_xy.svg",
        "figures/attitude_los.svg",
        "figures/torque_vs_sync.svg",
        "figures/barrier_minima.svg",
        "runs/2/scenario.toml",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("1.59 ms") && report.contains("3.75 ms") && report.contains("0.0432"));

    let o = cli(
        &["montecarlo", "rerun", out.to_str().unwrap(), "--run", "1"],
        &[],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(text(&o).contains("reproduced exactly"));
    let rr = out.join("runs/1/rerun");
    for f in [
        "telemetry.csv",
        "summary.json",
        "result.json",
        "figures/barriers.svg",
    ] {
        assert!(rr.join(f).is_file(), "rerun {f} missing");
    }

    let mut shards = Vec::new();
    for i in 0..2 {
        let sd = d.join(format!("s{i}"));
        let o = cli(
            &[
                "montecarlo",
                "--runs",
                "3",
                "--seed",
                "5",
                "--jobs",
                "1",
                "--scenario",
                sc,
                "--shard",
                &format!("{i}/2"),
                "--out",
                sd.to_str().unwrap(),
                "-q",
            ],
            &[],
        );
        assert_eq!(o.status.code(), Some(1), "{}", text(&o));
        shards.push(sd.to_str().unwrap().to_string());
    }
    let merged = d.join("m");
    let o = cli(
        &[
            "montecarlo",
            "merge",
            &shards[0],
            &shards[1],
            "--out",
            merged.to_str().unwrap(),
        ],
        &[],
    );
    assert!(text(&o).contains("3 runs (seed 5)"), "{}", text(&o));
    for f in [
        "runs.csv",
        "figures/trajectories_xy.svg",
        "runs/0/result.json",
    ] {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(merged.join(f)).unwrap(),
            "{f} differs"
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn an_injected_panic_is_reported_and_the_campaign_completes() {
    let d = tmp("inject");
    let sc = short_scenario(&d, 1.0);
    let out = d.join("c");
    let o = cli(
        &[
            "montecarlo",
            "--runs",
            "3",
            "--jobs",
            "2",
            "--scenario",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[("SC_MONTECARLO_INJECT_PANIC", "1")],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let t = text(&o);
    assert!(
        t.contains("1 failed") && t.contains("run 1 failed: panicked: injected failure"),
        "{t}"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["runs"], 3);
    assert_eq!(s["failed_runs"], 1);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_montecarlo_arguments_are_one_line_errors() {
    let d = tmp("args");
    let cases: [&[&str]; 4] = [
        &["montecarlo", "--mode", "partition", "--runs", "1"],
        &["montecarlo", "--shard", "2/2", "--runs", "1"],
        &[
            "montecarlo",
            "--config",
            "/nonexistent/mc.toml",
            "--runs",
            "1",
        ],
        &["montecarlo", "rerun", "/nonexistent/campaign", "--run", "0"],
    ];
    let expect = [
        "not available yet",
        "2/2",
        "/nonexistent/mc.toml",
        "/nonexistent/campaign",
    ];
    for (args, want) in cases.iter().zip(expect) {
        let mut a: Vec<&str> = args.to_vec();
        let out = d.join("o");
        a.extend(["--out", out.to_str().unwrap()]);
        let a: Vec<&str> = if args[1] == "rerun" { args.to_vec() } else { a };
        let o = cli(&a, &[]);
        assert_eq!(o.status.code(), Some(2), "{a:?}: {}", text(&o));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(want), "{a:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{a:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn run_writes_figures_with_the_nominal_comparison() {
    let d = tmp("run");
    let sc = short_scenario(&d, 3.0);
    let out = d.join("r");
    let o = cli(
        &[
            "run",
            "--scenario",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    assert!(o.status.code().is_some_and(|c| c <= 1), "{}", text(&o));
    for f in [
        "trajectory.svg",
        "barriers.svg",
        "range_rate.svg",
        "sync_error.svg",
        "joint_torques.svg",
        "line_of_sight.svg",
    ] {
        let s = std::fs::read_to_string(out.join("figures").join(f)).unwrap();
        assert!(s.starts_with("<svg"), "{f}");
    }
    assert!(out.join("nominal/summary.json").is_file());
    assert!(
        std::fs::read_to_string(out.join("figures/barriers.svg"))
            .unwrap()
            .contains("nominal")
    );
    let out2 = d.join("r2");
    let o = cli(
        &[
            "run",
            "--scenario",
            sc.to_str().unwrap(),
            "--out",
            out2.to_str().unwrap(),
            "-q",
            "--no-compare",
        ],
        &[],
    );
    assert!(o.status.code().is_some_and(|c| c <= 1), "{}", text(&o));
    assert!(!out2.join("nominal").exists());
    assert!(
        !std::fs::read_to_string(out2.join("figures/barriers.svg"))
            .unwrap()
            .contains("nominal")
    );
    let _ = std::fs::remove_dir_all(&d);
}
