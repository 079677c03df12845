//! A partner's navigation process (the SDK's `sc_partner.Navigation`, Python) in the
//! partition's `navigation` role:
//! - the worked example (the measurement as the estimate) runs the mission, and the
//!   lock-step telemetry is the in-process run's byte for byte;
//! - a hostile navigation (`scripts/python/hostile_navigation.py`: non-finite, jumping,
//!   stale, mislabelled, non-unit or missing estimates) is refused from the tick it
//!   starts: every such tick is flagged `NAVIGATION_REJECTED` in the summary, the
//!   simulator logs why, and what the filters saw is the simulator's own navigation —
//!   the telemetry is that of the run in one process whose navigation is never
//!   refused (exact), or whose refused estimates are the same (realistic).
//!
//! The interpreter is `SC_PYTHON` (scripts/test.sh), else scripts/.venv/bin/python;
//! without either the tests are skipped with the reason printed.

mod common;
use common::*;
use sc_mission::{Mission, RunOptions, Setup, TelemetryWriter};
use sc_sim::{Estimator, NavSample};
use std::path::{Path, PathBuf};

/// Simulated seconds of the hostile runs, and the first tick attacked.
const HOSTILE_DURATION_S: f64 = 4.0;
const FROM_TICK: u64 = 12;
/// Simulated seconds of the worked example's run.
const EXAMPLE_DURATION_S: f64 = 15.0;

/// telemetry.csv and navigation.csv (if any) of the run in one process of the scenario
/// in `dir`, with `navigation` in place of the default one if given.
fn in_process(dir: &Path, navigation: Option<Box<dyn Estimator + Send>>) -> (Vec<u8>, Vec<u8>) {
    let setup = Setup::load(&dir.join("scenario.toml")).unwrap();
    let (mut tel, mut tim, mut records) = (Vec::new(), Vec::new(), Vec::new());
    {
        let mut w = TelemetryWriter::new(&mut tel, &mut tim).unwrap();
        let mut m = Mission::new(setup, RunOptions::default()).unwrap();
        if let Some(n) = navigation {
            m.set_navigation(n);
        }
        m.run(|_, r| {
            w.write(r).unwrap();
            records.push(*r);
        });
        w.flush().unwrap();
    }
    let nav = dir.join("in_process_navigation.csv");
    sc_mission::record::write_knowledge(&nav, &records).unwrap();
    (tel, std::fs::read(&nav).unwrap_or_default())
}

/// Launches the partition of `config` with `args` (a Python script and its options) in
/// the navigation role; returns the output folder.
fn launch_with_navigation(
    py: &Path,
    config: &Path,
    dir: &Path,
    tag: &str,
    args: &[String],
) -> PathBuf {
    let out = dir.join(tag);
    let mut opts = options(config, &out, tag);
    opts.role_override
        .push(("navigation".into(), py.display().to_string(), args.to_vec()));
    let rep = sc_ground::launch(&opts).unwrap();
    assert_clean(&rep, &out);
    out
}

fn script(name: &str) -> String {
    repo()
        .join("scripts/python")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn python_navigation_runs_the_mission_as_the_rust_one() {
    let Some(py) = python() else {
        return;
    };
    let dir = scratch("pynav");
    let config = write_config(&dir, Some(EXAMPLE_DURATION_S), None, 20.0);
    let out = launch_with_navigation(&py, &config, &dir, "example", &[script("navigation.py")]);
    assert_no_lost_wakeups(&out);
    let (tel, _) = in_process(&dir, None);
    let part = std::fs::read(out.join("telemetry.csv")).unwrap();
    let s = summary(&out);
    if part != tel {
        let (a, b) = (
            String::from_utf8_lossy(&part),
            String::from_utf8_lossy(&tel),
        );
        let d = a.lines().zip(b.lines()).position(|(x, y)| x != y);
        panic!(
            "telemetry.csv differs from the in-process run from line {d:?} ({} vs {} lines); faults {}",
            a.lines().count(),
            b.lines().count(),
            s["faults"]
        );
    }
    assert_eq!(s["fault_count"], 0, "{s}");
    let log = std::fs::read_to_string(out.join("logs/navigation.log")).unwrap();
    assert!(
        log.contains("navigation.py: handled") && log.contains("(0 without a valid estimate)"),
        "{log}"
    );
    let eff = std::fs::read_to_string(out.join("partition.effective.toml")).unwrap();
    assert!(eff.contains("navigation.py"), "{eff}");
    offline_harness_replays_the_recorded_measurements(&py, &dir, &out, &config);
}

/// The offline harness runs a navigation on the measurements the run recorded: the
/// example gives the recorded estimates exactly; a navigation 0.25 m off in r_i[2] from
/// tick 5 on differs by that, and says where.
fn offline_harness_replays_the_recorded_measurements(
    py: &Path,
    dir: &Path,
    out: &Path,
    config: &Path,
) {
    let harness = |spec: &str, extra: &[&str]| {
        let o = std::process::Command::new(py)
            .args(["-m", "sc_partner.harness", spec, "--mcap"])
            .arg(out.join("recording.mcap"))
            .arg("--config")
            .arg(config)
            .args(extra)
            .env("PYTHONPATH", repo().join("scripts/python"))
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .output()
            .unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        (o.status.code(), text)
    };
    let steps = contiguous_steps(out);
    let estimates = dir.join("estimates.csv");
    let (code, text) = harness(
        "sc_partner.examples.navigation",
        &["--out", estimates.to_str().unwrap(), "--strict"],
    );
    assert_eq!(code, Some(0), "{text}");
    let want = format!(
        "on {steps} measurements: {steps} estimates, 0 without one -> {}; largest difference to the recorded estimate: 0\n",
        estimates.display()
    );
    assert!(text.contains(&want), "{text}");
    let rows = std::fs::read_to_string(&estimates).unwrap().lines().count();
    assert_eq!(rows, steps + 1, "a header and an estimate per measurement");
    let off = dir.join("off.py");
    std::fs::write(
        &off,
        "from sc_partner import Navigation\n\n\
         class Off(Navigation):\n    def estimate(self, m):\n        e = m.estimate()\n        \
         if m.tick >= 5:\n            e.r_i[2] += 0.25\n        return e\n",
    )
    .unwrap();
    let (code, text) = harness(off.to_str().unwrap(), &[]);
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.contains("largest difference to the recorded estimate: 0.25 (tick 5, r_i_2;"),
        "{text}"
    );
}

