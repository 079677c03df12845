//! Figures of one mission (paper Figs. 3–4): nominal-only run dashed, filtered run solid.

use crate::chart::{Area, DrawResult, Line, Panel, RefLine, svg};
use crate::colour::palette;
use crate::{Geometry, PlotError};
use nalgebra::Vector3;
use plotters::prelude::*;
use sc_mission::StepRecord;
use sc_scenario::Scenario;
use std::path::{Path, PathBuf};

const CORRIDOR: RGBColor = RGBColor(44, 160, 44);
const CAZ: RGBColor = RGBColor(214, 39, 40);
const ZERO: RGBColor = RGBColor(214, 39, 40);
const PHASE: RGBColor = RGBColor(120, 120, 120);
const FILTERED: RGBColor = RGBColor(31, 119, 180);
const NOMINAL: RGBColor = RGBColor(255, 127, 14);

/// Line-of-sight direction (servicer base → grasping point) in F_B as two angles [deg]
/// from the boresight `d_B`: about the two axes of an orthonormal basis perpendicular to
/// `d_B` (for `d_B = x_B`: the y_B and z_B components). Inside the LOS cone of half-angle
/// β both are within ±β; `None` for a zero or non-finite vector.
pub fn los_angles_deg(grasp_b: &Vector3<f64>, boresight_b: &Vector3<f64>) -> Option<[f64; 2]> {
    let n = grasp_b.norm();
    if !n.is_finite() || n <= 0.0 {
        return None;
    }
    let s = grasp_b / n;
    let d = boresight_b;
    // e1: the axis of the basis least aligned with d, orthogonalised
    let pick = if d.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = (pick - d * d.dot(&pick)).normalize();
    let e2 = d.cross(&e1);
    let a = s.dot(&e1).atan2(s.dot(d)).to_degrees();
    let b = s.dot(&e2).atan2(s.dot(d)).to_degrees();
    Some([a, b])
}

/// The barrier panels: (title, y label, selector by constraint name).
type Family = (&'static str, &'static str, fn(&str) -> bool);
const FAMILIES: [&[Family]; 3] = [
    &[
        ("Translational: approach corridor", "h_AC [m]", |n| {
            n == "approach_corridor"
        }),
        (
            "Translational: collision-avoidance zone",
            "h_CAZ [m²]",
            |n| n == "collision_avoidance_zone",
        ),
    ],
    &[
        ("Attitude: line-of-sight cone", "h_ATT [-]", |n| {
            n == "line_of_sight"
        }),
        (
            "Attitude: rate limits (min of 6)",
            "min h_ω [rad/s]",
            |n| n.starts_with("omega_"),
        ),
    ],
    &[
        (
            "Robotic: joint angles (min of 7)",
            "min h_θ [rad²]",
            |n| n.starts_with("theta_") && !n.starts_with("theta_dot"),
        ),
        (
            "Robotic: joint rates (min of 14)",
            "min h_θ̇ [rad/s]",
            |n| n.starts_with("theta_dot"),
        ),
        (
            "Robotic: link–base spheres (min of 21)",
            "min h_LB [m²]",
            |n| n.starts_with("link_base"),
        ),
        (
            "Robotic: arm and base off the target (min of 22)",
            "min h_LT [m²]",
            |n| n.starts_with("link_target") || n == "base_target",
        ),
    ],
];

/// Time series of the minimum over the selected barriers.
fn family_series(records: &[StepRecord], select: fn(&str) -> bool) -> Vec<(f64, f64)> {
    let names = sc_mission::constraint_names();
    let idx: Vec<usize> = names
        .iter()
        .enumerate()
        .filter(|(_, n)| select(n))
        .map(|(i, _)| i)
        .collect();
    records
        .iter()
        .map(|r| {
            let h = r.h();
            let m = idx
                .iter()
                .filter_map(|&i| h.get(i).copied())
                .fold(f64::INFINITY, f64::min);
            (r.t, m)
        })
        .collect()
}

/// Starts of the phases after the first [s], dashed, labelled with the phase's name.
fn phase_lines(s: &Scenario) -> Vec<RefLine> {
    s.mission
        .phases
        .iter()
        .skip(1)
        .map(|p| RefLine::new(p.start_s, PHASE, p.name.replace('_', " ")).dashed())
        .collect()
}

