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

/// Colour of a violated cell.
const VIOLATED: RGBColor = RGBColor(214, 39, 40);
/// Room left of the cells for the case names [px].
const LEFT_PX: i32 = 260;
/// Room above the cells for the title and the barrier names [px].
const TOP_PX: i32 = 150;
/// Room below the cells for the colour legend [px].
const LEGEND_PX: i32 = 60;

type Svg<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

/// Colour of a normalised margin: red for a violation (or NaN), else viridis over
/// `log10` of the margin between 1e-6 and 1.
fn cell_colour(v: f64) -> RGBColor {
    if v.is_nan() || v < 0.0 {
        return VIOLATED;
    }
    let t = ((v.max(1e-6).log10() + 6.0) / 6.0).clamp(0.0, 1.0);
    viridis(t)
}

/// Where the cells go: left and top edge of the grid, cell width and height [px].
#[derive(Clone, Copy)]
struct Grid {
    left: i32,
    top: i32,
    cw: i32,
    ch: i32,
}

fn draw(area: &Svg, f: &RedTeamMargins) -> DrawResult {
    let (w, h) = area.dim_in_pixel();
    let rows = f.cases.len().max(1) as i32;
    let cols = f.barriers.len().max(1) as i32;
    let g = Grid {
        left: LEFT_PX,
        top: TOP_PX,
        cw: ((w as i32 - LEFT_PX - 20) / cols).max(1),
        ch: ((h as i32 - TOP_PX - LEGEND_PX) / rows).max(1),
    };
    area.draw(&Text::new(
        "Red team: smallest value of every barrier over each case (true state, every physics step)",
        (10, 14),
        ("sans-serif", 15).into_font(),
    ))
    .map_err(e)?;
    barrier_names(area, f, g)?;
    cells(area, f, g)?;
    colour_legend(area, g.left, g.top + rows * g.ch + 18)
}

/// The barrier names above the columns, written upwards.
fn barrier_names(area: &Svg, f: &RedTeamMargins, g: Grid) -> DrawResult {
    let small = ("sans-serif", 9).into_font();
    for (j, name) in f.barriers.iter().enumerate() {
        let x = g.left + j as i32 * g.cw + g.cw / 2;
        let style = small
            .clone()
            .transform(FontTransform::Rotate270)
            .color(&BLACK)
            .pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(name.clone(), (x, g.top - 6), style))
            .map_err(e)?;
    }
    Ok(())
}

/// One row per case: its name, then a cell per barrier.
fn cells(area: &Svg, f: &RedTeamMargins, g: Grid) -> DrawResult {
    let font = ("sans-serif", 11).into_font();
    for (i, case) in f.cases.iter().enumerate() {
        let y = g.top + i as i32 * g.ch;
        area.draw(&Text::new(
            case.clone(),
            (g.left - 6, y + g.ch / 2),
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
            let x = g.left + j as i32 * g.cw;
            area.draw(&Rectangle::new(
                [(x, y), (x + g.cw - 1, y + g.ch - 1)],
                cell_colour(v).filled(),
            ))
            .map_err(e)?;
        }
    }
    Ok(())
}

/// The colour legend at `(left, y)`: violated, then the margins 1e-6 … 1e0.
fn colour_legend(area: &Svg, left: i32, y: i32) -> DrawResult {
    let font = ("sans-serif", 11).into_font();
    area.draw(&Rectangle::new(
        [(left, y), (left + 14, y + 14)],
        VIOLATED.filled(),
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
