//! `parse_telemetry` gives back what `TelemetryWriter` wrote: every recorded field with
//! the same bits, and so the same summary.

use sc_mission::{
    Mission, MissionEnd, RunOptions, Setup, StepRecord, TelemetryWriter, parse_telemetry, summarize,
};
use std::path::Path;

fn run(
    duration_s: f64,
    no_filter: bool,
) -> (Vec<StepRecord>, MissionEnd, String, String, Vec<String>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml");
    let mut setup = Setup::load(&path).unwrap();
    setup.scenario.mission.duration_s = duration_s;
    let phases = setup
        .scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let mut tel = Vec::new();
    let mut tim = Vec::new();
    let mut records = Vec::new();
    let end = {
        let mut w = TelemetryWriter::new(&mut tel, &mut tim).unwrap();
        let mut m = Mission::new(setup, RunOptions { no_filter }).unwrap();
        let end = m.run(|_, r| {
            w.write(r).unwrap();
            records.push(*r);
        });
        w.flush().unwrap();
        end
    };
    (
        records,
        end,
        String::from_utf8(tel).unwrap(),
        String::from_utf8(tim).unwrap(),
        phases,
    )
}

fn bits<const N: usize>(a: &[f64], b: &[f64], what: &str, step: u64) {
    assert_eq!(a.len(), N);
    for (x, y) in a.iter().zip(b) {
        assert!(
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
            "step {step}: {what}: {x} != {y}"
        );
    }
}

fn assert_recorded_fields_equal(a: &StepRecord, b: &StepRecord, filtered: bool) {
    let s = a.step;
    assert_eq!((a.step, a.phase), (b.step, b.phase));
    assert_eq!(a.t.to_bits(), b.t.to_bits());
    let (o, p) = (&a.obs, &b.obs);
    for (what, x, y) in [
        ("r_h", o.r_h, p.r_h),
        ("v_h", o.v_h, p.v_h),
        ("r_r", o.r_r, p.r_r),
        ("v_r", o.v_r, p.v_r),
        ("omega_b", o.omega_b, p.omega_b),
        ("omega_t", o.omega_t, p.omega_t),
        ("grasp_r", o.grasp_r, p.grasp_r),
        ("grasp_b", o.grasp_b, p.grasp_b),
        ("ee_r", o.ee_r, p.ee_r),
        ("f_h_nom", a.f_h_nom, b.f_h_nom),
        ("tau_b_nom", a.tau_b_nom, b.tau_b_nom),
        ("f_h_safe", a.translational.u, b.translational.u),
        ("force_b", a.applied.force_b, b.applied.force_b),
        ("torque_b", a.applied.torque_b, b.applied.torque_b),
    ] {
        bits::<3>(x.as_slice(), y.as_slice(), what, s);
    }
    bits::<4>(&o.q_rb, &p.q_rb, "q_rb", s);
    bits::<4>(&o.q_rt, &p.q_rt, "q_rt", s);
    for (what, x, y) in [
        ("theta", o.theta, p.theta),
        ("theta_dot", o.theta_dot, p.theta_dot),
        ("tau_m_nom", a.tau_m_nom, b.tau_m_nom),
        ("tau", a.applied.tau, b.applied.tau),
    ] {
        bits::<7>(x.as_slice(), y.as_slice(), what, s);
    }
    bits::<{ sc_cbf::monitor::N_ALL }>(&a.h(), &b.h(), "h", s);
    assert_eq!(a.solve_time_us(), b.solve_time_us(), "step {s}");
    for (x, y) in [
        (
            (
                a.translational.report.status,
                a.translational.report.iterations,
            ),
            (
                b.translational.report.status,
                b.translational.report.iterations,
            ),
        ),
        (
            (a.attitude.report.status, a.attitude.report.iterations),
            (b.attitude.report.status, b.attitude.report.iterations),
        ),
        (
            (a.robotic.report.status, a.robotic.report.iterations),
            (b.robotic.report.status, b.robotic.report.iterations),
        ),
    ] {
        assert_eq!(x, y, "step {s}");
    }
    assert_eq!(
        [
            a.translational.report.faults,
            a.attitude.report.faults,
            a.robotic.report.faults
        ],
        [
            b.translational.report.faults,
            b.attitude.report.faults,
            b.robotic.report.faults
        ],
        "step {s}"
    );
    assert_eq!(
        [
            a.translational.report.active,
            a.attitude.report.active,
            a.robotic.report.active
        ],
        [
            b.translational.report.active,
            b.attitude.report.active,
            b.robotic.report.active
        ],
        "step {s}"
    );
    if filtered {
        bits::<3>(
            a.attitude.u.as_slice(),
            b.attitude.u.as_slice(),
            "attitude.u",
            s,
        );
        bits::<7>(
            a.robotic.u.as_slice(),
            b.robotic.u.as_slice(),
            "robotic.u",
            s,
        );
        bits::<3>(
            a.translational.actuated.as_slice(),
            b.translational.actuated.as_slice(),
            "translational.actuated",
            s,
        );
    } else {
        assert!(b.attitude.u.iter().all(|x| x.is_nan()));
        assert!(b.robotic.u.iter().all(|x| x.is_nan()));
    }
    // not in the files
    assert!(b.obs.mean_motion.is_nan() && b.obs.ee_b.iter().all(|x| x.is_nan()));
}

