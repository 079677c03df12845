//! Checks before any process starts: what would otherwise fail only once the partition
//! is running (a process that cannot start, a scenario every process rejects, a partner
//! script the interpreter cannot open while the scheduler waits for the handshake).
//! Every error is one line naming the key or role, the cause and the fix.
//!
//! Programs are found exactly as the launcher finds them ([`resolve_exec`]: a path
//! relative to the config's directory, a bare name next to the launcher or in
//! `SC_PARTITION_BIN_DIR`, then `PATH`).

use crate::launcher::{BIN_DIR_ENV, resolve_exec};
use sc_flight::config::{ConfigError, PartitionConfig};
use sc_icd::ROLES;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};

/// The command that builds the partition's flight executables (package sc-partition-apps).
pub const BUILD_COMMAND: &str = "cargo build --release -p sc-partition-apps";
/// The command that builds its ground executables (the recorder: package safe-capture).
pub const BUILD_GROUND_COMMAND: &str = "cargo build --release -p safe-capture";

/// Mode bits that make a file executable by someone.
const ANY_EXECUTE: u32 = 0o111;

/// What the pre-flight check found in a valid config.
#[derive(Debug, Clone, PartialEq)]
pub struct Preflight {
    /// Roles whose program was found.
    pub roles: usize,
    /// The scenario the config names, resolved.
    pub scenario: PathBuf,
}

fn err<T>(msg: String) -> Result<T, ConfigError> {
    Err(ConfigError(msg))
}

/// The scenario, every role's program and the simulator's plant program.
pub fn preflight(
    cfg: &PartitionConfig,
    bin_dir: &Option<PathBuf>,
) -> Result<Preflight, ConfigError> {
    let scenario = check_scenario(cfg)?;
    let roles = check_programs(cfg, bin_dir)?;
    Ok(Preflight { roles, scenario })
}

/// Loads and validates the scenario the config names; returns its path.
pub fn check_scenario(cfg: &PartitionConfig) -> Result<PathBuf, ConfigError> {
    let path = cfg.scenario_path();
    match sc_scenario::Scenario::load(&path) {
        // refused, not ignored: a plant process propagates the declared model, so the
        // realised plant of the uncertainty would silently not be the truth
        Ok(s) if s.uncertainty.is_some() && !cfg.simulator.plant.is_empty() => err(format!(
            "scenario = {:?} declares an `[uncertainty]` profile, but `[simulator] plant` propagates the declared model only; drop the plant (the built-in simulator propagates the realised plant) or the section",
            cfg.scenario
        )),
        // the cross-checks with the servicer model, and the envelope bounds every ground
        // command checks (the flight processes trust them)
        Ok(s) => {
            held_envelope(cfg, &s)?;
            sc_mission::Setup::from_scenario(s)
                .and_then(|setup| setup.check_before_run(&path))
                .map(|()| path.clone())
                .map_err(|e| {
                    ConfigError(format!(
                        "scenario = {:?}: {e}; correct the scenario or point `scenario` at another",
                        cfg.scenario
                    ))
                })
        }
        Err(e @ sc_scenario::ScenarioError::Io { .. }) => err(format!(
            "scenario = {:?}: {e}; point `scenario` at a scenario file (a relative path is relative to the config's directory {})",
            cfg.scenario,
            shown_dir(&cfg.base_dir)
        )),
        Err(e) => err(format!(
            "scenario = {:?}: {e}; correct the scenario or point `scenario` at another",
            cfg.scenario
        )),
    }
}

