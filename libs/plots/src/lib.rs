//! Figures of runs and campaigns (plotters, SVG).
//!
//! * [`run_figures`] — the figures of one mission, like the paper's Figs. 3–4: approach
//!   trajectory in F_R (x–y and x–z) with the approach corridor and the collision-avoidance
//!   sphere, every barrier over time, range rate vs distance, rate-synchronisation error
//!   and joint torques; the nominal-only run dashed, the filtered run solid.
//! * [`campaign_figures`] — the figures of a Monte Carlo campaign, like the paper's
//!   Figs. 5–6: solve times, all approach trajectories coloured by speed, attitude motion
//!   against the line-of-sight cone coloured by synchronisation error, joint-torque norm vs
//!   peak synchronisation error coloured by tumbling rate, distributions of every barrier's
//!   minimum.
//! * [`redteam_margins`] — every red-team case against every barrier.
//! * [`latency_percentiles`], [`latency_timeline`] — the partition's latency benchmark.
//! * [`paper`] — the paper's published numbers the figures and reports set beside ours.
//! * [`export_figures`] — every SVG of a folder also as PNG and/or PDF
//!   ([`FigureFormats`], e.g. parsed from `svg,png,pdf`).
//!
//! Every axis has at least three ticks labelled as numbers are written (`50`, `0.02`,
//! `1e7`); legend swatches are drawn as their series (dashed, same width); reference lines
//! carry their label. SVG text is written as `<text>` elements, so no system fonts are
//! needed for SVG (PNG and PDF need one, see [`export_figures`]). Output is a pure
//! function of the input data (no timestamps), so identical data give identical files. Bad data (NaN, empty series) never panics: non-finite points are dropped and
//! empty panels get a unit range.

mod campaign;
mod chart;
mod colour;
mod compare;
mod export;
mod latency;
pub mod paper;
mod redteam;
mod run;
mod ticks;

pub use campaign::{
    BarrierMinima, CampaignFigures, RunPoint, RuntimeBar, TracePoint, campaign_figures,
};
pub use chart::DrawError;
pub use colour::viridis;
pub use compare::difference_figure;
pub use export::{
    ConvertError, FigureFormat, FigureFormats, PNG_SCALE, check_formats, export_figure,
    export_figures,
};
pub use latency::{LatencyPercentiles, LatencyTimeline, latency_percentiles, latency_timeline};
pub use redteam::{RedTeamMargins, redteam_margins};
pub use run::{los_angles_deg, run_figures};

use nalgebra::Vector3;
use sc_scenario::Scenario;

/// Why a figure could not be written. One line, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("cannot create {path}: {message}")]
    Io { path: String, message: String },
    #[error("cannot draw {path}: {source}")]
    Draw {
        path: String,
        source: chart::DrawError,
    },
    /// A figure format list that does not parse.
    #[error("{message}")]
    Format { message: String },
    /// No font to set the figures' text in.
    #[error("cannot export figures: {message}")]
    Font { message: String },
    #[error("cannot export {path}: {source}")]
    Export {
        path: String,
        source: export::ConvertError,
    },
}

/// The safety-zone geometry the figures draw, from the scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// Corridor axis d_R (unit, F_R), from the target towards the servicer.
    pub corridor_axis_r: Vector3<f64>,
    /// ψ_AC [deg].
    pub corridor_half_angle_deg: f64,
    /// R_CAZ [m].
    pub caz_radius_m: f64,
    /// β_ATT [deg].
    pub los_half_angle_deg: f64,
    /// Go-for-Capture distance along d_R [m].
    pub gfc_distance_m: f64,
    /// Boresight d_B (unit, F_B).
    pub boresight_b: Vector3<f64>,
    /// |τ_M|∞ [N m].
    pub joint_torque_max_nm: f64,
}

impl Geometry {
    pub fn from_scenario(s: &Scenario) -> Self {
        let unit = |v: [f64; 3]| {
            let v = Vector3::from(v);
            let n = v.norm();
            if n.is_finite() && n > 0.0 {
                v / n
            } else {
                Vector3::x()
            }
        };
        Self {
            corridor_axis_r: unit(s.safety.translational.corridor_axis),
            corridor_half_angle_deg: s.safety.translational.corridor_half_angle_deg,
            caz_radius_m: s.safety.translational.caz_radius_m,
            los_half_angle_deg: s.safety.attitude.los_half_angle_deg,
            gfc_distance_m: s.nominal.translational.gfc_distance_m,
            boresight_b: unit(s.servicer.boresight_body),
            joint_torque_max_nm: s.limits.joint_torque_max_nm,
        }
    }
}