#[test]
fn filtered_run_round_trips_bit_for_bit_and_summarizes_the_same() {
    let (records, end, tel, tim, phases) = run(30.0, false);
    let parsed = parse_telemetry(&tel, &tim, true).unwrap();
    assert_eq!(parsed.len(), records.len());
    for (a, b) in records.iter().zip(&parsed) {
        assert_recorded_fields_equal(a, b, true);
    }
    let end2 = MissionEnd::from_name(end.name(), parsed.last().unwrap().t).unwrap();
    assert_eq!(end2, end);
    // the whole summary, solve times and interventions included
    assert_eq!(
        serde_json::to_value(summarize(&records, &end, &phases, true)).unwrap(),
        serde_json::to_value(summarize(&parsed, &end2, &phases, true)).unwrap()
    );
}

#[test]
fn unfiltered_run_round_trips_with_its_faults() {
    let (records, end, tel, tim, phases) = run(60.0, true);
    let parsed = parse_telemetry(&tel, &tim, false).unwrap();
    for (a, b) in records.iter().zip(&parsed) {
        assert_recorded_fields_equal(a, b, false);
    }
    let mut x = serde_json::to_value(summarize(&records, &end, &phases, false)).unwrap();
    let mut y = serde_json::to_value(summarize(&parsed, &end, &phases, false)).unwrap();
    assert!(
        x["fault_count"].as_u64().unwrap() > 0,
        "{}",
        x["fault_count"]
    );
    // the unapplied safe commands of an unfiltered run are not in the files
    x.as_object_mut().unwrap().remove("interventions");
    y.as_object_mut().unwrap().remove("interventions");
    assert_eq!(x, y);
}

#[test]
fn bad_files_are_one_line_errors() {
    let (_, _, tel, tim, _) = run(0.5, false);
    let cases: Vec<(String, String, &str)> = vec![
        (
            tel.replacen("step,", "stp,", 1),
            tim.clone(),
            "telemetry.csv: the header",
        ),
        (
            tel.clone(),
            tim.replacen("step,", "stp,", 1),
            "timing.csv: the header",
        ),
        (
            {
                let mut l: Vec<&str> = tel.lines().collect();
                let bad = l[2].replacen(',', ",x", 2);
                l[2] = &bad;
                l.join("\n")
            },
            tim.clone(),
            "telemetry.csv line 3: `t_s`",
        ),
        (
            tel.clone(),
            tim.lines().take(2).collect::<Vec<_>>().join("\n"),
            "timing.csv: ends before step 1",
        ),
        (
            tel.lines().take(2).collect::<Vec<_>>().join("\n"),
            tim.clone(),
            "timing.csv: more rows",
        ),
        (
            {
                // a changed synchronisation error no longer matches the state
                let l: Vec<&str> = tel.lines().collect();
                let hdr: Vec<&str> = l[0].split(',').collect();
                let col = hdr
                    .iter()
                    .position(|c| *c == "sync_error_b_x_rad_s")
                    .unwrap();
                let mut f: Vec<String> = l[1].split(',').map(String::from).collect();
                f[col] = "12.5".into();
                format!("{}\n{}\n", l[0], f.join(","))
            },
            tim.lines().take(2).collect::<Vec<_>>().join("\n"),
            "telemetry.csv line 2: sync_error_b does not match",
        ),
    ];
    for (t, m, want) in cases {
        let e = parse_telemetry(&t, &m, true).unwrap_err().to_string();
        assert!(e.contains(want), "{e}\nwanted: {want}");
        assert!(!e.contains('\n'), "{e}");
    }
}

/// The filters' thread CPU time is measured inside their wall interval: on every step and
/// filter it is at most the wall time, and the filters did measurable work.
#[test]
fn thread_cpu_time_lies_within_the_wall_time() {
    let (records, _, _, _, _) = run(30.0, false);
    let mut cpu_total = 0u64;
    for r in &records {
        for (name, cpu, wall) in [
            (
                "translational",
                r.translational.report.solve_cpu_ns,
                r.translational.report.solve_time_ns,
            ),
            (
                "attitude",
                r.attitude.report.solve_cpu_ns,
                r.attitude.report.solve_time_ns,
            ),
            (
                "robotic",
                r.robotic.report.solve_cpu_ns,
                r.robotic.report.solve_time_ns,
            ),
        ] {
            assert!(
                cpu <= wall,
                "step {} {name}: cpu {cpu} ns > wall {wall} ns",
                r.step
            );
            cpu_total += cpu;
        }
    }
    assert!(
        cpu_total > 0,
        "no CPU time measured over {} steps",
        records.len()
    );
}

