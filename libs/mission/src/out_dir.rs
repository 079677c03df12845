//! The output-folder policy of every command that writes a folder (`run`, `launch`,
//! `montecarlo`, `redteam`, `compare`, `bench latency`, …):
//!
//! - a folder is *ours* when it holds the marker file [`MARKER`] (written by
//!   safe-capture: the command, version and git commit of the build);
//! - a non-empty folder that is not ours is refused unless the user forces it
//!   (`--force`), before anything is written;
//! - a run writes into the sibling `OUT.incomplete` ([`Staged::path`]) and only a run
//!   that finished replaces `OUT` as a whole ([`Staged::commit`]): an old run's files
//!   are never mixed with a new run's, and a run that failed leaves its partial output
//!   under a name that says so, never in `OUT` where it could be taken for a result.

use std::path::{Path, PathBuf};

/// The marker file of a folder written by safe-capture.
pub const MARKER: &str = ".safe-capture";

/// Suffix of the folder a run writes into before it replaces its output folder, and
/// the name its partial output keeps when the run fails.
pub const INCOMPLETE_SUFFIX: &str = ".incomplete";

/// Suffix of the old output folder while the new one takes its place.
const REPLACED_SUFFIX: &str = ".replaced";

/// Why an output folder cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum OutDirError {
    #[error(
        "{} is not empty and was not written by safe-capture (no {MARKER} file in it): choose another --out, or pass --force to replace it",
        .0.display()
    )]
    NotOurs(PathBuf),
    #[error("{} is not a folder: choose another --out", .0.display())]
    NotAFolder(PathBuf),
    #[error("{}: an output folder needs a name (not / or ..): choose another --out", .0.display())]
    NoName(PathBuf),
    #[error(
        "{} holds {what} ({}): replacing it would delete that; choose another --out",
        .dir.display(),
        .inside.display()
    )]
    Holds {
        dir: PathBuf,
        what: &'static str,
        inside: PathBuf,
    },
    #[error(
        "{} holds the output of `safe-capture {other}`, not of `{command}`: choose another --out, or pass --force to replace it",
        .dir.display()
    )]
    OtherCommand {
        dir: PathBuf,
        other: String,
        command: String,
    },
    #[error(
        "{} is being written by another safe-capture (process {pid}): wait for it or choose another --out",
        .dir.display()
    )]
    Busy { dir: PathBuf, pid: u32 },
    #[error(
        "{} exists already (another command writing the same --out just now?): wait for it or choose another --out",
        .0.display()
    )]
    Taken(PathBuf),
    // the cause is in the message, not a `source`: one line, said once
    #[error("{}: {error}", .path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
}

fn io(p: &Path) -> impl FnOnce(std::io::Error) -> OutDirError + '_ {
    move |e| OutDirError::Io {
        path: p.to_path_buf(),
        error: e,
    }
}

/// What the marker file records.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Marker {
    /// The command that wrote the folder, e.g. "run" or "montecarlo merge".
    pub command: String,
    pub version: String,
    pub git_commit: String,
    /// The process that wrote it.
    pub pid: u32,
}

/// The marker of `dir`, if it is ours (a marker that cannot be parsed still makes the
/// folder ours: safe-capture wrote it).
pub fn marker(dir: &Path) -> Option<Option<Marker>> {
    let text = std::fs::read_to_string(dir.join(MARKER)).ok()?;
    Some(serde_json::from_str(&text).ok())
}

/// The process still writing `dir`, if its marker names one that runs (not this one).
pub fn writer_alive(dir: &Path) -> Option<u32> {
    marker(dir)
        .flatten()
        .map(|m| m.pid)
        .filter(|&pid| alive(pid))
}

/// True when `dir` holds the marker of a folder written by safe-capture.
pub fn is_ours(dir: &Path) -> bool {
    dir.join(MARKER).is_file()
}

