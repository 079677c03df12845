//! Small drawing helpers over plotters' SVG backend.

use crate::PlotError;
use crate::colour::viridis;
use crate::ticks::{MIN_TICKS, linear_label, linear_ticks, log_label, log_ticks, step_of};
use plotters::chart::SeriesAnno;
use plotters::coord::Shift;
use plotters::coord::combinators::LogCoord;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters_backend::DrawingErrorKind;
use std::path::Path;

/// Font family of every text (resolved by the viewer, or by [`crate::export_figures`]).
pub const FONT: &str = "sans-serif";
/// Caption font size [px].
pub const TITLE_PX: u32 = 18;
/// Margin around a chart [px].
pub const MARGIN: u32 = 8;
/// Height of the x label area (tick labels and axis description) [px].
pub const X_LABEL_AREA: u32 = 40;
/// Width of the y label area [px].
pub const Y_LABEL_AREA: u32 = 64;
/// Ticks a linear axis gets at most.
pub const TICKS: usize = 6;
/// Powers of ten a log axis labels at most (beyond, every other one or fewer).
pub const LOG_TICKS: usize = 10;
/// Dash and gap of a dashed series [px]; legend swatches use the same.
pub const DASH: u32 = 6;
pub const GAP: u32 = 4;
/// Length of a legend swatch [px] (three dashes of a dashed series).
const SWATCH: i32 = 26;
/// Room for the swatch before a legend label [px].
const LEGEND_AREA: u32 = 34;
/// Integer steps tried for a count axis (1, 2, 5, 10, … up to 5e6).
const COUNT_STEP_TRIES: usize = 21;
/// Room above the highest integer tick of a count axis (in counts).
const COUNT_HEADROOM: f64 = 0.15;
/// Opacity of scatter markers (overlapping dots stay visible).
const MARKER_OPACITY: f64 = 0.6;
/// Font size of reference-line labels [px].
pub const REF_LABEL_PX: u32 = 12;
/// Width of a character of sans-serif text, as a share of the font size (generous).
const CHAR_WIDTH: f64 = 0.6;
/// Offset of a reference-line label from its line [px].
const REF_LABEL_OFFSET: i32 = 3;

pub type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
pub type DrawResult = Result<(), DrawError>;

/// Why a figure could not be drawn (inside [`crate::PlotError::Draw`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DrawError {
    /// The plotting library refused: its message (plotters' errors are generic over the
    /// backend, so their text is kept).
    #[error("{0}")]
    Backend(String),
    /// The plotting library panicked (it has a few panics on degenerate input).
    #[error("plotting library panicked")]
    Panicked,
}

/// Maps any plotters error to a [`DrawError`].
pub fn e<T: std::fmt::Display>(x: T) -> DrawError {
    DrawError::Backend(x.to_string())
}

/// Ranges for a spatial chart of the standard layout ([`Panel`]: caption `title`,
/// [`MARGIN`], [`X_LABEL_AREA`], [`Y_LABEL_AREA`]) on `area`: the shorter range is widened about its centre so
/// that a metre is as long on both axes and a sphere is drawn round.
pub fn equal_aspect(
    area: &Area,
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
) -> ((f64, f64), (f64, f64)) {
    // the plotting area this layout leaves, measured on a scratch canvas of the same size
    let mut scratch = String::new();
    let root = SVGBackend::with_string(&mut scratch, area.dim_in_pixel()).into_drawing_area();
    let Ok(chart) = standard(&root, title).build_cartesian_2d(0f64..1.0, 0f64..1.0) else {
        return (x, y);
    };
    let (w, h) = chart.plotting_area().dim_in_pixel();
    if w == 0 || h == 0 {
        return (x, y);
    }
    let per_px = ((x.1 - x.0) / w as f64).max((y.1 - y.0) / h as f64);
    let widen = |r: (f64, f64), px: u32| {
        let (c, half) = (0.5 * (r.0 + r.1), 0.5 * per_px * px as f64);
        (c - half, c + half)
    };
    (widen(x, w), widen(y, h))
}

/// Renders an SVG of `size` with `draw` and writes it to `path`. A panic inside plotters
/// (it has a few on degenerate input) is caught and reported as an error.
pub fn svg(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&Area) -> DrawResult,
) -> Result<(), PlotError> {
    let shown = path.display().to_string();
    let mut text = String::new();
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let backend = SVGBackend::with_string(&mut text, size);
        let root = backend.into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        draw(&root)?;
        root.present().map_err(e)
    }));
    match outcome {
        Ok(Ok(())) => {}
        Ok(Err(source)) => {
            return Err(PlotError::Draw {
                path: shown,
                source,
            });
        }
        Err(_) => {
            return Err(PlotError::Draw {
                path: shown,
                source: DrawError::Panicked,
            });
        }
    }
    std::fs::write(path, text).map_err(|err| PlotError::Io {
        path: shown,
        message: err.to_string(),
    })
}