/// `read_knowledge` gives back what `write_knowledge` wrote under a declared profile:
/// every navigation error and barrier on knowledge with the same bits; a navigation.csv
/// of another run (its steps not the telemetry's) or cut short is refused.
#[test]
fn knowledge_round_trips_bit_for_bit() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml");
    let mut setup = Setup::load(&path).unwrap();
    setup.scenario.mission.duration_s = 3.0;
    let spec = sc_scenario::UncertaintySpec {
        profile: "realistic".into(),
        seed: 2,
        model: None,
        actuators: None,
        navigation: None,
        truth: None,
    };
    setup.scenario.set_uncertainty(spec).unwrap();
    let mut records = Vec::new();
    Mission::new(setup, RunOptions { no_filter: false })
        .unwrap()
        .run(|_, r| records.push(*r));
    let dir = std::env::temp_dir().join(format!("sc-knowledge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("navigation.csv");
    sc_mission::record::write_knowledge(&file, &records).unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let mut back: Vec<StepRecord> = records
        .iter()
        .map(|r| StepRecord {
            navigation_error: None,
            knowledge_barriers: None,
            ..*r
        })
        .collect();
    sc_mission::record::read_knowledge(&text, &mut back).unwrap();
    for (a, b) in records.iter().zip(&back) {
        let (ea, eb) = (a.navigation_error.unwrap(), b.navigation_error.unwrap());
        bits::<10>(&ea.values(), &eb.values(), "navigation_error", a.step);
        bits::<{ sc_cbf::monitor::N_ALL }>(
            &a.knowledge_barriers.unwrap(),
            &b.knowledge_barriers.unwrap(),
            "knowledge_barriers",
            a.step,
        );
    }
    // a file from before the refusal flag still reads, every step unflagged
    let old: String = text
        .lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(2);
            format!("{}\n", f.join(","))
        })
        .collect();
    let mut older = back.clone();
    sc_mission::record::read_knowledge(&old, &mut older).unwrap();
    assert!(
        older
            .iter()
            .all(|r| !r.navigation_rejected && r.navigation_error.is_some())
    );
    let err = sc_mission::record::read_knowledge(&text, &mut back[1..]).unwrap_err();
    assert!(err.to_string().contains("is not the step"), "{err}");
    let short: String = text.lines().take(3).map(|l| format!("{l}\n")).collect();
    let err = sc_mission::record::read_knowledge(&short, &mut back).unwrap_err();
    assert!(err.to_string().contains("rows for the"), "{err}");
}

/// A refused navigation estimate survives the files: with nothing declared, a run whose
/// navigation is refused on some steps writes navigation.csv with the flags and without
/// errors or barriers on knowledge (knowledge is the truth), and reading it back gives the
/// same flags, no knowledge apart from the truth — and the same summary as the run, its
/// `navigation` fault events included (a partition campaign rebuilds its runs this way).
#[test]
fn a_refused_estimate_round_trips_without_a_declared_uncertainty() {
    struct Jump;
    impl sc_sim::Estimator for Jump {
        fn estimate(&mut self, m: &sc_sim::NavSample) -> sc_sim::NavSample {
            let mut e = *m;
            if e.tick % 3 == 1 {
                e.state.dr[0] += 1.0;
            }
            e
        }
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml");
    let mut setup = Setup::load(&path).unwrap();
    setup.scenario.mission.duration_s = 2.0;
    let names: Vec<String> = setup
        .scenario
        .mission
        .phases
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let mut records = Vec::new();
    let mut m = Mission::new(setup, RunOptions { no_filter: false }).unwrap();
    m.set_navigation(Box::new(Jump));
    let end = m.run(|_, r| records.push(*r));
    let rejected: Vec<u64> = records
        .iter()
        .filter(|r| r.navigation_rejected)
        .map(|r| r.step)
        .collect();
    assert!(
        rejected.len() >= 5 && rejected.iter().all(|k| k % 3 == 1),
        "{rejected:?}"
    );
    let dir = std::env::temp_dir().join(format!("sc-refused-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("navigation.csv");
    sc_mission::record::write_knowledge(&file, &records).unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let mut back: Vec<StepRecord> = records
        .iter()
        .map(|r| StepRecord {
            navigation_rejected: false,
            ..*r
        })
        .collect();
    sc_mission::record::read_knowledge(&text, &mut back).unwrap();
    for (a, b) in records.iter().zip(&back) {
        assert_eq!(
            a.navigation_rejected, b.navigation_rejected,
            "step {}",
            a.step
        );
        assert!(b.navigation_error.is_none() && b.knowledge_barriers.is_none());
    }
    let summary = |r: &[StepRecord]| {
        serde_json::to_value(sc_mission::summarize(r, &end, &names, true)).unwrap()
    };
    let (a, b) = (summary(&records), summary(&back));
    assert_eq!(a["faults"], b["faults"]);
    assert_eq!(a["fault_count"], b["fault_count"]);
    assert!(a["faults"].to_string().contains("NAVIGATION_REJECTED"));
}
