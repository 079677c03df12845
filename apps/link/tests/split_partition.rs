//! The lock-step partition split across two hosts (config/partition_across_hosts.toml:
//! the scheduler, simulator, recorder, navigation and nominal controllers on host
//! `ground`, the three safety filters on host `flight`) gives telemetry byte-identical to
//! `safe-capture run` of the same scenario, and leaves nothing in either host's /dev/shm
//! or /tmp/iceoryx2 nor the hosts themselves. The two hosts are two network namespaces
//! joined by a veth pair, each with its own /dev/shm (`scripts/two_hosts.sh`); each
//! runs `safe-capture launch` as a user would (the home host's launch prints the other's
//! command, which the test runs).
//!
//! Needs root with `ip`, `unshare` and `nsenter`; without them the test says so and
//! passes, unless `SC_REQUIRE_NETNS=1` (scripts/test.sh sets it as root), then it fails.

mod common;
use common::*;
use std::process::{Command, Stdio};

/// The home host's launch prints how to start the other host: `... --host flight ...`.
fn remote_command(line: &str) -> Vec<String> {
    let cmd = line
        .split_once("start host flight with: safe-capture ")
        .unwrap_or_else(|| panic!("no command for the other host in {line:?}"))
        .1;
    cmd.split_whitespace().map(str::to_string).collect()
}

/// The first line of the child's stdout, read as soon as it is printed (a byte at a
/// time: the rest stays in the pipe for `wait_with_output`).
fn first_line(child: &mut std::process::Child) -> String {
    use std::io::Read;
    let out = child.stdout.as_mut().unwrap();
    let mut line = Vec::new();
    let mut byte = [0u8];
    while out.read(&mut byte).unwrap() == 1 && byte[0] != b'\n' {
        line.push(byte[0]);
    }
    String::from_utf8_lossy(&line).into_owned()
}

/// A scratch folder, removed when the test ends, passed or failed.
struct Scratch(std::path::PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn a_lock_step_mission_split_across_two_hosts_is_the_same_bytes_as_run() {
    if !can_make_hosts() {
        return;
    }
    let exe = sibling("safe-capture");
    let scratch = Scratch(std::env::temp_dir().join(format!("sc-split-{}", std::process::id())));
    let dir = &scratch.0;
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).unwrap();
    let run = Command::new(&exe)
        .args(["run", "--no-figures", "--out"])
        .arg(dir.join("run"))
        .output()
        .unwrap();
    assert!(run.status.success(), "safe-capture run: {run:?}");

    let name = format!("s{:x}", std::process::id() % 0xfffffff);
    let run_id = format!("split-{}", std::process::id());
    let mut hosts = TwoHosts::up(&name);
    let config = repo().join("config/partition_across_hosts.toml");
    let mut home = hosts.on("a", &exe);
    home.args(["launch", "--no-figures", "--run-id", &run_id, "--config"])
        .arg(&config)
        .arg("--out")
        .arg(dir.join("ground"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut home = home.spawn().unwrap();
    let said = first_line(&mut home);
    let args = remote_command(&said);
    assert!(args.contains(&run_id), "{said}");
    let mut flight = hosts.on("b", &exe);
    flight
        .args(&args)
        .arg("--out")
        .arg(dir.join("flight"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let flight = hosts.spawn(flight);
    let home = home.wait_with_output().unwrap();
    // the flight side ends on the stop tick; if the home side failed it may never get
    // one: give up on it after a grace period (the hosts' teardown kills it)
    let flight = hosts.wait_at_most(flight, std::time::Duration::from_secs(60));
    let text = |o: &std::process::Output| {
        format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        )
    };
    eprintln!("home: {said}\n{}\nflight: {}", text(&home), text(&flight));
    assert!(
        home.status.success(),
        "the home host's launch: {}",
        text(&home)
    );
    assert!(
        flight.status.success(),
        "the flight host's launch: {}",
        text(&flight)
    );
    assert!(text(&home).contains("shm leftovers: 0"), "{}", text(&home));
    assert!(
        text(&flight).contains("3 processes ended well"),
        "{}",
        text(&flight)
    );
    let same = std::fs::read(dir.join("run/telemetry.csv")).unwrap()
        == std::fs::read(dir.join("ground/telemetry.csv")).unwrap();
    assert!(
        same,
        "telemetry.csv across two hosts differs from run's ({})",
        dir.display()
    );
    for side in ["a", "b"] {
        let left = hosts.run_files(side, &run_id);
        assert!(
            left.is_empty(),
            "host {side} keeps files of the run: {left}"
        );
    }
    assert!(hosts.down(), "the two hosts were not removed");
}
