//! A mergeable log-binned histogram of solve times, so that campaign-wide percentiles can
//! be computed from shards without keeping every sample.

use sc_mission::summary::TimeStats;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Relative bin width: percentiles are exact to within ±0.05 %.
pub const RATIO: f64 = 1.001;
/// Smallest value [µs] (as in [`TimeStats::of`], zeros count as 1 ns).
pub const FLOOR_US: f64 = 1e-3;

/// Counts per log bin, plus the exact count, sum of logarithms and maximum.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct LogHistogram {
    pub count: u64,
    pub sum_ln: f64,
    pub max: f64,
    pub bins: BTreeMap<u32, u64>,
}

impl LogHistogram {
    fn bin(x: f64) -> u32 {
        ((x / FLOOR_US).ln() / RATIO.ln())
            .floor()
            .clamp(0.0, u32::MAX as f64) as u32
    }

    /// Adds one sample [µs] (non-finite samples are ignored).
    pub fn add(&mut self, x: f64) {
        if !x.is_finite() {
            return;
        }
        let x = x.max(FLOOR_US);
        self.count += 1;
        self.sum_ln += x.ln();
        self.max = self.max.max(x);
        *self.bins.entry(Self::bin(x)).or_insert(0) += 1;
    }

    /// Adds all samples of `other`.
    pub fn merge(&mut self, other: &LogHistogram) {
        self.count += other.count;
        self.sum_ln += other.sum_ln;
        self.max = self.max.max(other.max);
        for (b, c) in &other.bins {
            *self.bins.entry(*b).or_insert(0) += c;
        }
    }

    /// Nearest-rank percentile `p` (bin centre, capped at the maximum).
    pub fn percentile(&self, p: f64) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        let rank = ((p / 100.0 * self.count as f64).ceil() as u64).clamp(1, self.count);
        let mut seen = 0;
        for (b, c) in &self.bins {
            seen += c;
            if seen >= rank {
                let v = FLOOR_US * RATIO.powf(*b as f64 + 0.5);
                return v.min(self.max);
            }
        }
        self.max
    }

    /// The statistics in the shape of a run's summary.
    pub fn stats(&self) -> TimeStats {
        if self.count == 0 {
            return TimeStats::default();
        }
        TimeStats {
            geomean: (self.sum_ln / self.count as f64).exp(),
            p50: self.percentile(50.0),
            p99: self.percentile(99.0),
            max: self.max,
            samples: self.count as usize,
        }
    }
}
