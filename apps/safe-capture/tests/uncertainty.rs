//! The declared uncertainty as a user meets it (docs/UNCERTAINTY.md): `exact` changes
//! nothing, a realisation is reproducible from its seed, a truth drawn outside the
//! declared bounds is said and fails the run, the partition runs a profile as `run`
//! does and refuses what it cannot run yet.

use std::path::Path;
use std::process::Output;

mod common;
use common::{cli, root, short_scenario, text, tmp};

/// Seconds simulated per run: long enough for every subsystem to act.
const DURATION_S: f64 = 8.0;

fn run(scenario: &Path, out: &Path, extra: &[&str]) -> Output {
    let (s, o) = (scenario.to_str().unwrap(), out.to_str().unwrap());
    let mut args = vec![
        "run",
        "--quiet",
        "--no-compare",
        "--no-figures",
        "--scenario",
        s,
        "--out",
        o,
    ];
    args.extend_from_slice(extra);
    cli(&args, &[])
}

fn telemetry(out: &Path) -> Vec<u8> {
    std::fs::read(out.join("telemetry.csv")).unwrap()
}

#[test]
fn the_exact_profile_is_the_run_without_a_profile() {
    let d = tmp("unc-exact");
    let s = short_scenario(&d.0, DURATION_S);
    let plain = run(&s, &d.0.join("plain"), &[]);
    let exact = run(&s, &d.0.join("exact"), &["--uncertainty", "exact"]);
    assert_eq!(plain.status.code(), exact.status.code(), "{}", text(&exact));
    assert!(
        telemetry(&d.0.join("plain")) == telemetry(&d.0.join("exact")),
        "telemetry differs under `exact`"
    );
}

#[test]
fn a_realisation_is_reproducible_from_its_seed_and_said_within_bounds() {
    let d = tmp("unc-seed");
    // the whole default mission: a safe capture exits 0
    let s = root().join("config/scenario.toml");
    let args = ["--uncertainty", "realistic", "--uncertainty-seed", "3"];
    let a = run(&s, &d.0.join("a"), &args);
    let b = run(&s, &d.0.join("b"), &args);
    assert_eq!(a.status.code(), Some(0), "{}", text(&a));
    let c = run(
        &s,
        &d.0.join("c"),
        &["--uncertainty", "realistic", "--uncertainty-seed", "4"],
    );
    let out = text(&a);
    assert!(
        out.contains("uncertainty: profile realistic (seed 3): realised plant, actuator and navigation errors within the declared bounds"),
        "{out}"
    );
    // within the bounds is not covered by the margins: the run names what is not
    assert!(
        out.contains("the filters' margins do not cover the declared [model.servicer_mass_rel,")
            && out.contains("navigation.relative_position_m")
            && !out.contains("actuators.joint_torque_bias_nm"),
        "{out}"
    );
    assert_eq!(b.status.code(), a.status.code(), "{}", text(&b));
    assert_ne!(c.status.code(), Some(2), "{}", text(&c));
    assert!(
        telemetry(&d.0.join("a")) == telemetry(&d.0.join("b")),
        "same seed, other run"
    );
    assert!(
        telemetry(&d.0.join("a")) != telemetry(&d.0.join("c")),
        "the seed changes nothing"
    );
    let exact = run(&s, &d.0.join("e"), &[]);
    assert_eq!(exact.status.code(), Some(0), "{}", text(&exact));
    assert!(
        telemetry(&d.0.join("a")) != telemetry(&d.0.join("e")),
        "`realistic` ran the exact truth"
    );
}

#[test]
fn a_truth_outside_the_declared_bounds_is_said_and_fails_the_run() {
    let d = tmp("unc-truth");
    // the whole default mission (it captures under `realistic`): exit 1 is the verdict on
    // the bounds, not a timeout
    let s = root().join("config/scenario.toml");
    let o = run(
        &s,
        &d.0.join("o"),
        &["--uncertainty", "exact", "--uncertainty-truth", "realistic"],
    );
    let out = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(out.contains("LEFT the declared bounds"), "{out}");
    assert!(out.contains("model.servicer_mass_rel"), "{out}");
}

