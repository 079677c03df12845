//! Figures of runs and campaigns (plotters, SVG).
