//! The partition in lock-step: bit-identical to the in-process run, multi-rate to
//! capture, schedule validation.

mod common;
use common::*;
use sc_mission::{Mission, RunOptions, Setup, TelemetryWriter, summarize};

/// telemetry.csv and summary.json (except solve times) of the partition equal the
/// in-process run's byte for byte (full default mission).
#[test]
fn lock_step_telemetry_is_identical_to_in_process_run() {
    let dir = tmp("ident");
    let out = dir.join("out");
    let config = repo().join("config/partition.toml");
    let rep = sc_ground::launch(&options(&config, &out, "ident")).unwrap();
    assert_eq!(rep.code, 0, "{rep:?}");
    assert_clean(&rep, &out);
    assert_no_lost_wakeups(&out);

    let b = assert_as_in_process(&repo().join("config/scenario.toml"), &out);
    assert_eq!(b["end"], "captured");
    // MCAP and counts; the MCAP's log time is mission time (Foxglove's timeline shows the
    // mission, not the host's uptime), the host's clock stays in publish_time
    let bytes = std::fs::read(out.join("recording.mcap")).unwrap();
    assert!(bytes.len() > 1000);
    let (mut states, mut last, mut frames) = (0u64, 0u64, 0u64);
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic == sc_ground::mcap_out::TF_TOPIC {
            let s = m.channel.schema.as_ref().unwrap();
            assert_eq!(s.name, "foxglove.FrameTransform");
            frames += 1;
            continue;
        }
        if m.channel.topic != "safe_capture/sim/state" {
            continue;
        }
        let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
        let tick = v["tick"].as_u64().unwrap();
        assert_eq!(m.log_time, tick * 100_000_000, "tick {tick}");
        assert_ne!(m.publish_time, m.log_time);
        states += 1;
        last = last.max(m.log_time);
    }
    assert_eq!(states, b["steps"].as_u64().unwrap());
    // reference → servicer body, reference → target body, body → end effector,
    // reference → servicer centre of mass
    assert_eq!(frames, 4 * states);
    assert_eq!(last as f64 * 1e-9, b["final_time_s"].as_f64().unwrap());
    // the run's metadata record: the build and the scenario and config it ran
    let summ = mcap::Summary::read(&bytes).unwrap().unwrap();
    let idx = summ
        .metadata_indexes
        .iter()
        .find(|i| i.name == sc_ground::recorder::MCAP_METADATA_NAME)
        .expect("metadata record");
    let meta = mcap::read::metadata(&bytes, idx).unwrap().metadata;
    assert_eq!(meta["version"], b["version"].as_str().unwrap());
    assert_eq!(meta["git_commit"], b["git_commit"].as_str().unwrap());
    // the config the processes ran: the launcher's resolved copy of `config`, named
    // relative to the output folder (which the launcher renames after the run)
    assert_eq!(meta["partition_config_path"], "partition.effective.toml");
    assert_eq!(
        meta["partition_config"],
        std::fs::read_to_string(out.join(&meta["partition_config_path"])).unwrap()
    );
    assert!(meta["partition_config"].contains("clock = \"lock_step\""));
    assert_eq!(
        meta["scenario"],
        std::fs::read_to_string(&meta["scenario_path"]).unwrap()
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("recorder.json")).unwrap()).unwrap();
    assert_eq!(
        r["missing"]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap())
            .sum::<u64>(),
        0,
        "{r}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The partition's telemetry.csv and summary.json (except solve times) in `out` equal
/// those of the scenario `scenario` run in this process; returns the summary.
fn assert_as_in_process(scenario: &std::path::Path, out: &std::path::Path) -> serde_json::Value {
    let setup = Setup::load(scenario).unwrap();
    let names: Vec<String> = setup
        .scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let declared = setup.scenario.clone();
    let mut tel = Vec::new();
    let mut tim = Vec::new();
    let mut records = Vec::new();
    let end = {
        let mut w = TelemetryWriter::new(&mut tel, &mut tim).unwrap();
        let mut m = Mission::new(setup, RunOptions::default()).unwrap();
        let end = m.run(|_, r| {
            w.write(r).unwrap();
            records.push(*r);
        });
        w.flush().unwrap();
        end
    };
    let part = std::fs::read(out.join("telemetry.csv")).unwrap();
    assert!(part == tel, "telemetry.csv differs from the in-process run");
    // this process stands for the same build as the recorder: the summaries name it alike
    sc_mission::build::register(env!("CARGO_PKG_VERSION"), env!("SC_GIT_COMMIT"));
    let mut local = summarize(&records, &end, &names, true);
    local.safe_mode = sc_mission::SafeModeSummary::of(&records, &declared);
    let mut a = serde_json::to_value(local).unwrap();
    let mut b = summary(out);
    // wall and CPU time are measurements, not results
    for k in ["solve_time_us", "solve_cpu_us"] {
        a.as_object_mut().unwrap().remove(k);
        b.as_object_mut().unwrap().remove(k);
    }
    assert_eq!(a, b);
    b
}