/// Finite range of `values`, padded by `pad` of its width; a unit range if empty.
pub fn range(values: impl IntoIterator<Item = f64>, pad: f64) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for v in values {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    let w = hi - lo;
    let w = if w > 1e-12 * (lo.abs() + hi.abs()).max(1e-300) {
        w
    } else {
        lo.abs().max(1.0) * 0.1
    };
    (lo - pad * w, hi + pad * w)
}

/// The standard chart layout: caption, margin and label areas.
pub fn standard<'a, 'b>(area: &'a Area<'b>, title: &str) -> ChartBuilder<'a, 'b, SVGBackend<'b>> {
    let mut b = ChartBuilder::on(area);
    if !title.is_empty() {
        b.caption(title, (FONT, TITLE_PX));
    }
    b.margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA);
    b
}

/// One axis in drawing units (log10 of the value on a log axis), with its ticks.
#[derive(Debug, Clone)]
pub struct Axis {
    pub lo: f64,
    pub hi: f64,
    pub log: bool,
    /// In drawing units.
    pub ticks: Vec<f64>,
    step: f64,
}

impl Axis {
    /// A linear axis over `r` (a unit range if `r` is empty or not finite).
    pub fn linear(r: (f64, f64), max_ticks: usize) -> Self {
        let (lo, hi) = sane(r);
        let ticks = linear_ticks(lo, hi, max_ticks);
        Self {
            lo,
            hi,
            log: false,
            step: step_of(&ticks),
            ticks,
        }
    }

    /// A linear axis over `r` with integer ticks (counts) 1, 2 or 5 × 10^k apart, widened
    /// up to at least [`MIN_TICKS`] integers; at least [`MIN_TICKS`] ticks, a little more
    /// than `max_ticks` if round steps allow no fewer.
    pub fn counts(r: (f64, f64), max_ticks: usize) -> Self {
        let (lo, hi) = sane(r);
        let hi = hi.max(lo.ceil() + (MIN_TICKS - 1) as f64 + COUNT_HEADROOM);
        let max_ticks = max_ticks.max(MIN_TICKS);
        let mut a = Self::linear((lo, hi), max_ticks);
        let integers = |step: f64| -> Vec<f64> {
            ((lo / step).ceil() as i64..=(hi / step).floor() as i64)
                .map(|k| k as f64 * step)
                .collect()
        };
        let steps = (0..).flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)));
        // the finest step with at most max_ticks, unless that leaves too few: then the
        // step before it (a tick or two over max_ticks)
        let mut prev: Option<(Vec<f64>, f64)> = None;
        for step in steps.take(COUNT_STEP_TRIES) {
            let t = integers(step);
            if t.len() <= max_ticks {
                let (t, step) = match prev {
                    Some(p) if t.len() < MIN_TICKS => p,
                    _ => (t, step),
                };
                a.ticks = t;
                a.step = step;
                break;
            }
            prev = Some((t, step));
        }
        a
    }

    /// A log axis over `r` given in drawing units (log10 of the values).
    pub fn log10(r: (f64, f64), max_ticks: usize) -> Self {
        let (lo, hi) = sane(r);
        let ticks = log_ticks(10f64.powf(lo), 10f64.powf(hi), max_ticks)
            .into_iter()
            .map(f64::log10)
            .collect();
        Self {
            lo,
            hi,
            log: true,
            ticks,
            step: 0.0,
        }
    }

    /// The value in drawing units (NaN for a non-positive value on a log axis).
    pub fn map(&self, v: f64) -> f64 {
        to_axis(v, self.log)
    }

    /// The tick label of `v` in drawing units.
    pub fn label(&self, v: f64) -> String {
        if self.log {
            log_label(10f64.powf(v))
        } else {
            linear_label(v, self.step)
        }
    }

    /// The plotters coordinate with exactly these ticks.
    pub fn coord(&self) -> Ticked<RangedCoordf64> {
        Ticked {
            inner: (self.lo..self.hi).into(),
            ticks: self.ticks.clone(),
        }
    }
}

/// A plotters coordinate whose ticks are given (no minor ticks).
#[derive(Clone)]
pub struct Ticked<R> {
    pub inner: R,
    pub ticks: Vec<f64>,
}

