//! `safe-capture montecarlo` (campaign, rerun, merge, injected failure, --mode partition
//! against in-process) and the figures of `safe-capture run`, mostly on short missions.

mod common;
use common::*;
use std::collections::BTreeMap;
use std::path::Path;

#[test]
fn campaign_rerun_and_merge_from_the_command_line() {
    let _cpu = exclusive();
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
        text(&o).contains("3 runs (seed 5): 3 safe, 0 captured, 0 with faults, 0 failed"),
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
    let _cpu = exclusive();
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
    let missing_exec = d.join("partition.toml");
    std::fs::write(
        &missing_exec,
        partition_toml_absolute_scenario().replace(
            "[roles.scheduler]\n",
            "[roles.scheduler]\nexec = \"/nonexistent/sc-scheduler\"\n",
        ),
    )
    .unwrap();
    let missing_exec = missing_exec.to_str().unwrap();
    let cases: [&[&str]; 7] = [
        &[
            "montecarlo",
            "--mode",
            "partition",
            "--partition-config",
            "/nonexistent/partition.toml",
            "--runs",
            "1",
        ],
        &[
            "montecarlo",
            "--mode",
            "partition",
            "--partition-config",
            missing_exec,
            "--runs",
            "1",
        ],
        &["montecarlo", "--keep-recordings", "--runs", "1"],
        &["montecarlo", "--shard", "2/2", "--runs", "1"],
        &[
            "montecarlo",
            "--config",
            "/nonexistent/mc.toml",
            "--runs",
            "1",
        ],
        &["montecarlo", "rerun", "/nonexistent/campaign", "--run", "0"],
        &["montecarlo", "--resume"],
    ];
    let expect = [
        "/nonexistent/partition.toml",
        "role `scheduler`: the executable /nonexistent/sc-scheduler does not exist",
        "--keep-recordings needs --mode partition",
        "2/2",
        "/nonexistent/mc.toml",
        "/nonexistent/campaign",
        "holds no campaign (no campaign.json)",
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
    let _cpu = exclusive();
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

/// Nothing of the campaign process `pid` left in /dev/shm (run ids `mc<K>-<pid>-…`).
fn assert_no_shm_leftovers(pid: u32) {
    let left: Vec<String> = std::fs::read_dir("/dev/shm")
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("sc_mc") && n.contains(&format!("-{pid}-")))
        .collect();
    assert!(left.is_empty(), "left in /dev/shm: {left:?}");
}

/// `summary.json` of a campaign without its wall-clock keys (solve times, wall time,
/// host load).
fn deterministic_summary(dir: &Path) -> serde_json::Value {
    let mut v = json(&dir.join("summary.json"));
    for k in sc_montecarlo::WALL_CLOCK_KEYS {
        v.as_object_mut().unwrap().remove(k);
    }
    v
}

/// `runs.csv` as run → (column → value).
fn runs_csv(dir: &Path) -> (Vec<String>, BTreeMap<String, BTreeMap<String, String>>) {
    let text = std::fs::read_to_string(dir.join("runs.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut rows = BTreeMap::new();
    for l in lines {
        // no quoted fields in completed runs (the error column is empty)
        let f: Vec<&str> = l.split(',').collect();
        assert_eq!(f.len(), header.len(), "{l}");
        let row: BTreeMap<String, String> = header
            .iter()
            .cloned()
            .zip(f.iter().map(|x| x.to_string()))
            .collect();
        rows.insert(row["run"].clone(), row);
    }
    (header, rows)
}

/// The issue's guarantee: a campaign through the process partition gives exactly the
/// in-process results (every per-run row field, result.json, trace, summary, figures);
/// only the wall-clock outputs (solve times, wall time) differ. Full missions, so
/// capture and capture time are compared too; one partition at a time (the default).
#[test]
fn partition_mode_gives_exactly_the_in_process_results() {
    let _cpu = exclusive();
    let d = tmp("partition");
    let (inp, part) = (d.join("in-process"), d.join("partition"));
    let common = ["montecarlo", "--runs", "3", "--seed", "2", "-q"];
    let o = cli(
        &[&common[..], &["--out", inp.to_str().unwrap()]].concat(),
        &[],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let args = [
        &common[..],
        &["--mode", "partition", "--out", part.to_str().unwrap()],
    ]
    .concat();
    let (o, pid) = cli_partition(&args, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let t = text(&o);
    assert!(
        t.contains("3 runs (seed 2): 3 safe, 3 captured, 0 with faults, 0 failed"),
        "{t}"
    );
    assert!(!t.contains("launch:"), "the launcher must be quiet: {t}");
    assert_no_shm_leftovers(pid);

    // every per-run row, field by field (runs.csv holds no wall-clock column)
    let (hi, ri) = runs_csv(&inp);
    let (hp, rp) = runs_csv(&part);
    assert_eq!(hi, hp);
    assert_eq!(ri.len(), 3);
    for (run, row) in &ri {
        for col in &hi {
            assert_eq!(
                row[col], rp[run][col],
                "run {run}, column {col}: in-process {} vs partition {}",
                row[col], rp[run][col]
            );
        }
        assert_eq!(row["captured"], "true", "run {run}");
    }
    for k in 0..3 {
        let (a, b) = (
            inp.join(format!("runs/{k}")),
            part.join(format!("runs/{k}")),
        );
        for f in ["result.json", "trace.csv", "scenario.toml"] {
            assert_eq!(
                std::fs::read(a.join(f)).unwrap(),
                std::fs::read(b.join(f)).unwrap(),
                "runs/{k}/{f} differs"
            );
        }
        // the solve times are the partition filters' own, one per step
        let steps = json(&b.join("result.json"))["metrics"]["steps"]
            .as_u64()
            .unwrap();
        let timing = json(&b.join("timing.json"));
        assert_eq!(timing["stats"]["total"]["samples"].as_u64(), Some(steps));
        // evidence of the launch; the large recordings are not kept by default
        let pd = b.join("partition");
        let launch = json(&pd.join("launch.json"));
        assert_eq!(launch["code"], 0, "{launch}");
        assert_eq!(launch["leftovers"].as_array().unwrap().len(), 0, "{launch}");
        let roles = sc_icd::ROLES.len();
        assert_eq!(launch["exits"].as_array().unwrap().len(), roles, "{launch}");
        let rid = launch["run_id"].as_str().unwrap();
        assert!(rid.starts_with(&format!("mc{k}-{pid}-")), "{rid}");
        let rec = json(&pd.join("recorder.json"));
        assert_eq!(rec["steps"].as_u64(), Some(steps));
        assert!(
            rec["missing"].as_object().unwrap().values().all(|v| v == 0),
            "{rec}"
        );
        assert!(!pd.join("telemetry.csv").exists() && !pd.join("recording.mcap").exists());
    }
    assert_eq!(deterministic_summary(&inp), deterministic_summary(&part));
    for f in [
        "trajectories_xy.svg",
        "attitude_los.svg",
        "torque_vs_sync.svg",
        "barrier_minima.svg",
    ] {
        assert_eq!(
            std::fs::read(inp.join("figures").join(f)).unwrap(),
            std::fs::read(part.join("figures").join(f)).unwrap(),
            "figures/{f} differs"
        );
    }
    assert_eq!(json(&part.join("campaign.json"))["execution"], "partition");
    assert!(
        std::fs::read_to_string(part.join("report.md"))
            .unwrap()
            .contains("through the process partition")
    );
    // and the in-process rerun of a partition run reproduces it exactly
    let o = cli(
        &[
            "montecarlo",
            "rerun",
            part.to_str().unwrap(),
            "--run",
            "1",
            "--no-figures",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(text(&o).contains("reproduced exactly"), "{}", text(&o));
    let _ = std::fs::remove_dir_all(&d);
}

/// A partition launch that fails is a failed run with its reason; the other runs
/// complete, two partitions at a time (each with its own run id); nothing is left in
/// /dev/shm. `--keep-recordings` keeps the telemetry.
#[test]
fn a_failed_partition_launch_is_a_failed_run_and_the_campaign_goes_on() {
    let _cpu = exclusive();
    let d = tmp("partition-fail");
    let sc = short_scenario(&d, 1.0);
    let out = d.join("c");
    let (o, pid) = cli_partition(
        &[
            "montecarlo",
            "--mode",
            "partition",
            "--runs",
            "3",
            "--scenario",
            sc.to_str().unwrap(),
            "--keep-recordings",
            "--jobs",
            "2",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[("SC_MONTECARLO_INJECT_PANIC", "1")],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let t = text(&o);
    assert!(
        t.contains("3 runs (seed 1): 2 safe, 0 captured, 0 with faults, 1 failed")
            && t.contains("run 1 failed: partition: cannot start role `simulator`"),
        "{t}"
    );
    assert_no_shm_leftovers(pid);
    let r = json(&out.join("runs/1/result.json"));
    assert_eq!(r["status"], "failed");
    let launch = json(&out.join("runs/1/partition/launch.json"));
    assert_eq!(launch["code"], 3, "{launch}");
    assert_eq!(launch["leftovers"].as_array().unwrap().len(), 0, "{launch}");
    for k in [0, 2] {
        let pd = out.join(format!("runs/{k}/partition"));
        for f in [
            "telemetry.csv",
            "timing.csv",
            "recording.mcap",
            "latency.csv",
        ] {
            assert!(pd.join(f).is_file(), "runs/{k}/partition/{f} not kept");
        }
    }
    let s = json(&out.join("summary.json"));
    assert_eq!(
        (s["runs"].as_u64(), s["failed_runs"].as_u64()),
        (Some(3), Some(1))
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Mission length of the interrupted campaign: long enough that the runs after the
/// first outlast the time the test takes to see it finish and send the signal.
const INTERRUPTED_MISSION_S: f64 = 20.0;

/// Runs of the interrupted campaign (one at a time).
const INTERRUPTED_RUNS: usize = 6;

/// How often the test looks for the first finished run.
const POLL: std::time::Duration = std::time::Duration::from_millis(10);

/// How long the first run may take before the test gives up.
const FIRST_RUN_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(120);

/// Exit code of an interrupted campaign (`safe-capture montecarlo --help`).
const EXIT_INTERRUPTED: i32 = 3;

/// The numbered run directories of a campaign, and every other entry of its `runs/`.
fn run_dirs(dir: &Path) -> (Vec<usize>, Vec<String>) {
    let (mut runs, mut other) = (Vec::new(), Vec::new());
    for e in std::fs::read_dir(dir.join("runs")).unwrap() {
        let n = e.unwrap().file_name().to_string_lossy().into_owned();
        match n.parse() {
            Ok(k) => runs.push(k),
            Err(_) => other.push(n),
        }
    }
    runs.sort_unstable();
    (runs, other)
}

/// Starts the campaign `common` of scenario `sc` into `out` and returns once its first
/// run is saved (a new campaign is written into `out.incomplete`, which replaces `out`
/// at the end).
fn spawn_until_first_run(common: &[&str], sc: &str, out: &Path) -> std::process::Child {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_safe-capture"))
        .current_dir(root())
        .args(common)
        .args(["--scenario", sc, "--out", out.to_str().unwrap()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    let mut staging = out.as_os_str().to_owned();
    staging.push(".incomplete");
    while !Path::new(&staging).join("runs/0").is_dir() {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the campaign ended before a run finished: {status}");
        }
        if started.elapsed() > FIRST_RUN_TIMEOUT {
            let _ = child.kill();
            panic!("no run finished within {FIRST_RUN_TIMEOUT:?}");
        }
        std::thread::sleep(POLL);
    }
    child
}

/// A campaign killed outright (SIGKILL: a cluster's task pre-empted or timed out without
/// a grace period) never reached `--out`; `--resume --out` with the same folder takes its
/// saved runs over from the staging folder and completes it, `runs.csv` identical to an
/// uninterrupted campaign's (issue #28).
#[test]
fn a_killed_campaign_resumes_from_its_staging_folder() {
    let _cpu = exclusive();
    let d = tmp("killed");
    let sc = short_scenario(&d, INTERRUPTED_MISSION_S);
    let sc = sc.to_str().unwrap();
    let out = d.join("c");
    let runs = INTERRUPTED_RUNS.to_string();
    let common = [
        "montecarlo",
        "--runs",
        &runs,
        "--seed",
        "5",
        "--jobs",
        "1",
        "-q",
    ];
    let mut child = spawn_until_first_run(&common, sc, &out);
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!out.exists());
    let saved = run_dirs(&d.join("c.incomplete")).0;
    assert!(
        !saved.is_empty() && saved.len() < INTERRUPTED_RUNS,
        "{saved:?}"
    );
    // a run saved before the kill is kept as it was, not run again
    let first = format!("runs/{}/result.json", saved[0]);
    let written = std::fs::metadata(d.join("c.incomplete").join(&first))
        .unwrap()
        .modified()
        .unwrap();
    let o = cli(
        &[
            "montecarlo",
            "--resume",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    // short missions do not capture: 1, the campaign complete
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("resuming the campaign that was stopped before it reached"),
        "{}",
        text(&o)
    );
    assert!(!d.join("c.incomplete").exists());
    let kept = std::fs::metadata(out.join(&first))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(kept, written, "run {} was run again", saved[0]);
    let whole = d.join("whole");
    let o = cli(
        &[
            &common[..],
            &["--scenario", sc, "--out", whole.to_str().unwrap()],
        ]
        .concat(),
        &[],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert_eq!(run_dirs(&out), run_dirs(&whole));
    assert_eq!(
        std::fs::read(out.join("runs.csv")).unwrap(),
        std::fs::read(whole.join("runs.csv")).unwrap()
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Ctrl-C in-process: SIGINT after the first run finished stops the campaign — exit 3,
/// summary.json, report.md and the terminal say "interrupted after K of N", only the
/// finished runs are there and aggregated (no run half-written); `--resume` completes
/// it with the deterministic outputs of an uninterrupted campaign; `--resume` on a
/// campaign of another seed is refused in one line with exit 2.
#[test]
fn ctrl_c_stops_an_in_process_campaign_and_resume_completes_it() {
    let _cpu = exclusive();
    let d = tmp("interrupt");
    let sc = short_scenario(&d, INTERRUPTED_MISSION_S);
    let sc = sc.to_str().unwrap();
    let out = d.join("c");
    let runs = INTERRUPTED_RUNS.to_string();
    let common = [
        "montecarlo",
        "--runs",
        &runs,
        "--seed",
        "5",
        "--jobs",
        "1",
        "-q",
    ];
    let child = spawn_until_first_run(&common, sc, &out);
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(EXIT_INTERRUPTED), "{t}");
    let s = json(&out.join("summary.json"));
    let k = s["interrupted"]["completed_runs"].as_u64().unwrap() as usize;
    assert_eq!(s["interrupted"]["planned_runs"], INTERRUPTED_RUNS, "{s}");
    assert!((1..INTERRUPTED_RUNS).contains(&k), "{s}");
    assert_eq!(s["runs"], k, "{s}");
    assert!(
        t.contains(&format!("interrupted after {k} of {INTERRUPTED_RUNS} runs")),
        "{t}"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains(&format!("after {k} of {INTERRUPTED_RUNS} runs")),
        "{report}"
    );
    // the runs in flight finished; nothing half-written is left, nothing uncounted
    let (done, other) = run_dirs(&out);
    assert_eq!(done, (0..k).collect::<Vec<_>>());
    assert!(other.is_empty(), "{other:?}");
    for r in &done {
        assert!(out.join(format!("runs/{r}/result.json")).is_file());
    }
    let load = &s["host_load"][0];
    assert!(load["start"]["cpus"].as_u64().unwrap() >= 1, "{s}");
    assert!(load["end"]["load_avg_1min"].as_f64().unwrap() >= 0.0, "{s}");
    assert!(report.contains("inflated under load"), "{report}");

    // another seed: refused, the campaign untouched
    let o = cli(
        &[
            "montecarlo",
            "--resume",
            "--seed",
            "6",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("holds another campaign: seed 5 (not 6)"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert_eq!(run_dirs(&out).0, done);

    // --resume takes the rest of the parameters from the campaign
    let o = cli(
        &[
            "montecarlo",
            "--resume",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    // short missions do not capture: 1, the campaign complete
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(!text(&o).contains("interrupted"), "{}", text(&o));
    let whole = d.join("whole");
    let o = cli(
        &[
            &common[..],
            &["--scenario", sc, "--out", whole.to_str().unwrap()],
        ]
        .concat(),
        &[],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let resumed = json(&out.join("summary.json"));
    assert!(resumed.get("interrupted").is_none(), "{resumed}");
    assert_eq!(resumed["host_load"].as_array().unwrap().len(), 2);
    assert_eq!(deterministic_summary(&out), deterministic_summary(&whole));
    assert_eq!(run_dirs(&out), run_dirs(&whole));
    let mut files = vec!["runs.csv".to_string(), "figures/trajectories_xy.svg".into()];
    for r in 0..INTERRUPTED_RUNS {
        for f in ["result.json", "scenario.toml", "trace.csv"] {
            files.push(format!("runs/{r}/{f}"));
        }
    }
    for f in files {
        assert_eq!(
            std::fs::read(out.join(&f)).unwrap(),
            std::fs::read(whole.join(&f)).unwrap(),
            "{f} differs between the resumed and the uninterrupted campaign"
        );
    }
}

/// A campaign of no runs is refused before anything runs (issue #27: it was accepted
/// with exit 0).
#[test]
fn zero_runs_are_refused() {
    let d = tmp("zero-runs");
    let out = d.join("o");
    let o = cli(
        &["montecarlo", "--runs", "0", "--out", out.to_str().unwrap()],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("invalid value '0' for '--runs <RUNS>'"),
        "{}",
        text(&o)
    );
    assert!(!out.exists());
}

/// A run with a filter fault is not a pass (issue #27: the campaign counted it safe and
/// exited 0 while `run` exited 1 on it): seed 1's run 6 has one relaxed attitude step —
/// every barrier held, so it is safe, and the campaign names it and exits 1.
#[test]
fn a_run_with_faults_is_named_and_fails_the_campaign() {
    let _cpu = exclusive();
    let d = tmp("faulted");
    let out = d.join("mc");
    let o = cli(
        &[
            "montecarlo",
            "--runs",
            "7",
            "--seed",
            "1",
            "-q",
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(
        t.contains("7 runs (seed 1): 7 safe, 7 captured, 1 with faults, 0 failed")
            && t.contains("runs with faults: [6]"),
        "{t}"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("faults on 1 step"), "{report}");
}
