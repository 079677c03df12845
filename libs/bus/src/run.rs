//! Run-scoped configuration: one iceoryx2 `global.prefix` per run.
//!
//! Every file iceoryx2 creates (in `/dev/shm` and under `/tmp/iceoryx2`) starts with
//! the prefix, so two runs (or two tests) with different prefixes never see each
//! other's services or nodes, and a run's leftovers can be found and removed.
//!
//! ```no_run
//! use sc_bus::RunScope;
//! let run = RunScope::new("2024-06-01T12-00-00")?;   // prefix "sc_2024-06-01T12-00-00_"
//! let node = run.node("simulator")?;                  // cleans dead nodes of the run first
//! // ... create ports, run ...
//! drop(node);
//! run.teardown()?;                                    // removes every file of the prefix
//! # Ok::<(), sc_bus::BusError>(())
//! ```

use crate::error::{BusError, Result, reason};
use iceoryx2::config::Config;
use iceoryx2::prelude::*;
use std::path::{Path, PathBuf};

/// How long opening a service may wait for another process that is creating it
/// (iceoryx2's `global.creation_timeout`, default 1 s). The roles of a run open their
/// services concurrently at start-up; on a loaded 2-core machine a creator was measured
/// to take longer than 1 s, and the opener then failed with `DoesNotExist`.
pub const SERVICE_CREATION_TIMEOUT: core::time::Duration = core::time::Duration::from_secs(10);

/// Environment variable read by [`RunScope::from_env`]: the run id of this run.
pub const RUN_ID_ENV: &str = "SC_RUN_ID";

/// Longest accepted run id (the prefix must stay a short file name).
pub const MAX_RUN_ID_LEN: usize = 48;

/// The iceoryx2 node type used throughout the project (inter-process, single-threaded ports).
pub type BusNode = Node<ipc::Service>;

/// A run-scoped iceoryx2 configuration.
///
/// The prefix is `sc_<run id>_`. Run ids may contain `[A-Za-z0-9.-]` only (anything
/// else becomes `-`), so no prefix is the beginning of another run's prefix.
#[derive(Debug, Clone)]
pub struct RunScope {
    run_id: String,
    prefix: String,
    config: Config,
}

impl RunScope {
    /// Scope for the given run id.
    pub fn new(run_id: &str) -> Result<Self> {
        let clean: String = run_id
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                    c
                } else {
                    '-'
                }
            })
            .collect();
        if clean.trim_matches(['-', '.']).is_empty() {
            return Err(BusError::InvalidRunId {
                run_id: run_id.to_string(),
                reason: "needs at least one letter or digit",
            });
        }
        if clean.len() > MAX_RUN_ID_LEN {
            return Err(BusError::InvalidRunId {
                run_id: run_id.to_string(),
                reason: "longer than MAX_RUN_ID_LEN (48) characters",
            });
        }
        let prefix = format!("sc_{clean}_");
        let mut config = Config::default();
        config.global.creation_timeout = SERVICE_CREATION_TIMEOUT;
        config.global.prefix =
            FileName::new(prefix.as_bytes()).map_err(|e| BusError::InvalidName {
                what: "prefix",
                name: prefix.clone(),
                reason: reason(e),
            })?;
        Ok(Self {
            run_id: clean,
            prefix,
            config,
        })
    }

    /// Scope with a fresh id (`<pid>-<monotonic ns>`), for tests and ad-hoc runs.
    pub fn unique(tag: &str) -> Result<Self> {
        let tag: String = tag.chars().take(16).collect();
        Self::new(&format!(
            "{tag}-{}-{}",
            std::process::id(),
            sc_icd::monotonic_ns()
        ))
    }

    /// Scope from the `SC_RUN_ID` environment variable (set by the launcher for
    /// every process of a run), or `None` if unset.
    pub fn from_env() -> Option<Result<Self>> {
        std::env::var(RUN_ID_ENV).ok().map(|id| Self::new(&id))
    }

    /// The cleaned run id (what to pass to child processes in `SC_RUN_ID`).
    pub fn run_id(&self) -> &str {
        &self.run_id
    }

    /// The iceoryx2 `global.prefix`, e.g. `sc_run42_`.
    pub fn prefix(&self) -> &str {
        &self.prefix
    }

    /// The iceoryx2 configuration of the run (defaults + prefix).
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Creates a node named `name` in this run. iceoryx2 removes the stale
    /// resources of dead nodes of the same prefix while doing so.
    pub fn node(&self, name: &str) -> Result<BusNode> {
        let node_name = NodeName::new(name).map_err(|e| BusError::InvalidName {
            what: "node",
            name: name.to_string(),
            reason: reason(e),
        })?;
        NodeBuilder::new()
            .name(&node_name)
            .config(&self.config)
            .create::<ipc::Service>()
            .map_err(|e| BusError::NodeCreate {
                node: name.to_string(),
                reason: reason(e),
            })
    }

    /// Files of this prefix still present in `/dev/shm` and under the iceoryx2
    /// root (`/tmp/iceoryx2`). Empty after a clean [`teardown`](Self::teardown).
    pub fn leftovers(&self) -> Vec<PathBuf> {
        let mut out = Vec::new();
        collect_with_prefix(Path::new("/dev/shm"), &self.prefix, false, &mut out);
        collect_with_prefix(&self.root_dir(), &self.prefix, true, &mut out);
        out.sort();
        out
    }

    /// Removes everything the run left behind.
    ///
    /// 1. lets iceoryx2 clean up dead nodes of the prefix (the proper way);
    /// 2. refuses with [`BusError::NodesStillAlive`] if a node of the prefix is
    ///    still alive (removing files under a live node corrupts it);
    /// 3. deletes the remaining prefix files in `/dev/shm` **and** `/tmp/iceoryx2`
    ///    together (never one without the other).
    ///
    /// Call it after every node of the run was dropped or its process ended.
    pub fn teardown(&self) -> Result<()> {
        let report = crate::liveness::reap_dead_nodes(self)?;
        if !report.alive.is_empty() {
            return Err(BusError::NodesStillAlive {
                prefix: self.prefix.clone(),
                alive: report.alive.len(),
            });
        }
        self.force_remove_files()
    }

    /// Deletes the prefix files without checking for live nodes. Only for a
    /// launcher that knows every process of the run has exited.
    pub fn force_remove_files(&self) -> Result<()> {
        for path in self.leftovers() {
            match std::fs::remove_file(&path) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(source) => {
                    return Err(BusError::Io {
                        path: path.display().to_string(),
                        source,
                    });
                }
            }
        }
        Ok(())
    }

    fn root_dir(&self) -> PathBuf {
        PathBuf::from(self.config.global.root_path().to_string())
    }
}

fn collect_with_prefix(dir: &Path, prefix: &str, recursive: bool, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let Ok(ft) = entry.file_type() else { continue };
        if ft.is_dir() {
            if recursive {
                collect_with_prefix(&path, prefix, true, out);
            }
        } else if entry.file_name().to_string_lossy().starts_with(prefix) {
            out.push(path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_ids_are_sanitised_and_unambiguous() {
        let a = RunScope::new("a_b c").unwrap();
        assert_eq!(a.prefix(), "sc_a-b-c_");
        assert!(RunScope::new("__").is_err());
        assert!(RunScope::new(&"x".repeat(49)).is_err());
        // '_' is never part of an id, so "sc_1_" cannot be the start of another prefix.
        let b = RunScope::new("1_2").unwrap();
        assert!(!b.prefix().starts_with(RunScope::new("1").unwrap().prefix()));
    }
}
