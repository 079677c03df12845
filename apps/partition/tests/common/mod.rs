//! Helpers of the partition's integration tests: unique run ids, temp configs with
//! a shortened scenario, finding and killing one process of a run.
#![allow(dead_code)]

use sc_ground::{LaunchOptions, LaunchReport};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The partition's executables, built with this test's profile into its target
/// directory: the flight ones are this package's (`CARGO_BIN_EXE_*`), the ground ones
/// (`sc-recorder`, `sc-hop-cost`) the safe-capture package's, which cargo builds here
/// once per test binary (a no-op when they are up to date, e.g. under
/// `cargo test --workspace`).
pub fn bin_dir() -> PathBuf {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let dir = PathBuf::from(env!("CARGO_BIN_EXE_sc-scheduler"))
            .parent()
            .unwrap()
            .to_path_buf();
        let profile_dir = dir.file_name().unwrap().to_str().unwrap().to_string();
        let mut c = std::process::Command::new(env!("CARGO"));
        c.current_dir(repo())
            .args(["build", "--quiet", "--bins", "-p", "sc-partition-apps"])
            .args(["-p", "safe-capture", "--target-dir"])
            .arg(dir.parent().unwrap());
        match profile_dir.as_str() {
            "debug" => c.args(["--profile", "test"]),
            "release" => c.arg("--release"),
            p => c.args(["--profile", p]),
        };
        let o = c.output().unwrap();
        assert!(
            o.status.success(),
            "building the partition's executables failed: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        for b in ["sc-scheduler", "sc-recorder", "sc-hop-cost"] {
            assert!(dir.join(b).is_file(), "{b} missing in {}", dir.display());
        }
        dir
    })
    .clone()
}

/// A fresh temp directory.
pub fn tmp(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "sc-part-{tag}-{}-{}",
        std::process::id(),
        sc_icd::monotonic_ns()
    ));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A scratch directory that is removed when the test ends, passed or failed.
pub struct Scratch(pub PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A fresh temp directory, removed when the returned guard is dropped.
pub fn scratch(tag: &str) -> Scratch {
    Scratch(tmp(tag))
}

/// Writes a scenario copy with `duration_s` (None = unchanged) and a partition config
/// into `dir`; `groups` replaces the rate groups if given; returns the config path.
pub fn write_config(
    dir: &Path,
    duration_s: Option<f64>,
    groups: Option<&str>,
    deadline_scale: f64,
) -> PathBuf {
    let cfg = repo().join("config");
    let mut sc = std::fs::read_to_string(cfg.join("scenario.toml")).unwrap();
    sc = sc.replace(
        "urdf = \"servicer.urdf\"",
        &format!("urdf = \"{}\"", cfg.join("servicer.urdf").display()),
    );
    if let Some(d) = duration_s {
        let start = sc.find("duration_s = ").unwrap();
        let end = start + sc[start..].find('\n').unwrap();
        sc.replace_range(start..end, &format!("duration_s = {d}"));
    }
    std::fs::write(dir.join("scenario.toml"), sc).unwrap();
    let mut p = std::fs::read_to_string(cfg.join("partition.toml")).unwrap();
    if let Some(g) = groups {
        let a = p.find("[[rate_groups]]").unwrap();
        let b = p.find("# Per-stage deadlines").unwrap();
        p.replace_range(a..b, g);
    }
    p = p.replace(
        "deadline_scale = 20.0",
        &format!("deadline_scale = {deadline_scale}"),
    );
    let path = dir.join("partition.toml");
    std::fs::write(&path, p).unwrap();
    path
}

pub fn options(config: &Path, out: &Path, tag: &str) -> LaunchOptions {
    LaunchOptions {
        config: config.to_path_buf(),
        out: out.to_path_buf(),
        bin_dir: Some(bin_dir()),
        run_id: Some(format!(
            "t{tag}-{}-{}",
            std::process::id(),
            sc_icd::monotonic_ns() % 1_000_000_000
        )),
        timeout: Some(Duration::from_secs(240)),
        ..Default::default()
    }
}

/// Pids of the processes whose command line contains `needle` and `out`.
pub fn pids_of(needle: &str, out: &Path) -> Vec<i32> {
    let out = out.display().to_string();
    let mut v = Vec::new();
    for e in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<i32>() else {
            continue;
        };
        let Ok(cmd) = std::fs::read(e.path().join("cmdline")) else {
            continue;
        };
        let cmd = String::from_utf8_lossy(&cmd).to_string();
        let argv0 = cmd.split('\0').next().unwrap_or("");
        let prog = argv0.rsplit('/').next().unwrap_or("");
        if prog.starts_with(needle) && cmd.contains(&out) {
            // skip zombies (exited, not yet reaped)
            let st = std::fs::read_to_string(e.path().join("stat")).unwrap_or_default();
            if !st.contains(") Z ") {
                v.push(pid);
            }
        }
    }
    v
}