/// The h = 0 line of a barrier panel: below it the barrier is violated.
fn zero_line() -> RefLine {
    RefLine::new(0.0, ZERO, "h = 0 (below: violated)")
}

/// The two runs, each as (records, label, colour, dashed).
struct Runs<'a> {
    runs: Vec<(&'a [StepRecord], &'static str, RGBColor, bool)>,
}

impl<'a> Runs<'a> {
    fn new(filtered: &'a [StepRecord], nominal: Option<&'a [StepRecord]>) -> Self {
        let mut runs = Vec::new();
        if let Some(n) = nominal {
            runs.push((n, "nominal", NOMINAL, true));
        }
        runs.push((filtered, "filtered", FILTERED, false));
        Self { runs }
    }

    fn lines(&self, f: impl Fn(&StepRecord) -> (f64, f64)) -> Vec<Line> {
        self.runs
            .iter()
            .map(|(r, label, c, dashed)| {
                Line::new(r.iter().map(&f).collect(), *c, *dashed).label(*label)
            })
            .collect()
    }
}

/// Section of the corridor cone and the CAZ sphere by the F_R coordinate plane (i, j).
fn zone_lines(g: &Geometry, i: usize, j: usize, reach: f64) -> Vec<Line> {
    let mut out = Vec::new();
    let (ax, ay) = (g.corridor_axis_r[i], g.corridor_axis_r[j]);
    let n = (ax * ax + ay * ay).sqrt();
    if n > 1e-6 {
        let psi = g.corridor_half_angle_deg.to_radians();
        for (k, s) in [1.0, -1.0].iter().enumerate() {
            let (c, sn) = (psi.cos(), s * psi.sin());
            let (dx, dy) = ((ax * c - ay * sn) / n, (ax * sn + ay * c) / n);
            let l = Line::new(vec![(0.0, 0.0), (dx * reach, dy * reach)], CORRIDOR, false);
            out.push(if k == 0 {
                l.label("approach corridor")
            } else {
                l
            });
        }
    }
    let circle: Vec<(f64, f64)> = (0..=120)
        .map(|k| {
            let a = k as f64 / 120.0 * std::f64::consts::TAU;
            (g.caz_radius_m * a.cos(), g.caz_radius_m * a.sin())
        })
        .collect();
    out.push(Line::new(circle, CAZ, false).label("collision-avoidance zone"));
    out
}

fn trajectory(area: &Area, runs: &Runs, g: &Geometry) -> DrawResult {
    let panels = area.split_evenly((2, 1));
    let reach = runs
        .runs
        .iter()
        .flat_map(|(r, ..)| r.iter().map(|x| x.obs.r_r.norm()))
        .filter(|x| x.is_finite())
        .fold(g.caz_radius_m, f64::max)
        * 1.05;
    for (k, (j, name)) in [(1usize, "y_R"), (2usize, "z_R")].iter().enumerate() {
        let mut p = Panel::new(
            &format!("Approach trajectory in F_R: x_R–{name} plane"),
            "x_R [m]",
            &format!("{name} [m]"),
        );
        p.lines = zone_lines(g, 0, *j, reach);
        p.lines
            .extend(runs.lines(|r| (r.obs.r_r[0], r.obs.r_r[*j])));
        let xs = runs
            .runs
            .iter()
            .flat_map(|(r, ..)| r.iter().map(|x| x.obs.r_r[0]));
        let ys = runs
            .runs
            .iter()
            .flat_map(|(r, ..)| r.iter().map(|x| x.obs.r_r[*j]));
        let xr = crate::chart::range(xs.chain([g.caz_radius_m, -g.caz_radius_m]), 0.05);
        let yr = crate::chart::range(ys.chain([g.caz_radius_m, -g.caz_radius_m]), 0.1);
        let (xr, yr) = crate::chart::equal_aspect(&panels[k], &p.title, xr, yr);
        p.x_range = Some(xr);
        p.y_range = Some(yr);
        p.draw(&panels[k])?;
    }
    Ok(())
}

