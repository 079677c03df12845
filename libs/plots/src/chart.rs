//! Small drawing helpers over plotters' SVG backend.

use crate::PlotError;
use crate::colour::viridis;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

pub type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
pub type DrawResult = Result<(), String>;

/// Maps any plotters error to its message.
pub fn e<T: std::fmt::Display>(x: T) -> String {
    x.to_string()
}

/// Ranges for a spatial chart of the standard layout ([`Panel`]: caption `title`, margin 8,
/// label areas 36 and 64 px) on `area`: the shorter range is widened about its centre so
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
    let Ok(chart) = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(8)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(0f64..1.0, 0f64..1.0)
    else {
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
        Ok(Err(message)) => {
            return Err(PlotError::Draw {
                path: shown,
                message,
            });
        }
        Err(_) => {
            return Err(PlotError::Draw {
                path: shown,
                message: "plotting library panicked".into(),
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

/// A polyline of a panel.
#[derive(Debug, Clone)]
pub struct Line {
    pub pts: Vec<(f64, f64)>,
    pub colour: RGBColor,
    pub dashed: bool,
    pub width: u32,
    pub label: Option<String>,
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
        }
    }
    pub fn label(mut self, s: impl Into<String>) -> Self {
        self.label = Some(s.into());
        self
    }
}

/// A 2-D line panel.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    pub title: String,
    pub xlabel: String,
    pub ylabel: String,
    pub lines: Vec<Line>,
    /// Vertical reference lines (x, colour).
    pub vlines: Vec<(f64, RGBColor)>,
    /// Horizontal reference lines (y, colour).
    pub hlines: Vec<(f64, RGBColor)>,
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
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

    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let xs = self.lines.iter().flat_map(|l| l.pts.iter().map(|p| p.0));
        let x = self.x_range.unwrap_or_else(|| range(xs, 0.02));
        let ys = self
            .lines
            .iter()
            .flat_map(|l| {
                l.pts
                    .iter()
                    .filter(|p| p.0 >= x.0 && p.0 <= x.1)
                    .map(|p| p.1)
            })
            .chain(self.hlines.iter().map(|h| h.0));
        let y = self.y_range.unwrap_or_else(|| range(ys, 0.05));
        (x, y)
    }

    pub fn draw(&self, area: &Area) -> DrawResult {
        let (x, y) = self.ranges();
        let mut chart = ChartBuilder::on(area)
            .caption(&self.title, ("sans-serif", 18))
            .margin(8)
            .x_label_area_size(36)
            .y_label_area_size(64)
            .build_cartesian_2d(x.0..x.1, y.0..y.1)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(self.xlabel.as_str())
            .y_desc(self.ylabel.as_str())
            .x_labels(6)
            .y_labels(6)
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(e)?;
        for (v, c) in &self.vlines {
            if v.is_finite() && *v >= x.0 && *v <= x.1 {
                chart
                    .draw_series(DashedLineSeries::new(
                        vec![(*v, y.0), (*v, y.1)],
                        4,
                        4,
                        c.stroke_width(1),
                    ))
                    .map_err(e)?;
            }
        }
        for (h, c) in &self.hlines {
            if h.is_finite() && *h >= y.0 && *h <= y.1 {
                chart
                    .draw_series(LineSeries::new(
                        vec![(x.0, *h), (x.1, *h)],
                        c.stroke_width(1),
                    ))
                    .map_err(e)?;
            }
        }
        let mut labelled = false;
        for l in &self.lines {
            if l.pts.is_empty() {
                continue;
            }
            let style = l.colour.stroke_width(l.width);
            let anno = if l.dashed {
                chart
                    .draw_series(DashedLineSeries::new(l.pts.clone(), 6, 4, style))
                    .map_err(e)?
            } else {
                chart
                    .draw_series(LineSeries::new(l.pts.clone(), style))
                    .map_err(e)?
            };
            if let Some(lab) = &l.label {
                labelled = true;
                let c = l.colour;
                let dashed = l.dashed;
                anno.label(lab.as_str()).legend(move |(px, py)| {
                    let w = if dashed { 1 } else { 3 };
                    PathElement::new(vec![(px, py), (px + 18, py)], c.stroke_width(w))
                });
            }
        }
        if labelled {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK.mix(0.3))
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(e)?;
        }
        Ok(())
    }
}

/// A vertical colour bar for values in `lo..hi`.
pub fn colour_bar(area: &Area, label: &str, lo: f64, hi: f64) -> DrawResult {
    let (lo, hi) = if hi > lo { (lo, hi) } else { (lo, lo + 1.0) };
    let mut chart = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(44)
        .margin_right(4)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_labels(6)
        .y_label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 13))
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
