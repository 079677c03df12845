//! Samples and their wake-ups cross between two hosts over `sc-link`: two network
//! namespaces joined by a veth pair, each with its own /dev/shm and /tmp/iceoryx2
//! (`scripts/two_hosts.sh`), so nothing is shared but the network. `sc-hop-cost`
//! sends 300 ticks from host a and its echo answers from host b; every round trip
//! must come back (a sample stranded without its wake-up fails the measurement:
//! "no echo of tick N"). The hosts are removed afterwards, also when the test fails.
//!
//! Needs root with `ip`, `unshare` and `nsenter`; without them the test says so and
//! passes, unless `SC_REQUIRE_NETNS=1` (scripts/test.sh sets it as root), then it fails.

mod common;
use common::*;
use std::path::PathBuf;
use std::time::Instant;

#[test]
fn samples_and_their_wake_ups_cross_between_two_hosts() {
    if !can_make_hosts() {
        return;
    }
    let id = std::process::id();
    let name = format!("l{:x}", id % 0xfffffff);
    let run_id = format!("across-{id}");
    let mut hosts = TwoHosts::up(&name);
    let link = PathBuf::from(env!("CARGO_BIN_EXE_sc-link"));
    let hop = sibling("sc-hop-cost");

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
