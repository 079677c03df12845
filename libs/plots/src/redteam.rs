//! The red-team figure: every case against every barrier, one cell each, coloured by the
//! smallest value the barrier took over the case (normalised by the barrier's scale).
//! A violated cell is red whatever its size, so one glance shows whether any case broke
//! any barrier.

use crate::PlotError;
use crate::chart::{DrawResult, e, svg};
use crate::colour::viridis;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// What the red-team heatmap shows.
#[derive(Debug, Clone)]
pub struct RedTeamMargins<'a> {
    /// Case names (rows), grouped: consecutive rows of a group share its label.
    pub cases: &'a [String],
    /// Barrier names (columns).
    pub barriers: &'a [String],
    /// `values[case][barrier]`: the smallest barrier value over the case divided by the
    /// barrier's scale (≥ 0 safe; NaN: not evaluable, drawn as violated).
    pub values: &'a [Vec<f64>],
}

/// Colour of a normalised margin: red for a violation (or NaN), else viridis over
/// `log10` of the margin between 1e-6 and 1.
fn cell_colour(v: f64) -> RGBColor {
    if v.is_nan() || v < 0.0 {
        return RGBColor(214, 39, 40);
    }
    let t = ((v.max(1e-6).log10() + 6.0) / 6.0).clamp(0.0, 1.0);
    viridis(t)
}

fn draw(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    f: &RedTeamMargins,
) -> DrawResult {
    let (w, h) = area.dim_in_pixel();
    let left = 260i32;
    let top = 150i32;
    let legend = 60i32;
    let rows = f.cases.len().max(1) as i32;
    let cols = f.barriers.len().max(1) as i32;
    let cw = ((w as i32 - left - 20) / cols).max(1);
    let ch = ((h as i32 - top - legend) / rows).max(1);
    let font = ("sans-serif", 11).into_font();
    let small = ("sans-serif", 9).into_font();
    area.draw(&Text::new(
        "Red team: smallest value of every barrier over each case (true state, every physics step)",
        (10, 14),
        ("sans-serif", 15).into_font(),
    ))
    .map_err(e)?;
    for (j, name) in f.barriers.iter().enumerate() {
        let x = left + j as i32 * cw + cw / 2;
        let style = small
            .clone()
            .transform(FontTransform::Rotate270)
            .color(&BLACK)
            .pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(name.clone(), (x, top - 6), style))
            .map_err(e)?;
    }
    for (i, case) in f.cases.iter().enumerate() {
        let y = top + i as i32 * ch;
        area.draw(&Text::new(
            case.clone(),
            (left - 6, y + ch / 2),
            font.clone()
                .color(&BLACK)
                .pos(Pos::new(HPos::Right, VPos::Center)),
        ))
        .map_err(e)?;
        for j in 0..f.barriers.len() {
            let v = f
                .values
                .get(i)
                .and_then(|r| r.get(j))
                .copied()
                .unwrap_or(f64::NAN);
            let x = left + j as i32 * cw;
            area.draw(&Rectangle::new(
                [(x, y), (x + cw - 1, y + ch - 1)],
                cell_colour(v).filled(),
            ))
            .map_err(e)?;
        }
    }
    // legend
    let y = top + rows * ch + 18;
    area.draw(&Rectangle::new(
        [(left, y), (left + 14, y + 14)],
        RGBColor(214, 39, 40).filled(),
    ))
    .map_err(e)?;
    area.draw(&Text::new(
        "violated (< 0)",
        (left + 20, y + 2),
        font.clone(),
    ))
    .map_err(e)?;
    for k in 0..=6 {
        let x = left + 160 + k * 70;
        let v = 10f64.powi(k - 6);
        area.draw(&Rectangle::new(
            [(x, y), (x + 14, y + 14)],
            cell_colour(v).filled(),
        ))
        .map_err(e)?;
        area.draw(&Text::new(
            format!("1e{}", k - 6),
            (x + 20, y + 2),
            font.clone(),
        ))
        .map_err(e)?;
    }
    area.draw(&Text::new(
        "margin / barrier scale",
        (left + 160 + 7 * 70, y + 2),
        font,
    ))
    .map_err(e)?;
    Ok(())
}

/// Writes the red-team heatmap to `path` (SVG).
pub fn redteam_margins(path: &Path, f: &RedTeamMargins) -> Result<(), PlotError> {
    let rows = f.cases.len().max(1) as u32;
    let cols = f.barriers.len().max(1) as u32;
    let size = (280 + 18 * cols, 230 + 13 * rows);
    svg(path, size, |a| draw(a, f))
}