/// The certified envelope at the attitude filter's hold: in a multi-rate partition its
/// rows' margins — and the run-time watch on the tumble (`SafetyLayer::with_holds`) — take
/// its rate group's period, so the declared tumble must be inside the envelope of the
/// scenario held that long too (else the watch would put the run in safe mode at once).
/// A config whose schedule is invalid is refused where the schedule is built. `launch`
/// runs it on the config's scenario, the campaigns' `--partition` modes on theirs.
pub fn held_envelope(cfg: &PartitionConfig, s: &sc_scenario::Scenario) -> Result<(), ConfigError> {
    let Ok(schedule) = cfg.schedule() else {
        return Ok(());
    };
    let hold = schedule.period_s[sc_core::Subsystem::Attitude];
    if hold == s.mission.control_period_s {
        return Ok(());
    }
    let mut held = s.clone();
    held.mission.control_period_s = hold;
    held.validate_envelope().map_err(|e| {
        ConfigError(format!(
            "scenario = {:?} held for the attitude rate group's period {hold} s (its filter certifies for that hold): {e}; give the attitude group a shorter period or slow the tumble",
            cfg.scenario
        ))
    })
}

/// Every role's program (and the partner script its arguments name), and the
/// simulator's plant program if any. Returns the number of roles checked.
pub fn check_programs(
    cfg: &PartitionConfig,
    bin_dir: &Option<PathBuf>,
) -> Result<usize, ConfigError> {
    let mut n = 0;
    for role in ROLES.iter().map(|r| r.name) {
        let Some(e) = cfg.roles.get(role) else {
            return err(format!(
                "roles.{role}: missing (every role needs an executable)"
            ));
        };
        let key = format!("roles.{role}.exec");
        check_role_program(&format!("role `{role}`"), &key, &e.exec, cfg, bin_dir)?;
        check_script(
            &format!("role `{role}`"),
            &format!("roles.{role}.args"),
            &e.args,
            &cfg.base_dir,
        )?;
        n += 1;
    }
    if cfg.across_hosts() {
        // the link runs beside the roles on every host (docs/PARTITION.md "Across hosts")
        let link =
            crate::launcher::resolve_exec(crate::launcher::LINK_EXEC, &cfg.base_dir, bin_dir);
        if !link.is_file() {
            return err(format!(
                "[hosts]: the link's program `{}` is not next to safe-capture nor in SC_PARTITION_BIN_DIR ({}); build it: cargo build --release -p sc-link",
                crate::launcher::LINK_EXEC,
                link.display()
            ));
        }
    }
    if let Some((program, args)) = cfg.simulator.plant.split_first() {
        check_plant_program(program, &cfg.base_dir)?;
        check_script(
            "the simulator's plant",
            "simulator.plant",
            args,
            &cfg.base_dir,
        )?;
    }
    Ok(n)
}

fn shown_dir(d: &Path) -> String {
    if d.as_os_str().is_empty() {
        ".".into()
    } else {
        d.display().to_string()
    }
}

/// How to get a missing program: build ours, create the Python environment, or
/// correct the path.
fn fix_for(program: &Path, key: &str) -> String {
    let name = program
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    if let Some(role) = ROLES.iter().find(|r| r.exec == name) {
        let build = if role.flight {
            BUILD_COMMAND
        } else {
            BUILD_GROUND_COMMAND
        };
        format!("build it with `{build}` or correct `{key}`")
    } else if program.ends_with(".venv/bin/python") {
        format!("create the Python environment with `scripts/setup.sh` or correct `{key}`")
    } else {
        format!("install it or correct `{key}`")
    }
}

fn is_executable(p: &Path) -> bool {
    p.metadata()
        .is_ok_and(|m| m.is_file() && m.permissions().mode() & ANY_EXECUTE != 0)
}

/// A bare program name on `PATH`.
fn on_path(name: &Path) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(name))
        .find(|c| c.is_file())
}

