//! Samples and their wake-ups cross between two hosts over `sc-link`: two network
//! namespaces joined by a veth pair, each with its own /dev/shm and /tmp/iceoryx2
//! (`scripts/two_hosts.sh`), so nothing is shared but the network. `sc-hop-cost`
//! sends 300 ticks from host a and its echo answers from host b; every round trip
//! must come back (a sample stranded without its wake-up fails the measurement:
//! "no echo of tick N"). The hosts are removed afterwards, also when the test fails.
//!
//! Needs root with `ip`, `unshare` and `nsenter`; without them the test says so and
//! passes, unless `SC_REQUIRE_NETNS=1` (scripts/test.sh sets it as root), then it fails.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::Instant;

const ENDPOINT_B: &str = "tcp/127.201.0.2:7447";

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `sc-hop-cost`, of package `safe-capture`: built by `cargo test --workspace`
/// (scripts/test.sh), not by `cargo test -p sc-link` alone.
fn hop_cost() -> PathBuf {
    let link = PathBuf::from(env!("CARGO_BIN_EXE_sc-link"));
    let hop = link.with_file_name("sc-hop-cost");
    assert!(
        hop.exists(),
        "{} is missing: build it (cargo build -p safe-capture --bin sc-hop-cost, same profile) or run cargo test --workspace",
        hop.display()
    );
    hop
}

fn have(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// The two hosts; `down` on drop, whatever happened.
struct TwoHosts {
    name: String,
    children: Vec<Child>,
}

impl TwoHosts {
    fn up(name: &str) -> Self {
        let hosts = Self {
            name: name.to_string(),
            children: Vec::new(),
        };
        let out = hosts.script(&["up", name]);
        assert!(out.status.success(), "two_hosts up: {out:?}");
        hosts
    }

    fn script(&self, args: &[&str]) -> Output {
        Command::new(repo().join("scripts/two_hosts.sh"))
            .args(args)
            .output()
            .unwrap()
    }

    fn on(&self, side: &str, program: &Path) -> Command {
        let mut c = Command::new(repo().join("scripts/two_hosts.sh"));
        c.args(["exec", &self.name, side]).arg(program);
        c
    }

    fn spawn(&mut self, mut c: Command) {
        self.children.push(c.spawn().unwrap());
    }
}

impl Drop for TwoHosts {
    fn drop(&mut self) {
        for c in &mut self.children {
            let _ = c.kill();
            let _ = c.wait();
        }
        let out = self.script(&["down", &self.name]);
        if !out.status.success() {
            eprintln!("two_hosts down: {out:?}");
        }
    }
}

#[test]
fn samples_and_their_wake_ups_cross_between_two_hosts() {
    let tools = ["ip", "unshare", "nsenter"].into_iter().all(have);
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    if !(tools && root) {
        let why = format!("root {root}, ip/unshare/nsenter {tools}");
        assert!(
            std::env::var("SC_REQUIRE_NETNS").as_deref() != Ok("1"),
            "SC_REQUIRE_NETNS=1 but two hosts cannot be made here ({why})"
        );
        eprintln!("skipped: two network namespaces need root and iproute2 ({why})");
        return;
    }
    let id = std::process::id();
    let name = format!("l{:x}", id % 0xfffffff);
    let run_id = format!("across-{id}");
    let mut hosts = TwoHosts::up(&name);
    let link = PathBuf::from(env!("CARGO_BIN_EXE_sc-link"));
    let hop = hop_cost();

    let mut b = hosts.on("b", &link);
    b.args(["--run-id", &run_id, "--listen", ENDPOINT_B]);
    hosts.spawn(b);
    let mut a = hosts.on("a", &link);
    a.args(["--run-id", &run_id, "--connect", ENDPOINT_B]);
    hosts.spawn(a);
    let mut echo = hosts.on("b", &hop);
    echo.arg("--echo").env("SC_RUN_ID", &run_id);
    hosts.spawn(echo);

    let started = Instant::now();
    let mut sender = hosts.on("a", &hop);
    sender.args([
        "--remote-echo",
        &run_id,
        "--n",
        "300",
        "--period-us",
        "2000",
    ]);
    let out = sender.output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "the round trips across the link: {stdout} {stderr}"
    );
    assert!(
        stdout.contains("round trip (2 hops), 300 samples"),
        "{stdout}"
    );
    eprintln!("across the link, {:?}: {stdout}", started.elapsed());
}
