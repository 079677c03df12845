//! `safe-capture check FILE…`: every configuration a user can give, validated before
//! anything runs, one line per file, exit 0 only when all are valid (issue #16).

mod common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The build command a missing partition executable's line names.
const BUILD: &str = "cargo build --release -p sc-partition-apps";

/// `check` with the partition's executables of this build next to it.
fn check(args: &[&str]) -> Output {
    let mut a = vec!["check"];
    a.extend_from_slice(args);
    cli_partition(&a, &[]).0
}

/// Asserts an invalid file: exit 2, no panic, nothing on stdout, one line on stderr
/// that starts with the file and contains every needle.
fn assert_invalid(o: &Output, file: &Path, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{}", text(o));
    assert!(!err.contains("panicked"), "{err}");
    assert!(o.stdout.is_empty(), "{}", text(o));
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one line: {err}");
    assert!(
        lines[0].starts_with(&format!("{}: ", file.display())),
        "{err}"
    );
    for n in needles {
        assert!(lines[0].contains(n), "`{n}` not in: {err}");
    }
}

/// A copy of a shipped config in `dir` with `from` replaced by `to` (once), its
/// relative paths made absolute so that it is valid where it is.
fn shipped_with(dir: &Path, name: &str, from: &str, to: &str) -> PathBuf {
    let text = std::fs::read_to_string(root().join("config").join(name)).unwrap();
    assert!(text.contains(from), "`{from}` not in config/{name}");
    let config = std::path::absolute(root().join("config")).unwrap();
    let text = text
        .replacen(from, to, 1)
        .replace(
            "urdf = \"servicer.urdf\"",
            &format!("urdf = \"{}\"", config.join("servicer.urdf").display()),
        )
        .replace(
            "scenario = \"scenario.toml\"",
            &format!("scenario = \"{}\"", config.join("scenario.toml").display()),
        );
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn the_shipped_configs_are_valid() {
    let o = check(&[
        "config/scenario.toml",
        "config/partition.toml",
        "config/montecarlo.toml",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let lines: Vec<&str> = out.lines().collect();
    // the default scenario is the installation's, wherever the command runs
    let installed = std::fs::canonicalize(root().join("config/scenario.toml")).unwrap();
    assert_eq!(
        lines,
        [
            "config/scenario.toml: ok (scenario: 3 phases, 240 s at most, control period 0.1 s; tumble 0.0800 rad/s, the certified envelope's limit 0.1241 rad/s)"
                .to_string(),
            format!(
                "config/partition.toml: ok (partition: {} roles, scenario config/scenario.toml)",
                sc_icd::ROLES.len()
            ),
            format!(
                "config/montecarlo.toml: ok (montecarlo: distance 7–11 m, tumbling rate 0–0.12 rad/s; fits the scenario {})",
                installed.display()
            ),
        ],
        "{}",
        text(&o)
    );
    assert!(o.stderr.is_empty(), "{}", text(&o));
}

/// A scenario whose declared uncertainty leaves the corridor's wall without a certified
/// command is valid, but `check` says so before anything runs (docs/SAFETY.md,
/// "Translational: what the declared errors cost").
#[test]
fn a_declared_uncertainty_the_rows_cannot_certify_is_named_before_the_run() {
    let d = tmp("check-uncertified");
    let s = shipped_with(
        &d,
        "scenario.toml",
        "[mission]",
        "[uncertainty]\nprofile = \"realistic\"\n\n[mission]",
    );
    let o = check(&[s.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("NOTE: under the declared uncertainty the translational rows cannot certify")
            && out.contains("corridor's wall at ranges up to 3.65 m"),
        "{}",
        text(&o)
    );
}

/// A `[world]` event (undeclared to the filters) is named by `check`, with what it does to
/// the certified envelope; a negative time is refused on one line (docs/SCENARIO.md).
#[test]
fn a_world_event_is_named_and_checked() {
    let d = tmp("check-world");
    let world =
        "[world.target_spin_change]\nt_s = 100.0\nomega_rad_s = [-0.3, 0.0, 0.0]\n\n[mission]";
    let s = shipped_with(&d, "scenario.toml", "[mission]", world);
    let o = check(&[s.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("NOTE: [world] changes the target's rate to [-0.3, 0.0, 0.0] rad/s at t = 100 s, undeclared to the filters: outside the certified envelope (rate_synchronisation): the run tests the safe mode"),
        "{}",
        text(&o)
    );
    let s = shipped_with(
        &d,
        "scenario.toml",
        "[mission]",
        &world.replace("t_s = 100.0", "t_s = -1.0"),
    );
    let o = check(&[s.to_str().unwrap()]);
    assert_invalid(
        &o,
        &s,
        &[
            "`world.target_spin_change.t_s` = -1.0",
            "must not be negative",
        ],
    );
}

/// `check` of the shipped scenario with `world` put before `[mission]`: accepted (exit 0);
/// its output and stdout.
fn accepted_with_world(d: &Path, world: &str) -> (Output, String) {
    let s = shipped_with(d, "scenario.toml", "[mission]", world);
    let o = check(&[s.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    (o, out)
}

/// The world's fixture elsewhere than declared is named with what the run-time watch will
/// make of it: outside the envelope at 0.8 m off the spin axis, inside at 0.4 m; a
/// non-finite one is refused on one line.
#[test]
fn a_world_fixture_is_named_and_checked() {
    let d = tmp("check-world-fixture");
    for (y, after) in [
        (
            "0.8",
            "outside the certified envelope (line_of_sight_rate): the run tests the safe mode",
        ),
        ("0.4", "inside the certified envelope"),
    ] {
        let world = format!("[world]\ngrasp_point_m = [-0.55, {y}, 0.0]\n\n[mission]");
        let (o, out) = accepted_with_world(&d, &world);
        let note = format!(
            "NOTE: [world] puts the grasping fixture at [-0.55, {y}, 0.0] m in F_T (declared [-0.55, 0.35, 0.0]), undeclared to the filters: {after}"
        );
        assert!(out.contains(&note), "{}", text(&o));
    }
    // with the rate changed too, the fixture is judged at the changed rate as well: 0.6 m
    // off the axis is inside at 0.08 rad/s, outside at 0.12
    let world = "[world]\ngrasp_point_m = [-0.55, 0.6, 0.0]\n\n[world.target_spin_change]\nt_s = 100.0\nomega_rad_s = [-0.12, 0.0, 0.0]\n\n[mission]";
    let (o, out) = accepted_with_world(&d, world);
    assert!(
        out.contains("inside the certified envelope; with the rate changed at t = 100 s: outside the certified envelope (line_of_sight_rate)"),
        "{}",
        text(&o)
    );
    // a fixture the gripper cannot close on without touching the body: no capture
    let world = "[world]\ngrasp_point_m = [-0.47, 0.0, 0.0]\n\n[mission]";
    let (o, out) = accepted_with_world(&d, world);
    assert!(
        out.contains("NOTE: the world's fixture stands 0.020 m off the target's keep-out spheres, the gripper's spheres stick out 0.040 m beyond the grasping point: the arm–target barriers keep the gripper off it, so the run cannot capture"),
        "{}",
        text(&o)
    );
    let world = "[world]\ngrasp_point_m = [-0.55, nan, 0.0]\n\n[mission]";
    let s = shipped_with(&d, "scenario.toml", "[mission]", world);
    let o = check(&[s.to_str().unwrap()]);
    assert_invalid(&o, &s, &["`world.grasp_point_m`"]);
}

#[test]
fn a_scenario_with_a_bad_value_names_the_key_and_the_rule() {
    let d = tmp("check-bad-value");
    let s = shipped_with(&d, "scenario.toml", "mass_kg = 800.0", "mass_kg = -800.0");
    let o = check(&[s.to_str().unwrap()]);
    assert_invalid(&o, &s, &["`target.mass_kg` = -800.0", "must be"]);
}

/// A tumble beyond the certified envelope (the 0.17 rad/s, which ended with the line
/// of sight far below zero) is refused before anything runs, on one line naming the key,
/// its value and the limit (docs/SAFETY.md, "The certified envelope").
#[test]
fn a_tumble_outside_the_certified_envelope_is_refused() {
    let d = tmp("check-envelope");
    let s = shipped_with(
        &d,
        "scenario.toml",
        "initial_omega_rad_s = [-0.08, 0.0, 0.0]",
        "initial_omega_rad_s = [-0.17, 0.0, 0.0]",
    );
    let o = check(&[s.to_str().unwrap()]);
    assert_invalid(
        &o,
        &s,
        &[
            "`target.initial_omega_rad_s` = [-0.17, 0.0, 0.0]: outside the certified envelope",
            "at most 0.1241 rad/s",
        ],
    );
}

/// A bound a filter's certificate rests on, set below what the servicer model reaches in
/// the certified envelope, is refused with the value a targeted search found there
/// (issue #26 item 2).
#[test]
fn a_bound_the_model_exceeds_is_refused() {
    let d = tmp("check-bound");
    let s = shipped_with(
        &d,
        "scenario.toml",
        "angular_jerk_bound_rad_s3 = 0.35",
        "angular_jerk_bound_rad_s3 = 0.05",
    );
    let o = check(&[s.to_str().unwrap()]);
    assert_invalid(
        &o,
        &s,
        &[
            "`safety.attitude.angular_jerk_bound_rad_s3` = 0.05: not a bound",
            "the servicer model reaches 0.1",
            "the filters' certificate rests on it",
        ],
    );
}

#[test]
fn an_unknown_key_is_named() {
    let d = tmp("check-unknown-key");
    let s = shipped_with(
        &d,
        "scenario.toml",
        "duration_s = 240.0",
        "duration_s = 240.0\nduration_max_s = 300.0",
    );
    let o = check(&[s.to_str().unwrap()]);
    assert_invalid(&o, &s, &["unknown field `duration_max_s`"]);
    let p = shipped_with(
        &d,
        "partition.toml",
        "handshake_timeout_s = 30.0",
        "handshake_timeout_s = 30.0\nhandshake_retries = 3",
    );
    let o = check(&[p.to_str().unwrap()]);
    assert_invalid(&o, &p, &["unknown field `handshake_retries`"]);
}

#[test]
fn a_partition_config_naming_a_missing_scenario_is_invalid() {
    let d = tmp("check-missing-scenario");
    let p = shipped_with(
        &d,
        "partition.toml",
        "scenario = \"scenario.toml\"",
        "scenario = \"missing.toml\"",
    );
    let o = check(&[p.to_str().unwrap()]);
    assert_invalid(
        &o,
        &p,
        &[
            "scenario = \"missing.toml\": cannot read",
            "missing.toml",
            "point `scenario` at a scenario file",
        ],
    );
    // and one naming a scenario with a bad value says what is wrong in it
    let s = shipped_with(&d, "scenario.toml", "mass_kg = 800.0", "mass_kg = -800.0");
    let p = shipped_with(
        &d,
        "partition.toml",
        "scenario = \"scenario.toml\"",
        &format!("scenario = \"{}\"", s.display()),
    );
    let o = check(&[p.to_str().unwrap()]);
    assert_invalid(&o, &p, &["`target.mass_kg` = -800.0"]);
}

#[test]
fn a_missing_role_executable_names_the_role_and_the_fix() {
    let d = tmp("check-missing-exec");
    // a path that does not exist
    let p = shipped_with(
        &d,
        "partition.toml",
        "\n[roles.simulator]\n",
        "\n[roles.simulator]\nexec = \"bin/sc-simulator\"\n",
    );
    let o = check(&[p.to_str().unwrap()]);
    assert_invalid(
        &o,
        &p,
        &[
            "role `simulator`: the executable",
            "bin/sc-simulator does not exist",
            BUILD,
        ],
    );
    // a bare name found nowhere
    let p = shipped_with(
        &d,
        "partition.toml",
        "\n[roles.safety_attitude]\n",
        "\n[roles.safety_attitude]\nexec = \"sc-safety-attitude-v2\"\n",
    );
    let o = check(&[p.to_str().unwrap()]);
    assert_invalid(
        &o,
        &p,
        &[
            "role `safety_attitude`: the executable `sc-safety-attitude-v2` was found neither",
            "SC_PARTITION_BIN_DIR",
            "correct `roles.safety_attitude.exec`",
        ],
    );
    // a partner's script that is not there (its interpreter is)
    let p = shipped_with(
        &d,
        "partition.toml",
        "\n[roles.nominal_translational]\n",
        "\n[roles.nominal_translational]\nexec = \"sh\"\nargs = [\"partners/no_such_partner.sh\"]\n",
    );
    let o = check(&[p.to_str().unwrap()]);
    assert_invalid(
        &o,
        &p,
        &[
            "role `nominal_translational`: the script \"partners/no_such_partner.sh\" in `roles.nominal_translational.args`",
            "correct the path",
        ],
    );
    std::fs::create_dir_all(d.join("partners")).unwrap();
    std::fs::write(d.join("partners/no_such_partner.sh"), "").unwrap();
    let o = check(&[p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

#[test]
fn a_malformed_montecarlo_config_is_invalid() {
    let d = tmp("check-montecarlo");
    let m = shipped_with(
        &d,
        "montecarlo.toml",
        "distance_max_m = 11.0",
        "distance_max_m = 5.0",
    );
    let o = check(&[m.to_str().unwrap()]);
    assert_invalid(&o, &m, &["initial_position.distance_max_m"]);
    let m = shipped_with(
        &d,
        "montecarlo.toml",
        "rate_max_rad_s = 0.12",
        "rate_max_rad_s = ",
    );
    let o = check(&[m.to_str().unwrap()]);
    assert_invalid(&o, &m, &["parse error at line"]);
    let m = shipped_with(
        &d,
        "montecarlo.toml",
        "trace_every_steps = 5",
        "trace_every_steps = 5\ntrace_columns = 3",
    );
    let o = check(&[m.to_str().unwrap()]);
    assert_invalid(&o, &m, &["unknown field `trace_columns`"]);
}

/// Several files: each gets its line, one invalid file makes the exit code 2; a file
/// whose kind its keys do not tell asks for --kind, which then decides.
#[test]
fn every_file_gets_its_line_and_the_kind_can_be_given() {
    let d = tmp("check-several");
    let bad = shipped_with(&d, "scenario.toml", "mass_kg = 800.0", "mass_kg = -800.0");
    let o = check(&["config/montecarlo.toml", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).starts_with("config/montecarlo.toml: ok (montecarlo"),
        "{}",
        text(&o)
    );
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("`target.mass_kg` = -800.0"),
        "{}",
        text(&o)
    );
    let odd = d.join("odd.toml");
    std::fs::write(&odd, "name = \"x\"\n").unwrap();
    let o = check(&[odd.to_str().unwrap()]);
    assert_invalid(&o, &odd, &["from its keys (name); give --kind"]);
    let o = check(&["--kind", "scenario", odd.to_str().unwrap()]);
    assert_invalid(&o, &odd, &["unknown field `name`"]);
    let o = check(&["/nonexistent/partition.toml"]);
    assert_invalid(
        &o,
        Path::new("/nonexistent/partition.toml"),
        &["cannot read"],
    );
}

/// Physically implausible scenarios (issue #27, "a partner's first day") are caught before
/// anything runs, with one line each naming the key and the fix — by `check` and by `run`
/// alike: an altitude typed in km into a metre key, a control period out of proportion to
/// the dynamics, a start on the wrong side of the target, and a partition config given
/// where a scenario is expected.
#[test]
fn implausible_scenarios_are_one_line_each_from_check_and_run() {
    let d = tmp("check-implausible");
    let cases: [(&str, &str, &[&str]); 4] = [
        (
            "altitude_m = 600000.0",
            "altitude_m = 600.0",
            &["`orbit.altitude_m` = 600.0", "in metres"],
        ),
        (
            "control_period_s = 0.1 ",
            "control_period_s = 100.0 ",
            &["mission.control_period_s = 100 s", "could not follow"],
        ),
        (
            "initial_position_m = [-9.0, 0.45, -0.35]",
            "initial_position_m = [9.0, 0.45, -0.35]",
            &[
                "`servicer.initial_position_m` = [9.0, 0.45, -0.35]",
                "the start is outside the certified set",
                "approach_corridor",
            ],
        ),
        // every barrier holds, but towards the target faster than the thrusters brake:
        // the translational filter's rows cannot all hold at t = 0
        (
            "initial_velocity_m_s = [0.0, 0.004, 0.0]",
            "initial_velocity_m_s = [0.6, 0.004, 0.0]",
            &[
                "`servicer.initial_position_m/initial_velocity_m_s`",
                "the start is outside the certified set: at t = 0 the translational filter's rows cannot all hold",
            ],
        ),
    ];
    for (from, to, needles) in cases {
        let s = shipped_with(&d, "scenario.toml", from, to);
        assert_invalid(&check(&[s.to_str().unwrap()]), &s, needles);
        let out = d.join("run");
        let o = cli(
            &[
                "run",
                "--scenario",
                s.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            &[],
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{to}: {}", text(&o));
        let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
        assert_eq!(lines.len(), 1, "{to}: one line expected: {err}");
        assert!(lines[0].contains(&s.display().to_string()), "{err}");
        for n in needles {
            assert!(lines[0].contains(n), "`{n}` not in: {err}");
        }
        assert!(!out.exists(), "{to}: a refused run wrote {}", out.display());
    }
    // a partition config where a scenario is expected: named as what it is
    let p = root().join("config/partition.toml");
    let o = cli(
        &[
            "run",
            "--scenario",
            p.to_str().unwrap(),
            "--out",
            d.join("run").to_str().unwrap(),
        ],
        &[],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        err.contains(
            "a partition config, not a scenario: give it to `safe-capture launch --config FILE`"
        ),
        "{err}"
    );
    assert_eq!(
        err.lines().filter(|l| !l.trim().is_empty()).count(),
        1,
        "{err}"
    );
    let m = root().join("config/montecarlo.toml");
    let o = check(&["--kind", "scenario", m.to_str().unwrap()]);
    assert_invalid(
        &o,
        &m,
        &[
            "a Monte Carlo config, not a scenario: give it to `safe-capture montecarlo --config FILE`",
        ],
    );
}