/// A role's program, found as the launcher finds it.
fn check_role_program(
    who: &str,
    key: &str,
    exec: &str,
    cfg: &PartitionConfig,
    bin_dir: &Option<PathBuf>,
) -> Result<(), ConfigError> {
    let resolved = resolve_exec(exec, &cfg.base_dir, bin_dir);
    let bare = !exec.contains('/');
    let found = if bare && resolved.components().count() == 1 {
        on_path(&resolved)
    } else {
        Some(resolved.clone()).filter(|p| p.is_file())
    };
    match found {
        Some(p) if is_executable(&p) => Ok(()),
        Some(p) => err(format!(
            "{who}: {} is not executable; make it so with `chmod +x {}` or correct `{key}`",
            p.display(),
            p.display()
        )),
        None if bare => {
            let me = std::env::current_exe().ok();
            let here = me
                .as_ref()
                .and_then(|p| Some((p.file_name()?, p.parent()?)))
                .map(|(n, d)| format!("{} ({})", n.to_string_lossy(), d.display()))
                .unwrap_or_else(|| "the launcher".into());
            err(format!(
                "{who}: the executable `{exec}` was found neither next to {here}, nor in ${BIN_DIR_ENV}, nor on PATH; {}",
                fix_for(Path::new(exec), key)
            ))
        }
        None => err(format!(
            "{who}: the executable {} does not exist ({key} = {exec:?}{}); {}",
            resolved.display(),
            if Path::new(exec).is_absolute() {
                String::new()
            } else {
                format!(
                    ", relative to the config's directory {}",
                    shown_dir(&cfg.base_dir)
                )
            },
            fix_for(&resolved, key)
        )),
    }
}

/// The plant program: relative to the config's directory when it is there (as the
/// launcher rewrites it), else as the simulator will start it (a path relative to the
/// working directory, a bare name on `PATH`).
fn check_plant_program(program: &str, base_dir: &Path) -> Result<(), ConfigError> {
    let key = "simulator.plant";
    let p = Path::new(program);
    let in_base = base_dir.join(p);
    let found = if in_base.is_file() {
        Some(in_base.clone())
    } else if program.contains('/') {
        Some(p.to_path_buf()).filter(|p| p.is_file())
    } else {
        on_path(p)
    };
    match found {
        Some(f) if is_executable(&f) => Ok(()),
        Some(f) => err(format!(
            "the simulator's plant: {} is not executable; make it so with `chmod +x {}` or correct `{key}`",
            f.display(),
            f.display()
        )),
        None => err(format!(
            "the simulator's plant: the program {program:?} exists neither relative to the config's directory {} nor {}; {}",
            shown_dir(base_dir),
            if program.contains('/') {
                "relative to the working directory"
            } else {
                "on PATH"
            },
            fix_for(&in_base, key)
        )),
    }
}

/// File extensions of the scripts a role's interpreter may be asked to run.
const SCRIPT_EXTENSIONS: [&str; 2] = ["py", "sh"];

