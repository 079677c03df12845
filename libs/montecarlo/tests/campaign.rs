//! Campaigns: config rules, seeds and dispersions, shard/merge byte-identity, rerun,
//! injected failures. Short missions (a few seconds) keep them fast.

use sc_mission::{
    ExecError, Executed, Execution, Executor, InProcess, Job, MissionEnd, TelemetryWriter,
    parse_telemetry,
};
use sc_montecarlo::sample::{initial_los_deg, run_seed, sample};
use sc_montecarlo::{
    CampaignOptions, MonteCarloConfig, merge, parse_shard, rerun, run_campaign, run_campaign_with,
    shard_runs,
};
use sc_montecarlo::{WALL_CLOCK_FILES, WALL_CLOCK_KEYS};
use sc_scenario::Scenario;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sc-mc-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn config() -> MonteCarloConfig {
    MonteCarloConfig::load(&root().join("config/montecarlo.toml")).unwrap()
}

fn scenario() -> Scenario {
    Scenario::load(&root().join("config/scenario.toml")).unwrap()
}

/// The default scenario with a short duration, written to `dir/scenario.toml`.
fn short_scenario(dir: &Path, duration: f64) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let mut s = scenario();
    s.mission.duration_s = duration;
    s.servicer.urdf = std::path::absolute(s.urdf_path()).unwrap();
    let p = dir.join("scenario.toml");
    std::fs::write(&p, s.to_toml_string()).unwrap();
    p
}

fn options(scenario: PathBuf, out: PathBuf, runs: usize) -> CampaignOptions {
    CampaignOptions {
        scenario,
        config: config(),
        runs,
        seed: 7,
        jobs: 2,
        shard: None,
        out,
        inject_panic: Vec::new(),
        progress: false,
        resume: false,
        uncertainty: None,
    }
}