/// Missing, or a folder without any entry.
fn is_empty(dir: &Path) -> Result<bool, OutDirError> {
    match std::fs::read_dir(dir) {
        Ok(mut rd) => Ok(rd.next().is_none()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(true),
        Err(e) => Err(io(dir)(e)),
    }
}

/// Refuses `dir` unless it is missing, empty or ours, or `force` is given: a path that
/// is not a folder is always refused.
pub fn check(dir: &Path, force: bool) -> Result<(), OutDirError> {
    if dir.exists() && !dir.is_dir() {
        return Err(OutDirError::NotAFolder(dir.to_path_buf()));
    }
    if force || is_ours(dir) || is_empty(dir)? {
        Ok(())
    } else {
        Err(OutDirError::NotOurs(dir.to_path_buf()))
    }
}

/// The command's name without its sub-command (`"montecarlo merge"` → `"montecarlo"`).
fn command_name(c: &str) -> &str {
    c.split_whitespace().next().unwrap_or(c)
}

/// [`check`] for `command`: a folder another command wrote (e.g. a Monte Carlo campaign
/// under `run --out`) is replaced only with `force`.
fn check_for(dir: &Path, command: &str, force: bool) -> Result<(), OutDirError> {
    check(dir, force)?;
    if !force
        && let Some(Some(m)) = marker(dir)
        && command_name(&m.command) != command_name(command)
    {
        return Err(OutDirError::OtherCommand {
            dir: dir.to_path_buf(),
            other: m.command,
            command: command.to_string(),
        });
    }
    Ok(())
}

/// Refuses, even with `force`, an output folder that is or contains the working
/// directory or one of the command's inputs (replacing it would delete them).
fn check_not_holding(target: &Path, inputs: &[&Path]) -> Result<(), OutDirError> {
    let canon = |p: &Path| std::fs::canonicalize(p).ok();
    let Some(t) = canon(target) else {
        return Ok(()); // a folder that does not exist holds nothing
    };
    let cwd = std::env::current_dir().ok().and_then(|d| canon(&d));
    let holds = |p: &Option<PathBuf>| p.as_ref().is_some_and(|p| p.starts_with(&t));
    if holds(&cwd) {
        return Err(OutDirError::Holds {
            dir: target.to_path_buf(),
            what: "the working directory",
            inside: cwd.unwrap_or_default(),
        });
    }
    for i in inputs {
        if holds(&canon(i)) {
            return Err(OutDirError::Holds {
                dir: target.to_path_buf(),
                what: "an input of this command",
                inside: i.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// Writes the marker of `command` into `dir` (which exists).
pub fn write_marker(dir: &Path, command: &str) -> Result<(), OutDirError> {
    let b = crate::build::current();
    let m = Marker {
        command: command.into(),
        version: b.version,
        git_commit: b.git_commit,
        pid: std::process::id(),
    };
    let text = serde_json::to_string_pretty(&m).unwrap_or_default() + "\n";
    let p = dir.join(MARKER);
    std::fs::write(&p, text).map_err(io(&p))
}

/// The absolute form of `p` (symbolic links resolved when it exists), with a name.
fn absolute(p: &Path) -> Result<PathBuf, OutDirError> {
    let a = if p.exists() {
        std::fs::canonicalize(p).map_err(io(p))?
    } else {
        std::path::absolute(p).map_err(io(p))?
    };
    match a.file_name() {
        Some(_) if a.parent().is_some() => Ok(a),
        _ => Err(OutDirError::NoName(p.to_path_buf())),
    }
}

/// `dir` with `suffix` appended to its name.
fn sibling(dir: &Path, suffix: &str) -> PathBuf {
    let mut name = dir.file_name().unwrap_or_default().to_os_string();
    name.push(suffix);
    dir.with_file_name(name)
}

/// True when process `pid` runs (Linux: it has a /proc entry).
fn alive(pid: u32) -> bool {
    pid != std::process::id() && Path::new("/proc").join(pid.to_string()).exists()
}

fn remove(p: &Path) -> Result<(), OutDirError> {
    if p.is_dir() {
        std::fs::remove_dir_all(p).map_err(io(p))
    } else {
        std::fs::remove_file(p).map_err(io(p))
    }
}

/// An output folder being written: everything goes into [`Staged::path`]
/// (`OUT.incomplete`), which replaces `OUT` at [`Staged::commit`]. Dropped without a
/// commit, it leaves its partial output in `OUT.incomplete` (or removes it when nothing
/// but the marker was written) and says so on stderr.
#[derive(Debug)]
pub struct Staged {
    target: PathBuf,
    staging: PathBuf,
    done: bool,
}

impl Staged {
    /// Checks the output folder `target` ([`check`]), then creates its staging folder
    /// with the marker of `command` (an earlier run's partial output in it is removed;
    /// one another live process is writing is refused).
    pub fn begin(target: &Path, command: &str, force: bool) -> Result<Staged, OutDirError> {
        Self::begin_with_inputs(target, command, force, &[])
    }

    /// [`Self::begin`] for a command that reads `inputs` (run folders, a campaign): an
    /// output folder that is or contains one of them, or the working directory, is
    /// refused even with `force`; so is one another command wrote, unless `force`.
    pub fn begin_with_inputs(
        target: &Path,
        command: &str,
        force: bool,
        inputs: &[&Path],
    ) -> Result<Staged, OutDirError> {
        check_for(target, command, force)?;
        let abs = absolute(target)?;
        check_not_holding(target, inputs)?;
        let target = abs;
        let staging = sibling(&target, INCOMPLETE_SUFFIX);
        if staging.exists() {
            if let Some(Some(m)) = marker(&staging)
                && alive(m.pid)
                && !force
            {
                return Err(OutDirError::Busy {
                    dir: staging,
                    pid: m.pid,
                });
            }
            check(&staging, force)?;
            // not `eprintln!`: a closed stderr must not panic
            use std::io::Write as _;
            let _ = writeln!(
                std::io::stderr().lock(),
                "removing the partial output of an earlier run: {}",
                staging.display()
            );
            remove(&staging)?;
        }
        if let Some(parent) = staging.parent() {
            std::fs::create_dir_all(parent).map_err(io(parent))?;
        }
        // `create_dir`, not `create_dir_all`: of two commands started on the same --out
        // at once, one gets the folder and the other is refused
        if let Err(e) = std::fs::create_dir(&staging) {
            return Err(if e.kind() == std::io::ErrorKind::AlreadyExists {
                OutDirError::Taken(staging)
            } else {
                io(&staging)(e)
            });
        }
        write_marker(&staging, command)?;
        Ok(Staged {
            target,
            staging,
            done: false,
        })
    }

    /// Where the run writes (absolute).
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The output folder the run replaces when it finishes (absolute).
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// The run finished: its folder replaces the output folder as a whole. Returns the
    /// output folder.
    pub fn commit(mut self) -> Result<PathBuf, OutDirError> {
        self.done = true;
        // a name of this process's own: a folder of the user's is never taken for it
        let aside = sibling(
            &self.target,
            &format!("{REPLACED_SUFFIX}.{}", std::process::id()),
        );
        if aside.exists() {
            return Err(OutDirError::Taken(aside));
        }
        let old = self.target.exists();
        if old {
            std::fs::rename(&self.target, &aside).map_err(io(&self.target))?;
        }
        if let Err(e) = std::fs::rename(&self.staging, &self.target) {
            if old {
                // put the old folder back: the run's output stays in staging
                let _ = std::fs::rename(&aside, &self.target);
            }
            return Err(io(&self.target)(e));
        }
        if old && let Err(e) = remove(&aside) {
            // the new output is in place: the old one left behind is worth a word, not
            // a failed run
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr().lock(), "warning: {e}");
        }
        Ok(self.target.clone())
    }

    /// The run did not finish: its partial output stays in [`Staged::path`], which is
    /// returned, or, when nothing but the marker was written, is removed (`None`).
    pub fn abandon(mut self) -> Option<PathBuf> {
        self.done = true;
        self.leave()
    }

    fn leave(&self) -> Option<PathBuf> {
        let only_marker = std::fs::read_dir(&self.staging)
            .map(|rd| rd.flatten().all(|e| e.file_name() == MARKER))
            .unwrap_or(false);
        if only_marker {
            let _ = std::fs::remove_dir_all(&self.staging);
            None
        } else {
            Some(self.staging.clone())
        }
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.done
            && let Some(p) = self.leave()
        {
            // not `eprintln!`: a closed stderr must not panic in a drop
            use std::io::Write as _;
            let _ = writeln!(
                std::io::stderr().lock(),
                "the partial output is in {} ({} not replaced)",
                p.display(),
                self.target.display()
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Tmp(PathBuf);
    impl Drop for Tmp {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
    fn tmp(name: &str) -> Tmp {
        let d = std::env::temp_dir().join(format!("sc-out-dir-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Tmp(d)
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_missing_or_empty_folder_is_written_and_marked() {
        let t = tmp("new");
        for out in [t.0.join("a/b"), t.0.join("empty")] {
            if out.ends_with("empty") {
                std::fs::create_dir_all(&out).unwrap();
            }
            let s = Staged::begin(&out, "run", false).unwrap();
            assert!(s.path().ends_with(format!(
                "{}.incomplete",
                out.file_name().unwrap().to_str().unwrap()
            )));
            std::fs::write(s.path().join("summary.json"), "{}").unwrap();
            assert_eq!(s.commit().unwrap(), out);
            assert_eq!(names(&out), [MARKER, "summary.json"]);
            let m = marker(&out).unwrap().unwrap();
            assert_eq!(m.command, "run");
            assert_eq!(m.pid, std::process::id());
        }
        assert_eq!(names(&t.0), ["a", "empty"]);
    }

    #[test]
    fn a_folder_not_ours_is_refused_unless_forced_and_nothing_is_written() {
        let t = tmp("theirs");
        let out = t.0.join("theirs");
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(out.join("notes.txt"), "mine").unwrap();
        let e = Staged::begin(&out, "run", false).unwrap_err();
        assert!(matches!(e, OutDirError::NotOurs(_)), "{e}");
        let msg = e.to_string();
        assert!(
            msg.contains(&out.display().to_string()) && msg.contains("--force"),
            "{msg}"
        );
        assert_eq!(names(&t.0), ["theirs"], "nothing written beside it");
        assert_eq!(names(&out), ["notes.txt"]);
        let s = Staged::begin(&out, "run", true).unwrap();
        std::fs::write(s.path().join("telemetry.csv"), "t").unwrap();
        s.commit().unwrap();
        assert_eq!(names(&out), [MARKER, "telemetry.csv"]);
    }

    /// A campaign under `run --out` is not replaced without --force; a sub-command of
    /// the same command is the same command.
    #[test]
    fn another_commands_folder_needs_force() {
        let t = tmp("other");
        let out = t.0.join("campaign");
        let s = Staged::begin(&out, "montecarlo", false).unwrap();
        std::fs::write(s.path().join("campaign.json"), "{}").unwrap();
        s.commit().unwrap();
        let e = Staged::begin(&out, "run", false).unwrap_err();
        assert!(matches!(e, OutDirError::OtherCommand { .. }), "{e}");
        assert!(e.to_string().contains("`safe-capture montecarlo`"), "{e}");
        assert_eq!(names(&out), [MARKER, "campaign.json"], "untouched");
        Staged::begin(&out, "montecarlo merge", false)
            .unwrap()
            .commit()
            .unwrap();
        Staged::begin(&out, "run", true).unwrap().commit().unwrap();
        assert_eq!(marker(&out).unwrap().unwrap().command, "run");
    }

    /// An output folder that is or holds one of the command's inputs is refused even
    /// with --force (compare A B --out B would delete B).
    #[test]
    fn a_folder_holding_an_input_is_refused_even_forced() {
        let t = tmp("inputs");
        let b = t.0.join("b");
        Staged::begin(&b, "run", false).unwrap().commit().unwrap();
        let inside = b.join("telemetry.csv");
        std::fs::write(&inside, "t").unwrap();
        for (out, input) in [(&b, &b), (&t.0, &inside)] {
            assert!(Staged::begin_with_inputs(out, "run", false, &[input]).is_err());
            let e = Staged::begin_with_inputs(out, "run", true, &[input]).unwrap_err();
            assert!(matches!(e, OutDirError::Holds { .. }), "{e}");
        }
        assert!(inside.is_file());
        // inside an input is fine (compare's default B/compare)
        Staged::begin_with_inputs(&b.join("compare"), "compare", false, &[&b])
            .unwrap()
            .commit()
            .unwrap();
    }

    /// A folder of the user's named like the old output set aside survives a commit.
    #[test]
    fn a_users_replaced_folder_is_not_touched() {
        let t = tmp("aside");
        let out = t.0.join("out");
        Staged::begin(&out, "run", false).unwrap().commit().unwrap();
        let users = t.0.join("out.replaced");
        std::fs::create_dir_all(&users).unwrap();
        std::fs::write(users.join("mine.txt"), "x").unwrap();
        Staged::begin(&out, "run", false).unwrap().commit().unwrap();
        assert_eq!(names(&users), ["mine.txt"]);
        assert_eq!(names(&t.0), ["out", "out.replaced"]);
    }

    #[test]
    fn a_file_is_refused_even_forced() {
        let t = tmp("file");
        let f = t.0.join("f");
        std::fs::write(&f, "x").unwrap();
        for force in [false, true] {
            let e = Staged::begin(&f, "run", force).unwrap_err();
            assert!(matches!(e, OutDirError::NotAFolder(_)), "{e}");
        }
        assert!(matches!(
            Staged::begin(Path::new("/"), "run", true).unwrap_err(),
            OutDirError::NoName(_)
        ));
    }

    #[test]
    fn a_folder_of_ours_is_replaced_as_a_whole() {
        let t = tmp("ours");
        let out = t.0.join("run");
        let s = Staged::begin(&out, "run", false).unwrap();
        std::fs::create_dir_all(s.path().join("nominal")).unwrap();
        std::fs::write(s.path().join("summary.json"), "old").unwrap();
        s.commit().unwrap();
        let s = Staged::begin(&out, "run --no-filter", false).unwrap();
        std::fs::write(s.path().join("summary.json"), "new").unwrap();
        // the old result stays whole until the new one replaces it
        assert_eq!(
            std::fs::read_to_string(out.join("summary.json")).unwrap(),
            "old"
        );
        s.commit().unwrap();
        assert_eq!(names(&out), [MARKER, "summary.json"], "no stale nominal/");
        assert_eq!(
            std::fs::read_to_string(out.join("summary.json")).unwrap(),
            "new"
        );
        assert_eq!(names(&t.0), ["run"]);
    }

    #[test]
    fn a_failed_run_leaves_the_old_folder_and_its_partial_output_apart() {
        let t = tmp("failed");
        let out = t.0.join("run");
        let s = Staged::begin(&out, "launch", false).unwrap();
        std::fs::write(s.path().join("summary.json"), "old").unwrap();
        s.commit().unwrap();
        let s = Staged::begin(&out, "launch", false).unwrap();
        std::fs::write(s.path().join("launch.json"), "failed").unwrap();
        let kept = s.abandon().unwrap();
        assert_eq!(kept, t.0.join("run.incomplete"));
        assert_eq!(names(&kept), [MARKER, "launch.json"]);
        assert_eq!(
            std::fs::read_to_string(out.join("summary.json")).unwrap(),
            "old"
        );
        // the next run replaces the partial output of the failed one
        let s = Staged::begin(&out, "launch", false).unwrap();
        assert_eq!(names(s.path()), [MARKER]);
        // nothing written: nothing kept
        assert_eq!(s.abandon(), None);
        assert_eq!(names(&t.0), ["run"]);
        // dropped without a commit: the same as abandoned
        let s = Staged::begin(&out, "launch", false).unwrap();
        std::fs::write(s.path().join("x"), "").unwrap();
        drop(s);
        assert_eq!(names(&t.0), ["run", "run.incomplete"]);
    }

    #[test]
    fn a_partial_folder_not_ours_or_in_use_is_refused() {
        let t = tmp("busy");
        let out = t.0.join("run");
        let inc = t.0.join("run.incomplete");
        std::fs::create_dir_all(&inc).unwrap();
        std::fs::write(inc.join("mine"), "").unwrap();
        assert!(matches!(
            Staged::begin(&out, "run", false).unwrap_err(),
            OutDirError::NotOurs(p) if p == inc
        ));
        std::fs::remove_file(inc.join("mine")).unwrap();
        // a live process other than this one is writing it (pid 1 always runs)
        let m = Marker {
            command: "run".into(),
            version: "0".into(),
            git_commit: "x".into(),
            pid: 1,
        };
        std::fs::write(inc.join(MARKER), serde_json::to_string(&m).unwrap()).unwrap();
        assert!(matches!(
            Staged::begin(&out, "run", false).unwrap_err(),
            OutDirError::Busy { pid: 1, .. }
        ));
    }
}