/// A log coordinate over `lo..hi` (data units, both > 0) with [`log_ticks`].
pub fn log_coord(lo: f64, hi: f64) -> Ticked<LogCoord<f64>> {
    Ticked {
        inner: (lo..hi).log_scale().into(),
        ticks: log_ticks(lo, hi, LOG_TICKS),
    }
}

impl<R: Ranged<ValueType = f64>> Ranged for Ticked<R> {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

/// `r` if finite and non-empty, else a unit range about it.
fn sane(r: (f64, f64)) -> (f64, f64) {
    if r.0.is_finite() && r.1.is_finite() && r.1 > r.0 {
        r
    } else if r.0.is_finite() {
        (r.0, r.0 + 1.0)
    } else {
        (0.0, 1.0)
    }
}

fn to_axis(v: f64, log: bool) -> f64 {
    if !log {
        v
    } else if v > 0.0 {
        v.log10()
    } else {
        f64::NAN
    }
}

/// A legend swatch: the series' line style over [`SWATCH`] pixels, dashed as the series
/// is ([`DASH`] on, [`GAP`] off).
pub struct Swatch {
    /// Segment end points, in pairs.
    ends: Vec<(i32, i32)>,
    style: ShapeStyle,
}

impl Swatch {
    pub fn new(p: (i32, i32), colour: RGBColor, width: u32, dashed: bool) -> Self {
        let (dash, period) = if dashed {
            (DASH as i32, (DASH + GAP) as i32)
        } else {
            (SWATCH, SWATCH)
        };
        let ends = (0..SWATCH)
            .step_by(period.max(1) as usize)
            .flat_map(|x0| [(p.0 + x0, p.1), (p.0 + (x0 + dash).min(SWATCH), p.1)])
            .collect();
        Self {
            ends,
            style: colour.stroke_width(width),
        }
    }
}

impl<'a> PointCollection<'a, (i32, i32)> for &'a Swatch {
    type Point = &'a (i32, i32);
    type IntoIter = &'a [(i32, i32)];
    fn point_iter(self) -> Self::IntoIter {
        &self.ends
    }
}

impl<DB: DrawingBackend> Drawable<DB> for Swatch {
    fn draw<I: Iterator<Item = (i32, i32)>>(
        &self,
        pos: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let pts: Vec<(i32, i32)> = pos.collect();
        for seg in pts.chunks_exact(2) {
            backend.draw_path(seg.iter().copied(), &self.style)?;
        }
        Ok(())
    }
}

/// The legend swatch of a series drawn at `p`.
pub fn swatch(p: (i32, i32), colour: RGBColor, width: u32, dashed: bool) -> Swatch {
    Swatch::new(p, colour, width, dashed)
}

/// Draws the legend of the labelled series of `chart` in its upper right corner.
pub fn legend<'a, 'b: 'a, X: Ranged, Y: Ranged>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
) -> DrawResult {
    chart
        .configure_series_labels()
        .legend_area_size(LEGEND_AREA)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK.mix(0.3))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(e)
}

/// A polyline of a panel.
#[derive(Debug, Clone)]
pub struct Line {
    pub pts: Vec<(f64, f64)>,
    pub colour: RGBColor,
    pub dashed: bool,
    pub width: u32,
    pub label: Option<String>,
    /// Draw a dot of radius `width` at each point instead of a line.
    pub markers: bool,
}

impl Line {
    pub fn new(pts: Vec<(f64, f64)>, colour: RGBColor, dashed: bool) -> Self {
        Self {
            pts: pts
                .into_iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect(),
            colour,
            dashed,
            width: 2,
            label: None,
            markers: false,
        }
    }
    pub fn label(mut self, s: impl Into<String>) -> Self {
        self.label = Some(s.into());
        self
    }
}

/// A labelled reference line (a bound, a threshold, a phase start).
#[derive(Debug, Clone)]
pub struct RefLine {
    pub at: f64,
    pub colour: RGBColor,
    pub label: String,
    pub dashed: bool,
}

impl RefLine {
    pub fn new(at: f64, colour: RGBColor, label: impl Into<String>) -> Self {
        Self {
            at,
            colour,
            label: label.into(),
            dashed: false,
        }
    }
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }
}

/// Draws `pts` (drawing units) solid or dashed and returns the series' annotation.
fn series<'c, 'a, 'b: 'a, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &'c mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    pts: Vec<(f64, f64)>,
    colour: RGBColor,
    width: u32,
    dashed: bool,
) -> Result<&'c mut SeriesAnno<'a, SVGBackend<'b>>, DrawError> {
    let style = colour.stroke_width(width);
    if dashed {
        chart
            .draw_series(DashedLineSeries::new(pts, DASH, GAP, style))
            .map_err(e)
    } else {
        chart.draw_series(LineSeries::new(pts, style)).map_err(e)
    }
}

