//! Basilisk in the loop (`safe-capture run --basilisk`): the default mission with
//! Basilisk propagating the true state against the same mission on our simulator.
//! Over the first 60 s the Hill position, the base attitude and the joint angles agree
//! to 1e-6 (m, rad), the outcome is the same, and every barrier holds. Through the
//! partition (config/partition_basilisk.toml) the result is the same byte for byte.
//!
//! Needs a Python with Basilisk (`scripts/setup.sh --with-basilisk`, which
//! scripts/test.sh runs): `SC_PYTHON`, else scripts/.venv/bin/python. Where Basilisk is
//! not installed the test is skipped with the reason printed — unless
//! `SC_REQUIRE_BASILISK` is set (scripts/test.sh sets it), then it fails.

mod common;
use common::*;
use std::path::{Path, PathBuf};

fn python_with_basilisk() -> Option<PathBuf> {
    let py = std::env::var_os("SC_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("scripts/.venv/bin/python"));
    let ok = std::process::Command::new(&py)
        .args(["-c", "import Basilisk"])
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if ok {
        return Some(py);
    }
    assert!(
        std::env::var_os("SC_REQUIRE_BASILISK").is_none(),
        "SC_REQUIRE_BASILISK is set but {} cannot import Basilisk",
        py.display()
    );
    eprintln!(
        "SKIPPED: {} cannot import Basilisk (run scripts/setup.sh --with-basilisk)",
        py.display()
    );
    None
}

/// (t, Hill position, q_RB, joint angles) per control step of a run's telemetry.
type Row = (f64, [f64; 3], [f64; 4], [f64; 7]);

fn telemetry(dir: &Path) -> Vec<Row> {
    let text = std::fs::read_to_string(dir.join("telemetry.csv")).unwrap();
    let mut lines = text.lines();
    let cols: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = |n: &str| {
        cols.iter()
            .position(|c| *c == n)
            .unwrap_or_else(|| panic!("{n}"))
    };
    let (t, rh, q, th) = (k("t_s"), k("r_h_x_m"), k("q0_rb"), k("theta_1_rad"));
    lines
        .map(|l| {
            let v: Vec<f64> = l
                .split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect();
            (
                v[t],
                std::array::from_fn(|i| v[rh + i]),
                std::array::from_fn(|i| v[q + i]),
                std::array::from_fn(|i| v[th + i]),
            )
        })
        .collect()
}

/// Angle of the rotation between two unit quaternions [rad], accurate when small.
fn angle(p: &[f64; 4], r: &[f64; 4]) -> f64 {
    let w = p.iter().zip(r).map(|(a, b)| a * b).sum::<f64>();
    let x = p[0] * r[1] - p[1] * r[0] - p[2] * r[3] + p[3] * r[2];
    let y = p[0] * r[2] + p[1] * r[3] - p[2] * r[0] - p[3] * r[1];
    let z = p[0] * r[3] - p[1] * r[2] + p[2] * r[1] - p[3] * r[0];
    2.0 * (x * x + y * y + z * z).sqrt().atan2(w.abs())
}

#[test]
fn the_mission_with_basilisk_as_the_plant_matches_ours() {
    let Some(py) = python_with_basilisk() else {
        return;
    };
    let d = tmp("basilisk");
    let (ours, theirs) = (d.join("ours"), d.join("basilisk"));
    let o = cli(
        &[
            "run",
            "--no-compare",
            "--no-figures",
            "-q",
            "--out",
            ours.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    let o = cli(
        &[
            "run",
            "--basilisk",
            "--python",
            py.to_str().unwrap(),
            "--no-figures",
            "-q",
            "--out",
            theirs.to_str().unwrap(),
        ],
        &[],
    );
    // captured, every barrier ≥ 0 at every physics step of Basilisk's state, no fault
    assert!(o.status.success(), "{}", text(&o));
    let (s_ours, s_theirs) = (
        json(&ours.join("summary.json")),
        json(&theirs.join("summary.json")),
    );
    assert_eq!(s_theirs["end"], s_ours["end"]);
    assert_eq!(s_theirs["capture_time_s"], s_ours["capture_time_s"]);
    let (a, b) = (telemetry(&ours), telemetry(&theirs));
    assert_eq!(a.len(), b.len());
    let (mut dp, mut dq, mut dj) = (0.0f64, 0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(&b).take_while(|(x, _)| x.0 <= 60.0) {
        assert_eq!(x.0, y.0);
        let p = (0..3)
            .map(|i| (x.1[i] - y.1[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        dp = dp.max(p);
        dq = dq.max(angle(&x.2, &y.2));
        dj = (0..7).fold(dj, |m, i| m.max((x.3[i] - y.3[i]).abs()));
    }
    eprintln!("first 60 s: Hill position {dp:.2e} m, attitude {dq:.2e} rad, joints {dj:.2e} rad");
    assert!(dp <= 1e-6 && dq <= 1e-6 && dj <= 1e-6, "{dp} {dq} {dj}");
    // `compare` says the same, and fails a tolerance the runs do not meet
    let (sa, sb) = (ours.to_str().unwrap(), theirs.to_str().unwrap());
    let o = cli(&["compare", sa, sb, "--tolerance", "1e-6"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("compare: first 60.0 s (601 steps)"),
        "{}",
        text(&o)
    );
    for f in ["compare.csv", "compare.json", "compare.svg"] {
        assert!(theirs.join("compare").join(f).is_file(), "{f}");
    }
    let o = cli(&["compare", sa, sb, "--tolerance", "1e-12"], &[]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));

    // the same through the partition, Basilisk behind the simulator role
    // (config/partition_basilisk.toml, with this interpreter): lock-step gives the
    // in-process result byte for byte, and nothing is left in shared memory
    let _cpu = exclusive();
    let text_cfg = std::fs::read_to_string(root().join("config/partition_basilisk.toml"))
        .unwrap()
        .replace(
            "scenario = \"scenario.toml\"",
            &format!(
                "scenario = \"{}\"",
                root().join("config/scenario.toml").display()
            ),
        )
        .replace(
            "plant = [\"../scripts/.venv/bin/python\", \"../scripts/basilisk_plant.py\"]",
            &format!(
                "plant = [\"{}\", \"{}\"]",
                py.display(),
                root().join("scripts/basilisk_plant.py").display()
            ),
        );
    assert!(
        text_cfg.contains(&format!("plant = [\"{}\"", py.display())),
        "config/partition_basilisk.toml: plant line not as expected"
    );
    let cfg = d.join("partition_basilisk.toml");
    std::fs::write(&cfg, text_cfg).unwrap();
    let part = d.join("partition");
    let (o, _) = cli_partition(
        &[
            "launch",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            part.to_str().unwrap(),
        ],
        &[],
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(
        t.contains("captured") && t.contains("shm leftovers: 0"),
        "{t}"
    );
    let log = std::fs::read_to_string(part.join("logs/simulator.log")).unwrap();
    assert!(log.contains("basilisk_plant.py` propagates"), "{log}");
    assert!(
        std::fs::read(part.join("telemetry.csv")).unwrap()
            == std::fs::read(theirs.join("telemetry.csv")).unwrap(),
        "the partition's telemetry differs from run --basilisk"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A plant that does not speak the protocol ends the run with one line naming it, and no
/// panic: here `cat`, which refuses the script's arguments and exits.
#[test]
fn a_plant_that_does_not_answer_is_named() {
    let d = tmp("basilisk-bad");
    let o = cli(
        &[
            "run",
            "--basilisk",
            "--python",
            "cat",
            "--no-figures",
            "-q",
            "--out",
            d.join("out").to_str().unwrap(),
        ],
        &[],
    );
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert_ne!(o.status.code(), Some(101), "panicked: {t}");
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("error: plant `cat "), "{t}");
    let o = cli(
        &[
            "run",
            "--basilisk",
            "--python",
            "/no/such/python",
            "-q",
            "--out",
            d.join("out2").to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("cannot start the plant"), "{}", text(&o));
    let _ = std::fs::remove_dir_all(&d);
}
