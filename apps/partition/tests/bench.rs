//! `bench latency` on a short real-time run: the report is consistent with the run
//! (counts, ordering of percentiles, files). No timing assertions.

mod common;
use common::*;
use sc_ground::latency::{BenchOptions, bench};

#[test]
fn latency_report_is_consistent() {
    let dir = tmp("bench");
    let out = dir.join("out");
    let config = write_config(&dir, None, None, 20.0);
    let r = bench(&BenchOptions {
        config: config.clone(),
        out: out.clone(),
        ticks: 25,
        warmup: 5,
        bin_dir: Some(bin_dir()),
        run_id: Some(format!("tbench-{}", std::process::id())),
    })
    .unwrap();
    assert_eq!(r.clock, "RealTime");
    assert_eq!(r.ticks_total, 30);
    assert_eq!(r.warmup_ticks, 5);
    assert_eq!(r.whole_tick.n, 25, "{r:?}");
    assert_eq!(r.hops.len(), 9);
    for (name, h) in r.hops.iter().chain([(&"whole".to_string(), &r.whole_tick)]) {
        assert_eq!(h.n, 25, "{name}");
        let v = [h.min_us, h.p50_us, h.p90_us, h.p99_us, h.p99_9_us, h.max_us];
        assert!(v.windows(2).all(|w| w[0] <= w[1]), "{name}: {v:?}");
        assert!(h.min_us > 0.0, "{name}");
    }
    // the whole tick contains the causal chain of hops 1, 2, 6, 7, 8, 9
    assert!(r.whole_tick.max_us >= r.hops["8 attitude -> robotic filter out"].min_us);
    assert!(r.machine.cores > 0 && !r.machine.kernel.is_empty());
    // what the launcher did about the CPU wake-up latency is reported, whatever it was
    assert!(!r.machine.cpu_wakeup_latency.is_empty(), "{:?}", r.machine);
    // Linux reports steal time in /proc/stat; it can only grow during the run
    assert!(
        r.machine.steal_s.is_some_and(|s| s >= 0.0),
        "{:?}",
        r.machine
    );
    let launch: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("launch.json")).unwrap()).unwrap();
    assert_eq!(
        launch["cpu_wakeup_latency"].as_str(),
        Some(r.machine.cpu_wakeup_latency.as_str())
    );
    // the steal series beside the run: every measured tick is either in a window with
    // steal or counted in the latency without steal
    let st = r.steal.as_ref().expect("steal.csv sampled beside the run");
    assert_eq!(
        st.ticks_with_steal + st.whole_tick_without_steal.n,
        25,
        "{st:?}"
    );
    assert!(
        st.over_1ms_with_steal <= st.over_1ms && st.over_1ms <= 25,
        "{st:?}"
    );
    assert!(
        st.sample_period_s > 0.05 && st.sample_period_s < 1.0,
        "{st:?}"
    );
    let series = sc_ground::steal::read_csv(&out.join("steal.csv"))
        .unwrap()
        .unwrap();
    assert!(
        (series.last().unwrap().steal_s - series[0].steal_s - r.machine.steal_s.unwrap()).abs()
            < 1e-9
    );
    for f in [
        "latency_timeline.svg",
        "steal.csv",
        "latency_whole_tick.hgrm",
        "latency.svg",
        "latency_report.json",
        "latency_report.md",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let hgrm = std::fs::read_to_string(out.join("latency_whole_tick.hgrm")).unwrap();
    assert!(hgrm.contains("Total count = 25"), "{hgrm}");
    let launch: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("launch.json")).unwrap()).unwrap();
    assert!(launch["leftovers"].as_array().unwrap().is_empty());

    // The default config has the pre-tick warm-up, so the processes rehearsed their
    // step before every tick. It changes no command: without a deadline miss (a miss
    // applies a fallback, and then the runs part), the real-time telemetry is the
    // in-process run's, row for row.
    let lead = sc_ground::PartitionConfig::load(&config)
        .unwrap()
        .warmup_lead_us;
    assert!(lead > 0, "the default config has the warm-up");
    assert_eq!(r.warmup_lead_us, lead);
    let md = std::fs::read_to_string(out.join("latency_report.md")).unwrap();
    assert!(md.contains(&format!("pre-tick warm-up {lead} us")), "{md}");
    let part = std::fs::read_to_string(out.join("telemetry.csv")).unwrap();
    let part: Vec<&str> = part.lines().collect();
    assert_eq!(part.len(), 1 + 30, "header + one row per tick");
    if r.deadline_misses == 0 {
        let setup = sc_mission::Setup::load(&dir.join("scenario.toml")).unwrap();
        let mut tel = Vec::new();
        let mut tim = Vec::new();
        {
            let mut w = sc_mission::TelemetryWriter::new(&mut tel, &mut tim).unwrap();
            let mut m = sc_mission::Mission::new(setup, sc_mission::RunOptions::default()).unwrap();
            m.run(|_, rec| w.write(rec).unwrap());
            w.flush().unwrap();
        }
        let tel = String::from_utf8(tel).unwrap();
        let want: Vec<&str> = tel.lines().take(part.len()).collect();
        assert!(
            part == want,
            "real-time telemetry differs from the in-process run"
        );
    } else {
        eprintln!(
            "{} deadline misses on this loaded machine: the telemetry comparison is not applicable",
            r.deadline_misses
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `sc-hop-cost` measures round trips through a second process it starts, reports
/// ordered percentiles, leaves nothing in /dev/shm, and rejects bad arguments.
#[test]
fn hop_cost_reports_round_trips_and_cleans_up() {
    let exe = bin_dir().join("sc-hop-cost");
    let out = std::process::Command::new(&exe)
        .args(["--n", "20", "--period-us", "1000", "--prewarm-us", "300"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("round trip (2 hops), 20 samples"), "{text}");
    let v: Vec<f64> = ["min", "p50", "p90", "p99", "max"]
        .iter()
        .map(|k| {
            let rest = &text[text.find(&format!(" {k} ")).unwrap() + k.len() + 2..];
            rest.split_whitespace().next().unwrap().parse().unwrap()
        })
        .collect();
    assert!(v[0] > 0.0 && v.windows(2).all(|w| w[0] <= w[1]), "{v:?}");
    let left: Vec<String> = std::fs::read_dir("/dev/shm")
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.contains("hopcost"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    let bad = std::process::Command::new(&exe)
        .args(["--cpus", "1"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
