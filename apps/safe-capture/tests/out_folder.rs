//! The output-folder policy as every command that writes a folder applies it (issue
//! #16): a non-empty folder safe-capture did not write is refused unless --force, one of
//! ours is replaced as a whole, and nothing of a refused or failed run is mixed in.

mod common;
use common::*;
use std::path::Path;

/// The marker file of a folder written by safe-capture.
const MARKER: &str = ".safe-capture";

/// A mission short enough for a quick run [s].
const SHORT_MISSION_S: f64 = 2.0;

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A folder with a file of the user's in it.
fn foreign_folder(parent: &Path) -> std::path::PathBuf {
    let f = parent.join("theirs");
    std::fs::create_dir_all(&f).unwrap();
    std::fs::write(f.join("notes.txt"), "mine\n").unwrap();
    f
}

/// Every command that writes a folder refuses one that is not empty and not ours: exit 2,
/// one line naming the folder and the fix, nothing written into it or beside it.
#[test]
fn every_command_refuses_a_folder_not_ours_and_writes_nothing() {
    let d = tmp("out-refused");
    let sc = short_scenario(&d, SHORT_MISSION_S);
    let sc = sc.to_str().unwrap();
    let cfg = d.join("partition.toml");
    std::fs::write(&cfg, partition_toml_absolute_scenario()).unwrap();
    let cfg = cfg.to_str().unwrap();
    let parent = d.join("p");
    let theirs = foreign_folder(&parent);
    let f = theirs.to_str().unwrap();
    // a campaign and a run to rerun, merge and compare
    let campaign = d.join("c");
    let c = campaign.to_str().unwrap();
    let o = cli(
        &[
            "montecarlo",
            "--runs",
            "1",
            "-q",
            "--scenario",
            sc,
            "--out",
            c,
        ],
        &[],
    );
    assert!(campaign.join("summary.json").is_file(), "{}", text(&o));
    let run = d.join("r");
    let o = cli(
        &[
            "run",
            "-q",
            "--no-compare",
            "--no-figures",
            "--scenario",
            sc,
            "--out",
            run.to_str().unwrap(),
        ],
        &[],
    );
    assert!(run.join("telemetry.csv").is_file(), "{}", text(&o));
    let r = run.to_str().unwrap();
    let commands: [&[&str]; 8] = [
        &["run", "--scenario", sc],
        &["launch", "--config", cfg],
        &["bench", "latency", "--ticks", "1", "--config", cfg],
        &["montecarlo", "--runs", "1", "--scenario", sc],
        &["montecarlo", "merge", c],
        &["montecarlo", "rerun", c, "--run", "0"],
        &["redteam", "--scenario", sc, "--cases", "robotic/frozen"],
        &["compare", r, r],
    ];
    for args in commands {
        let mut a = args.to_vec();
        a.extend(["--out", f]);
        let (o, _) = cli_partition(&a, &[]);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{a:?}: {t}");
        assert!(o.stdout.is_empty(), "{a:?}: {t}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{a:?}: {t}");
        assert!(
            err.contains(&format!(
                "{f} is not empty and was not written by safe-capture"
            )) && err.contains("--force"),
            "{a:?}: {t}"
        );
        assert_eq!(names(&theirs), ["notes.txt"], "{a:?}");
        assert_eq!(
            names(&parent),
            ["theirs"],
            "{a:?}: something written beside it"
        );
    }
    // a file is no folder, forced or not
    let file = theirs.join("notes.txt");
    for force in [&[][..], &["--force"]] {
        let o = cli(
            &[
                &["run", "--scenario", sc, "--out", file.to_str().unwrap()][..],
                force,
            ]
            .concat(),
            &[],
        );
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        assert!(text(&o).contains("is not a folder"), "{}", text(&o));
    }
    assert_eq!(names(&parent), ["theirs"]);
}

