//! `safe-capture redteam`, the acceptance of "safety against any nominal" on a subset
//! that fits CI: in process, every strategy on every target (one seed of the random
//! ones); through the partition, hostile Python partner processes that crash, hang, fall
//! silent, flood, send garbage or non-finite values. The verdict is the campaign's own
//! (barriers recomputed from the simulator's true state at every physics step); the
//! test also checks that the hostile partners really misbehaved (their logs) and that
//! no run left shared memory behind.
//!
//! The partition part needs a Python with iceoryx2: `SC_PYTHON` (scripts/test.sh sets
//! it; then a broken interpreter fails the test), else scripts/.venv/bin/python; without
//! either it is skipped with the reason printed.

mod common;
use common::*;

/// The campaign's summary.json must say: every case ran and is safe, no non-finite or
/// out-of-bound command applied, every barrier's worst value ≥ 0.
fn assert_all_safe(out: &std::path::Path, cases: usize) {
    let s = json(&out.join("summary.json"));
    assert_eq!(s["cases"].as_u64(), Some(cases as u64), "{s}");
    assert_eq!(s["errors"].as_array().unwrap().len(), 0, "{s}");
    assert_eq!(s["unsafe_cases"].as_array().unwrap().len(), 0, "{s}");
    assert_eq!(s["safe"].as_u64(), Some(cases as u64), "{s}");
    assert_eq!(s["nonfinite_applied"].as_u64(), Some(0), "{s}");
    assert_eq!(s["out_of_bounds_applied"].as_u64(), Some(0), "{s}");
    // an attack on one subsystem never disturbs another's filter (input lost or refused,
    // backup run): deterministic in process and in lock-step
    assert_eq!(
        s["bystanders_disturbed"].as_array().map(Vec::len),
        Some(0),
        "{s}"
    );
    let worst = s["worst"].as_object().unwrap();
    assert!(worst.len() >= 10, "{s}");
    for (name, v) in worst {
        let h = v[0].as_f64().unwrap_or(f64::NAN);
        assert!(h >= 0.0, "{name}: worst {h} in {}", v[1]);
    }
    for f in [
        "cases.csv",
        "min_h.csv",
        "report.md",
        "figures/redteam_margins.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let lines = std::fs::read_to_string(out.join("cases.csv")).unwrap();
    assert_eq!(lines.lines().count(), cases + 1);
}

#[test]
fn every_strategy_on_every_target_in_process_is_safe() {
    let _cpu = exclusive();
    let d = tmp("redteam");
    let out = d.join("rt");
    let list = cli(&["redteam", "--seeds", "1", "--list"], &[]);
    assert!(list.status.success(), "{}", text(&list));
    let cases = String::from_utf8_lossy(&list.stdout).lines().count();
    // every target, each with bang-bang, random, non-finite, huge, frozen, stale, silent
    for t in ["translational/", "attitude/", "robotic/", "all/"] {
        for s in ["random:1", "nonfinite", "huge", "frozen", "stale", "silent"] {
            let have = String::from_utf8_lossy(&list.stdout)
                .lines()
                .any(|l| l.starts_with(t) && l.contains(s));
            assert!(have, "no {t}{s}* case in --list");
        }
    }
    assert!(cases >= 40, "{cases} cases");
    let o = cli(
        &[
            "redteam",
            "--seeds",
            "1",
            "-j",
            "2",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_all_safe(&out, cases);
    let _ = std::fs::remove_dir_all(&d);
}

/// The robotic filter's certificate does not rest on the envelope's jerk bounds (issue
/// #26 item 2): it verifies every command on the sample the servicer model predicts. With
/// every joint and link-sphere jerk bound cut to a tenth, cases that broke joint-rate
/// barriers before the per-step verification (measured: 21 of 95 unsafe over the whole
/// red team, all on joint rates) stay safe on the true state.
#[test]
fn the_arm_stays_safe_with_its_jerk_bounds_cut_to_a_tenth() {
    let _cpu = exclusive();
    let d = tmp("redteam-jerk-tenth");
    let scenario = scenario_with(
        &d,
        "joint_jerk_bound_rad_s3 = [7.0, 2.4, 21.0, 5.6, 30.0, 12.5, 32.0]\n\
         # ... and on the jerk of each link's sphere centres [m/s^3] (link 1's lie on joint 1's axis).\n\
         link_sphere_jerk_bound_m_s3 = [0.0, 0.7, 1.7, 1.6, 2.8, 2.3, 6.8]",
        "joint_jerk_bound_rad_s3 = [0.7, 0.24, 2.1, 0.56, 3.0, 1.25, 3.2]\n\
         link_sphere_jerk_bound_m_s3 = [0.0, 0.07, 0.17, 0.16, 0.28, 0.23, 0.68]",
    );
    let out = d.join("rt");
    let cases =
        "robotic/toward:link_base_4_2,robotic/toward:link_base_5_1,robotic/random:1,all/random:1";
    let o = cli(
        &[
            "redteam",
            "--scenario",
            scenario.to_str().unwrap(),
            "--cases",
            cases,
            "-j",
            "2",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    let s = json(&out.join("summary.json"));
    assert_eq!(s["cases"].as_u64(), Some(4), "{s}");
    assert_eq!(s["unsafe_cases"].as_array().map(Vec::len), Some(0), "{s}");
}

/// `--telemetry` writes a case's steps in process, consistent with its verdict: one row
/// per control step, and no logged barrier value below the case's minimum (which is
/// taken over every physics step).
#[test]
fn a_case_can_be_looked_at_step_by_step() {
    let d = tmp("redteam-telemetry");
    let out = d.join("rt");
    let o = cli(
        &[
            "redteam",
            "--cases",
            "translational/frozen",
            "--telemetry",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    let cases = std::fs::read_to_string(out.join("cases.csv")).unwrap();
    let header: Vec<&str> = cases.lines().next().unwrap().split(',').collect();
    let row: Vec<&str> = cases.lines().nth(1).unwrap().split(',').collect();
    let steps: usize = row[header.iter().position(|c| *c == "steps").unwrap()]
        .parse()
        .unwrap();
    let dir = out.join("cases").join("translational_frozen");
    let tel = std::fs::read_to_string(dir.join("telemetry.csv")).unwrap();
    assert_eq!(tel.lines().count(), steps + 1, "one row per control step");
    assert!(dir.join("timing.csv").is_file());
    let cols: Vec<&str> = tel.lines().next().unwrap().split(',').collect();
    let k = cols.iter().position(|c| *c == "h_line_of_sight").unwrap();
    let logged = tel
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(k).unwrap().parse::<f64>().unwrap())
        .fold(f64::INFINITY, f64::min);
    let min_h = std::fs::read_to_string(out.join("min_h.csv")).unwrap();
    let mh: Vec<&str> = min_h.lines().next().unwrap().split(',').collect();
    let mr: Vec<&str> = min_h.lines().nth(1).unwrap().split(',').collect();
    let j = mh.iter().position(|c| *c == "line_of_sight").unwrap();
    let case_min: f64 = mr[j].parse().unwrap();
    assert!(
        logged >= case_min && logged.is_finite(),
        "logged {logged} < {case_min}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Hostile partner processes through the partition: ≥ 8 behaviours, 60 s of mission
/// each (600 ticks) in lock-step; an impersonation attempt is refused and logged.
#[test]
fn hostile_partner_processes_through_the_partition_are_safe() {
    let Some(py) = python() else {
        return;
    };
    let _cpu = exclusive();
    let d = tmp("redteam-partition");
    let out = d.join("rt");
    // (case, a line its hostile partner must have logged)
    let cases = [
        ("translational/toward_zone+crash:150", "crashing at tick"),
        ("attitude/spin:x+hang:100", "hanging at tick"),
        ("robotic/joints:1+silent", ""),
        ("all/random:2+burst:10", ""),
        ("translational/off_corridor", ""),
        ("attitude/nonfinite", ""),
        ("robotic/huge+garbage", ""),
        ("all/random:1+old_tick:10", ""),
        // tries to publish on its filter's safe-command service: refused twice
        (
            "translational/off_corridor+impersonate",
            "impersonation refused",
        ),
    ];
    let names: Vec<&str> = cases.iter().map(|c| c.0).collect();
    let joined = names.join(",");
    let (o, pid) = cli_partition(
        &[
            "redteam",
            "--partition",
            "--cases",
            &joined,
            "--max-ticks",
            "600",
            "-j",
            "1",
            "--python",
            py.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_all_safe(&out, cases.len());
    for (k, (case, line)) in cases.iter().enumerate() {
        let (target, _) = case.split_once('/').unwrap();
        let dir_name: String = case
            .chars()
            .map(|c| match c {
                '/' => '_',
                ':' => '=',
                c => c,
            })
            .collect();
        let dir = out.join("cases").join(dir_name);
        let launch = json(&dir.join("launch.json"));
        assert_eq!(
            launch["run_id"].as_str(),
            Some(format!("rt{k}-{pid}").as_str()),
            "{launch}"
        );
        assert_eq!(launch["leftovers"].as_array().unwrap().len(), 0, "{launch}");
        if !line.is_empty() {
            let log = std::fs::read_to_string(dir.join(format!("logs/nominal_{target}.log")))
                .unwrap_or_default();
            assert!(log.contains(line), "{case}: no `{line}` in its log:\n{log}");
            assert!(
                !log.contains("impersonation: got a publisher"),
                "{case}:\n{log}"
            );
        }
        // the simulator applied only its filters' commands
        let sim = std::fs::read_to_string(dir.join("logs/simulator.log")).unwrap();
        assert!(
            sim.contains("safe commands rejected (translational, attitude, robotic) [0, 0, 0], navigation estimates missing or rejected 0, samples from a second publisher dropped [0, 0, 0]"),
            "{case}: {sim}"
        );
    }
    // nothing of these runs left in shared memory
    let ours = format!("-{pid}_");
    let left: Vec<String> = std::fs::read_dir("/dev/shm")
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with("sc_rt") && n.contains(&ours))
                .collect()
        })
        .unwrap_or_default();
    assert!(left.is_empty(), "left in /dev/shm: {left:?}");
    let _ = std::fs::remove_dir_all(&d);
}

/// Through the partition, a role's program that is not there stops the campaign before
/// any case runs: exit 2, one line naming the role and the fix, no output (issue #16).
#[test]
fn a_missing_partition_program_stops_the_campaign_before_any_case() {
    let Some(py) = python() else { return };
    let d = tmp("redteam-missing-exec");
    let cfg = partition_toml_absolute_scenario().replace(
        "[roles.safety_robotic]\n",
        "[roles.safety_robotic]\nexec = \"bin/sc-safety-robotic\"\n",
    );
    assert!(cfg.contains("bin/sc-safety-robotic"));
    let p = d.join("partition.toml");
    std::fs::write(&p, cfg).unwrap();
    let out = d.join("out");
    let (o, _) = cli_partition(
        &[
            "redteam",
            "--partition",
            "--python",
            py.to_str().unwrap(),
            "--partition-config",
            p.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert_eq!(t.lines().count(), 1, "{t}");
    assert!(
        t.starts_with("error: --partition-config ")
            && t.contains("role `safety_robotic`: the executable")
            && t.contains("cargo build --release -p sc-partition-apps"),
        "{t}"
    );
    assert!(!out.exists(), "{t}");
}

/// A partition whose attitude group holds its commands longer than the scenario's tumble
/// allows is refused before any case runs, as `launch` refuses it: one line naming the
/// hold and the tumble's limit (no partner process is needed to see it).
#[test]
fn a_partition_holding_the_attitude_too_long_is_refused_before_any_case() {
    let d = tmp("redteam-held-envelope");
    let cfg = partition_toml_absolute_scenario().replace(
        "[[rate_groups]]\nname = \"control\"\nperiod_s = 0.1\nmembers = [\"translational\", \"attitude\", \"robotic\"]",
        "[[rate_groups]]\nname = \"control\"\nperiod_s = 0.3\nmembers = [\"translational\", \"attitude\", \"robotic\"]",
    );
    assert!(
        cfg.contains("period_s = 0.3"),
        "the config's rate group changed"
    );
    let p = d.join("partition.toml");
    std::fs::write(&p, cfg).unwrap();
    let out = d.join("out");
    let (o, _) = cli_partition(
        &[
            "redteam",
            "--partition",
            "--partition-config",
            p.to_str().unwrap(),
            "--cases",
            "robotic/frozen",
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert_eq!(t.lines().count(), 1, "{t}");
    assert!(
        t.contains("held for the attitude rate group's period 0.3 s")
            && t.contains("the tumble may be at most"),
        "{t}"
    );
    assert!(!out.exists(), "{t}");
}

/// How long the first case of a shard may take, and how often it is looked for.
const CASE_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(120);
const POLL: std::time::Duration = std::time::Duration::from_millis(20);

/// A child process killed when the test ends, however it ends.
struct KillOnDrop(std::process::Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `cases.csv` without its wall-clock columns (the solve times).
fn cases_without_wall_clock(dir: &std::path::Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("cases.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| !header[i].starts_with("solve_"))
        .collect();
    text.lines()
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            keep.iter().map(|&i| f[i]).collect::<Vec<_>>().join(",")
        })
        .collect()
}

/// Shards (issue #28): `--shard i/N` runs every N-th case, `redteam merge` gives the
/// unsharded campaign's `min_h.csv` and `cases.csv` (but for the solve times), the merge
/// merged again the same, and a shard that is missing is named with its command.
#[test]
fn shards_merge_to_the_whole_red_team() {
    let _cpu = exclusive();
    let d = tmp("redteam-shards");
    let p = |n: &str| d.join(n).to_str().unwrap().to_string();
    let run = |extra: &[&str], out: &str| {
        let mut args = vec!["redteam", "--target", "attitude", "--seeds", "1", "-q"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", out]);
        let o = cli(&args, &[]);
        assert!(o.status.success(), "{}", text(&o));
    };
    run(&[], &p("whole"));
    run(&["--shard", "0/2"], &p("s0"));
    run(&["--shard", "1/2", "-j", "1"], &p("s1"));
    let info = json(&d.join("s1/campaign.json"));
    assert_eq!(info["shard"], serde_json::json!([1, 2]), "{info}");
    assert_eq!(info["cases"].as_array().unwrap().len(), 14, "{info}");
    let o = cli(
        &[
            "redteam",
            "merge",
            &p("s1"),
            &p("s0"),
            "--out",
            &p("merged"),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        std::fs::read(d.join("whole/min_h.csv")).unwrap(),
        std::fs::read(d.join("merged/min_h.csv")).unwrap()
    );
    assert_eq!(
        cases_without_wall_clock(&d.join("whole")),
        cases_without_wall_clock(&d.join("merged"))
    );
    // the merged campaign records its cases: merged again, it is the same
    let o = cli(
        &["redteam", "merge", &p("merged"), "--out", &p("again")],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        std::fs::read(d.join("merged/min_h.csv")).unwrap(),
        std::fs::read(d.join("again/min_h.csv")).unwrap()
    );
    let o = cli(&["redteam", "merge", &p("s0"), "--out", &p("half")], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("7 of 14 cases missing")
            && text(&o).contains("shard 1/2 was not given")
            && text(&o).contains("--target attitude --seeds 1 --shard 1/2"),
        "{}",
        text(&o)
    );
}

/// A shard killed outright (SIGKILL) after its first recorded case is completed by
/// `--resume` with that case kept as it was, the same as a shard that ran through;
/// `--resume` refuses options of its own (issue #28).
#[test]
fn a_killed_red_team_shard_resumes_keeping_its_finished_cases() {
    let _cpu = exclusive();
    let d = tmp("redteam-killed");
    let p = |n: &str| d.join(n).to_str().unwrap().to_string();
    // killed after its first recorded case, resumed: the shard as if it had run through
    let killed = d.join("k");
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_safe-capture"))
        .current_dir(root())
        .args([
            "redteam", "--target", "robotic", "--seeds", "1", "--shard", "0/4",
        ])
        .args(["-j", "1", "-q", "--out", killed.to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // killed on every way out of this test
    let mut child = KillOnDrop(child);
    let started = std::time::Instant::now();
    let recorded = || {
        std::fs::read_dir(d.join("k.incomplete/cases")).map_or(Vec::new(), |r| {
            r.flatten()
                .map(|e| e.path().join("result.json"))
                .filter(|p| p.is_file())
                .collect::<Vec<_>>()
        })
    };
    while recorded().is_empty() {
        assert!(
            child.0.try_wait().unwrap().is_none(),
            "the shard ended first"
        );
        assert!(started.elapsed() < CASE_TIMEOUT, "no case recorded");
        std::thread::sleep(POLL);
    }
    child.0.kill().unwrap();
    child.0.wait().unwrap();
    // a case that finished before the kill is kept as it was, not run again
    let first = recorded()[0].clone();
    let kept = killed.join(first.strip_prefix(d.join("k.incomplete")).unwrap());
    let written = std::fs::metadata(&first).unwrap().modified().unwrap();
    // --resume takes the campaign's own options, no others
    let o = cli(
        &[
            "redteam",
            "--resume",
            "--seeds",
            "2",
            "--out",
            killed.to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("give only --out"), "{}", text(&o));
    let o = cli(
        &[
            "redteam",
            "--resume",
            "--out",
            killed.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("cases finished before"), "{}", text(&o));
    assert!(!text(&o).contains(" 0 of "), "{}", text(&o));
    assert_eq!(
        std::fs::metadata(&kept).unwrap().modified().unwrap(),
        written
    );
    let o = cli(
        &[
            "redteam", "--target", "robotic", "--seeds", "1", "--shard", "0/4", "-q",
        ]
        .iter()
        .copied()
        .chain(["--out", &p("kwhole")])
        .collect::<Vec<_>>(),
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        std::fs::read(killed.join("min_h.csv")).unwrap(),
        std::fs::read(d.join("kwhole/min_h.csv")).unwrap()
    );
    assert_eq!(
        cases_without_wall_clock(&killed),
        cases_without_wall_clock(&d.join("kwhole"))
    );
}
