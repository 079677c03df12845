//! Figures of a Monte Carlo campaign (paper Figs. 5–6).

use crate::chart::{
    Area, Axis, DrawResult, FONT, RefLine, TICKS, colour_bar, e, label_at, legend, log_coord,
    range, ref_lines, standard, svg, swatch, with_bar,
};
use crate::colour::viridis;
use crate::ticks::log_label;
use crate::{Geometry, PlotError};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::{Path, PathBuf};

const CORRIDOR: RGBColor = RGBColor(44, 160, 44);
const CAZ: RGBColor = RGBColor(214, 39, 40);
const GEOMEAN: RGBColor = RGBColor(31, 119, 180);
const MAX: RGBColor = RGBColor(255, 127, 14);
const CPU_GEOMEAN: RGBColor = RGBColor(158, 202, 225);
const CPU_MAX: RGBColor = RGBColor(253, 190, 133);
const LEVELS: usize = 32;
/// Histogram bins of a barrier's minima.
const BINS: usize = 20;
/// Barrier-minima cells per row.
const MINIMA_COLS: usize = 7;
/// Height of one row of barrier-minima cells, and of the figure's title strip [px].
const MINIMA_ROW_PX: u32 = 170;
const MINIMA_TITLE_PX: u32 = 30;
/// Width of a line of the zone geometry [px].
const ZONE_WIDTH: u32 = 2;

/// One decimated sample of a run's trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TracePoint {
    pub t: f64,
    pub phase: usize,
    /// Servicer base position w.r.t. the target CoM in F_R [m].
    pub r_r: [f64; 3],
    /// ‖v_R‖ [m/s].
    pub speed: f64,
    /// Line of sight in F_B as angles from the boresight [deg] (see [`crate::los_angles_deg`]).
    pub los_deg: [f64; 2],
    /// ‖ω_B − R_BT ω_T‖ [rad/s].
    pub sync_error: f64,
}

/// One run's point of the torque-vs-synchronisation scatter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunPoint {
    pub run: usize,
    /// Target tumbling rate [rad/s].
    pub tumble_rate: f64,
    /// Peak synchronisation error in the grasping phase [rad/s].
    pub peak_sync_grasp: f64,
    /// Joint-torque norm in the grasping phase [N m].
    pub torque_norm_grasp: f64,
}

/// Solve-time statistics of one filter (or the total) over the campaign [µs].
#[derive(Debug, Clone, PartialEq)]
pub struct RuntimeBar {
    pub name: String,
    /// Wall clock (what a deadline sees, preemption included).
    pub geomean_us: f64,
    pub max_us: f64,
    /// The filters' thread CPU time (their own work); NaN if not measured.
    pub cpu_geomean_us: f64,
    pub cpu_max_us: f64,
}

/// Every run's minimum of one barrier.
#[derive(Debug, Clone, PartialEq)]
pub struct BarrierMinima {
    pub name: String,
    pub values: Vec<f64>,
}

/// Everything the campaign figures show.
#[derive(Debug, Clone)]
pub struct CampaignFigures<'a> {
    pub geometry: Geometry,
    /// (run index, decimated trajectory) per successful run.
    pub traces: &'a [(usize, Vec<TracePoint>)],
    pub points: &'a [RunPoint],
    /// The total first, then one per filter.
    pub runtime: &'a [RuntimeBar],
    /// Reference total solve times (geomean, max) [µs] drawn as dashed lines, e.g. the paper's.
    pub runtime_reference: Option<(String, f64, f64)>,
    pub minima: &'a [BarrierMinima],
}

/// Polylines of consecutive points with the same colour level (keeps the SVG small).
fn coloured_runs(pts: &[(f64, f64, f64)], lo: f64, hi: f64) -> Vec<(usize, Vec<(f64, f64)>)> {
    let level = |v: f64| {
        let t = if hi > lo { (v - lo) / (hi - lo) } else { 0.0 };
        ((t.clamp(0.0, 1.0) * (LEVELS - 1) as f64).round()) as usize
    };
    let mut out: Vec<(usize, Vec<(f64, f64)>)> = Vec::new();
    let finite: Vec<&(f64, f64, f64)> = pts
        .iter()
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    for w in finite.windows(2) {
        let l = level(0.5 * (w[0].2 + w[1].2));
        match out.last_mut() {
            Some((last, line)) if *last == l => line.push((w[1].0, w[1].1)),
            _ => out.push((l, vec![(w[0].0, w[0].1), (w[1].0, w[1].1)])),
        }
    }
    out
}