/// Draws `text` at a point given in drawing units, shifted by `offset` pixels.
pub fn label_at<'a, 'b: 'a, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    at: (f64, f64),
    offset: (i32, i32),
    text: &str,
    colour: RGBColor,
    anchor: (HPos, VPos),
) -> DrawResult {
    let style = (FONT, REF_LABEL_PX)
        .into_font()
        .color(&colour)
        .pos(Pos::new(anchor.0, anchor.1));
    chart
        .draw_series(std::iter::once(
            EmptyElement::at(at) + Text::new(text.to_string(), offset, style),
        ))
        .map(|_| ())
        .map_err(e)
}

/// Draws the horizontal reference lines `h` (drawing units) across `x`, each with its
/// label above its left end, and the vertical ones `v` up `y`, each labelled at its foot
/// (the legend sits at the top).
pub fn ref_lines<'a, 'b: 'a, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    x: (f64, f64),
    y: (f64, f64),
    h: &[(f64, &RefLine)],
    v: &[(f64, &RefLine)],
) -> DrawResult {
    for (at, r) in v {
        if at.is_finite() && *at >= x.0 && *at <= x.1 {
            series(chart, vec![(*at, y.0), (*at, y.1)], r.colour, 1, r.dashed)?;
            if !r.label.is_empty() {
                // right of the line, or left of it where the plot ends too soon
                let width = chart.plotting_area().dim_in_pixel().0 as f64;
                let room = (x.1 - at) / (x.1 - x.0) * width;
                let need = r.label.chars().count() as f64 * REF_LABEL_PX as f64 * CHAR_WIDTH;
                let (dx, h) = if need + REF_LABEL_OFFSET as f64 <= room {
                    (REF_LABEL_OFFSET, HPos::Left)
                } else {
                    (-REF_LABEL_OFFSET, HPos::Right)
                };
                label_at(
                    chart,
                    (*at, y.0),
                    (dx, -REF_LABEL_OFFSET),
                    &r.label,
                    r.colour,
                    (h, VPos::Bottom),
                )?;
            }
        }
    }
    for (at, r) in h {
        if at.is_finite() && *at >= y.0 && *at <= y.1 {
            series(chart, vec![(x.0, *at), (x.1, *at)], r.colour, 1, r.dashed)?;
            if !r.label.is_empty() {
                label_at(
                    chart,
                    (x.0, *at),
                    (REF_LABEL_OFFSET, -REF_LABEL_OFFSET),
                    &r.label,
                    r.colour,
                    (HPos::Left, VPos::Bottom),
                )?;
            }
        }
    }
    Ok(())
}

/// A 2-D line panel.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    pub title: String,
    pub xlabel: String,
    pub ylabel: String,
    pub lines: Vec<Line>,
    /// Vertical reference lines.
    pub vlines: Vec<RefLine>,
    /// Horizontal reference lines.
    pub hlines: Vec<RefLine>,
    /// In data units (also on a log axis).
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    /// Log axes: ticks at powers of ten; non-positive values are not drawn.
    pub x_log: bool,
    pub y_log: bool,
    /// Room above the data for the legend, as a fraction of the data's span (0: none),
    /// so that the legend in the upper right corner covers no curve.
    pub legend_headroom: f64,
}

impl Panel {
    pub fn new(title: &str, xlabel: &str, ylabel: &str) -> Self {
        Self {
            title: title.into(),
            xlabel: xlabel.into(),
            ylabel: ylabel.into(),
            ..Default::default()
        }
    }

    /// The lines in drawing units (log10 on a log axis), non-finite points dropped.
    fn mapped(&self) -> Vec<Vec<(f64, f64)>> {
        self.lines
            .iter()
            .map(|l| {
                l.pts
                    .iter()
                    .map(|p| (to_axis(p.0, self.x_log), to_axis(p.1, self.y_log)))
                    .filter(|p| p.0.is_finite() && p.1.is_finite())
                    .collect()
            })
            .collect()
    }

