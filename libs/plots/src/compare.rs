//! `compare.svg`: how two runs of the same mission part, step by step (log scale).

use crate::PlotError;
use crate::chart::{Line, Panel, svg};
use plotters::style::RGBColor;
use sc_mission::compare::StepDifference;
use std::path::Path;

/// Smallest difference drawn [m or rad]: exact agreement is drawn here.
const FLOOR: f64 = 1e-18;

/// One curve: its legend, the difference it shows and its colour.
type Series = (&'static str, fn(&StepDifference) -> f64, RGBColor);

/// Writes the differences over time on a log axis (exact agreement drawn at 1e-18).
pub fn difference_figure(path: &Path, d: &[StepDifference], title: &str) -> Result<(), PlotError> {
    let series: [Series; 4] = [
        (
            "Hill position [m]",
            |x| x.hill_position_m,
            RGBColor(31, 119, 180),
        ),
        (
            "base attitude [rad]",
            |x| x.attitude_rad,
            RGBColor(214, 39, 40),
        ),
        (
            "joint angles, max [rad]",
            |x| x.joint_angle_rad,
            RGBColor(44, 160, 44),
        ),
        (
            "target attitude [rad]",
            |x| x.target_attitude_rad,
            RGBColor(148, 103, 189),
        ),
    ];
    svg(path, (900, 450), |area| {
        let mut p = Panel::new(title, "t [s]", "difference [m or rad] (log)");
        p.y_log = true;
        for (name, f, colour) in series {
            let pts = d.iter().map(|x| (x.t, f(x).max(FLOOR))).collect();
            p.lines.push(Line::new(pts, colour, false).label(name));
        }
        p.draw(area)
    })
}