fn level_colour(l: usize) -> RGBColor {
    viridis(l as f64 / (LEVELS - 1) as f64)
}

fn trajectories(area: &Area, f: &CampaignFigures) -> DrawResult {
    let g = &f.geometry;
    let (main, bar) = with_bar(area, 110);
    let all = || f.traces.iter().flat_map(|(_, t)| t.iter());
    let speed = range(all().map(|p| p.speed), 0.0);
    let speed = (speed.0.max(0.0), speed.1);
    let xr = range(
        all()
            .map(|p| p.r_r[0])
            .chain([g.caz_radius_m, -g.caz_radius_m]),
        0.05,
    );
    let yr = range(
        all()
            .map(|p| p.r_r[1])
            .chain([g.caz_radius_m, -g.caz_radius_m]),
        0.1,
    );
    let title = format!(
        "Approach trajectories of {} runs in F_R (x_R–y_R), coloured by speed",
        f.traces.len()
    );
    let (xr, yr) = crate::chart::equal_aspect(&main, &title, xr, yr);
    let (xa, ya) = (Axis::linear(xr, TICKS), Axis::linear(yr, TICKS));
    let mut chart = standard(&main, &title)
        .build_cartesian_2d(xa.coord(), ya.coord())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("x_R [m]")
        .y_desc("y_R [m]")
        .x_label_formatter(&|v| xa.label(*v))
        .y_label_formatter(&|v| ya.label(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(e)?;
    let reach = xr.0.abs().max(xr.1.abs()) * 1.5;
    let (ax, ay) = (g.corridor_axis_r[0], g.corridor_axis_r[1]);
    let n = (ax * ax + ay * ay).sqrt();
    if n > 1e-6 {
        let psi = g.corridor_half_angle_deg.to_radians();
        for s in [1.0, -1.0] {
            let (c, sn) = (psi.cos(), s * psi.sin());
            let (dx, dy) = ((ax * c - ay * sn) / n, (ax * sn + ay * c) / n);
            let a = chart
                .draw_series(LineSeries::new(
                    vec![(0.0, 0.0), (dx * reach, dy * reach)],
                    CORRIDOR.stroke_width(ZONE_WIDTH),
                ))
                .map_err(e)?;
            if s > 0.0 {
                a.label("approach corridor")
                    .legend(|p| swatch(p, CORRIDOR, ZONE_WIDTH, false));
            }
        }
    }
    let circle: Vec<(f64, f64)> = (0..=120)
        .map(|k| {
            let a = k as f64 / 120.0 * std::f64::consts::TAU;
            (g.caz_radius_m * a.cos(), g.caz_radius_m * a.sin())
        })
        .collect();
    chart
        .draw_series(LineSeries::new(circle, CAZ.stroke_width(ZONE_WIDTH)))
        .map_err(e)?
        .label("collision-avoidance zone")
        .legend(|p| swatch(p, CAZ, ZONE_WIDTH, false));
    for (_, t) in f.traces {
        let pts: Vec<(f64, f64, f64)> = t.iter().map(|p| (p.r_r[0], p.r_r[1], p.speed)).collect();
        for (l, line) in coloured_runs(&pts, speed.0, speed.1) {
            chart
                .draw_series(LineSeries::new(line, level_colour(l).stroke_width(1)))
                .map_err(e)?;
        }
    }
    legend(&mut chart)?;
    colour_bar(&bar, "speed ‖v_R‖ [m/s]", speed.0, speed.1)
}

fn attitude(area: &Area, f: &CampaignFigures) -> DrawResult {
    let b = f.geometry.los_half_angle_deg;
    let (main, bar) = with_bar(area, 110);
    let all = || f.traces.iter().flat_map(|(_, t)| t.iter());
    let err = range(all().map(|p| p.sync_error), 0.0);
    let err = (err.0.max(0.0), err.1);
    let lim = all()
        .flat_map(|p| p.los_deg)
        .filter(|x| x.is_finite())
        .fold(b * 1.3, |m, x| m.max(x.abs() * 1.05));
    let a = Axis::linear((-lim, lim), TICKS);
    let mut chart = standard(
        &main,
        "Line of sight in F_B against the LOS cone, coloured by sync error",
    )
    .build_cartesian_2d(a.coord(), a.coord())
    .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("LOS angle towards e1 (y_B for d_B = x_B) [deg]")
        .y_desc("LOS angle towards e2 (z_B for d_B = x_B) [deg]")
        .x_label_formatter(&|v| a.label(*v))
        .y_label_formatter(&|v| a.label(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(e)?;
    let circle: Vec<(f64, f64)> = (0..=120)
        .map(|k| {
            let a = k as f64 / 120.0 * std::f64::consts::TAU;
            (b * a.cos(), b * a.sin())
        })
        .collect();
    chart
        .draw_series(LineSeries::new(circle, CORRIDOR.stroke_width(ZONE_WIDTH)))
        .map_err(e)?
        .label(format!("LOS cone, β = {b}°"))
        .legend(|p| swatch(p, CORRIDOR, ZONE_WIDTH, false));
    for (_, t) in f.traces {
        let pts: Vec<(f64, f64, f64)> = t
            .iter()
            .map(|p| (p.los_deg[0], p.los_deg[1], p.sync_error))
            .collect();
        for (l, line) in coloured_runs(&pts, err.0, err.1) {
            chart
                .draw_series(LineSeries::new(line, level_colour(l).stroke_width(1)))
                .map_err(e)?;
        }
    }
    legend(&mut chart)?;
    colour_bar(&bar, "sync error [rad/s]", err.0, err.1)
}

fn scatter(area: &Area, f: &CampaignFigures) -> DrawResult {
    let (main, bar) = with_bar(area, 110);
    let rate = range(f.points.iter().map(|p| p.tumble_rate), 0.0);
    let xr = range(f.points.iter().map(|p| p.peak_sync_grasp), 0.08);
    let yr = range(f.points.iter().map(|p| p.torque_norm_grasp), 0.08);
    let (xa, ya) = (Axis::linear(xr, TICKS), Axis::linear(yr, TICKS));
    let mut chart = standard(
        &main,
        "Grasping (III): joint-torque norm vs peak sync error, coloured by tumbling rate",
    )
    .build_cartesian_2d(xa.coord(), ya.coord())
    .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("peak sync error in grasping [rad/s]")
        .y_desc("RMS joint-torque norm ‖τ_M‖ in grasping [N m]")
        .x_label_formatter(&|v| xa.label(*v))
        .y_label_formatter(&|v| ya.label(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(e)?;
    let t = |v: f64| {
        if rate.1 > rate.0 {
            (v - rate.0) / (rate.1 - rate.0)
        } else {
            0.0
        }
    };
    chart
        .draw_series(
            f.points
                .iter()
                .filter(|p| p.peak_sync_grasp.is_finite() && p.torque_norm_grasp.is_finite())
                .map(|p| {
                    Circle::new(
                        (p.peak_sync_grasp, p.torque_norm_grasp),
                        4,
                        viridis(t(p.tumble_rate)).filled(),
                    )
                }),
        )
        .map_err(e)?;
    colour_bar(&bar, "tumbling rate [rad/s]", rate.0, rate.1)
}

/// The solve-time bars: the safety layer's total on the left, each filter's QP on the
/// right, on one log axis; the paper's figures as reference lines on the total's panel.
fn runtime(area: &Area, f: &CampaignFigures) -> DrawResult {
    let panels = area.split_horizontally(area.dim_in_pixel().0 / 3);
    let groups: [(&Area, &[RuntimeBar], &str); 2] = [
        (
            &panels.0,
            &f.runtime[..f.runtime.len().min(1)],
            "Safety layer (total)",
        ),
        (
            &panels.1,
            &f.runtime[f.runtime.len().min(1)..],
            "Per filter QP",
        ),
    ];
    let (lo, hi) = runtime_range(f);
    for (k, (area, bars, title)) in groups.iter().enumerate() {
        let n = bars.len().max(1) as f64;
        let mut chart = standard(area, title)
            .build_cartesian_2d(0.0..n, log_coord(lo, hi))
            .map_err(e)?;
        let names: Vec<String> = bars.iter().map(|b| b.name.clone()).collect();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(bars.len().max(1) * 2 + 1)
            .x_label_formatter(&|x| {
                let i = x.floor() as usize;
                if (x - x.floor() - 0.5).abs() < 1e-6 {
                    names.get(i).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .y_label_formatter(&|v| log_label(*v))
            .y_desc("solve time per control step [µs]")
            .draw()
            .map_err(e)?;
        for (i, b) in bars.iter().enumerate() {
            runtime_bar(&mut chart, i, b, lo)?;
        }
        if k == 0
            && let Some((name, g, m)) = &f.runtime_reference
        {
            for (v, c, what) in [(*g, GEOMEAN, "geomean"), (*m, MAX, "max")] {
                // labelled in the legend (a label on the line would cross the bars)
                let r = RefLine::new(v, c, "").dashed();
                ref_lines(&mut chart, (0.0, n), (lo, hi), &[(v, &r)], &[])?;
                chart
                    .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                    .map_err(e)?
                    .label(format!("{name} {what}: {}", duration_us(v)))
                    .legend(move |p| swatch(p, c, 1, true));
            }
        }
        legend(&mut chart)?;
    }
    Ok(())
}

/// The log axis of the solve times: from a third of the smallest positive value to 40
/// times the largest (room for the labels above the bars), the reference included.
fn runtime_range(f: &CampaignFigures) -> (f64, f64) {
    let mut vals: Vec<f64> = f
        .runtime
        .iter()
        .flat_map(|b| [b.geomean_us, b.max_us, b.cpu_geomean_us, b.cpu_max_us])
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    if let Some((_, g, m)) = &f.runtime_reference {
        vals.extend([*g, *m]);
    }
    let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = vals.iter().copied().fold(0.0, f64::max);
    if lo.is_finite() && hi > 0.0 {
        (lo / 3.0, hi * 40.0)
    } else {
        (0.1, 10.0)
    }
}

/// The four bars of `b` (wall and CPU, geometric mean and maximum) at slot `i`, each
/// with its value above it; the first slot's bars make the legend.
fn runtime_bar<'a, 'b: 'a, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    i: usize,
    b: &RuntimeBar,
    lo: f64,
) -> DrawResult {
    const LEGEND: [&str; 4] = [
        "geometric mean (wall)",
        "maximum (wall)",
        "geometric mean (thread CPU)",
        "maximum (thread CPU)",
    ];
    let x = i as f64;
    for (j, (v, c)) in [
        (b.geomean_us, GEOMEAN),
        (b.max_us, MAX),
        (b.cpu_geomean_us, CPU_GEOMEAN),
        (b.cpu_max_us, CPU_MAX),
    ]
    .iter()
    .enumerate()
    {
        if v.is_finite() && *v > lo {
            let x0 = x + 0.08 + 0.21 * j as f64;
            let a = chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x0, lo), (x0 + 0.19, *v)],
                    c.filled(),
                )))
                .map_err(e)?;
            if i == 0 {
                let c = *c;
                a.label(LEGEND[j]).legend(move |(px, py)| {
                    Rectangle::new([(px, py - 5), (px + 12, py + 5)], c.filled())
                });
            }
            chart
                .draw_series(std::iter::once(Text::new(
                    duration_us(*v),
                    (x0, *v * 1.15),
                    (FONT, 12),
                )))
                .map_err(e)?;
        }
    }
    Ok(())
}

/// A duration given in µs as a reader wants it: `13.8 µs`, `1.59 ms`, `12 s`.
fn duration_us(v: f64) -> String {
    if v.abs() >= 1e6 {
        format!("{} s", round_sig(v / 1e6))
    } else if v.abs() >= 1000.0 {
        format!("{} ms", round_sig(v / 1000.0))
    } else {
        format!("{} µs", round_sig(v))
    }
}

/// `v` with three significant digits, no trailing zeros.
fn round_sig(v: f64) -> String {
    // linear_label shows one decimal more than its step
    crate::ticks::linear_label(v, 10f64.powf(v.abs().log10().floor() - 1.0))
}

fn minima(area: &Area, f: &CampaignFigures) -> DrawResult {
    let (head, body) = area.split_vertically(MINIMA_TITLE_PX);
    head.draw(&Text::new(
        "Every barrier's minimum over each run: runs per bin; h < 0 (left of the red h = 0 line) is a violation",
        (10, 8),
        (FONT, 16),
    ))
    .map_err(e)?;
    let rows = f.minima.len().div_ceil(MINIMA_COLS).max(1);
    let cells = body.split_evenly((rows, MINIMA_COLS));
    for (cell, m) in cells.iter().zip(f.minima.iter()) {
        let vals: Vec<f64> = m.values.iter().copied().filter(|v| v.is_finite()).collect();
        // 0 always in range, so that the margin to the boundary is seen
        let (lo, hi) = range(vals.iter().copied().chain([0.0]), 0.05);
        let w = (hi - lo) / BINS as f64;
        let mut counts = [0usize; BINS];
        for v in &vals {
            let i = (((v - lo) / w).floor().max(0.0) as usize).min(BINS - 1);
            counts[i] += 1;
        }
        let top = counts.iter().copied().max().unwrap_or(0).max(1) as f64 * 1.15;
        let colour = if vals.iter().any(|v| *v < 0.0) {
            CAZ
        } else {
            GEOMEAN
        };
        let (xa, ya) = (Axis::linear((lo, hi), 4), Axis::counts((0.0, top), 4));
        let mut chart = ChartBuilder::on(cell)
            .caption(&m.name, (FONT, 13))
            .margin(4)
            .x_label_area_size(34)
            .y_label_area_size(40)
            .build_cartesian_2d(xa.coord(), ya.coord())
            .map_err(e)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(format!(
                "minimum of h [{}]",
                sc_cbf::names::unit(&m.name).unwrap_or("?")
            ))
            .y_desc("runs")
            .x_label_formatter(&|v| xa.label(*v))
            .y_label_formatter(&|v| ya.label(*v))
            .x_label_style((FONT, 10))
            .y_label_style((FONT, 10))
            .axis_desc_style((FONT, 11))
            .draw()
            .map_err(e)?;
        chart
            .draw_series(
                counts
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| **c > 0)
                    .map(|(i, c)| {
                        let x0 = lo + w * i as f64;
                        Rectangle::new([(x0, 0.0), (x0 + w, *c as f64)], colour.mix(0.8).filled())
                    }),
            )
            .map_err(e)?;
        chart
            .draw_series(LineSeries::new(
                vec![(0.0, 0.0), (0.0, ya.hi)],
                CAZ.stroke_width(ZONE_WIDTH),
            ))
            .map_err(e)?;
        // label on the side of the line with more room
        let right = hi > -lo;
        label_at(
            &mut chart,
            (0.0, ya.hi),
            (if right { 3 } else { -3 }, 2),
            "h = 0",
            CAZ,
            (if right { HPos::Left } else { HPos::Right }, VPos::Top),
        )?;
    }
    Ok(())
}

/// Writes the campaign figures into `dir` (created if missing) and returns their paths:
/// `runtime.svg`, `trajectories_xy.svg`, `attitude_los.svg`, `torque_vs_sync.svg`,
/// `barrier_minima.svg`. Only `runtime.svg` depends on wall-clock data.
pub fn campaign_figures(dir: &Path, f: &CampaignFigures) -> Result<Vec<PathBuf>, PlotError> {
    std::fs::create_dir_all(dir).map_err(|err| PlotError::Io {
        path: dir.display().to_string(),
        message: err.to_string(),
    })?;
    let mut out = Vec::new();
    let mut emit = |name: &str, size: (u32, u32), draw: &dyn Fn(&Area) -> DrawResult| {
        let p = dir.join(name);
        svg(&p, size, draw)?;
        out.push(p);
        Ok::<(), PlotError>(())
    };
    emit("runtime.svg", (1000, 500), &|a| runtime(a, f))?;
    emit("trajectories_xy.svg", (1100, 600), &|a| trajectories(a, f))?;
    emit("attitude_los.svg", (800, 700), &|a| attitude(a, f))?;
    emit("torque_vs_sync.svg", (850, 600), &|a| scatter(a, f))?;
    let rows = f.minima.len().div_ceil(MINIMA_COLS).max(1) as u32;
    emit(
        "barrier_minima.svg",
        (1400, MINIMA_TITLE_PX + MINIMA_ROW_PX * rows),
        &|a| minima(a, f),
    )?;
    Ok(out)
}
