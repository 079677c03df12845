//! The flight executables carry nothing a flight processor would not: no plotting, no
//! campaign runner, no MCAP writer, no thread pool, no progress bars (issue #24; the
//! ground tools are the safe-capture package's).

/// Crates no flight executable may link.
const GROUND_ONLY: [&str; 6] = ["plotters", "resvg", "svg2pdf", "rayon", "indicatif", "mcap"];

#[test]
fn flight_executables_link_no_ground_crate() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = std::process::Command::new(env!("CARGO"))
        .current_dir(&root)
        .args([
            "tree",
            "--offline",
            "-e",
            "normal",
            "-p",
            "sc-partition-apps",
        ])
        .args(["--prefix", "none", "--format", "{p}"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tree = String::from_utf8(out.stdout).unwrap();
    let names: Vec<&str> = tree
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(
        names.contains(&"sc-flight"),
        "the tree is the flight package's: {tree}"
    );
    let found: Vec<&&str> = GROUND_ONLY.iter().filter(|c| names.contains(c)).collect();
    assert!(found.is_empty(), "the flight executables link {found:?}");
}