/// The steps a summary flags `NAVIGATION_REJECTED` (by `navigation`).
fn rejected_steps(s: &serde_json::Value) -> Vec<u64> {
    s["faults"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["filter"] == "navigation")
        .inspect(|e| {
            assert_eq!(
                e["flags"],
                serde_json::json!(["NAVIGATION_REJECTED"]),
                "{e}"
            )
        })
        .map(|e| e["step"].as_u64().unwrap())
        .collect()
}

#[test]
fn a_hostile_navigation_is_refused_flagged_and_never_reaches_the_filters() {
    let Some(py) = python() else {
        return;
    };
    let dir = scratch("pynav-hostile");
    let config = write_config(&dir, Some(HOSTILE_DURATION_S), None, 20.0);
    let (tel, _) = in_process(&dir, None);
    // strategy, what the simulator's log says about the first refused tick
    let cases = [
        ("nan", "not finite"),
        (
            "jump:1",
            "relative_position_m 1e0 farther from the measurement",
        ),
        ("stale:3", "relative_position_m"),
        (
            "old_tick",
            &format!("not current: it answers tick {}", FROM_TICK - 1),
        ),
        ("nonunit", "a quaternion off the unit sphere"),
        ("silent", "missing at the navigation deadline"),
    ];
    for (k, (strategy, why)) in cases.iter().enumerate() {
        let args = [
            script("hostile_navigation.py"),
            "--strategy".into(),
            strategy.to_string(),
            "--from-tick".into(),
            FROM_TICK.to_string(),
        ];
        let out = launch_with_navigation(&py, &config, &dir, &format!("h{k}"), &args);
        let s = summary(&out);
        let steps = contiguous_steps(&out) as u64;
        assert!(steps > FROM_TICK + 10, "{strategy}: {steps} steps");
        let want: Vec<u64> = (FROM_TICK..steps).collect();
        assert_eq!(rejected_steps(&s), want, "{strategy}: {s}");
        assert!(
            s["violated_constraints"].as_array().unwrap().is_empty(),
            "{strategy}: {s}"
        );
        let log = std::fs::read_to_string(out.join("logs/simulator.log")).unwrap();
        let first = format!("FAULT tick {FROM_TICK}: navigation estimate ");
        assert!(
            log.lines().any(|l| l.contains(&first) && l.contains(why)),
            "{strategy}: {log}"
        );
        let before = format!("FAULT tick {}: ", FROM_TICK - 1);
        assert!(
            !log.contains(&before),
            "{strategy}: refused before it attacked: {log}"
        );
        // exact: the substitute is the measurement, so the filters saw what they would
        // have seen without the hostile navigation
        let part = std::fs::read(out.join("telemetry.csv")).unwrap();
        assert!(
            part == tel,
            "{strategy}: a refused estimate changed the run"
        );
    }
}

/// The hostile navigation's `jump:1` in Rust, for the run in one process.
struct Jump;

impl Estimator for Jump {
    fn estimate(&mut self, m: &NavSample) -> NavSample {
        let mut e = *m;
        if e.tick >= FROM_TICK {
            e.state.dr[0] += 1.0;
        }
        e
    }
}

/// Under a declared profile the substitute is the simulator's own declared-error
/// navigation: the partition with the hostile process is the run in one process with
/// the same hostile estimator, byte for byte — the refusal and the substitute are one
/// code path.
#[test]
fn under_a_profile_a_refused_estimate_is_replaced_as_in_one_process() {
    let Some(py) = python() else {
        return;
    };
    let dir = scratch("pynav-profile");
    let config = write_config(&dir, Some(HOSTILE_DURATION_S), None, 20.0);
    let scenario = dir.join("scenario.toml");
    let mut text = std::fs::read_to_string(&scenario).unwrap();
    text.push_str("\n[uncertainty]\nprofile = \"realistic\"\nseed = 11\n");
    std::fs::write(&scenario, text).unwrap();
    let (tel, nav) = in_process(&dir, Some(Box::new(Jump)));
    assert!(!nav.is_empty(), "no navigation.csv in one process");
    let args = [
        script("hostile_navigation.py"),
        "--strategy".into(),
        "jump:1".into(),
        "--from-tick".into(),
        FROM_TICK.to_string(),
    ];
    let out = launch_with_navigation(&py, &config, &dir, "jump", &args);
    let s = summary(&out);
    let steps = contiguous_steps(&out) as u64;
    assert_eq!(
        rejected_steps(&s),
        (FROM_TICK..steps).collect::<Vec<_>>(),
        "{s}"
    );
    assert!(
        s["violated_constraints"].as_array().unwrap().is_empty(),
        "{s}"
    );
    assert!(
        std::fs::read(out.join("telemetry.csv")).unwrap() == tel,
        "telemetry.csv differs"
    );
    assert!(
        std::fs::read(out.join("navigation.csv")).unwrap() == nav,
        "navigation.csv differs"
    );
}
