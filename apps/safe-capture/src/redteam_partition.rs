//! `safe-capture redteam --partition` and `launch --hostile`: the hostile partner
//! processes (`scripts/python/hostile_nominal.py`, strategies in `sc_redteam::partners`)
//! in place of the nominal controllers, checked before anything runs. The runs
//! themselves go through the partition's executor (`sc_ground::executor::Partition`)
//! and are measured by `sc_redteam::campaign::measure`, exactly as in process.

use anyhow::Context;
use sc_redteam::{CaseLabel, HostilePartners};
use std::path::{Path, PathBuf};

/// `scripts/.venv/bin/python` unless `SC_PYTHON` names another interpreter.
pub fn default_python() -> PathBuf {
    std::env::var_os("SC_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate::home::shipped("scripts/.venv/bin/python"))
}

fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

/// The hostile partner program, after checking that the interpreter imports iceoryx2
/// and the script exists.
pub fn hostile_partners(python: &Path, script: &Path) -> anyhow::Result<HostilePartners> {
    let ok = std::process::Command::new(python)
        .args(["-c", "import iceoryx2"])
        .output()
        .map(|o| o.status.success());
    if ok.ok() != Some(true) {
        anyhow::bail!(
            "--python {}: cannot run it or it cannot import iceoryx2 (create the venv with scripts/setup.sh or pass --python)",
            python.display()
        );
    }
    if !script.is_file() {
        anyhow::bail!("--partner {}: no such file", script.display());
    }
    Ok(HostilePartners {
        python: absolute(python),
        script: absolute(script),
    })
}

/// Asks the script whether it understands the case (`--check`, with the partition
/// config `config`), before any run.
pub fn check_case(p: &HostilePartners, config: &Path, case: &CaseLabel) -> anyhow::Result<()> {
    for process in p.processes(case) {
        let out = std::process::Command::new(&process.program)
            .args(&process.args)
            .args(["--check", "--config"])
            .arg(config)
            .output()
            .with_context(|| format!("running {}", p.python.display()))?;
        if !out.status.success() {
            anyhow::bail!(
                "case {}: {}",
                case.name(),
                String::from_utf8_lossy(&out.stderr).trim()
            );
        }
    }
    Ok(())
}

/// Parses `--hostile <target>/<strategy>` of `launch`.
pub fn parse_hostile(s: &str) -> anyhow::Result<CaseLabel> {
    sc_redteam::partners::parse_partition_case(s).context("--hostile")
}
