//! Figures of a short mission and of synthetic campaign data: written, SVG, deterministic,
//! and no panic on empty or non-finite data.

use nalgebra::Vector3;
use sc_mission::compare::StepDifference;
use sc_mission::{Mission, RunOptions, Setup, StepRecord};
use sc_plots::{
    BarrierMinima, CampaignFigures, Geometry, LatencyPercentiles, LatencyTimeline, RunPoint,
    RuntimeBar, TracePoint, campaign_figures, difference_figure, latency_percentiles,
    latency_timeline, los_angles_deg, run_figures, viridis,
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

/// A `<text>` of a plotters SVG: position, anchor, vertical shift and content.
#[derive(Debug)]
struct SvgText {
    x: f64,
    y: f64,
    anchor: String,
    dy: String,
    text: String,
}

/// A `<polyline>` of a plotters SVG.
#[derive(Debug)]
struct Poly {
    stroke: String,
    width: f64,
    pts: Vec<(f64, f64)>,
}

fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    tag.split(&format!(" {name}=\"")).nth(1)?.split('"').next()
}

fn texts(svg: &str) -> Vec<SvgText> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let (head, rest) = t.split_once('>')?;
            let content = rest.split("</text>").next()?.trim().to_string();
            Some(SvgText {
                x: attr(head, "x")?.parse().ok()?,
                y: attr(head, "y")?.parse().ok()?,
                anchor: attr(head, "text-anchor").unwrap_or("start").into(),
                dy: attr(head, "dy").unwrap_or("").into(),
                text: content,
            })
        })
        .collect()
}

