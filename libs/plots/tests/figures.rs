//! Figures of a short mission and of synthetic campaign data: written, SVG, deterministic,
//! and no panic on empty or non-finite data.

use nalgebra::Vector3;
use sc_mission::{Mission, RunOptions, Setup, StepRecord};
use sc_plots::{
    BarrierMinima, CampaignFigures, Geometry, RunPoint, RuntimeBar, TracePoint, campaign_figures,
    los_angles_deg, run_figures, viridis,
};
use sc_scenario::Scenario;
use std::path::{Path, PathBuf};

/// A scratch directory, removed when the test ends (passed or failed).
struct TmpDir(PathBuf);

impl std::ops::Deref for TmpDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TmpDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TmpDir {
    fn drop(&mut self) {
        // a test may have made it a file
        let _ = std::fs::remove_dir_all(&self.0).or_else(|_| std::fs::remove_file(&self.0));
    }
}

fn tmp(name: &str) -> TmpDir {
    let d = std::env::temp_dir().join(format!("sc-plots-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    TmpDir(d)
}

fn short_scenario(duration: f64) -> Scenario {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config");
    let text = std::fs::read_to_string(dir.join("scenario.toml")).unwrap();
    let mut s = Scenario::from_toml_str(&text, &dir).unwrap();
    s.mission.duration_s = duration;
    s
}

fn records(s: &Scenario, no_filter: bool) -> Vec<StepRecord> {
    let setup = Setup::from_scenario(s.clone()).unwrap();
    let mut m = Mission::new(setup, RunOptions { no_filter }).unwrap();
    let mut v = Vec::new();
    m.run(|_, r| v.push(*r));
    v
}

const RUN_FILES: [&str; 6] = [
    "trajectory.svg",
    "barriers.svg",
    "range_rate.svg",
    "sync_error.svg",
    "joint_torques.svg",
    "line_of_sight.svg",
];

#[test]
fn run_figures_are_written_and_deterministic() {
    let s = short_scenario(3.0);
    let filtered = records(&s, false);
    let nominal = records(&s, true);
    let (a, b) = (tmp("run-a"), tmp("run-b"));
    let files = run_figures(&a, &s, &filtered, Some(&nominal)).unwrap();
    assert_eq!(files.len(), RUN_FILES.len());
    run_figures(&b, &s, &filtered, Some(&nominal)).unwrap();
    for f in RUN_FILES {
        let x = std::fs::read_to_string(a.join(f)).unwrap();
        assert!(x.starts_with("<svg"), "{f} is not SVG");
        assert_eq!(
            x,
            std::fs::read_to_string(b.join(f)).unwrap(),
            "{f} differs"
        );
    }
    let traj = std::fs::read_to_string(a.join("trajectory.svg")).unwrap();
    assert!(traj.contains("x_R [m]") && traj.contains("approach corridor"));
    let bar = std::fs::read_to_string(a.join("barriers.svg")).unwrap();
    assert!(bar.contains("h_AC [m]") && bar.contains("nominal") && bar.contains("filtered"));
    assert!(bar.contains("stroke-dasharray") || bar.matches("<polyline").count() > 10);
}

#[test]
fn run_figures_survive_empty_and_nan_records() {
    let s = short_scenario(0.5);
    run_figures(&tmp("empty"), &s, &[], None).unwrap();
    let mut r = records(&s, false);
    for x in r.iter_mut() {
        x.obs.r_r = Vector3::new(f64::NAN, f64::INFINITY, 0.0);
        x.applied.tau[0] = f64::NAN;
    }
    run_figures(&tmp("nan"), &s, &r, Some(&r)).unwrap();
}

#[test]
fn run_figures_report_an_unwritable_directory() {
    let s = short_scenario(0.2);
    let file = tmp("file");
    std::fs::write(&file, "x").unwrap();
    let e = run_figures(&file.join("sub"), &s, &[], None).unwrap_err();
    let m = e.to_string();
    assert!(m.contains("sub") && !m.contains('\n'), "{m}");
}

type CampaignData = (
    Vec<(usize, Vec<TracePoint>)>,
    Vec<RunPoint>,
    Vec<RuntimeBar>,
    Vec<BarrierMinima>,
);

fn campaign_data() -> CampaignData {
    let traces = (0..3)
        .map(|k| {
            let pts = (0..20)
                .map(|i| TracePoint {
                    t: i as f64,
                    phase: 0,
                    r_r: [-9.0 + 0.3 * i as f64, 0.1 * k as f64, 0.0],
                    speed: 0.01 * i as f64,
                    los_deg: [0.1 * i as f64, -0.05 * k as f64],
                    sync_error: if i == 5 { f64::NAN } else { 0.001 * i as f64 },
                })
                .collect();
            (k, pts)
        })
        .collect();
    let points = (0..3)
        .map(|k| RunPoint {
            run: k,
            tumble_rate: 0.05 * k as f64,
            peak_sync_grasp: 0.04 + 0.001 * k as f64,
            torque_norm_grasp: 1.0 + k as f64,
        })
        .collect();
    let runtime = ["total", "translational", "attitude", "robotic"]
        .iter()
        .map(|n| RuntimeBar {
            name: n.to_string(),
            geomean_us: 10.0,
            max_us: 100.0,
            cpu_geomean_us: 9.0,
            cpu_max_us: 40.0,
        })
        .collect();
    let minima = sc_mission::constraint_names()
        .iter()
        .map(|n| BarrierMinima {
            name: n.to_string(),
            values: vec![0.1, -0.02, 0.3, f64::NAN],
        })
        .collect();
    (traces, points, runtime, minima)
}

/// Pixel width and height of the widest polyline of `stroke` colour in an SVG.
fn widest_polyline_extent(svg: &str, stroke: &str) -> Option<(f64, f64)> {
    svg.split("<polyline")
        .skip(1)
        .filter(|p| p.contains(&format!("stroke=\"{stroke}\"")))
        .filter_map(|p| {
            let pts = p.split("points=\"").nth(1)?.split('"').next()?;
            let xy: Vec<(f64, f64)> = pts
                .split_whitespace()
                .filter_map(|q| {
                    let (x, y) = q.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect();
            let ext = |f: fn(&(f64, f64)) -> f64| {
                let v = xy.iter().map(f);
                v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
            };
            Some((ext(|p| p.0), ext(|p| p.1)))
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

#[test]
fn campaign_figures_are_written_and_deterministic() {
    let s = short_scenario(1.0);
    let (traces, points, runtime, minima) = campaign_data();
    let f = CampaignFigures {
        geometry: Geometry::from_scenario(&s),
        traces: &traces,
        points: &points,
        runtime: &runtime,
        runtime_reference: Some(("paper".into(), 1590.0, 3750.0)),
        minima: &minima,
    };
    let (a, b) = (tmp("mc-a"), tmp("mc-b"));
    let files = campaign_figures(&a, &f).unwrap();
    campaign_figures(&b, &f).unwrap();
    assert_eq!(files.len(), 5);
    for p in files {
        let name = p.file_name().unwrap();
        let x = std::fs::read_to_string(&p).unwrap();
        assert!(x.starts_with("<svg"));
        assert_eq!(x, std::fs::read_to_string(b.join(name)).unwrap());
    }
    // the collision-avoidance zone is drawn round (equal aspect): its polyline is as wide
    // as it is tall, in pixels
    let traj = std::fs::read_to_string(a.join("trajectories_xy.svg")).unwrap();
    let (w, h) = widest_polyline_extent(&traj, "#D62728").expect("zone drawn");
    assert!(w > 50.0 && (w - h).abs() <= 2.0, "zone {w} x {h} px");
    // empty campaign
    let empty = CampaignFigures {
        traces: &[],
        points: &[],
        runtime: &[],
        runtime_reference: None,
        minima: &[],
        ..f
    };
    campaign_figures(&tmp("mc-empty"), &empty).unwrap();
}

#[test]
fn colours_and_los_angles() {
    assert_eq!(viridis(0.0), viridis(-1.0));
    assert_eq!(viridis(1.0), viridis(2.0));
    assert_eq!(viridis(f64::NAN), viridis(0.0));
    let d = Vector3::x();
    let a = los_angles_deg(&Vector3::new(1.0, 1.0, 0.0), &d).unwrap();
    assert!((a[0] - 45.0).abs() < 1e-12 && a[1].abs() < 1e-12, "{a:?}");
    let a = los_angles_deg(&Vector3::new(1.0, 0.0, -1.0), &d).unwrap();
    assert!(a[0].abs() < 1e-12 && (a[1] + 45.0).abs() < 1e-12, "{a:?}");
    assert!(los_angles_deg(&Vector3::zeros(), &d).is_none());
    assert!(los_angles_deg(&Vector3::new(f64::NAN, 0.0, 0.0), &d).is_none());
}