/// --force replaces a folder that is not ours, as a whole, and marks it ours — after
/// saying on stderr what it held (issue #27: it deleted a user's files without a word).
#[test]
fn force_replaces_a_folder_not_ours() {
    let d = tmp("out-force");
    let sc = short_scenario(&d, SHORT_MISSION_S);
    let theirs = foreign_folder(&d.join("p"));
    let o = cli(
        &[
            "run",
            "-q",
            "--no-figures",
            "--force",
            "--scenario",
            sc.to_str().unwrap(),
            "--out",
            theirs.to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(
        o.status.code(),
        Some(1),
        "short missions do not capture: {}",
        text(&o)
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!(
            "run: --force: {} was not written by safe-capture; it is replaced when the command finishes, with its 1 entry: notes.txt",
            theirs.display()
        )),
        "{err}"
    );
    let n = names(&theirs);
    assert!(!n.contains(&"notes.txt".into()), "{n:?}");
    assert!(
        n.contains(&MARKER.into()) && n.contains(&"summary.json".into()),
        "{n:?}"
    );
    let marker = json(&theirs.join(MARKER));
    assert_eq!(marker["command"], "run", "{marker}");
    assert_eq!(names(&d.join("p")), ["theirs"]);
}

/// A folder of ours is replaced as a whole: `run --no-filter` after a run with its
/// nominal comparison leaves no stale nominal/ (issue #16).
#[test]
fn a_folder_of_ours_is_replaced_without_stale_files() {
    let d = tmp("out-replaced");
    let sc = short_scenario(&d, SHORT_MISSION_S);
    let out = d.join("run");
    let run = |extra: &[&str]| {
        let o = cli(
            &[
                &["run", "-q", "--scenario", sc.to_str().unwrap(), "--out"][..],
                &[out.to_str().unwrap()],
                extra,
            ]
            .concat(),
            &[],
        );
        assert_eq!(o.status.code(), Some(1), "{}", text(&o));
        o
    };
    run(&[]);
    assert!(out.join("nominal/summary.json").is_file());
    let o = run(&["--no-filter"]);
    assert!(
        !out.join("nominal").exists(),
        "stale nominal/: {:?}",
        names(&out)
    );
    assert!(
        String::from_utf8_lossy(&o.stdout).starts_with("nominal only:"),
        "{}",
        text(&o)
    );
    assert_eq!(json(&out.join("summary.json"))["filtered"], false);
    assert_eq!(
        names(&d),
        ["run", "scenario.toml"],
        "no staging folder left"
    );
}

/// A run that fails after its folder was staged leaves the earlier output as it was and
/// nothing beside it when it wrote nothing (here: Basilisk's interpreter is missing).
#[test]
fn a_run_that_fails_leaves_the_earlier_output_unchanged() {
    let d = tmp("out-failed");
    let sc = short_scenario(&d, SHORT_MISSION_S);
    let out = d.join("run");
    let args = [
        "run",
        "-q",
        "--no-figures",
        "--scenario",
        sc.to_str().unwrap(),
    ];
    let o = cli(
        &[&args[..], &["--out", out.to_str().unwrap()]].concat(),
        &[],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let before = std::fs::read(out.join("telemetry.csv")).unwrap();
    let o = cli(
        &[
            &args[..],
            &[
                "--basilisk",
                "--python",
                "/nonexistent/python",
                "--out",
                out.to_str().unwrap(),
            ],
        ]
        .concat(),
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert_eq!(std::fs::read(out.join("telemetry.csv")).unwrap(), before);
    assert_eq!(names(&d), ["run", "scenario.toml"], "{}", text(&o));
}

/// A campaign quit at once (second signal) or killed stays in OUT.incomplete: an empty or
/// absent OUT takes it over (`a_killed_campaign_resumes_from_its_staging_folder`,
/// tests/montecarlo.rs); an OUT holding something else is left alone and `--resume --out
/// OUT` names the staging folder and the command that resumes it.
#[test]
fn resume_names_a_campaign_left_in_its_staging_folder() {
    let d = tmp("out-resume");
    let staging = d.join("c.incomplete");
    std::fs::create_dir_all(&staging).unwrap();
    std::fs::write(staging.join("campaign.json"), "{}").unwrap();
    let out = d.join("c");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let o = cli(
        &["montecarlo", "--resume", "--out", out.to_str().unwrap()],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains(&format!("--resume --out {}", staging.display())),
        "{err}"
    );
    assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine");
    assert!(staging.join("campaign.json").is_file());
}