    /// The axes in drawing units.
    fn axes(&self, mapped: &[Vec<(f64, f64)>]) -> (Axis, Axis) {
        let map_range = |r: (f64, f64), log: bool| (to_axis(r.0, log), to_axis(r.1, log));
        let xs = mapped.iter().flat_map(|l| l.iter().map(|p| p.0));
        let x = self
            .x_range
            .map(|r| map_range(r, self.x_log))
            .unwrap_or_else(|| range(xs, 0.02));
        let ys = mapped
            .iter()
            .flat_map(|l| l.iter().filter(|p| p.0 >= x.0 && p.0 <= x.1).map(|p| p.1))
            .chain(self.hlines.iter().map(|h| to_axis(h.at, self.y_log)));
        let y = self
            .y_range
            .map(|r| map_range(r, self.y_log))
            .unwrap_or_else(|| {
                let (lo, hi) = range(ys, 0.05);
                (lo, hi + self.legend_headroom * (hi - lo))
            });
        let axis = |r, log| {
            if log {
                Axis::log10(r, LOG_TICKS)
            } else {
                Axis::linear(r, TICKS)
            }
        };
        (axis(x, self.x_log), axis(y, self.y_log))
    }

    pub fn draw(&self, area: &Area) -> DrawResult {
        let mapped = self.mapped();
        let (xa, ya) = self.axes(&mapped);
        let (x, y) = ((xa.lo, xa.hi), (ya.lo, ya.hi));
        let mut chart = standard(area, &self.title)
            .build_cartesian_2d(xa.coord(), ya.coord())
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(self.xlabel.as_str())
            .y_desc(self.ylabel.as_str())
            .x_label_formatter(&|v| xa.label(*v))
            .y_label_formatter(&|v| ya.label(*v))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(e)?;
        let hs: Vec<(f64, &RefLine)> = self.hlines.iter().map(|r| (ya.map(r.at), r)).collect();
        let vs: Vec<(f64, &RefLine)> = self.vlines.iter().map(|r| (xa.map(r.at), r)).collect();
        ref_lines(&mut chart, x, y, &hs, &vs)?;
        let mut labelled = false;
        for (l, pts) in self.lines.iter().zip(mapped) {
            if pts.is_empty() {
                continue;
            }
            let (c, w, dashed) = (l.colour, l.width, l.dashed);
            if l.markers {
                let style = c.mix(MARKER_OPACITY).filled();
                let anno = chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, w, style)))
                    .map_err(e)?;
                if let Some(lab) = &l.label {
                    labelled = true;
                    // a dot, as the series is drawn
                    anno.label(lab.as_str())
                        .legend(move |(x, y)| Circle::new((x + SWATCH / 2, y), w, style));
                }
            } else {
                let anno = series(&mut chart, pts, c, w, dashed)?;
                if let Some(lab) = &l.label {
                    labelled = true;
                    anno.label(lab.as_str())
                        .legend(move |p| swatch(p, c, w, dashed));
                }
            }
        }
        if labelled {
            legend(&mut chart)?;
        }
        Ok(())
    }
}

/// A vertical colour bar for values in `lo..hi`.
pub fn colour_bar(area: &Area, label: &str, lo: f64, hi: f64) -> DrawResult {
    let ya = Axis::linear((lo, hi), TICKS);
    let (lo, hi) = (ya.lo, ya.hi);
    let mut chart = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(44)
        .margin_right(4)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..1.0, ya.coord())
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_label_formatter(&|v| ya.label(*v))
        .y_label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .draw()
        .map_err(e)?;
    let n = 64;
    chart
        .draw_series((0..n).map(|i| {
            let a = lo + (hi - lo) * i as f64 / n as f64;
            let b = lo + (hi - lo) * (i + 1) as f64 / n as f64;
            Rectangle::new(
                [(0.0, a), (1.0, b)],
                viridis((i as f64 + 0.5) / n as f64).filled(),
            )
        }))
        .map_err(e)?;
    Ok(())
}

/// Splits `area` into a main area and a colour-bar strip of `bar_px` on the right.
pub fn with_bar<'a>(area: &Area<'a>, bar_px: u32) -> (Area<'a>, Area<'a>) {
    let (w, _) = area.dim_in_pixel();
    area.split_horizontally(w.saturating_sub(bar_px))
}

#[cfg(test)]
mod tests {
    use super::Axis;

    #[test]
    fn count_axes_have_integer_ticks() {
        for top in [0.0, 1.15, 2.3, 8.05, 9.2, 57.5, 1.2e4] {
            let a = Axis::counts((0.0, top), 4);
            assert!(
                a.ticks.len() >= 3 && a.ticks.len() <= 5,
                "{top}: {:?}",
                a.ticks
            );
            assert!(
                a.ticks.iter().all(|t| t.fract() == 0.0),
                "{top}: {:?}",
                a.ticks
            );
            assert!(a.hi >= top);
        }
    }
}