/// The script an interpreter is asked to run: the first argument that is not an option
/// and has a script extension ([`SCRIPT_EXTENSIONS`]; an option's value such as a log
/// path is not taken for one), when it names a path (contains `/`, no blanks), must exist
/// relative to the config's directory (where the launcher looks first) or to the working
/// directory.
fn check_script(who: &str, key: &str, args: &[String], base_dir: &Path) -> Result<(), ConfigError> {
    let is_script = |a: &&String| {
        !a.starts_with('-')
            && Path::new(a.as_str())
                .extension()
                .is_some_and(|e| SCRIPT_EXTENSIONS.iter().any(|s| e == *s))
    };
    let Some(script) = args.iter().find(is_script) else {
        return Ok(());
    };
    // a path, not a command line (`sh -c "cmd …"`) nor a value
    if !script.contains('/') || script.contains(char::is_whitespace) {
        return Ok(());
    }
    let p = Path::new(script);
    if base_dir.join(p).is_file() || p.is_file() {
        return Ok(());
    }
    err(format!(
        "{who}: the script {script:?} in `{key}` exists neither relative to the config's directory {} nor to the working directory; correct the path in `{key}`",
        shown_dir(base_dir)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(dir: &Path, roles: &str, extra: &str) -> PartitionConfig {
        PartitionConfig::from_toml_str(&config_text(roles, extra), dir).unwrap()
    }

    fn config_text(roles: &str, extra: &str) -> String {
        let mut s = format!(
            "scenario = \"scenario.toml\"\nclock = \"lock_step\"\nhandshake_timeout_s = 30\n{extra}[[rate_groups]]\nname = \"c\"\nperiod_s = 0.1\nmembers = [\"translational\", \"attitude\", \"robotic\"]\n[deadlines]\nsafety_translational_ms = 40\nsafety_attitude_ms = 60\nsafety_robotic_ms = 80\nsimulator_ms = 90\n[lock_step]\ndeadline_scale = 20\nrecorder_window_ticks = 8\n"
        );
        s += roles;
        s
    }

    fn roles_all(exec: &str) -> String {
        ROLES
            .iter()
            .map(|r| format!("[roles.{}]\nexec = \"{exec}\"\n", r.name))
            .collect()
    }

    struct Scratch(PathBuf);
    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn scratch(name: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("sc-preflight-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }

    fn write_program(p: &Path, mode: u32) {
        std::fs::write(p, "#!/bin/sh\n").unwrap();
        std::fs::set_permissions(p, std::fs::Permissions::from_mode(mode)).unwrap();
    }

    #[test]
    fn a_missing_program_names_its_role_and_the_fix() {
        let d = scratch("missing");
        write_program(&d.0.join("prog"), 0o755);
        let roles = roles_all("./prog").replace(
            "[roles.simulator]\nexec = \"./prog\"",
            "[roles.simulator]\nexec = \"bin/sc-simulator\"",
        );
        let e = check_programs(&config(&d.0, &roles, ""), &None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("role `simulator`: the executable")
                && e.contains("bin/sc-simulator does not exist")
                && e.contains(BUILD_COMMAND),
            "{e}"
        );
        assert_eq!(
            check_programs(&config(&d.0, &roles_all("./prog"), ""), &None).unwrap(),
            ROLES.len()
        );
    }

    #[test]
    fn a_bare_name_found_nowhere_is_named_with_where_it_was_looked_for() {
        let d = scratch("bare");
        let e = check_programs(&config(&d.0, &roles_all("sc-no-such-program"), ""), &None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(
                "role `scheduler`: the executable `sc-no-such-program` was found neither next to "
            ) && e.contains(BIN_DIR_ENV)
                && e.contains("install it or correct `roles.scheduler.exec`"),
            "{e}"
        );
    }

    #[test]
    fn a_file_that_is_not_executable_is_refused() {
        let d = scratch("mode");
        write_program(&d.0.join("prog"), 0o644);
        let e = check_programs(&config(&d.0, &roles_all("./prog"), ""), &None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("is not executable") && e.contains("chmod +x"),
            "{e}"
        );
    }

    #[test]
    fn a_missing_partner_script_and_plant_are_named() {
        let d = scratch("script");
        write_program(&d.0.join("prog"), 0o755);
        std::fs::write(d.0.join("partner.py"), "").unwrap();
        let with_args = |script: &str| {
            roles_all("./prog").replace(
                "[roles.nominal_attitude]\nexec = \"./prog\"\n",
                &format!(
                    "[roles.nominal_attitude]\nexec = \"./prog\"\nargs = [\"-u\", \"{script}\", \"--strategy\", \"a/b\"]\n"
                ),
            )
        };
        assert!(check_programs(&config(&d.0, &with_args("./partner.py"), ""), &None).is_ok());
        // a command line is no script path
        assert!(check_programs(&config(&d.0, &with_args("exec ./gone.py --x"), ""), &None).is_ok());
        // an option's value with a path is not taken for the script: the script after it is
        let log_first = |script: &str| {
            roles_all("./prog").replace(
                "[roles.nominal_attitude]\nexec = \"./prog\"\n",
                &format!(
                    "[roles.nominal_attitude]\nexec = \"./prog\"\nargs = [\"--log\", \"out/partner.log\", \"{script}\"]\n"
                ),
            )
        };
        assert!(check_programs(&config(&d.0, &log_first("./partner.py"), ""), &None).is_ok());
        let e = check_programs(&config(&d.0, &log_first("./gone.py"), ""), &None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("the script \"./gone.py\""), "{e}");
        let e = check_programs(&config(&d.0, &with_args("./gone.py"), ""), &None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(
                "role `nominal_attitude`: the script \"./gone.py\" in `roles.nominal_attitude.args`"
            ),
            "{e}"
        );
        let plant = |p: &str| format!("[simulator]\nplant = [\"{p}\", \"./partner.py\"]\n");
        let roles = roles_all("./prog") + &plant("./prog");
        assert!(check_programs(&config(&d.0, &roles, ""), &None).is_ok());
        let roles = roles_all("./prog") + &plant("./venv/.venv/bin/python");
        let e = check_programs(&config(&d.0, &roles, ""), &None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("the simulator's plant: the program \"./venv/.venv/bin/python\"")
                && e.contains("scripts/setup.sh"),
            "{e}"
        );
    }

    /// An attitude rate group slower than the scenario's control period: the declared
    /// tumble must be inside the envelope at that hold (0.3 s leaves 0.0764 rad/s of
    /// synchronisation, below the default 0.08), or the launch is refused before anything
    /// starts; 0.2 s (limit 0.0977 rad/s) is accepted.
    #[test]
    fn the_envelope_is_checked_at_the_attitude_groups_hold() {
        let d = scratch("held");
        let repo =
            std::path::absolute(Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")).unwrap();
        let sc = std::fs::read_to_string(repo.join("config/scenario.toml"))
            .unwrap()
            .replace(
                "urdf = \"servicer.urdf\"",
                &format!("urdf = \"{}\"", repo.join("config/servicer.urdf").display()),
            );
        std::fs::write(d.0.join("scenario.toml"), sc).unwrap();
        let groups = |a: f64| {
            format!(
                "[[rate_groups]]\nname = \"t\"\nperiod_s = {a}\nmembers = [\"translational\"]\n[[rate_groups]]\nname = \"a\"\nperiod_s = {a}\nmembers = [\"attitude\"]\n[[rate_groups]]\nname = \"r\"\nperiod_s = 0.1\nmembers = [\"robotic\"]\n"
            )
        };
        let with = |a: f64| {
            let text = config_text(&roles_all("./prog"), "").replace(
                "[[rate_groups]]\nname = \"c\"\nperiod_s = 0.1\nmembers = [\"translational\", \"attitude\", \"robotic\"]\n",
                &groups(a),
            );
            PartitionConfig::from_toml_str(&text, &d.0).unwrap()
        };
        let e = held_envelope(
            &with(0.3),
            &sc_scenario::Scenario::load(&d.0.join("scenario.toml")).unwrap(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("held for the attitude rate group's period 0.3 s")
                && e.contains("outside the certified envelope"),
            "{e}"
        );
        let s = sc_scenario::Scenario::load(&d.0.join("scenario.toml")).unwrap();
        assert!(held_envelope(&with(0.2), &s).is_ok());
    }

    #[test]
    fn a_missing_or_invalid_scenario_is_named_with_the_key() {
        let d = scratch("scenario");
        let cfg = config(&d.0, &roles_all("./prog"), "");
        let e = check_scenario(&cfg).unwrap_err().to_string();
        assert!(
            e.starts_with("scenario = \"scenario.toml\": cannot read")
                && e.contains("point `scenario` at a scenario file"),
            "{e}"
        );
        std::fs::write(d.0.join("scenario.toml"), "[mission]\n").unwrap();
        let e = check_scenario(&cfg).unwrap_err().to_string();
        assert!(
            e.starts_with("scenario = \"scenario.toml\": ") && !e.contains('\n'),
            "{e}"
        );
    }
}
