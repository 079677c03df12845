//! `safe-capture launch` as a user meets it around the partition's output folder.

mod common;
use common::*;

/// A partition config for a launch from `dir`: config/partition.toml with the default
/// scenario (absolute), a short handshake, and `from` replaced by `to`.
fn partition_with(dir: &std::path::Path, from: &str, to: &str) -> std::path::PathBuf {
    let cfg = partition_toml_absolute_scenario()
        .replace("handshake_timeout_s = 30.0", "handshake_timeout_s = 2.0");
    assert!(cfg.contains(from) && cfg.contains("handshake_timeout_s = 2.0"));
    let p = dir.join("partition.toml");
    std::fs::write(&p, cfg.replacen(from, to, 1)).unwrap();
    p
}

/// Files of this CLI process's runs in /dev/shm (their run ids hold its pid).
fn shm_files_of(pid: u32) -> Vec<String> {
    std::fs::read_dir("/dev/shm")
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("sc_") && n.contains(&format!("-{pid}-")))
        .collect()
}

/// A launch whose config names a missing scenario or program stops before anything
/// starts: exit 2, one line naming the key or role, the cause and the fix, no verdict
/// line, no output folder, nothing in /dev/shm (issue #16).
#[test]
fn a_missing_scenario_or_program_stops_the_launch_before_anything_starts() {
    let d = tmp("launch-preflight");
    for (from, to, needles) in [
        (
            "[roles.simulator]\n",
            "[roles.simulator]\nexec = \"bin/sc-simulator\"\n",
            &[
                "role `simulator`: the executable",
                "bin/sc-simulator does not exist",
                "cargo build --release -p sc-partition-apps",
            ][..],
        ),
        (
            "[roles.recorder]\n",
            "[roles.recorder]\nexec = \"sc-recorder-v2\"\n",
            &["role `recorder`: the executable `sc-recorder-v2` was found neither"],
        ),
        (
            "[roles.nominal_attitude]\n",
            "[roles.nominal_attitude]\nexec = \"sh\"\nargs = [\"partners/attitude.sh\"]\n",
            &["role `nominal_attitude`: the script \"partners/attitude.sh\""],
        ),
        (
            "handshake_timeout_s = 2.0",
            "handshake_timeout_s = 2.0\nscenario_override = 1",
            &["unknown field `scenario_override`"],
        ),
    ] {
        let cfg = partition_with(&d, from, to);
        let out = d.join("out");
        let (o, pid) = cli_partition(
            &[
                "launch",
                "--config",
                cfg.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            &[],
        );
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{t}");
        assert!(o.stdout.is_empty(), "a verdict line: {t}");
        let err = String::from_utf8_lossy(&o.stderr);
        let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
        assert_eq!(lines.len(), 1, "{t}");
        assert!(lines[0].starts_with("error: "), "{t}");
        for n in needles {
            assert!(lines[0].contains(n), "`{n}` not in: {t}");
        }
        assert!(!out.exists(), "{t}");
        assert_eq!(shm_files_of(pid), Vec::<String>::new());
    }
    // a scenario that is not there, or not valid
    for (scenario, needle) in [
        ("missing.toml", "scenario = \"missing.toml\": cannot read"),
        ("../partition.toml", "scenario = \"../partition.toml\": "),
    ] {
        let cfg = std::fs::read_to_string(root().join("config/partition.toml"))
            .unwrap()
            .replace(
                "scenario = \"scenario.toml\"",
                &format!("scenario = \"{scenario}\""),
            );
        let sub = d.join("sub");
        std::fs::create_dir_all(&sub).unwrap();
        std::fs::write(sub.join("partition.toml"), cfg).unwrap();
        // `launch` and `bench latency` check the same before starting anything
        for cmd in [&["launch"][..], &["bench", "latency", "--ticks", "1"]] {
            let mut args = cmd.to_vec();
            let cfg = sub.join("partition.toml");
            let out = d.join("out");
            args.extend([
                "--config",
                cfg.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ]);
            let (o, pid) = cli_partition(&args, &[]);
            let t = text(&o);
            assert_eq!(o.status.code(), Some(2), "{cmd:?}: {t}");
            assert_eq!(t.lines().count(), 1, "{cmd:?}: {t}");
            assert!(
                t.starts_with("error: ") && t.contains(needle),
                "{cmd:?}: {t}"
            );
            assert!(!out.exists(), "{cmd:?}: {t}");
            assert_eq!(shm_files_of(pid), Vec::<String>::new());
        }
    }
}

/// A process that starts but fails before every process is ready: the launch stops at
/// once instead of waiting for the handshake timeout, exit 3, and one verdict line that
/// says the run is no mission result and names that role alone (issue #16).
#[test]
fn a_process_that_fails_at_start_is_named_in_an_infrastructure_verdict() {
    let _cpu = exclusive();
    let d = tmp("launch-fails-at-start");
    let cfg = partition_with(
        &d,
        "[roles.nominal_robotic]\n",
        "[roles.nominal_robotic]\nexec = \"false\"\n",
    );
    // the default handshake timeout: the launch must not wait for it
    let default_timeout = std::fs::read_to_string(&cfg)
        .unwrap()
        .replace("handshake_timeout_s = 2.0", "handshake_timeout_s = 30.0");
    std::fs::write(&cfg, default_timeout).unwrap();
    let out = d.join("out");
    let t0 = std::time::Instant::now();
    let (o, pid) = cli_partition(
        &[
            "launch",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let t = text(&o);
    assert!(
        t0.elapsed() < std::time::Duration::from_secs(20),
        "waited for the handshake timeout: {t}"
    );
    assert_eq!(o.status.code(), Some(3), "{t}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    let verdict: Vec<&str> = stdout.lines().collect();
    assert_eq!(verdict.len(), 1, "{t}");
    assert!(
        verdict[0].starts_with(
            "partition: infrastructure failure (exit 3), no mission result: role `nominal_robotic` ended (exit code 1) before every process was ready"
        ) && !verdict[0].contains("no summary"),
        "{t}"
    );
    // on stderr only the process that failed by itself, not the ones the teardown stopped
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("nominal_robotic") && !stderr.contains("safety_attitude"),
        "{t}"
    );
    // the failed run's output is kept apart, under a name that says so
    assert!(!out.exists(), "{t}");
    let kept = d.join("out.incomplete");
    assert!(
        verdict[0].ends_with(&format!(
            "-> {} (partial output; {} not replaced)",
            kept.display(),
            out.display()
        )),
        "{t}"
    );
    assert_eq!(json(&kept.join("launch.json"))["code"], 3);
    assert_eq!(shm_files_of(pid), Vec::<String>::new());
}

/// A launch that fails at start into the folder of an earlier run reports no mission
/// result instead of the old run's and leaves that folder as it was; its own output is
/// kept in OUT.incomplete; a folder that is not ours is refused before anything starts
/// (issue #16).
#[test]
fn a_failed_launch_never_reports_an_old_run() {
    let _cpu = exclusive();
    let d = tmp("stale-launch");
    let cfg = partition_toml_absolute_scenario()
        .replace("handshake_timeout_s = 30.0", "handshake_timeout_s = 2.0")
        .replace(
            "[roles.nominal_robotic]\n",
            "[roles.nominal_robotic]\nexec = \"false\"\n",
        );
    assert!(cfg.contains("exec = \"false\"") && cfg.contains("handshake_timeout_s = 2.0"));
    std::fs::write(d.join("partition.toml"), cfg).unwrap();
    let out = d.join("out");
    std::fs::create_dir_all(out.join("logs")).unwrap();
    let old_summary = r#"{"end": "captured", "final_time_s": 99.0}"#;
    std::fs::write(out.join("summary.json"), old_summary).unwrap();
    std::fs::write(out.join("logs/simulator.log"), "an old run's log\n").unwrap();
    std::fs::write(out.join("notes.txt"), "mine\n").unwrap();
    let launch = || {
        cli_partition(
            &[
                "launch",
                "--config",
                d.join("partition.toml").to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            &[],
        )
        .0
    };
    // not ours (no marker): refused, nothing started or written
    let o = launch();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("was not written by safe-capture") && t.contains("--force"),
        "{t}"
    );
    assert!(!d.join("out.incomplete").exists(), "{t}");
    // an earlier run's folder: the failed launch leaves it whole and reports none of it
    std::fs::write(out.join(".safe-capture"), "{}").unwrap();
    let o = launch();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(3), "{t}");
    assert!(
        t.contains("infrastructure failure") && !t.contains("captured"),
        "{t}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("summary.json")).unwrap(),
        old_summary
    );
    assert_eq!(
        std::fs::read_to_string(out.join("logs/simulator.log")).unwrap(),
        "an old run's log\n"
    );
    let kept = d.join("out.incomplete");
    assert!(!kept.join("summary.json").exists(), "{t}");
    assert_eq!(json(&kept.join("launch.json"))["code"], 3);
    assert!(t.contains(&format!("-> {}", kept.display())), "{t}");
}

/// Ticks of the short launches below.
const SHORT_TICKS: &str = "50";

/// `--max-ticks` ends a launch in its own words, not as a mission timeout, on the
/// terminal and in summary.json (issue #16).
#[test]
fn a_launch_stopped_by_max_ticks_says_so() {
    let _cpu = exclusive();
    let d = tmp("max-ticks");
    let cfg = d.join("partition.toml");
    std::fs::write(&cfg, partition_toml_absolute_scenario()).unwrap();
    let out = d.join("out");
    let (o, _) = cli_partition(
        &[
            "launch",
            "--config",
            cfg.to_str().unwrap(),
            "--max-ticks",
            SHORT_TICKS,
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.starts_with(&format!(
            "partition: stopped after {SHORT_TICKS} ticks (--max-ticks) at t = 4.9 s, before the mission ended; min margin "
        )) && stdout.contains(&format!(
            "; violated: []; faults: 0; {} processes, failed: []",
            sc_icd::ROLES.len()
        )),
        "{t}"
    );
    assert!(!t.contains("timeout"), "{t}");
    // summary.json and recorder.json say the same: the run stopped, the mission did not end
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["end"], "stopped", "{summary}");
    assert_eq!(summary["captured"], false, "{summary}");
    assert_eq!(json(&out.join("recorder.json"))["end"], "stopped");
    // the recorder recorded everything: it ended well although nothing was captured
    let launch = json(&out.join("launch.json"));
    let recorder = launch["exits"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["role"] == "recorder")
        .unwrap();
    assert_eq!(recorder["code"], 0, "{launch}");
}

/// A partner's controller that fails from t = 3 s — its `step` raises, returns two
/// values instead of three, or a non-finite command — is named in the verdict line with
/// how many steps it gave no valid command and the reason for the first, quoted from its
/// log; the run is not a pass (exit 1) (issue #27, "a failing partner controller looks
/// like success").
#[test]
fn a_failing_partner_is_named_in_the_verdict() {
    for (bad, reason) in [
        ("raise ValueError('boom')", "step raised ValueError: boom"),
        (
            "return [0.0, 0.0]",
            "step returned shape (2,), the attitude command is 3 values",
        ),
        (
            "return [float('nan'), 0.0, float('inf')]",
            "step returned a non-finite command [nan, 0.0, inf]",
        ),
    ] {
        failing_partner_is_named(bad, reason);
    }
}

fn failing_partner_is_named(bad: &str, reason: &str) {
    let _cpu = exclusive();
    let Some(py) = python() else {
        return;
    };
    let d = tmp("failing-partner");
    let script = d.join("bad_attitude.py");
    std::fs::write(
        &script,
        format!("import sys\nfrom sc_partner import NominalController\n\n\nclass Bad(NominalController):\n    subsystem = 'attitude'\n\n    def step(self, state):\n        if state.t > 2.95:\n            {bad}\n        return [0.0, 0.0, 0.0]\n\n\nsys.exit(Bad.main())\n"),
    )
    .unwrap();
    let cfg = partition_with(
        &d,
        "[roles.nominal_attitude]\n",
        &format!("[roles.nominal_attitude]\nexec = {py:?}\nargs = [{script:?}]\n"),
    );
    let out = d.join("out");
    let pythonpath = root().join("scripts/python");
    let (o, _) = cli_partition(
        &[
            "launch",
            "--config",
            cfg.to_str().unwrap(),
            "--max-ticks",
            SHORT_TICKS,
            "--out",
            out.to_str().unwrap(),
        ],
        &[("PYTHONPATH", pythonpath.to_str().unwrap())],
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains(&format!(
            "; nominal_attitude: 20 of {SHORT_TICKS} steps without a valid command (first at t = 3.0 s: {reason}"
        )),
        "{t}"
    );
    let s = json(&out.join("summary.json"));
    assert_eq!(s["partner_faults"]["nominal_attitude"]["steps"], 20, "{s}");
}

/// A Python partner script (`script`) in `role`'s slot of the default partition: the launch's
/// output (PYTHONPATH to the checkout's SDK), or `None` without a Python with iceoryx2.
fn launch_partner(
    dir: &std::path::Path,
    role: &str,
    script: &str,
    args: &[&str],
) -> Option<std::process::Output> {
    let py = python()?;
    let file = dir.join("partner.py");
    std::fs::write(&file, script).unwrap();
    let cfg = dir.join("partition.toml");
    let text = partition_toml_absolute_scenario().replacen(
        &format!("[roles.{role}]\n"),
        &format!("[roles.{role}]\nexec = {py:?}\nargs = [{file:?}]\n"),
        1,
    );
    std::fs::write(&cfg, text).unwrap();
    let out = dir.join("out");
    let pythonpath = root().join("scripts/python");
    let mut a = vec![
        "launch",
        "--config",
        cfg.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend_from_slice(args);
    Some(cli_partition(&a, &[("PYTHONPATH", pythonpath.to_str().unwrap())]).0)
}

/// A controller in another role's slot (a translational controller as
/// `nominal_attitude`) is named as such, before the run starts; a controller file that
/// never calls its `main()` is reported as soon as it ends — not after the handshake
/// timeout (30 s here) — with the fix (issue #27).
#[test]
fn a_partner_in_the_wrong_slot_or_without_main_is_named_at_once() {
    let _cpu = exclusive();
    let d = tmp("partner-start");
    let wrong = "import sys\nfrom sc_partner import NominalController\n\n\nclass T(NominalController):\n    subsystem = 'translational'\n\n    def step(self, state):\n        return [0.0, 0.0, 0.0]\n\n\nsys.exit(T.main())\n";
    let Some(o) = launch_partner(&d, "nominal_attitude", wrong, &[]) else {
        return;
    };
    let t = text(&o);
    assert_eq!(o.status.code(), Some(3), "{t}");
    assert!(
        t.contains("role `nominal_attitude` ended (exit code 2) before every process was ready")
            && t.contains("this controller commands the translational subsystem")
            && t.contains("put it under [roles.nominal_translational]"),
        "{t}"
    );
    let d = tmp("partner-no-main");
    let no_main = "from sc_partner import NominalController\n\n\nclass A(NominalController):\n    subsystem = 'attitude'\n\n    def step(self, state):\n        return [0.0, 0.0, 0.0]\n";
    let o = launch_partner(&d, "nominal_attitude", no_main, &[]).unwrap();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(3), "{t}");
    assert!(
        t.contains("role `nominal_attitude` ended (exit code 0) before every process was ready")
            && t.contains("sys.exit(MyController.main())")
            && !t.contains("handshake timed out"),
        "{t}"
    );
}

/// A partner that hangs (stops answering and ignores the stop tick) is a failed process:
/// exit 3 as `launch --help` says, named as stopped by the launcher (issue #27).
#[test]
fn a_hung_partner_is_a_failed_process() {
    let _cpu = exclusive();
    let d = tmp("hung-partner");
    let cfg = d.join("partition.toml");
    std::fs::write(&cfg, partition_toml_absolute_scenario()).unwrap();
    let Some(py) = python() else {
        return;
    };
    let out = d.join("out");
    let (o, _) = cli_partition(
        &[
            "launch",
            "--config",
            cfg.to_str().unwrap(),
            "--max-ticks",
            SHORT_TICKS,
            "--hostile",
            "attitude/spin:x+hang:20",
            "--python",
            py.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(3), "{t}");
    assert!(
        t.contains("did not end on the stop tick")
            && t.contains("then stopped by the launcher: nominal_attitude"),
        "{t}"
    );
}

/// A launch whose reader has gone (`launch … | head`, stdout and stderr closed) neither
/// panics nor stops before the teardown: its own exit code, its output committed,
/// nothing left in /dev/shm (issue #16).
#[test]
fn a_launch_into_a_closed_pipe_ends_cleanly() {
    let _cpu = exclusive();
    let d = tmp("closed-pipe");
    let cfg = d.join("partition.toml");
    std::fs::write(&cfg, partition_toml_absolute_scenario()).unwrap();
    let out = d.join("out");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_safe-capture"))
        .current_dir(root())
        .args(["launch", "--config", cfg.to_str().unwrap()])
        .args(["--max-ticks", SHORT_TICKS, "--out", out.to_str().unwrap()])
        .env("SC_PARTITION_BIN_DIR", partition_bin_dir())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // the reader goes before anything was written
    drop(child.stdout.take());
    drop(child.stderr.take());
    let pid = child.id();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(1), "{status}");
    assert!(out.join("summary.json").is_file());
    assert_eq!(shm_files_of(pid), Vec::<String>::new());
}

/// How long a real-time launch may take to have every process ready.
const READY_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(30);

/// Ctrl-C (SIGINT) and SIGTERM end a launch as interrupted, not as a mission timeout:
/// exit 3, the verdict line and summary.json say "interrupted", the output stays in
/// OUT.incomplete, nothing is left in /dev/shm (issue #16).
#[test]
fn an_interrupted_launch_says_so() {
    let _cpu = exclusive();
    let d = tmp("interrupted");
    let cfg = d.join("partition.toml");
    std::fs::write(&cfg, partition_toml_absolute_scenario()).unwrap();
    for signal in ["-INT", "-TERM"] {
        let out = d.join("out");
        let a = ["launch", "--real-time", "--config", cfg.to_str().unwrap()];
        let (o, pid) = interrupt_once_ready(&a, &out, signal);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(3), "{signal}: {t}");
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(
            stdout.starts_with("partition: interrupted by SIGINT/SIGTERM after ")
                && !t.contains("timeout"),
            "{signal}: {t}"
        );
        assert!(!out.exists(), "{signal}: {t}");
        assert!(d.join("out.incomplete/launch.json").is_file(), "{t}");
        // summary.json and recorder.json say the same, not "timeout" or "stopped"
        for file in ["summary.json", "recorder.json"] {
            let v = json(&d.join("out.incomplete").join(file));
            assert_eq!(v["end"], "interrupted", "{signal}: {file}: {v}");
        }
        assert_eq!(shm_files_of(pid), Vec::<String>::new());
    }
}

/// Runs the CLI with `args --out out`, sends `signal` (`-INT`, `-TERM`) half a second
/// after every process of its partition is ready, and returns its output and pid.
fn interrupt_once_ready(
    args: &[&str],
    out: &std::path::Path,
    signal: &str,
) -> (std::process::Output, u32) {
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_safe-capture"))
        .current_dir(root())
        .args(args)
        .arg("--out")
        .arg(out)
        .env("SC_PARTITION_BIN_DIR", partition_bin_dir())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let ready = out.with_extension("incomplete").join("all_ready");
    let started = std::time::Instant::now();
    while !ready.exists() {
        assert!(started.elapsed() < READY_TIMEOUT, "never ready");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    std::thread::sleep(std::time::Duration::from_millis(500));
    let kill = std::process::Command::new("kill")
        .args([signal, &pid.to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    (child.wait_with_output().unwrap(), pid)
}

/// The launch script's usage errors exit 2 with one line, before it builds anything
/// (issue #27: `--out` without a value failed with `$2: unbound variable`).
#[test]
fn the_launch_scripts_usage_errors_exit_2() {
    for args in [&["--out"][..], &["--max-ticks", "--out", "x"], &["--bogus"]] {
        let o = std::process::Command::new("bash")
            .arg(root().join("scripts/launch_partition.sh"))
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.starts_with("launch_partition.sh: "), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(!err.contains("unbound variable"), "{args:?}: {err}");
    }
}

/// An interrupted `bench latency` follows the output-folder policy (issue #27): exit 3,
/// the word "interrupted", no report, OUT not written (what was written stays in
/// OUT.incomplete) — before, it exited 0 and replaced OUT with a 29-tick report that
/// nowhere said so. Zero ticks are refused before anything runs.
#[test]
fn an_interrupted_latency_bench_says_so_and_keeps_no_report() {
    let _cpu = exclusive();
    let d = tmp("bench-interrupted");
    let cfg = d.join("partition.toml");
    std::fs::write(&cfg, partition_toml_absolute_scenario()).unwrap();
    let out = d.join("out");
    let a = [
        "bench",
        "latency",
        "--ticks",
        "3000",
        "--config",
        cfg.to_str().unwrap(),
    ];
    let (o, pid) = interrupt_once_ready(&a, &out, "-INT");
    let t = text(&o);
    assert_eq!(o.status.code(), Some(3), "{t}");
    assert!(
        t.contains("bench latency: interrupted by SIGINT/SIGTERM before the 3050 ticks were measured; no report"),
        "{t}"
    );
    assert!(!out.exists(), "{t}");
    assert!(!d.join("out.incomplete/latency_report.md").exists(), "{t}");
    assert_eq!(shm_files_of(pid), Vec::<String>::new());
    let (o, _) = cli_partition(
        &[
            "bench",
            "latency",
            "--ticks",
            "0",
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(!out.exists());
}

/// `launch` writes `run`'s figures from its own closed-loop telemetry (issue #27: a
/// partition run had none, and the workaround drew an open-loop replay as "nominal"):
/// in lock-step they are byte-identical to `run --no-compare`'s.
#[test]
fn a_launch_draws_the_figures_of_run() {
    let _cpu = exclusive();
    let d = tmp("launch-figures");
    let cfg = d.join("partition.toml");
    std::fs::write(&cfg, partition_toml_absolute_scenario()).unwrap();
    let (o, _) = cli_partition(
        &[
            "launch",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            d.join("p").to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let scenario = root().join("config/scenario.toml");
    let o = cli(
        &[
            "run",
            "-q",
            "--no-compare",
            "--scenario",
            scenario.to_str().unwrap(),
            "--out",
            d.join("r").to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let names = |dir: &std::path::Path| {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    let (pf, rf) = (d.join("p/figures"), d.join("r/figures"));
    assert_eq!(names(&pf), names(&rf));
    assert!(names(&pf).len() >= 6, "{:?}", names(&pf));
    for f in names(&pf) {
        assert!(
            std::fs::read(pf.join(&f)).unwrap() == std::fs::read(rf.join(&f)).unwrap(),
            "{f} differs between launch and run"
        );
    }
}

/// A real-time launch says how far it got while it runs (issue #27: `launch
/// --real-time` and `bench latency` showed no progress for minutes); the interval is
/// shortened for the test (`SC_LAUNCH_PROGRESS_S`, 10 s by default).
#[test]
fn a_real_time_launch_shows_its_progress() {
    let _cpu = exclusive();
    let d = tmp("progress");
    let cfg = d.join("partition.toml");
    std::fs::write(&cfg, partition_toml_absolute_scenario()).unwrap();
    let (o, _) = cli_partition(
        &[
            "launch",
            "--real-time",
            "--max-ticks",
            "30",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            d.join("out").to_str().unwrap(),
        ],
        &[("SC_LAUNCH_PROGRESS_S", "1")],
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.lines()
            .any(|l| l.starts_with("launch: ") && l.contains(" steps recorded after ")),
        "{t}"
    );
}
