//! The batch scripts (`scripts/slurm/`) against a running Slurm (issue #28): a single-node
//! cluster started by `scripts/slurm/local_cluster.sh` (munge and Slurm's daemons, no
//! systemd), a 200-run Monte Carlo submitted through `scripts/slurm/submit.sh` as an
//! array of 4 tasks with the merge after it — `runs.csv` and the aggregate identical to
//! the same campaign on one machine — and a task requeued mid-shard that completes its
//! shard with `--resume`. The cluster is torn down afterwards, whatever happened.
//!
//! Needs root and Debian's slurm-wlm and munge (`scripts/setup.sh --with-slurm`, which
//! scripts/test.sh runs). With `SC_REQUIRE_SLURM=1` (scripts/test.sh) a missing Slurm
//! fails the test; otherwise it is skipped with the reason printed.

mod common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// How long a campaign of this test may take on the cluster (2 cores: the 200 runs take
/// about a minute; a requeued task waits Slurm's requeue delay, two minutes).
const CAMPAIGN_TIMEOUT: Duration = Duration::from_secs(900);
const POLL: Duration = Duration::from_millis(500);

/// A running single-node cluster, stopped (every job cancelled, daemons stopped, its
/// folder removed) when dropped.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
}

impl Cluster {
    fn start(dir: &Path) -> Self {
        // the guard first: a failed start is stopped too
        let cluster = Self {
            dir: dir.to_path_buf(),
            conf: dir.join("slurm.conf"),
        };
        let o = Command::new("bash")
            .arg(root().join("scripts/slurm/local_cluster.sh"))
            .args(["start", dir.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(o.status.success(), "local_cluster.sh start: {}", text(&o));
        cluster
    }

    /// A Slurm client command against this cluster.
    fn cmd(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", &self.conf).current_dir(root());
        c
    }

    /// Submits a campaign through scripts/slurm/submit.sh; the array's and the merge's
    /// job ids.
    fn submit(&self, kind: &str, shards: usize, out: &Path, args: &[&str]) -> (String, String) {
        let o = self
            .cmd("bash")
            .arg(root().join("scripts/slurm/submit.sh"))
            .args([kind, "--shards", &shards.to_string()])
            .args(["--out", out.to_str().unwrap()])
            .args(["--bin", env!("CARGO_BIN_EXE_safe-capture"), "--"])
            .args(args)
            .output()
            .unwrap();
        let t = text(&o);
        assert!(o.status.success(), "submit.sh: {t}");
        let id = |after: &str| {
            let rest = &t[t
                .find(after)
                .unwrap_or_else(|| panic!("no `{after}` in {t}"))
                + after.len()..];
            rest.split_whitespace().next().unwrap().to_string()
        };
        assert!(
            t.contains(&format!("result: {}", out.join("merged").display())),
            "{t}"
        );
        (id("array job "), id("merge job "))
    }

    /// Waits until none of `jobs` is queued or running any more.
    fn wait(&self, jobs: &[&str]) {
        let started = Instant::now();
        loop {
            let o = self
                .cmd("squeue")
                .args(["-h", "-j", &jobs.join(",")])
                .output()
                .unwrap();
            if String::from_utf8_lossy(&o.stdout).trim().is_empty() {
                return;
            }
            assert!(
                started.elapsed() < CAMPAIGN_TIMEOUT,
                "jobs {jobs:?} still queued after {CAMPAIGN_TIMEOUT:?}: {}",
                text(&o)
            );
            std::thread::sleep(POLL);
        }
    }

    /// Runs a Slurm client command and expects success.
    fn ok(&self, program: &str, args: &[&str]) {
        let o = self.cmd(program).args(args).output().unwrap();
        assert!(o.status.success(), "{program} {args:?}: {}", text(&o));
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new("bash")
            .arg(root().join("scripts/slurm/local_cluster.sh"))
            .args(["stop", self.dir.to_str().unwrap()])
            .status();
    }
}

/// Why Slurm cannot be used here, if it cannot.
fn unavailable() -> Option<String> {
    let programs = [
        "slurmctld",
        "slurmd",
        "munged",
        "mungekey",
        "sbatch",
        "squeue",
        "sinfo",
        "scontrol",
        "scancel",
    ];
    for p in programs {
        let found = Command::new("sh")
            .args(["-c", &format!("command -v {p}")])
            .output()
            .is_ok_and(|o| o.status.success());
        if !found {
            return Some(format!("{p} not found (scripts/setup.sh --with-slurm)"));
        }
    }
    let root_user = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    (!root_user).then(|| "not root: the local cluster's daemons run as root".into())
}

/// The campaign's deterministic files: runs.csv and summary.json without its wall-clock
/// keys.
fn deterministic(dir: &Path) -> (Vec<u8>, serde_json::Value) {
    let mut s = json(&dir.join("summary.json"));
    for k in sc_montecarlo::WALL_CLOCK_KEYS {
        s.as_object_mut().unwrap().remove(k);
    }
    (std::fs::read(dir.join("runs.csv")).unwrap(), s)
}

/// The same campaign on one machine.
fn on_one_machine(out: &Path, runs: &str, seed: &str) -> (Vec<u8>, serde_json::Value) {
    let o = cli(
        &[
            "montecarlo",
            "--runs",
            runs,
            "--seed",
            seed,
            "--out",
            out.to_str().unwrap(),
            "-q",
        ],
        &[],
    );
    assert!(o.status.code().is_some_and(|c| c <= 1), "{}", text(&o));
    deterministic(out)
}

#[test]
fn campaigns_run_as_job_arrays_on_a_running_slurm() {
    if let Some(why) = unavailable() {
        assert!(
            std::env::var("SC_REQUIRE_SLURM").as_deref() != Ok("1"),
            "SC_REQUIRE_SLURM=1 but {why}"
        );
        eprintln!("skipped: {why}");
        return;
    }
    let _cpu = exclusive();
    let d = tmp("slurm");
    let cluster = Cluster::start(&d.join("cluster"));

    // 200 runs as an array of 4 tasks, merged after it: the campaign on one machine
    let out = d.join("mc");
    let (array, merge) = cluster.submit("montecarlo", 4, &out, &["--runs", "200", "--seed", "1"]);
    cluster.wait(&[&array, &merge]);
    let merged = out.join("merged");
    assert!(merged.join("runs.csv").is_file(), "{}", log(&out, "merge"));
    for i in 0..4 {
        let info = json(&out.join(format!("shards/{i}/campaign.json")));
        assert_eq!(info["shard"], serde_json::json!([i, 4]), "{info}");
        assert!(info["build"]["git_commit"].is_string(), "{info}");
    }
    let one = on_one_machine(&d.join("one"), "200", "1");
    assert!(
        deterministic(&merged) == one,
        "the merged array differs from one machine's campaign"
    );

    // a task requeued mid-shard (Slurm stops it with SIGTERM and queues it again) keeps
    // its finished runs and completes the shard with --resume
    let out = d.join("requeued");
    let (array, merge) = cluster.submit("montecarlo", 2, &out, &["--runs", "60", "--seed", "2"]);
    let task = format!("{array}_1");
    wait_for_a_saved_run(&out.join("shards/1.incomplete/runs"));
    cluster.ok("scontrol", &["requeue", &task]);
    // the task is eligible again after Slurm's requeue delay (two minutes in 22.05,
    // which does not let a requeued job's begin time be moved forward)
    cluster.wait(&[&array, &merge]);
    let task_log = log(&out, "task-1");
    assert!(task_log.contains("restart 1"), "{task_log}");
    assert!(task_log.contains("interrupted after"), "{task_log}");
    assert!(
        out.join("merged/runs.csv").is_file(),
        "{}",
        log(&out, "merge")
    );
    let one = on_one_machine(&d.join("one60"), "60", "2");
    assert!(
        deterministic(&out.join("merged")) == one,
        "the requeued campaign differs from one machine's"
    );
    red_team_as_a_job_array(&cluster, &d);
    drop(cluster);
}

/// The red team as an array of 2 tasks, merged after it: the same `min_h.csv` as the
/// campaign unsharded.
fn red_team_as_a_job_array(cluster: &Cluster, d: &Path) {
    let out = d.join("rt");
    let options = ["--target", "attitude", "--seeds", "1"];
    let (array, merge) = cluster.submit("redteam", 2, &out, &options);
    cluster.wait(&[&array, &merge]);
    assert!(
        out.join("merged/min_h.csv").is_file(),
        "{}",
        log(&out, "merge")
    );
    let whole = d.join("rt-whole");
    let o = cli(
        &[
            &["redteam", "-q", "--out", whole.to_str().unwrap()],
            &options[..],
        ]
        .concat(),
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        std::fs::read(out.join("merged/min_h.csv")).unwrap(),
        std::fs::read(whole.join("min_h.csv")).unwrap()
    );
}

/// Waits until a run of the shard is saved in `runs` (a folder named by its number).
fn wait_for_a_saved_run(runs: &Path) {
    let started = Instant::now();
    loop {
        let saved = std::fs::read_dir(runs).is_ok_and(|mut d| {
            d.any(|e| e.is_ok_and(|e| e.file_name().to_string_lossy().parse::<usize>().is_ok()))
        });
        if saved {
            return;
        }
        assert!(
            started.elapsed() < CAMPAIGN_TIMEOUT,
            "no run saved in {}",
            runs.display()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// A job's log in the campaign's `logs/` folder.
fn log(out: &Path, name: &str) -> String {
    std::fs::read_to_string(out.join(format!("logs/{name}.log")))
        .unwrap_or_else(|e| format!("(no log {name}: {e})"))
}
