//! `safe-capture launch` as a user meets it around the partition's output folder.

mod common;
use common::*;

/// A launch that fails at start into the folder of an earlier run reports no summary
/// instead of the old run's, and removes only what a run writes (issue #16).
#[test]
fn a_failed_launch_never_reports_an_old_run() {
    let d = tmp("stale-launch");
    let cfg = std::fs::read_to_string(root().join("config/partition.toml"))
        .unwrap()
        .replace(
            "scenario = \"scenario.toml\"",
            &format!(
                "scenario = \"{}\"",
                root().join("config/scenario.toml").display()
            ),
        )
        .replace(
            "exec = \"sc-simulator\"",
            "exec = \"/no/such/sc-simulator\"",
        );
    assert!(cfg.contains("/no/such/sc-simulator"));
    std::fs::write(d.join("partition.toml"), cfg).unwrap();
    let out = d.join("out");
    std::fs::create_dir_all(out.join("logs")).unwrap();
    std::fs::write(
        out.join("summary.json"),
        r#"{"end": "captured", "final_time_s": 99.0}"#,
    )
    .unwrap();
    std::fs::write(out.join("logs/simulator.log"), "an old run's log\n").unwrap();
    std::fs::write(out.join("notes.txt"), "mine\n").unwrap();
    let (o, _) = cli_partition(
        &[
            "launch",
            "--config",
            d.join("partition.toml").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("no summary") && !t.contains("captured"), "{t}");
    assert!(!out.join("summary.json").exists());
    assert_ne!(
        std::fs::read_to_string(out.join("logs/simulator.log")).unwrap_or_default(),
        "an old run's log\n"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine\n"
    );
    let _ = std::fs::remove_dir_all(&d);
}