/// Rows in `out/telemetry.csv` (header excluded).
pub fn rows(out: &Path) -> usize {
    std::fs::read_to_string(out.join("telemetry.csv"))
        .map(|s| s.lines().count().saturating_sub(1))
        .unwrap_or(0)
}

/// Waits until telemetry has `n` rows, then SIGKILLs the process `exec` of the run.
pub fn kill_when(out: &Path, exec: &str, n: usize) -> i32 {
    let t0 = Instant::now();
    while rows(out) < n {
        assert!(
            t0.elapsed() < Duration::from_secs(120),
            "telemetry never reached {n} rows"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    let pids = pids_of(exec, out);
    assert_eq!(pids.len(), 1, "one {exec} expected, found {pids:?}");
    // SAFETY: kill(2) on a pid found above.
    unsafe { libc::kill(pids[0], libc::SIGKILL) };
    pids[0]
}

/// The common post-conditions: nothing of the run left running or in /dev/shm.
pub fn assert_clean(rep: &LaunchReport, out: &Path) {
    assert!(rep.leftovers.is_empty(), "leftovers {:?}", rep.leftovers);
    let run = sc_bus::RunScope::new(&rep.run_id).unwrap();
    assert!(
        run.leftovers().is_empty(),
        "leftovers {:?}",
        run.leftovers()
    );
    let left: Vec<i32> = pids_of("sc-", out);
    assert!(left.is_empty(), "processes left behind: {left:?}");
    assert_eq!(rep.exits.len(), sc_icd::ROLES.len(), "{:?}", rep.exits);
}

/// Telemetry steps are 0..n without gaps; returns n.
pub fn contiguous_steps(out: &Path) -> usize {
    let s = std::fs::read_to_string(out.join("telemetry.csv")).unwrap();
    let mut n = 0;
    for (i, line) in s.lines().skip(1).enumerate() {
        let step: usize = line.split(',').next().unwrap().parse().unwrap();
        assert_eq!(step, i, "telemetry row {i} has step {step}");
        n += 1;
    }
    n
}

pub fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// No process of a healthy lock-step run slept through an input it had already
/// been sent (a lost wake-up):
/// - no stage was woken by the scheduler's stage-deadline watchdog. Its lock-step
///   deadlines are 20 times the real-time ones (0.8 s and more after the tick), so
///   a wake-up there means a lost wake-up, not a slow machine;
/// - no process saw the stop only when its 1 s wait ran out (it logs
///   [`sc_flight::roles::LOST_STOP_WAKEUP`] then).
pub fn assert_no_lost_wakeups(out: &Path) {
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("scheduler.json")).unwrap())
            .unwrap();
    assert_eq!(s["watchdog_wakeups"].as_u64(), Some(0), "{s}");
    assert_eq!(s["clock"], "LockStep", "{s}");
    for e in std::fs::read_dir(out.join("logs")).unwrap() {
        let path = e.unwrap().path();
        let log = std::fs::read_to_string(&path).unwrap();
        assert!(
            !log.contains(sc_flight::roles::LOST_STOP_WAKEUP),
            "{}: {log}",
            path.display()
        );
    }
}