/// Room above the barrier curves for a panel's legend (a fraction of the curves' span).
const BARRIER_LEGEND_HEADROOM: f64 = 0.45;

fn barriers(area: &Area, runs: &Runs, s: &Scenario) -> DrawResult {
    let rows = area.split_evenly((3, 1));
    for (row, fams) in rows.iter().zip(FAMILIES.iter()) {
        let cols = row.split_evenly((1, fams.len()));
        for (col, (title, ylabel, select)) in cols.iter().zip(fams.iter()) {
            let mut p = Panel::new(title, "t [s]", ylabel);
            p.legend_headroom = BARRIER_LEGEND_HEADROOM;
            p.hlines.push(zero_line());
            p.vlines = phase_lines(s);
            for (recs, label, c, dashed) in &runs.runs {
                p.lines
                    .push(Line::new(family_series(recs, *select), *c, *dashed).label(*label));
            }
            p.draw(col)?;
        }
    }
    Ok(())
}

fn range_rate(area: &Area, runs: &Runs, g: &Geometry) -> DrawResult {
    let mut p = Panel::new(
        "Range rate vs distance",
        "distance ‖r‖ [m]",
        "range rate d‖r‖/dt [m/s]",
    );
    p.vlines = vec![
        RefLine::new(g.caz_radius_m, CAZ, "R_CAZ").dashed(),
        RefLine::new(g.gfc_distance_m, CORRIDOR, "Go-for-Capture").dashed(),
    ];
    p.hlines
        .push(RefLine::new(0.0, PHASE, "0 (below: closing)"));
    // from contact to the farthest point, the zone boundaries always in view
    let far = runs
        .runs
        .iter()
        .flat_map(|(r, ..)| r.iter().map(|x| x.obs.r_r.norm()))
        .chain([g.caz_radius_m, g.gfc_distance_m])
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max);
    p.x_range = Some((0.0, if far > 0.0 { far * 1.02 } else { 1.0 }));
    p.lines = runs.lines(|r| {
        let d = r.obs.r_r.norm();
        (
            d,
            if d > 0.0 {
                r.obs.r_r.dot(&r.obs.v_r) / d
            } else {
                0.0
            },
        )
    });
    p.draw(area)
}

fn sync_error(area: &Area, runs: &Runs, s: &Scenario) -> DrawResult {
    let mut p = Panel::new(
        "Rate-synchronisation error ‖ω_B − R_BT ω_T‖",
        "t [s]",
        "sync error [rad/s]",
    );
    p.vlines = phase_lines(s);
    p.lines = runs.lines(|r| (r.t, r.obs.sync_error().norm()));
    p.draw(area)
}

/// Radius of the line-of-sight figure's start and end markers [px].
const LOS_MARKER_PX: u32 = 6;

/// The joint-torque figure starts this long before the grasping phase [s].
const BEFORE_GRASP_S: f64 = 5.0;

fn joint_torques(area: &Area, runs: &Runs, s: &Scenario, g: &Geometry) -> DrawResult {
    let grasp_start = s
        .mission
        .phases
        .iter()
        .find(|p| p.robotic == sc_scenario::RoboticMode::Grasp)
        .map(|p| p.start_s);
    let t_end = runs
        .runs
        .iter()
        .flat_map(|(r, ..)| r.last().map(|x| x.t))
        .fold(f64::NEG_INFINITY, f64::max);
    // the window around the grasp (the arm rests before it), said in the title; a run
    // that ended before it is shown whole
    let window = grasp_start
        .map(|t0| (t0 - BEFORE_GRASP_S, t_end.max(t0 + 1.0)))
        .filter(|(a, _)| t_end > *a);
    let title = match window {
        Some((a, b)) => format!(
            "Applied joint torques τ_M around the grasp, t = {a:.1}–{b:.1} s (filtered solid, nominal dashed)"
        ),
        None => "Applied joint torques τ_M (filtered solid, nominal dashed)".to_string(),
    };
    let mut p = Panel::new(&title, "t [s]", "τ_M [N m]");
    let max = g.joint_torque_max_nm;
    p.hlines = vec![
        RefLine::new(max, ZERO, format!("+|τ_M|max = {max} N m")),
        RefLine::new(-max, ZERO, format!("−|τ_M|max = −{max} N m")),
    ];
    p.vlines = phase_lines(s);
    let shown = |t: f64| window.is_none_or(|(a, b)| t >= a && t <= b);
    for (recs, _, _, dashed) in &runs.runs {
        for jn in 0..7 {
            // only the window's points: a line clipped at its edge drew a spike there
            let mut l = Line::new(
                recs.iter()
                    .filter(|r| shown(r.t))
                    .map(|r| (r.t, r.applied.tau[jn]))
                    .collect(),
                palette(jn),
                *dashed,
            );
            l.width = 1;
            // one legend entry per joint, in its colour; the title says what dashed is
            if !*dashed {
                l = l.label(format!("joint {}", jn + 1));
            }
            p.lines.push(l);
        }
    }
    p.x_range = window;
    p.draw(area)
}