#[test]
fn a_campaign_refuses_one_seed_for_all_its_runs() {
    let o = cli(
        &[
            "montecarlo",
            "--runs",
            "2",
            "--uncertainty",
            "realistic",
            "--uncertainty-seed",
            "3",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("--uncertainty-seed"), "{}", text(&o));
}

/// A partition config running `scenario` (the default config otherwise).
fn partition_config(dir: &Path, scenario: &Path, extra: &str) -> std::path::PathBuf {
    let cfg = std::fs::read_to_string(root().join("config/partition.toml")).unwrap();
    let cfg = cfg.replacen(
        "scenario = \"scenario.toml\"",
        &format!("scenario = {:?}", scenario.display().to_string()),
        1,
    );
    assert!(
        cfg.contains(&scenario.display().to_string()),
        "no scenario line"
    );
    let p = dir.join("partition.toml");
    std::fs::write(&p, cfg + extra).unwrap();
    p
}

fn launch(config: &Path, out: &Path) -> Output {
    let (c, o) = (config.to_str().unwrap(), out.to_str().unwrap());
    cli(&["launch", "--config", c, "--out", o], &[])
}

/// "In one process, the same": under a declared profile the partition's simulator
/// propagates the same realised plant and actuators and publishes the same estimate as
/// `run` — telemetry.csv (the truth) and navigation.csv (the errors, the barriers on
/// knowledge) are byte-identical in lock-step, and `launch` says the same about them.
#[test]
fn a_lock_step_partition_under_a_profile_is_the_run_in_one_process() {
    let d = tmp("unc-partition");
    let s = short_scenario(&d.0, DURATION_S);
    let mut text_s = std::fs::read_to_string(&s).unwrap();
    text_s.push_str("\n[uncertainty]\nprofile = \"realistic\"\nseed = 5\n");
    std::fs::write(&s, text_s).unwrap();
    let one = run(&s, &d.0.join("run"), &[]);
    let p = partition_config(&d.0, &s, "");
    let part = launch(&p, &d.0.join("launch"));
    // an unfinished short mission exits 1 in both
    assert_eq!(one.status.code(), part.status.code(), "{}", text(&part));
    for f in ["telemetry.csv", "navigation.csv"] {
        let a = std::fs::read(d.0.join("run").join(f)).unwrap();
        let b = std::fs::read(d.0.join("launch").join(f)).unwrap();
        assert!(a == b, "{f} differs between run and launch");
    }
    let line = |o: &Output| {
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .find(|l| l.starts_with("uncertainty: "))
            .map(str::to_string)
    };
    assert!(line(&one).is_some(), "{}", text(&one));
    assert_eq!(line(&one), line(&part), "{}", text(&part));
}

/// A plant process propagates the declared model: with a declared profile the
/// partition refuses it before anything starts instead of running the model as truth.
#[test]
fn the_partition_refuses_a_profile_with_a_plant_process() {
    let d = tmp("unc-partition-plant");
    let s = short_scenario(&d.0, DURATION_S);
    let mut text_s = std::fs::read_to_string(&s).unwrap();
    text_s.push_str("\n[uncertainty]\nprofile = \"realistic\"\n");
    std::fs::write(&s, text_s).unwrap();
    let p = partition_config(&d.0, &s, "\n[simulator]\nplant = [\"/bin/true\"]\n");
    let o = launch(&p, &d.0.join("o"));
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("`[simulator] plant`"), "{}", text(&o));
    assert!(!d.0.join("o").exists(), "a run was started");
}

/// `montecarlo --mode partition` under a profile: every run draws the realisation of its
/// run seed in the partition's simulator, and the campaign's runs.csv is the in-process
/// campaign's, byte for byte.
#[test]
fn a_partition_campaign_under_a_profile_is_the_campaign_in_process() {
    let d = tmp("unc-mc-partition");
    let campaign = |mode: &str, out: &str| {
        let o = d.0.join(out);
        let mut args = vec![
            "montecarlo",
            "--runs",
            "2",
            "--mode",
            mode,
            "--uncertainty",
            "realistic",
            "--out",
            o.to_str().unwrap(),
        ];
        if mode == "partition" {
            // navigation.csv is kept with the recordings only
            args.push("--keep-recordings");
        }
        let r = cli(&args, &[]);
        assert_eq!(r.status.code(), Some(0), "{}", text(&r));
        std::fs::read(o.join("runs.csv")).unwrap()
    };
    let in_process = campaign("in-process", "ip");
    let partition = campaign("partition", "p");
    assert!(in_process == partition, "runs.csv differs");
    assert!(
        d.0.join("p/runs/0/partition/navigation.csv").exists(),
        "the partition ran without the profile"
    );
}