/// The Python interpreter with the `iceoryx2` package for tests that start Python
/// partner processes: `SC_PYTHON` (set by scripts/test.sh; then a broken interpreter
/// fails the test), else scripts/.venv/bin/python; without either `None`, and the test
/// is skipped with the reason printed.
pub fn python() -> Option<PathBuf> {
    python_with("iceoryx2")
}

/// The interpreter ([`python`]'s choice) that imports `module`: `SC_PYTHON` must (the test
/// fails otherwise: scripts/setup.sh installs scripts/requirements.txt); the venv's may
/// not, and then `None` and the test is skipped with the reason printed.
pub fn python_with(module: &str) -> Option<PathBuf> {
    let required = std::env::var_os("SC_PYTHON");
    let py = required
        .clone()
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("scripts/.venv/bin/python"));
    let ok = std::process::Command::new(&py)
        .args(["-c", &format!("import {module}")])
        .status()
        .map(|s| s.success());
    if ok.ok() == Some(true) {
        return Some(py);
    }
    assert!(
        required.is_none(),
        "SC_PYTHON={} cannot import {module} (scripts/setup.sh installs scripts/requirements.txt)",
        py.display()
    );
    eprintln!(
        "SKIPPED: no python with {module} at {} (run scripts/setup.sh or set SC_PYTHON)",
        py.display()
    );
    None
}

/// The messages of `topic` in the recording of `out`, by tick.
pub fn recorded_by_tick(
    out: &Path,
    topic: &str,
) -> std::collections::BTreeMap<u64, serde_json::Value> {
    let bytes = std::fs::read(out.join("recording.mcap")).unwrap();
    let mut m = std::collections::BTreeMap::new();
    for msg in mcap::MessageStream::new(&bytes).unwrap() {
        let msg = msg.unwrap();
        if msg.channel.topic == topic {
            let v: serde_json::Value = serde_json::from_slice(&msg.data).unwrap();
            m.insert(v["tick"].as_u64().unwrap(), v);
        }
    }
    m
}

fn json3(v: &serde_json::Value) -> [f64; 3] {
    let a = v.as_array().unwrap();
    [0, 1, 2].map(|i| a[i].as_f64().unwrap())
}

/// From the recording of `out`: in every step where the robotic (attitude) safe command of
/// the tick acted, the force and torque (force) applied are exactly those it was certified
/// against (its `xi`). Returns (steps, steps where the robotic command acted, steps with
/// `COUPLING_MISMATCH`).
pub fn assert_applied_as_certified(out: &Path) -> (usize, usize, usize) {
    let results = recorded_by_tick(out, "safe_capture/sim/step_result");
    let robotic = recorded_by_tick(out, "safe_capture/safe/robotic");
    let attitude = recorded_by_tick(out, "safe_capture/safe/attitude");
    let (mut acted, mut mismatched) = (0, 0);
    for (k, r) in &results {
        let flags = r["fault_flags"].as_u64().unwrap();
        mismatched += usize::from(flags & u64::from(sc_icd::fault::COUPLING_MISMATCH) != 0);
        let (force, torque) = (json3(&r["force_b"]), json3(&r["torque_b"]));
        let acts = |bit: u32| {
            let bit = u64::from(bit);
            r["fallback_mask"].as_u64().unwrap() & bit == 0
                && r["held_mask"].as_u64().unwrap() & bit == 0
        };
        if acts(sc_icd::due::ATTITUDE) {
            let a = &attitude[k];
            assert_eq!(
                force,
                json3(&a["xi_f_b"]),
                "tick {k}: attitude command acted with another force"
            );
        }
        if acts(sc_icd::due::ROBOTIC) {
            let c = &robotic[k];
            let xi = (json3(&c["xi_f_b"]), json3(&c["xi_tau_b"]));
            assert_eq!(
                (force, torque),
                xi,
                "tick {k}: robotic command acted with other upstream commands than it was certified against"
            );
            acted += 1;
        }
    }
    (results.len(), acted, mismatched)
}