fn polylines(svg: &str) -> Vec<Poly> {
    svg.split("<polyline")
        .skip(1)
        .filter_map(|p| {
            let head = p.split("/>").next()?;
            let pts = attr(head, "points")?
                .split_whitespace()
                .filter_map(|q| {
                    let (x, y) = q.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect();
            Some(Poly {
                stroke: attr(head, "stroke")?.into(),
                width: attr(head, "stroke-width")?.parse().ok()?,
                pts,
            })
        })
        .collect()
}

/// The tick labels of every y axis: each axis is a long vertical black line; its labels
/// are the right-aligned, vertically centred texts just left of it, along it.
fn y_axes(svg: &str) -> Vec<(i64, Vec<String>)> {
    let all = texts(svg);
    polylines(svg)
        .into_iter()
        .filter(|p| p.stroke == "#000000" && p.pts.len() == 2)
        .filter(|p| p.pts[0].0 == p.pts[1].0 && (p.pts[0].1 - p.pts[1].1).abs() > 20.0)
        .map(|p| {
            let x = p.pts[0].0;
            let (y0, y1) = (p.pts[0].1.min(p.pts[1].1), p.pts[0].1.max(p.pts[1].1));
            let labels = all
                .iter()
                .filter(|t| t.anchor == "end" && t.dy == "0.5ex")
                .filter(|t| t.x < x && t.x >= x - 15.0 && t.y >= y0 - 1.0 && t.y <= y1 + 1.0)
                .map(|t| t.text.clone())
                .collect();
            (x as i64, labels)
        })
        .collect()
}

/// Every y axis of `svg` has at least three ticks; returns how many axes there are.
fn assert_y_ticks(name: &str, svg: &str) -> usize {
    let axes = y_axes(svg);
    assert!(!axes.is_empty(), "{name}: no y axis found");
    for (x, labels) in &axes {
        assert!(labels.len() >= 3, "{name}: y axis at x = {x}: {labels:?}");
    }
    axes.len()
}

/// No label of `svg` is written like `10000000.0`, `50.0` or `-0`.
fn assert_readable_labels(name: &str, svg: &str) {
    for t in texts(svg) {
        let s = t.text.as_str();
        let numeric = !s.is_empty() && s.parse::<f64>().is_ok();
        assert!(!s.contains("0000000"), "{name}: label {s}");
        if numeric {
            assert!(!s.ends_with(".0") && s != "-0", "{name}: label {s}");
        }
    }
}

/// Horizontal segments of `colour` inside the legend swatch area left of `label`.
fn swatch_segments(svg: &str, label: &str, colour: &str) -> Vec<(f64, f64, f64)> {
    let t = texts(svg)
        .into_iter()
        .find(|t| t.text == label)
        .unwrap_or_else(|| panic!("no legend entry {label}"));
    polylines(svg)
        .into_iter()
        .filter(|p| p.stroke == colour && p.pts.len() == 2)
        .filter(|p| p.pts[0].1 == p.pts[1].1)
        .filter(|p| {
            let (x0, x1, y) = (p.pts[0].0, p.pts[1].0, p.pts[0].1);
            x0 >= t.x - 40.0 && x1 < t.x && y >= t.y - 2.0 && y <= t.y + 16.0
        })
        .map(|p| (p.pts[0].0, p.pts[1].0, p.width))
        .collect()
}

#[test]
fn legend_swatches_are_drawn_as_their_series() {
    let s = short_scenario(3.0);
    let filtered = records(&s, false);
    let nominal = records(&s, true);
    let d = tmp("swatch");
    run_figures(&d, &s, &filtered, Some(&nominal)).unwrap();
    for f in ["range_rate.svg", "barriers.svg", "sync_error.svg"] {
        let svg = std::fs::read_to_string(d.join(f)).unwrap();
        // the nominal run is dashed: its swatch is three dashes of 6 px, 10 px apart
        let mut dashes = swatch_segments(&svg, "nominal", "#FF7F0E");
        dashes.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert!(dashes.len() >= 3, "{f}: nominal swatch {dashes:?}");
        let x0 = dashes[0].0;
        for (k, (a, b, w)) in dashes.iter().take(3).enumerate() {
            assert_eq!(*a, x0 + 10.0 * k as f64, "{f}: {dashes:?}");
            assert_eq!(b - a, 6.0, "{f}: {dashes:?}");
            assert_eq!(*w, 2.0, "{f}: dashed swatch as wide as its series");
        }
        // the filtered run is solid: one segment, same width as the series
        let solid = swatch_segments(&svg, "filtered", "#1F77B4");
        assert_eq!(solid.len(), 1, "{f}: filtered swatch {solid:?}");
        assert_eq!(solid[0].1 - solid[0].0, 26.0);
        assert_eq!(solid[0].2, 2.0);
    }
    // joint torques: one entry per joint, its swatch the joint's thin solid line (a
    // "nominal (all joints)" entry in joint 1's colour matched no curve); the title says
    // what dashed is
    let svg = std::fs::read_to_string(d.join("joint_torques.svg")).unwrap();
    let solid = swatch_segments(&svg, "joint 1", "#1F77B4");
    assert!(solid.len() == 1 && solid[0].2 == 1.0, "{solid:?}");
    let t: Vec<String> = texts(&svg).into_iter().map(|t| t.text).collect();
    assert!(!t.iter().any(|l| l.contains("all joints")), "{t:?}");
    assert!(t.iter().any(|l| l.contains("nominal dashed")), "{t:?}");
}

#[test]
fn run_figures_have_readable_ticks_and_labelled_reference_lines() {
    let s = short_scenario(3.0);
    let filtered = records(&s, false);
    let nominal = records(&s, true);
    let d = tmp("ticks");
    run_figures(&d, &s, &filtered, Some(&nominal)).unwrap();
    for f in RUN_FILES {
        let svg = std::fs::read_to_string(d.join(f)).unwrap();
        assert_y_ticks(f, &svg);
        assert_readable_labels(f, &svg);
    }
    let bar = std::fs::read_to_string(d.join("barriers.svg")).unwrap();
    assert_eq!(assert_y_ticks("barriers.svg", &bar), 8);
    let zero = texts(&bar)
        .iter()
        .filter(|t| t.text.starts_with("h = 0"))
        .count();
    assert_eq!(zero, 8, "every barrier panel labels its h = 0 line");
    let rr = std::fs::read_to_string(d.join("range_rate.svg")).unwrap();
    assert!(rr.contains("R_CAZ") && rr.contains("Go-for-Capture"));
    let jt = std::fs::read_to_string(d.join("joint_torques.svg")).unwrap();
    assert!(jt.contains("|τ_M|max"), "torque bounds labelled");
}

#[test]
fn campaign_figures_have_readable_ticks_and_minima_around_zero() {
    let s = short_scenario(1.0);
    let (traces, points, mut runtime, mut minima) = campaign_data();
    // a wide log range: labels like 1e7, never 10000000.0
    runtime[0].max_us = 1.2e7;
    // all safe: 0 must still be in range, with the h = 0 line labelled
    for m in minima.iter_mut() {
        m.values = vec![0.5, 0.7, 0.71];
    }
    let f = CampaignFigures {
        geometry: Geometry::from_scenario(&s),
        traces: &traces,
        points: &points,
        runtime: &runtime,
        runtime_reference: Some(("paper".into(), 1590.0, 3750.0)),
        minima: &minima,
    };
    let d = tmp("mc-ticks");
    for p in campaign_figures(&d, &f).unwrap() {
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        let svg = std::fs::read_to_string(&p).unwrap();
        assert_y_ticks(&name, &svg);
        assert_readable_labels(&name, &svg);
    }
    let rt = std::fs::read_to_string(d.join("runtime.svg")).unwrap();
    let labels: Vec<String> = texts(&rt).into_iter().map(|t| t.text).collect();
    assert!(labels.iter().any(|l| l == "1e7"), "{labels:?}");
    assert!(
        labels.iter().any(|l| l == "paper geomean: 1.59 ms")
            && labels.iter().any(|l| l == "paper max: 3.75 ms"),
        "reference lines labelled: {labels:?}"
    );
    let bm = std::fs::read_to_string(d.join("barrier_minima.svg")).unwrap();
    let t = texts(&bm);
    let n = minima.len();
    assert_eq!(t.iter().filter(|t| t.text == "h = 0").count(), n);
    assert_eq!(t.iter().filter(|t| t.text == "runs").count(), n);
    // each axis with its barrier's unit
    assert_eq!(
        t.iter()
            .filter(|t| t.text.starts_with("minimum of h [") && !t.text.contains('?'))
            .count(),
        n
    );
    // 0 is a tick of every histogram's x axis
    assert_eq!(
        t.iter()
            .filter(|t| t.text == "0" && t.anchor == "middle")
            .count(),
        n
    );
    assert_eq!(y_axes(&bm).len(), n);
}

#[test]
fn compare_and_latency_figures_use_log_axes_with_readable_ticks() {
    let d = tmp("log");
    let diffs: Vec<StepDifference> = (0..50)
        .map(|i| StepDifference {
            t: i as f64 * 0.1,
            hill_position_m: 1e-15 * 10f64.powi(i / 5),
            attitude_rad: 0.0,
            joint_angle_rad: f64::NAN,
            target_attitude_rad: 1e-9,
        })
        .collect();
    let cmp = d.join("compare.svg");
    std::fs::create_dir_all(&*d).unwrap();
    difference_figure(&cmp, &diffs, "A against B").unwrap();
    let svg = std::fs::read_to_string(&cmp).unwrap();
    assert_eq!(assert_y_ticks("compare.svg", &svg), 1);
    assert_readable_labels("compare.svg", &svg);
    assert!(
        y_axes(&svg)[0]
            .1
            .iter()
            .all(|l| l.contains("e-") || l == "1" || l.starts_with("0."))
    );

    let pts: Vec<(f64, f64)> = (0..40)
        .map(|i| (10f64.powf(i as f64 / 10.0), 50.0 * 1.6f64.powi(i)))
        .collect();
    let refs = [("1 ms target".to_string(), 1000.0)];
    let lat = d.join("latency.svg");
    latency_percentiles(
        &lat,
        &LatencyPercentiles {
            title: "whole-tick latency",
            points: &pts,
            references: &refs,
        },
    )
    .unwrap();
    let svg = std::fs::read_to_string(&lat).unwrap();
    assert_eq!(assert_y_ticks("latency.svg", &svg), 1);
    assert_readable_labels("latency.svg", &svg);
    assert!(svg.contains("1 ms target"));
    // a narrow range (less than a decade) still gets three ticks
    let narrow: Vec<(f64, f64)> = (1..30).map(|i| (i as f64, 400.0 + i as f64)).collect();
    latency_percentiles(
        &lat,
        &LatencyPercentiles {
            title: "narrow",
            points: &narrow,
            references: &[],
        },
    )
    .unwrap();
    assert_y_ticks(
        "narrow latency.svg",
        &std::fs::read_to_string(&lat).unwrap(),
    );

    let ticks: Vec<(f64, f64)> = (0..200)
        .map(|i| (i as f64 * 0.01, 80.0 + (i % 7) as f64 * 30.0))
        .collect();
    let steal = [(0.5, 0.0), (1.0, 12.0), (1.5, 3.0)];
    let tl = d.join("latency_timeline.svg");
    latency_timeline(
        &tl,
        &LatencyTimeline {
            title: "whole-tick latency over the run",
            ticks: &ticks,
            steal: &steal,
            references: &refs,
        },
    )
    .unwrap();
    let svg = std::fs::read_to_string(&tl).unwrap();
    assert_eq!(assert_y_ticks("latency_timeline.svg", &svg), 2);
    assert_readable_labels("latency_timeline.svg", &svg);
    // empty data: written, no panic
    latency_timeline(
        &tl,
        &LatencyTimeline {
            title: "empty",
            ticks: &[],
            steal: &[],
            references: &[],
        },
    )
    .unwrap();
    latency_percentiles(
        &lat,
        &LatencyPercentiles {
            title: "empty",
            points: &[(f64::NAN, -1.0)],
            references: &[],
        },
    )
    .unwrap();
}
