//! Figures of the partition's latency benchmark: the whole-tick latency distribution as
//! percentiles (log–log) and the latency of every tick over the run above the host's
//! steal rate. Reference latencies (a target, a paper's figure) are drawn as labelled
//! lines.

use crate::PlotError;
use crate::chart::{Area, DrawResult, Line, Panel, RefLine, svg};
use plotters::style::RGBColor;
use std::path::Path;

const LATENCY: RGBColor = RGBColor(31, 119, 180);
const STEAL: RGBColor = RGBColor(60, 60, 60);
/// Colours of the reference lines, in turn.
const REFERENCES: [RGBColor; 3] = [
    RGBColor(214, 39, 40),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
];
/// Radius of a tick's dot in the timeline [px].
const DOT: u32 = 2;
/// Figure sizes [px].
const PERCENTILES_SIZE: (u32, u32) = (900, 560);
const TIMELINE_SIZE: (u32, u32) = (1000, 640);
/// Height of the latency panel of the timeline [px]; the steal panel gets the rest.
const TIMELINE_TOP: u32 = 420;

/// The latency distribution figure.
#[derive(Debug, Clone)]
pub struct LatencyPercentiles<'a> {
    pub title: &'a str,
    /// (1/(1−p), latency [µs]) for percentiles p, as an HDR histogram's percentile
    /// distribution lists them; non-positive and non-finite points are not drawn.
    pub points: &'a [(f64, f64)],
    /// Horizontal reference latencies [µs], each with its label (e.g. "1 ms target").
    pub references: &'a [(String, f64)],
}

/// The latency-over-the-run figure.
#[derive(Debug, Clone)]
pub struct LatencyTimeline<'a> {
    pub title: &'a str,
    /// (time since the first measured tick [s], whole-tick latency [µs]) per tick.
    pub ticks: &'a [(f64, f64)],
    /// (time [s], host steal rate [ms of CPU per s]) between the steal counter's readings.
    pub steal: &'a [(f64, f64)],
    /// Horizontal reference latencies [µs] with their labels.
    pub references: &'a [(String, f64)],
}

fn reference_lines(refs: &[(String, f64)]) -> Vec<RefLine> {
    refs.iter()
        .zip(REFERENCES.iter().cycle())
        .map(|((label, v), c)| RefLine::new(*v, *c, label.as_str()).dashed())
        .collect()
}

/// Writes the percentile plot (log–log) to `path` (SVG).
pub fn latency_percentiles(path: &Path, f: &LatencyPercentiles) -> Result<(), PlotError> {
    svg(path, PERCENTILES_SIZE, |area| {
        let mut p = Panel::new(
            f.title,
            "percentile as 1/(1−p): 10 = p90, 100 = p99, 1000 = p99.9",
            "whole-tick latency [µs]",
        );
        p.x_log = true;
        p.y_log = true;
        p.hlines = reference_lines(f.references);
        p.lines
            .push(Line::new(f.points.to_vec(), LATENCY, false).label("whole tick"));
        // from the median on, as far as the data go
        let x_hi = f
            .points
            .iter()
            .map(|q| q.0)
            .filter(|x| x.is_finite() && *x > 0.0)
            .fold(10.0, f64::max);
        p.x_range = Some((1.0, x_hi * 1.5));
        p.draw(area)
    })
}

fn timeline(area: &Area, f: &LatencyTimeline) -> DrawResult {
    let (top, bottom) = area.split_vertically(TIMELINE_TOP);
    let t_end = f
        .ticks
        .iter()
        .chain(f.steal.iter())
        .map(|q| q.0)
        .filter(|t| t.is_finite())
        .fold(0.0, f64::max);
    let x_range = Some((0.0, if t_end > 0.0 { t_end } else { 1.0 }));
    let mut p = Panel::new(f.title, "", "whole-tick latency [µs]");
    p.y_log = true;
    p.x_range = x_range;
    p.hlines = reference_lines(f.references);
    let mut dots = Line::new(f.ticks.to_vec(), LATENCY, false).label("one tick");
    dots.markers = true;
    dots.width = DOT;
    p.lines.push(dots);
    p.draw(&top)?;
    let mut q = Panel::new(
        "",
        "time since the first measured tick [s]",
        "host steal [ms/s]",
    );
    q.x_range = x_range;
    q.lines
        .push(Line::new(f.steal.to_vec(), STEAL, false).label("host steal rate"));
    let hi = f
        .steal
        .iter()
        .map(|s| s.1)
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    q.y_range = Some((0.0, if hi > 0.0 { hi * 1.1 } else { 1.0 }));
    q.draw(&bottom)
}

/// Writes the timeline (latency per tick, log scale, above the host's steal rate) to
/// `path` (SVG).
pub fn latency_timeline(path: &Path, f: &LatencyTimeline) -> Result<(), PlotError> {
    svg(path, TIMELINE_SIZE, |area| timeline(area, f))
}