/// The world spins the target up beyond the certified envelope (undeclared to the
/// filters): the three filter processes go to safe mode on the same tick as the mission
/// in one process, and the lock-step telemetry stays byte-identical to it.
#[test]
fn a_spin_up_puts_the_partition_in_safe_mode_as_in_process() {
    let dir = tmp("spinup");
    let out = dir.join("out");
    let config = write_config(&dir, Some(40.0), None, 20.0);
    let scenario = dir.join("scenario.toml");
    let mut text = std::fs::read_to_string(&scenario).unwrap();
    text.push_str("\n[world.target_spin_change]\nt_s = 20.0\nomega_rad_s = [-0.3, 0.0, 0.0]\n");
    std::fs::write(&scenario, text).unwrap();
    let rep = sc_ground::launch(&options(&config, &out, "spinup")).unwrap();
    // no capture: the run does not pass
    assert_eq!(rep.code, 1, "{rep:?}");
    assert_clean(&rep, &out);
    let b = assert_as_in_process(&scenario, &out);
    let m = &b["safe_mode"];
    assert!(
        (m["entered_t_s"].as_f64().unwrap() - 20.1).abs() < 1e-9,
        "{b}"
    );
    assert_eq!(m["undetected_t_s"], serde_json::Value::Null);
    assert!(
        b["violated_constraints"].as_array().unwrap().is_empty(),
        "{b}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The world's fixture 0.45 m farther off the spin axis than declared (undeclared to the
/// filters): the simulator process takes it as the truth and estimates it, and the three
/// filter processes go to safe mode on the first tick, as the mission in one process does,
/// telemetry byte for byte; the summary names both fixtures.
#[test]
fn a_fixture_elsewhere_puts_the_partition_in_safe_mode_as_in_process() {
    let dir = tmp("fixture");
    let out = dir.join("out");
    let config = write_config(&dir, Some(10.0), None, 20.0);
    let scenario = dir.join("scenario.toml");
    let mut text = std::fs::read_to_string(&scenario).unwrap();
    text.push_str("\n[world]\ngrasp_point_m = [-0.55, 0.8, 0.0]\n");
    std::fs::write(&scenario, text).unwrap();
    let rep = sc_ground::launch(&options(&config, &out, "fixture")).unwrap();
    assert_eq!(rep.code, 1, "{rep:?}");
    assert_clean(&rep, &out);
    let b = assert_as_in_process(&scenario, &out);
    let m = &b["safe_mode"];
    assert_eq!(m["entered_t_s"].as_f64(), Some(0.0), "{b}");
    assert_eq!(m["rule"], "line_of_sight_rate", "{b}");
    assert_eq!(m["fixture_m"], serde_json::json!([-0.55, 0.8, 0.0]), "{b}");
    assert_eq!(m["undetected_t_s"], serde_json::Value::Null);
    std::fs::remove_dir_all(&dir).ok();
}

const MULTI_RATE: &str = "[[rate_groups]]\nname = \"translational\"\nperiod_s = 0.2\nmembers = [\"translational\"]\n\n[[rate_groups]]\nname = \"attitude\"\nperiod_s = 0.1\nmembers = [\"attitude\"]\n\n[[rate_groups]]\nname = \"robotic\"\nperiod_s = 0.02\nmembers = [\"robotic\"]\n\n";

/// Robotic 0.02 s, attitude 0.1 s, translational 0.2 s: runs to capture.
#[test]
fn multi_rate_schedule_runs_to_capture() {
    let dir = tmp("multi");
    let out = dir.join("out");
    let config = write_config(&dir, None, Some(MULTI_RATE), 20.0);
    let rep = sc_ground::launch(&options(&config, &out, "multi")).unwrap();
    assert_eq!(rep.code, 0, "{rep:?}");
    assert_clean(&rep, &out);
    assert_no_lost_wakeups(&out);
    let s = summary(&out);
    assert_eq!(s["end"], "captured", "{s}");
    assert!(
        s["violated_constraints"].as_array().unwrap().is_empty(),
        "{s}"
    );
    // base period 0.02 s: five simulator steps per attitude period
    let n = contiguous_steps(&out);
    assert!(n > 3000, "{n} steps");
    let lat = std::fs::read_to_string(out.join("latency.csv")).unwrap();
    let held = lat
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(16) != Some("0"))
        .count();
    assert!(
        held > n / 2,
        "slower groups' commands are held on most ticks ({held} of {n})"
    );
    // each command acted with exactly what it was certified against, the held upstream
    // commands included, and none was refused for it
    let (steps, acted, mismatched) = assert_applied_as_certified(&out);
    assert_eq!((acted, mismatched), (steps, 0));
    std::fs::remove_dir_all(&dir).ok();
}

/// A downstream filter slower than its upstream one is rejected at start-up with a
/// clear one-line error, before any process starts.
#[test]
fn slower_downstream_filter_is_rejected() {
    let dir = tmp("reject");
    let groups = "[[rate_groups]]\nname = \"fast\"\nperiod_s = 0.1\nmembers = [\"translational\", \"attitude\"]\n\n[[rate_groups]]\nname = \"slow\"\nperiod_s = 0.2\nmembers = [\"robotic\"]\n\n";
    let config = write_config(&dir, None, Some(groups), 20.0);
    let e = sc_ground::launch(&options(&config, &dir.join("out"), "reject"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("robotic filter (period 0.2 s) is slower than its upstream attitude filter (period 0.1 s)"), "{e}");
    assert!(!e.contains('\n'), "{e}");
    assert!(!dir.join("out/logs").exists(), "nothing may start");
    std::fs::remove_dir_all(&dir).ok();
}
