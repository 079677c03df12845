//! Two "hosts" on this machine for the tests across hosts (`scripts/two_hosts.sh`): two
//! network namespaces joined by a veth pair, each with its own /dev/shm and
//! /tmp/iceoryx2, removed on drop whatever happened.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

pub const ENDPOINT_B: &str = "tcp/127.201.0.2:7447";

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A program of package `safe-capture` or `sc-partition-apps` next to `sc-link`: built
/// by `cargo test --workspace` (scripts/test.sh), not by `cargo test -p sc-link` alone.
pub fn sibling(name: &str) -> PathBuf {
    let link = PathBuf::from(env!("CARGO_BIN_EXE_sc-link"));
    let p = link.with_file_name(name);
    assert!(
        p.exists(),
        "{} is missing: build it (cargo build --bins, same profile) or run cargo test --workspace",
        p.display()
    );
    p
}

fn have(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Whether two hosts can be made here (root, ip, unshare, nsenter). Without them the
/// test says so and passes, unless `SC_REQUIRE_NETNS=1` (scripts/test.sh sets it as
/// root): then it fails.
pub fn can_make_hosts() -> bool {
    let tools = ["ip", "unshare", "nsenter"].into_iter().all(have);
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    if tools && root {
        return true;
    }
    let why = format!("root {root}, ip/unshare/nsenter {tools}");
    assert!(
        std::env::var("SC_REQUIRE_NETNS").as_deref() != Ok("1"),
        "SC_REQUIRE_NETNS=1 but two hosts cannot be made here ({why})"
    );
    eprintln!("skipped: two network namespaces need root and iproute2 ({why})");
    false
}

/// The two hosts; `down` on drop, whatever happened.
pub struct TwoHosts {
    pub name: String,
    children: Vec<Child>,
    down: bool,
}

impl TwoHosts {
    pub fn up(name: &str) -> Self {
        let hosts = Self {
            name: name.to_string(),
            children: Vec::new(),
            down: false,
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

    /// `program` to run on host `side` (`a` or `b`), in the repository's directory.
    pub fn on(&self, side: &str, program: &Path) -> Command {
        let mut c = Command::new(repo().join("scripts/two_hosts.sh"));
        c.current_dir(repo())
            .args(["exec", &self.name, side])
            .arg(program);
        c
    }

    /// Starts `c`; it is killed on drop if still running.
    pub fn spawn(&mut self, mut c: Command) -> usize {
        self.children.push(c.spawn().unwrap());
        self.children.len() - 1
    }

    /// Waits for the process `spawn` numbered `i` and returns its output (its stdout and
    /// stderr must have been piped).
    pub fn wait(&mut self, i: usize) -> Output {
        let child = std::mem::replace(&mut self.children[i], Command::new("true").spawn().unwrap());
        child.wait_with_output().unwrap()
    }

    /// Like [`wait`](Self::wait), but kills the process after `limit`.
    pub fn wait_at_most(&mut self, i: usize, limit: std::time::Duration) -> Output {
        let start = std::time::Instant::now();
        while self.children[i].try_wait().unwrap().is_none() && start.elapsed() < limit {
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        let _ = self.children[i].kill();
        self.wait(i)
    }

    /// The files of run `run_id` in host `side`'s /dev/shm and /tmp/iceoryx2.
    pub fn run_files(&self, side: &str, run_id: &str) -> String {
        let mut c = self.on(side, Path::new("sh"));
        c.args([
            "-c",
            &format!("ls -A /dev/shm /tmp/iceoryx2 | grep -F sc_{run_id}_ || true"),
        ]);
        String::from_utf8_lossy(&c.output().unwrap().stdout).into_owned()
    }

    /// Removes both hosts now; whether that worked and nothing of them is left.
    pub fn down(&mut self) -> bool {
        self.down = true;
        let out = self.script(&["down", &self.name]);
        let list = Command::new("ip").args(["netns", "list"]).output().unwrap();
        let left = String::from_utf8_lossy(&list.stdout)
            .lines()
            .any(|l| l.starts_with(&format!("{}-", self.name)));
        out.status.success() && !left
    }
}

impl Drop for TwoHosts {
    fn drop(&mut self) {
        for c in &mut self.children {
            let _ = c.kill();
            let _ = c.wait();
        }
        if !self.down {
            let out = self.script(&["down", &self.name]);
            if !out.status.success() {
                eprintln!("two_hosts down: {out:?}");
            }
        }
    }
}