/// Both sides: the truth's barriers in telemetry.csv, knowledge's and the realised
/// navigation errors in navigation.csv — each error within its declared bound.
#[test]
fn the_realised_errors_and_the_barriers_on_knowledge_are_recorded() {
    let d = tmp("unc-knowledge");
    let s = short_scenario(&d.0, DURATION_S);
    let o = run(
        &s,
        &d.0.join("o"),
        &["--uncertainty", "realistic", "--uncertainty-seed", "5"],
    );
    assert_ne!(o.status.code(), Some(2), "{}", text(&o));
    let nav = std::fs::read_to_string(d.0.join("o/navigation.csv")).unwrap();
    let tel = std::fs::read_to_string(d.0.join("o/telemetry.csv")).unwrap();
    let mut lines = nav.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(
        rows.len(),
        tel.lines().count() - 1,
        "a row per control step"
    );
    // realistic: bias + noise per quantity (docs/UNCERTAINTY.md)
    let bound = |name: &str| match name {
        "nav_err_relative_position_m" => 0.02,
        "nav_err_target_attitude_rad" => 0.01,
        "nav_err_joint_rate_rad_s" => 2e-4,
        _ => f64::INFINITY,
    };
    let mut seen_error = false;
    for (j, name) in header.iter().enumerate() {
        for r in &rows {
            assert!(r[j].is_finite(), "{name}");
            if name.starts_with("nav_err_") {
                assert!(r[j] <= bound(name) * (1.0 + 1e-12), "{name} = {}", r[j]);
                seen_error |= r[j] > 0.0;
            }
        }
    }
    assert!(seen_error, "no navigation error realised");
    assert!(header.contains(&"hk_line_of_sight"), "{header:?}");
    // the exact profile writes none
    let e = run(&s, &d.0.join("e"), &[]);
    assert_ne!(e.status.code(), Some(2), "{}", text(&e));
    assert!(!d.0.join("e/navigation.csv").exists());
}

/// A campaign under a profile says so — on its last line, in report.md and in
/// summary.json — and every run's realisation is saved to be rerun.
#[test]
fn a_campaign_under_a_profile_says_so() {
    let d = tmp("unc-mc");
    let out = d.0.join("o");
    let o = cli(
        &[
            "montecarlo",
            "--runs",
            "3",
            "--uncertainty",
            "realistic",
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert_ne!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("(seed 1, uncertainty realistic: safe on the simulated truth)"),
        "{}",
        text(&o)
    );
    assert!(
        text(&o).contains("montecarlo: the filters' margins do not cover the declared [model."),
        "{}",
        text(&o)
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("Declared uncertainty: profile `realistic`")
            && report.contains("The filters' margins do not cover the declared model."),
        "{report}"
    );
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(
        summary.contains("\"uncertainty\": \"realistic\""),
        "{summary}"
    );
    let run = std::fs::read_to_string(out.join("runs/0/scenario.toml")).unwrap();
    assert!(
        run.contains("[uncertainty]") && run.contains("profile = \"realistic\""),
        "{run}"
    );
}

/// A red team under a profile says so on its last line and in its report.
#[test]
fn a_red_team_under_a_profile_says_so() {
    let d = tmp("unc-rt");
    let out = d.0.join("o");
    let o = cli(
        &[
            "redteam",
            "--uncertainty",
            "realistic",
            "--uncertainty-seed",
            "1",
            "--cases",
            "robotic/frozen",
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert_ne!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("redteam (uncertainty realistic, seed 1): ")
            && text(&o).contains("redteam: The filters' margins do not cover the declared model."),
        "{}",
        text(&o)
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("declared uncertainty profile `realistic` (seed 1")
            && report.contains("The filters' margins do not cover the declared model."),
        "{report}"
    );
}

/// Errors at the edge of their bounds are not reported as outside them: noise only (no
/// bias), and a measurement one whole control period old.
#[test]
fn errors_at_the_edge_of_their_bounds_are_within_them() {
    let d = tmp("unc-edge");
    let text_p = std::fs::read_to_string(root().join("config/uncertainty/realistic.toml")).unwrap();
    let mut edge = String::new();
    for line in text_p.lines() {
        let l = if line.contains("{ bias =") {
            let (key, rest) = line.split_once('=').unwrap();
            let noise = rest
                .split("noise =")
                .nth(1)
                .unwrap()
                .trim_matches([' ', '}']);
            format!("{key}= {{ bias = 0.0, noise = {noise} }}")
        } else if line.starts_with("measurement_age_s") {
            "measurement_age_s = 0.1".to_string()
        } else {
            line.to_string()
        };
        edge.push_str(&l);
        edge.push('\n');
    }
    assert!(
        edge.contains("joint_angle_rad = { bias = 0.0, noise = 1e-4 }"),
        "{edge}"
    );
    let p = d.0.join("edge.toml");
    std::fs::write(&p, edge).unwrap();
    let s = root().join("config/scenario.toml");
    for seed in ["1", "2"] {
        let o = run(
            &s,
            &d.0.join(seed),
            &[
                "--uncertainty",
                p.to_str().unwrap(),
                "--uncertainty-seed",
                seed,
            ],
        );
        assert!(
            text(&o).contains("errors within the declared bounds"),
            "{}",
            text(&o)
        );
    }
}

#[test]
fn campaigns_and_basilisk_refuse_what_they_cannot_check() {
    for args in [
        &[
            "montecarlo",
            "--runs",
            "1",
            "--uncertainty",
            "exact",
            "--uncertainty-truth",
            "realistic",
        ][..],
        &[
            "redteam",
            "--cases",
            "robotic/frozen",
            "--uncertainty",
            "exact",
            "--uncertainty-truth",
            "realistic",
        ][..],
    ] {
        let o = cli(args, &[]);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o));
        assert!(text(&o).contains("--uncertainty-truth"), "{}", text(&o));
    }
    let o = cli(&["run", "--basilisk", "--uncertainty", "realistic"], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("--basilisk"), "{}", text(&o));
}