fn los(area: &Area, runs: &Runs, g: &Geometry) -> DrawResult {
    let mut p = Panel::new(
        "Line of sight to the grasping point in F_B (cone of half-angle β)",
        "angle about e1 [deg]",
        "angle about e2 [deg]",
    );
    let b = g.los_half_angle_deg;
    let circle: Vec<(f64, f64)> = (0..=120)
        .map(|k| {
            let a = k as f64 / 120.0 * std::f64::consts::TAU;
            (b * a.cos(), b * a.sin())
        })
        .collect();
    p.lines
        .push(Line::new(circle, CORRIDOR, false).label("LOS cone"));
    let angles = |r: &StepRecord| {
        los_angles_deg(&r.obs.grasp_b, &g.boresight_b)
            .map(|a| (a[0], a[1]))
            .unwrap_or((f64::NAN, f64::NAN))
    };
    p.lines.extend(runs.lines(angles));
    // where the (first) run's line of sight starts and ends: the curve has no direction
    if let Some((recs, ..)) = runs.runs.iter().find(|(_, _, _, dashed)| !*dashed) {
        for (r, colour, what) in [(recs.first(), PHASE, "start"), (recs.last(), ZERO, "end")] {
            if let Some(r) = r {
                let mut m = Line::new(vec![angles(r)], colour, false)
                    .label(format!("{what}, t = {:.1} s", r.t));
                m.markers = true;
                m.width = LOS_MARKER_PX;
                p.lines.push(m);
            }
        }
    }
    let lim = b * 1.6;
    p.x_range = Some((-lim, lim));
    p.y_range = Some((-lim, lim));
    p.draw(area)
}

/// Writes the figures of a run into `dir` (created if missing) and returns their paths:
/// `trajectory.svg`, `barriers.svg`, `range_rate.svg`, `sync_error.svg`,
/// `joint_torques.svg`, `line_of_sight.svg`. `nominal`, if given, is drawn dashed.
pub fn run_figures(
    dir: &Path,
    scenario: &Scenario,
    filtered: &[StepRecord],
    nominal: Option<&[StepRecord]>,
) -> Result<Vec<PathBuf>, PlotError> {
    std::fs::create_dir_all(dir).map_err(|err| PlotError::Io {
        path: dir.display().to_string(),
        message: err.to_string(),
    })?;
    let g = Geometry::from_scenario(scenario);
    let runs = Runs::new(filtered, nominal);
    let mut out = Vec::new();
    let mut emit = |name: &str, size: (u32, u32), f: &dyn Fn(&Area) -> DrawResult| {
        let p = dir.join(name);
        svg(&p, size, f)?;
        out.push(p);
        Ok::<(), PlotError>(())
    };
    emit("trajectory.svg", (1000, 800), &|a| trajectory(a, &runs, &g))?;
    emit("barriers.svg", (1500, 1000), &|a| {
        barriers(a, &runs, scenario)
    })?;
    emit("range_rate.svg", (900, 550), &|a| range_rate(a, &runs, &g))?;
    emit("sync_error.svg", (900, 550), &|a| {
        sync_error(a, &runs, scenario)
    })?;
    emit("joint_torques.svg", (900, 550), &|a| {
        joint_torques(a, &runs, scenario, &g)
    })?;
    emit("line_of_sight.svg", (700, 650), &|a| los(a, &runs, &g))?;
    Ok(out)
}