/// Every file under `dir`, relative path → bytes.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p
                    .strip_prefix(dir)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// A copy of the folder tree `from` at `to`.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        if e.path().is_dir() {
            copy_tree(&e.path(), &to.join(e.file_name()));
        } else {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

fn deterministic(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut f = files(dir);
    f.retain(|k, _| !WALL_CLOCK_FILES.contains(&k.as_str()) && !k.ends_with("timing.json"));
    let mut summary: serde_json::Value = serde_json::from_slice(&f["summary.json"]).unwrap();
    for k in WALL_CLOCK_KEYS {
        summary.as_object_mut().unwrap().remove(k);
    }
    f.insert("summary.json".into(), serde_json::to_vec(&summary).unwrap());
    f
}

/// The default campaign is the paper's up to the certified envelope of the default
/// geometry (0.12 of the paper's 0.15 rad/s); the paper's whole range is refused.
#[test]
fn default_config_is_the_papers_within_the_envelope() {
    let c = config();
    assert_eq!(c.target_rate.rate_min_rad_s, 0.0);
    assert_eq!(c.target_rate.rate_max_rad_s, 0.12);
    assert_eq!(c.target_rate.axis_t, [-1.0, 0.0, 0.0]);
    c.check_against(&scenario()).unwrap();
    let mut paper = c.clone();
    paper.target_rate.rate_max_rad_s = 0.15;
    let m = paper.check_against(&scenario()).unwrap_err().to_string();
    assert!(
        m.starts_with(
            "`target_rate.rate_max_rad_s` = 0.15: outside the scenario's certified envelope"
        ) && m.contains("at most 0.1241 rad/s")
            && !m.contains('\n'),
        "{m}"
    );
}

/// The campaign's spin axis decides the geometry too: a fixture out of reach for the
/// scenario's own spin (about -x) can come within reach of the servicer for a spin about
/// z — refused under `target_rate.axis_t`, whatever the rate.
#[test]
fn a_campaign_axis_that_brings_the_fixture_within_reach_is_refused() {
    let mut s = scenario();
    // 2.02 m from the centre, beyond the zone (1.9 m): out of reach while it turns about
    // x (on the far side), within reach when it turns about z
    s.target.grasp_point_m = [2.0, 0.3, 0.0];
    s.validate()
        .expect("the scenario's own spin keeps the fixture out of reach");
    let mut c = config();
    c.target_rate.axis_t = [0.0, 0.0, 1.0];
    c.target_rate.rate_max_rad_s = 0.01;
    let m = c.check_against(&s).unwrap_err().to_string();
    assert!(
        m.starts_with("`target_rate.axis_t` = [0.0, 0.0, 1.0]: "),
        "{m}"
    );
}

#[test]
fn bad_configs_are_rejected_in_one_line() {
    let good = std::fs::read_to_string(root().join("config/montecarlo.toml")).unwrap();
    let cases = [
        (
            "distance_max_m = 11.0",
            "distance_max_m = 3.0",
            "initial_position.distance_max_m",
        ),
        (
            "rate_max_rad_s = 0.12",
            "rate_max_rad_s = nan",
            "target_rate.rate_max_rad_s",
        ),
        (
            "axis_t = [-1.0, 0.0, 0.0]",
            "axis_t = [-1.0, 1.0, 0.0]",
            "target_rate.axis_t",
        ),
        (
            "trace_every_steps = 5",
            "trace_every_steps = 0",
            "output.trace_every_steps",
        ),
        (
            "trace_every_steps = 5",
            "trace_every_steps = 5\nextra = 1",
            "extra",
        ),
        (
            "los_margin_deg = 0.5",
            "los_margin_deg = -1.0",
            "initial_position.los_margin_deg",
        ),
    ];
    for (from, to, key) in cases {
        assert!(good.contains(from), "{from}");
        let e = MonteCarloConfig::from_toml_str(&good.replace(from, to)).unwrap_err();
        let m = e.to_string();
        assert!(m.contains(key) && !m.contains('\n'), "{to}: {m}");
    }
    let mut c = config();
    c.initial_position.corridor_margin_deg = 5.0;
    let m = c.check_against(&scenario()).unwrap_err().to_string();
    assert!(m.contains("corridor_margin_deg") && m.contains("5"), "{m}");
    c = config();
    c.initial_position.distance_min_m = 1.0;
    assert!(c.check_against(&scenario()).is_err());
    let e = MonteCarloConfig::load(Path::new("/nonexistent/mc.toml")).unwrap_err();
    assert!(e.to_string().contains("/nonexistent/mc.toml"));
}

#[test]
fn seeds_are_deterministic_and_distinct() {
    assert_eq!(run_seed(7, 3), run_seed(7, 3));
    let seeds: std::collections::BTreeSet<u64> = (0..1000).map(|k| run_seed(7, k)).collect();
    assert_eq!(seeds.len(), 1000);
    assert_ne!(run_seed(7, 0), run_seed(8, 0));
}

#[test]
fn dispersions_stay_inside_the_corridor_and_the_rate_range() {
    let c = config();
    let s = scenario();
    let psi = s.safety.translational.corridor_half_angle_deg;
    let beta = s.safety.attitude.los_half_angle_deg;
    let axis = nalgebra::Vector3::from(s.safety.translational.corridor_axis);
    let mut rates = Vec::new();
    for k in 0..500 {
        let d = sample(&c, &s, run_seed(1, k)).unwrap();
        assert_eq!(d, sample(&c, &s, run_seed(1, k)).unwrap());
        let p = nalgebra::Vector3::from(d.position_r_m);
        let ang = (p.dot(&axis) / p.norm()).acos().to_degrees();
        assert!(
            ang <= psi - c.initial_position.corridor_margin_deg + 1e-9,
            "{ang}"
        );
        assert!((ang - d.off_axis_deg).abs() < 1e-6);
        assert!((p.norm() - d.distance_m).abs() < 1e-9);
        assert!(d.distance_m >= c.initial_position.distance_min_m);
        assert!(d.distance_m <= c.initial_position.distance_max_m);
        assert!(initial_los_deg(&s, &p) <= beta - c.initial_position.los_margin_deg);
        assert!((0.0..=0.12).contains(&d.tumble_rate_rad_s));
        assert_eq!(d.omega_t_rad_s, [-d.tumble_rate_rad_s, 0.0, 0.0]);
        rates.push(d.tumble_rate_rad_s);
    }
    let mean = rates.iter().sum::<f64>() / rates.len() as f64;
    assert!((mean - 0.0625).abs() < 0.01, "mean rate {mean}");
}

#[test]
fn an_unsatisfiable_los_margin_is_an_error() {
    let mut c = config();
    c.initial_position.los_margin_deg = 4.999;
    c.initial_position.distance_min_m = 2.0;
    c.initial_position.distance_max_m = 2.0;
    let e = sample(&c, &scenario(), 1).unwrap_err().to_string();
    assert!(e.contains("los_margin_deg"), "{e}");
}

#[test]
fn shards_partition_the_campaign() {
    assert_eq!(parse_shard("1/4").unwrap(), (1, 4));
    for bad in ["4/4", "1", "a/2", "0/0", "-1/2"] {
        let e = parse_shard(bad).unwrap_err().to_string();
        assert!(e.contains(bad), "{e}");
    }
    let mut all: Vec<usize> = (0..3).flat_map(|i| shard_runs(10, Some((i, 3)))).collect();
    all.sort_unstable();
    assert_eq!(all, (0..10).collect::<Vec<_>>());
    assert_eq!(shard_runs(5, None), vec![0, 1, 2, 3, 4]);
}

#[test]
fn merged_shards_equal_the_whole_campaign_and_reruns_reproduce() {
    let base = tmp("merge");
    let sc = short_scenario(&base, 2.0);
    let whole = base.join("whole");
    let s = run_campaign(&options(sc.clone(), whole.clone(), 5)).unwrap();
    assert_eq!(s.runs, 5);
    assert_eq!(s.failed_runs, 0);
    assert_eq!(s.safe_runs, 5, "{s:?}");
    assert!(s.solve_time_us["total"].samples > 0);
    let mut shards = Vec::new();
    for i in 0..2 {
        let mut o = options(sc.clone(), base.join(format!("shard{i}")), 5);
        o.shard = Some((i, 2));
        o.jobs = 1;
        let s = run_campaign(&o).unwrap();
        assert_eq!(s.runs, if i == 0 { 3 } else { 2 });
        shards.push(o.out);
    }
    let merged = base.join("merged");
    // shards in either order give the same result
    shards.reverse();
    let m = merge(&shards, &merged).unwrap();
    assert_eq!(m.runs, 5);
    let (a, b) = (deterministic(&whole), deterministic(&merged));
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        b.keys().collect::<Vec<_>>(),
        "file sets differ"
    );
    for (k, v) in &a {
        assert!(
            v == &b[k],
            "{k} differs between the whole campaign and the merged shards"
        );
    }
    assert!(a.contains_key("runs.csv") && a.contains_key("figures/trajectories_xy.svg"));
    assert!(a.contains_key("runs/4/scenario.toml") && a.contains_key("runs/4/trace.csv"));

    // rerun reproduces exactly, from the whole campaign and from the merge
    for dir in [&whole, &merged] {
        let r = rerun(dir, 3).unwrap();
        assert!(r.differences.is_empty(), "{:?}", r.differences);
        assert_eq!(r.result.run, 3);
    }
    assert!(rerun(&whole, 99).is_err());

    // merging an incomplete set or mixing campaigns is refused
    // (shards is [shard1, shard0] here): the shard not given is named with its command
    let e = merge(&shards[..1], &base.join("partial"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("3 of 5 runs missing"), "{e}");
    assert!(
        e.contains("shard 0/2 was not given (runs 0, 2, 4)")
            && e.contains("--runs 5 --seed 7 --shard 0/2")
            && e.contains("base_scenario.toml --config"),
        "{e}"
    );
    // a shard that lost a run (a task killed mid-shard) is named with `--resume`
    let cut = base.join("cut");
    copy_tree(&shards[1], &cut);
    std::fs::remove_dir_all(cut.join("runs/2")).unwrap();
    let e = merge(&[shards[0].clone(), cut.clone()], &base.join("lost"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("1 of 5 runs missing")
            && e.contains("shard 0/2")
            && e.contains("lacks runs 2: complete it with `safe-capture montecarlo --resume --out"),
        "{e}"
    );
    let mut other = options(sc.clone(), base.join("other"), 5);
    other.seed = 8;
    other.shard = Some((0, 2));
    run_campaign(&other).unwrap();
    let e = merge(&[shards[0].clone(), other.out.clone()], &base.join("mixed"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("different campaign"), "{e}");
    let e = merge(&[shards[0].clone(), shards[0].clone()], &base.join("dup"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("in both"), "{e}");
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn a_panicking_run_is_recorded_and_the_campaign_completes() {
    let base = tmp("panic");
    let sc = short_scenario(&base, 2.0);
    let mut o = options(sc, base.join("c"), 4);
    o.inject_panic = vec![2];
    let s = run_campaign(&o).unwrap();
    assert_eq!(s.runs, 4);
    assert_eq!(s.failed_runs, 1);
    assert_eq!(s.failed[0].run, 2);
    assert!(
        s.failed[0].error.contains("injected failure"),
        "{:?}",
        s.failed
    );
    assert_eq!(s.safe_runs, 3);
    let csv = std::fs::read_to_string(o.out.join("runs.csv")).unwrap();
    let row = csv.lines().find(|l| l.starts_with("2,")).unwrap();
    assert!(
        row.contains(",failed,") && row.contains("injected failure"),
        "{row}"
    );
    let header = csv.lines().next().unwrap().split(',').count();
    assert!(csv.lines().all(|l| l.split(',').count() == header));
    let report = std::fs::read_to_string(o.out.join("report.md")).unwrap();
    assert!(
        report.contains("failed: panicked: injected failure"),
        "{report}"
    );
    // its rerun completes and says that it differs from the saved failure
    let r = rerun(&o.out, 2).unwrap();
    assert_eq!(r.differences.len(), 1, "{:?}", r.differences);
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn bad_campaign_inputs_are_one_line_errors() {
    let base = tmp("bad");
    let sc = short_scenario(&base, 1.0);
    let mut o = options(sc.clone(), base.join("c"), 2);
    o.jobs = 0;
    assert!(run_campaign(&o).unwrap_err().to_string().contains("--jobs"));
    let o = options(base.join("missing.toml"), base.join("c2"), 2);
    let m = run_campaign(&o).unwrap_err().to_string();
    assert!(m.contains("missing.toml") && !m.contains('\n'), "{m}");
    // a non-empty directory that is no campaign is not overwritten
    let foreign = base.join("foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("precious.txt"), "x").unwrap();
    let m = run_campaign(&options(sc, foreign.clone(), 1))
        .unwrap_err()
        .to_string();
    assert!(m.contains("campaign.json"), "{m}");
    assert!(foreign.join("precious.txt").is_file());
    let _ = std::fs::remove_dir_all(&base);
}

/// Runs the mission here but hands over only what its telemetry files hold, as the
/// partition's recorder does; runs from `stop_at` on find the campaign stopped (Ctrl-C).
struct ViaTelemetry {
    stop_at: usize,
    stopped: AtomicBool,
}

impl Executor for ViaTelemetry {
    fn execute(&self, job: Job<'_>) -> Result<Executed, ExecError> {
        let name = &job.place.as_ref().unwrap().name;
        let k: usize = name.strip_prefix("mc").unwrap().parse().unwrap();
        if k >= self.stop_at {
            self.stopped.store(true, Ordering::SeqCst);
            return Err(ExecError::Interrupted);
        }
        let Executed { records, end } = InProcess.execute(job)?;
        let (mut tel, mut tim) = (Vec::new(), Vec::new());
        {
            let mut w = TelemetryWriter::new(&mut tel, &mut tim).unwrap();
            for r in &records {
                w.write(r).unwrap();
            }
            w.flush().unwrap();
        }
        let parsed = parse_telemetry(
            std::str::from_utf8(&tel).unwrap(),
            std::str::from_utf8(&tim).unwrap(),
            true,
        )
        .unwrap();
        let end = MissionEnd::from_name(end.name(), parsed.last().unwrap().t).unwrap();
        Ok(Executed {
            records: parsed,
            end,
        })
    }

    fn stopped(&self) -> bool {
        self.stopped.load(Ordering::SeqCst)
    }

    fn execution(&self) -> Execution {
        Execution::Partition
    }
}

/// Runs measured from their telemetry (what `--mode partition` does) give the in-process
/// campaign's deterministic outputs byte for byte; campaign.json records the execution.
#[test]
fn runs_rebuilt_from_telemetry_give_the_in_process_results() {
    let base = tmp("via-telemetry");
    let sc = short_scenario(&base, scenario().mission.duration_s);
    let a = options(sc.clone(), base.join("in-process"), 3);
    let b = options(sc, base.join("via-telemetry"), 3);
    let sa = run_campaign(&a).unwrap();
    let ex = ViaTelemetry {
        stop_at: usize::MAX,
        stopped: AtomicBool::new(false),
    };
    let sb = run_campaign_with(&b, &ex).unwrap();
    assert_eq!(sa.captured_runs, 3, "full missions capture");
    let (mut fa, mut fb) = (deterministic(&a.out), deterministic(&b.out));
    let ca: serde_json::Value =
        serde_json::from_slice(&fa.remove("campaign.json").unwrap()).unwrap();
    let cb: serde_json::Value =
        serde_json::from_slice(&fb.remove("campaign.json").unwrap()).unwrap();
    assert!(
        ca.get("execution").is_none(),
        "in-process campaign.json is unchanged"
    );
    assert_eq!(cb["execution"], "partition");
    assert_eq!(fa.keys().collect::<Vec<_>>(), fb.keys().collect::<Vec<_>>());
    for (k, v) in &fa {
        assert!(*v == fb[k], "{k} differs");
    }
    assert_eq!(sa.worst, sb.worst);
    // the solve times come from the timing file (whole ns), one per step
    assert_eq!(
        sa.solve_time_us["total"].samples,
        sb.solve_time_us["total"].samples
    );
    // shards of different executions do not merge
    let m = merge(&[a.out.clone(), b.out.clone()], &base.join("m"))
        .unwrap_err()
        .to_string();
    assert!(m.contains("execution mode"), "{m}");
    let _ = std::fs::remove_dir_all(&base);
}

/// A stopped executor (Ctrl-C): no further run starts, the run cut short leaves no
/// trace, the completed ones are aggregated, and the summary says the campaign was
/// interrupted. `resume` then completes it: the kept runs are verified, a run left
/// half-written (`K.partial`) or one that does not verify runs again, and the result
/// equals the uninterrupted campaign's.
#[test]
fn a_stopped_campaign_keeps_only_completed_runs_and_resumes() {
    let base = tmp("stopped");
    let sc = short_scenario(&base, 1.0);
    let mut o = options(sc.clone(), base.join("c"), 4);
    o.jobs = 1;
    let ex = ViaTelemetry {
        stop_at: 2,
        stopped: AtomicBool::new(false),
    };
    let s = run_campaign_with(&o, &ex).unwrap();
    let i = s.interrupted.expect("the summary says it was interrupted");
    assert_eq!((i.completed_runs, i.planned_runs), (2, 4));
    let runs = |dir: &Path| {
        let mut r: Vec<String> = std::fs::read_dir(dir.join("runs"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        r.sort();
        r
    };
    assert_eq!(runs(&o.out), ["0", "1"]);
    let sj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(o.out.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(
        (sj["runs"].as_u64(), sj["failed_runs"].as_u64()),
        (Some(2), Some(0))
    );
    assert_eq!(sj["interrupted"]["completed_runs"], 2);
    assert_eq!(sj["host_load"].as_array().map(Vec::len), Some(1));
    let report = std::fs::read_to_string(o.out.join("report.md")).unwrap();
    assert!(report.contains("**Interrupted**") && report.contains("after 2 of 4 runs"));
    assert!(report.contains("inflated under load"), "{report}");

    // a run being written when a campaign was killed, and a saved run that does not
    // verify (its scenario was edited): both run again
    std::fs::create_dir_all(o.out.join("runs/2.partial")).unwrap();
    std::fs::write(o.out.join("runs/2.partial/scenario.toml"), "half").unwrap();
    let edited = o.out.join("runs/1/scenario.toml");
    let text = std::fs::read_to_string(&edited).unwrap();
    let changed = text.replacen("duration_s = 1.0", "duration_s = 2.0", 1);
    assert_ne!(changed, text);
    std::fs::write(&edited, changed).unwrap();
    let kept = std::fs::metadata(o.out.join("runs/0/result.json"))
        .unwrap()
        .modified()
        .unwrap();
    o.resume = true;
    let ex = ViaTelemetry {
        stop_at: usize::MAX,
        stopped: AtomicBool::new(false),
    };
    let r = run_campaign_with(&o, &ex).unwrap();
    assert_eq!((r.runs, r.interrupted), (4, None));
    assert_eq!(runs(&o.out), ["0", "1", "2", "3"]);
    let after = std::fs::metadata(o.out.join("runs/0/result.json"))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(kept, after, "a verified run is kept, not run again");
    assert_eq!(
        r.host_load.len(),
        2,
        "the interrupted session and the resume"
    );

    let whole = options(sc, base.join("whole"), 4);
    run_campaign(&whole).unwrap();
    let (mut fa, mut fb) = (deterministic(&whole.out), deterministic(&o.out));
    // the execution differs (these runs came through telemetry, as in a partition)
    fa.remove("campaign.json");
    fb.remove("campaign.json");
    assert_eq!(fa.keys().collect::<Vec<_>>(), fb.keys().collect::<Vec<_>>());
    for (k, v) in &fa {
        assert!(
            *v == fb[k],
            "{k} differs between the resumed and the whole campaign"
        );
    }
    let _ = std::fs::remove_dir_all(&base);
}

/// `resume` refuses a directory of another campaign, and one with no campaign.
#[test]
fn resume_refuses_another_campaign() {
    let base = tmp("resume-other");
    let sc = short_scenario(&base, 1.0);
    let o = options(sc.clone(), base.join("c"), 2);
    run_campaign(&o).unwrap();
    let mut other = options(sc.clone(), base.join("c"), 3);
    other.seed = 8;
    other.resume = true;
    let m = run_campaign(&other).unwrap_err().to_string();
    assert!(
        m.contains("holds another campaign: seed 7 (not 8), 2 runs (not 3)"),
        "{m}"
    );
    let longer = short_scenario(&base.join("longer"), 2.0);
    let mut other = options(longer, base.join("c"), 2);
    other.resume = true;
    let m = run_campaign(&other).unwrap_err().to_string();
    assert!(m.contains("another base scenario"), "{m}");
    // runs of another build (here: campaign.json names another commit)
    let json = base.join("c/campaign.json");
    let text = std::fs::read_to_string(&json).unwrap();
    let mut j: serde_json::Value = serde_json::from_str(&text).unwrap();
    j["build"]["git_commit"] = serde_json::json!("0000000");
    std::fs::write(&json, serde_json::to_string_pretty(&j).unwrap()).unwrap();
    let mut same = options(sc.clone(), base.join("c"), 2);
    same.resume = true;
    let m = run_campaign(&same).unwrap_err().to_string();
    assert!(
        m.contains("runs of build") && m.contains("(0000000)"),
        "{m}"
    );
    let mut none = options(sc, base.join("empty"), 2);
    none.resume = true;
    let m = run_campaign(&none).unwrap_err().to_string();
    assert!(m.contains("holds no campaign"), "{m}");
    let _ = std::fs::remove_dir_all(&base);
}