/// The partition's processes read the scenario file: `redteam --partition` refuses a
/// command-line profile the file does not declare (it would be reported, not run).
#[test]
fn a_partition_red_team_refuses_a_profile_the_file_does_not_declare() {
    let d = tmp("unc-rt-partition");
    let o = cli(
        &[
            "redteam",
            "--partition",
            "--uncertainty",
            "realistic",
            "--out",
            d.0.join("o").to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("--partition"), "{}", text(&o));
    assert!(!d.0.join("o").exists(), "a case was started");
}

/// Plant mismatch through the partition, not declared: the filters are told `exact`
/// while the partition's simulator propagates a plant drawn from `realistic`
/// (`[uncertainty.truth]`: other masses, inertias and CoM, actuator and navigation
/// errors). `launch` says the realised errors left the declared bounds, naming them, and
/// exits 1 — never silently; the navigation's estimates, beyond the declared bounds, are
/// refused and flagged.
#[test]
fn an_undeclared_plant_mismatch_through_the_partition_is_said() {
    let d = tmp("unc-partition-truth");
    let s = short_scenario(&d.0, DURATION_S);
    let realistic =
        std::fs::read_to_string(root().join("config/uncertainty/realistic.toml")).unwrap();
    let truth: String = realistic
        .lines()
        .map(|l| match l.trim() {
            "[model]" | "[actuators]" | "[navigation]" => {
                format!("[uncertainty.truth.{}]\n", &l.trim()[1..l.trim().len() - 1])
            }
            _ => format!("{l}\n"),
        })
        .collect();
    let mut text_s = std::fs::read_to_string(&s).unwrap();
    text_s.push_str("\n[uncertainty]\nprofile = \"exact\"\nseed = 5\n\n");
    text_s.push_str(&truth);
    std::fs::write(&s, text_s).unwrap();
    let p = partition_config(&d.0, &s, "");
    let o = launch(&p, &d.0.join("launch"));
    let out = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(out.contains("LEFT the declared bounds"), "{out}");
    assert!(out.contains("model.link_mass_rel"), "{out}");
    assert!(
        out.contains("partition: timeout at t = 8.0 s"),
        "the run went through: {out}"
    );
    // the navigation's errors drawn from `realistic` are beyond `exact`'s zero bounds: the
    // simulator's gate refuses them and the filters get the measurement, flagged
    let summary = std::fs::read_to_string(d.0.join("launch/summary.json")).unwrap();
    assert!(summary.contains("NAVIGATION_REJECTED"), "{summary}");
}
