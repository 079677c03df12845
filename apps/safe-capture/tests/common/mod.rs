//! Helpers of the safe-capture CLI tests: the repository, temp directories, short
//! scenarios, running the CLI (with the partition's executables of this build).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::{Mutex, MutexGuard, OnceLock};

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A scratch directory, removed when the test ends (passed or failed).
pub struct TmpDir(pub PathBuf);

impl std::ops::Deref for TmpDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TmpDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TmpDir {
    fn drop(&mut self) {
        // a test may have made it a file
        let _ = std::fs::remove_dir_all(&self.0).or_else(|_| std::fs::remove_file(&self.0));
    }
}

pub fn tmp(name: &str) -> TmpDir {
    let d = std::env::temp_dir().join(format!("sc-mc-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    TmpDir(d)
}

/// The default scenario with a short duration (absolute URDF path), in `dir`.
pub fn short_scenario(dir: &Path, duration: f64) -> PathBuf {
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

/// The default scenario with its first `from` replaced by `to` (absolute URDF path), in
/// `dir`.
pub fn scenario_with(dir: &Path, from: &str, to: &str) -> PathBuf {
    let text = std::fs::read_to_string(root().join("config/scenario.toml")).unwrap();
    assert!(text.contains(from), "{from} not in the default scenario");
    let text = text.replacen(from, to, 1).replace(
        "urdf = \"servicer.urdf\"",
        &format!(
            "urdf = \"{}\"",
            root().join("config/servicer.urdf").display()
        ),
    );
    let p = dir.join("scenario.toml");
    std::fs::write(&p, text).unwrap();
    p
}

pub fn cli(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_safe-capture"));
    c.current_dir(root()).args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

/// Held by the tests that keep the CPU busy, one at a time: a partition in lock-step
/// is nine processes handing every tick on; several at once on a 2-core machine only
/// make each slower.
pub fn exclusive() -> MutexGuard<'static, ()> {
    static CPU: Mutex<()> = Mutex::new(());
    CPU.lock().unwrap_or_else(|e| e.into_inner())
}

pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The partition's executables (package sc-partition-apps), built with this test's
/// profile into its target directory, beside the safe-capture under test, which looks
/// for them next to itself. `CARGO_BIN_EXE_*` only names this package's binaries, so
/// cargo builds them once per test binary (a no-op when they are up to date, e.g. under
/// `cargo test --workspace`; safe-capture is named too so that the features, and so the
/// artifacts, are this build's).
pub fn partition_bin_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let exe = Path::new(env!("CARGO_BIN_EXE_safe-capture"));
        let dir = exe.parent().unwrap().to_path_buf();
        let profile_dir = dir.file_name().unwrap().to_str().unwrap().to_string();
        let mut c = Command::new(env!("CARGO"));
        c.current_dir(root())
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
            text(&o)
        );
        for b in [
            "sc-scheduler",
            "sc-simulator",
            "sc-recorder",
            "sc-safety-robotic",
        ] {
            assert!(dir.join(b).is_file(), "{b} missing in {}", dir.display());
        }
        dir
    })
}

/// Runs the CLI with the partition's executables of this build; returns its output and pid.
pub fn cli_partition(args: &[&str], env: &[(&str, &str)]) -> (Output, u32) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_safe-capture"));
    c.current_dir(root())
        .args(args)
        .env("SC_PARTITION_BIN_DIR", partition_bin_dir())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    for (k, v) in env {
        c.env(k, v);
    }
    let child = c.spawn().unwrap();
    let pid = child.id();
    (child.wait_with_output().unwrap(), pid)
}

pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The Python interpreter with the `iceoryx2` package for tests that start Python
/// partner processes: `SC_PYTHON` (set by scripts/test.sh; then a broken interpreter
/// fails the test), else scripts/.venv/bin/python; without either `None`, and the test
/// is skipped with the reason printed.
pub fn python() -> Option<PathBuf> {
    let required = std::env::var_os("SC_PYTHON");
    let py = required
        .clone()
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("scripts/.venv/bin/python"));
    let ok = std::process::Command::new(&py)
        .args(["-c", "import iceoryx2"])
        .status()
        .map(|s| s.success());
    if ok.ok() == Some(true) {
        return Some(py);
    }
    assert!(
        required.is_none(),
        "SC_PYTHON={} cannot import iceoryx2",
        py.display()
    );
    eprintln!(
        "SKIPPED: no python with iceoryx2 at {} (run scripts/setup.sh or set SC_PYTHON)",
        py.display()
    );
    None
}

/// config/partition.toml's text with its scenario as an absolute path, so that a copy
/// written into a scratch folder still finds it.
#[allow(dead_code)] // not every test binary uses it
pub fn partition_toml_absolute_scenario() -> String {
    std::fs::read_to_string(root().join("config/partition.toml"))
        .unwrap()
        .replace(
            "scenario = \"scenario.toml\"",
            &format!(
                "scenario = \"{}\"",
                std::path::absolute(root().join("config/scenario.toml"))
                    .unwrap()
                    .display()
            ),
        )
}
