//! Trends over a campaign: how a per-run result moves with a dispersed parameter (the
//! paper's "rises with the tumbling rate"), as Pearson's and Spearman's correlation.

use serde::{Deserialize, Serialize};

/// Correlation of one result with one dispersed parameter over the runs that have both.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Trend {
    /// Runs in the sample.
    pub runs: usize,
    /// Pearson's linear correlation coefficient, in [−1, 1] (`None`: fewer than two runs or
    /// a constant variable).
    pub pearson: Option<f64>,
    /// Spearman's rank correlation (Pearson's on the ranks, ties given their mean rank).
    pub spearman: Option<f64>,
}

/// Pearson's correlation of `x` and `y` (equal lengths; `None` when undefined).
pub fn pearson(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len();
    if n < 2 || y.len() != n {
        return None;
    }
    let mx = x.iter().sum::<f64>() / n as f64;
    let my = y.iter().sum::<f64>() / n as f64;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    let d = (sxx * syy).sqrt();
    (d > 0.0 && d.is_finite()).then(|| (sxy / d).clamp(-1.0, 1.0))
}

/// Ranks from 1, ties given their mean rank.
pub fn ranks(v: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..v.len()).collect();
    order.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let mut r = vec![0.0; v.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && v[order[j + 1]] == v[order[i]] {
            j += 1;
        }
        let mean = (i + j) as f64 / 2.0 + 1.0;
        for &k in &order[i..=j] {
            r[k] = mean;
        }
        i = j + 1;
    }
    r
}

/// The trend of `y` with `x` over the pairs given (non-finite pairs are left out).
pub fn trend(pairs: &[(f64, f64)]) -> Trend {
    let (x, y): (Vec<f64>, Vec<f64>) = pairs
        .iter()
        .copied()
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .unzip();
    Trend {
        runs: x.len(),
        pearson: pearson(&x, &y),
        spearman: pearson(&ranks(&x), &ranks(&y)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // y = x²: monotone (Spearman 1), not linear (Pearson < 1)
        let p: Vec<(f64, f64)> = (0..5).map(|i| (i as f64, (i * i) as f64)).collect();
        let t = trend(&p);
        assert_eq!(t.runs, 5);
        assert!((t.spearman.unwrap() - 1.0).abs() < 1e-12);
        // Pearson of (0..4, squares) = 0.9589 (by hand: sxy 40, sxx 10, syy 174)
        assert!((t.pearson.unwrap() - 40.0 / (10.0f64 * 174.0).sqrt()).abs() < 1e-12);
        // reversed: −1 on the ranks
        let q: Vec<(f64, f64)> = p.iter().map(|&(a, b)| (a, -b)).collect();
        assert!((trend(&q).spearman.unwrap() + 1.0).abs() < 1e-12);
    }

    #[test]
    fn ties_share_their_mean_rank_and_degenerate_samples_give_none() {
        assert_eq!(ranks(&[3.0, 1.0, 3.0, 2.0]), vec![3.5, 1.0, 3.5, 2.0]);
        assert_eq!(trend(&[(1.0, 2.0)]).pearson, None);
        assert_eq!(trend(&[(1.0, 2.0), (2.0, 2.0)]).pearson, None);
        let t = trend(&[(1.0, f64::NAN), (1.0, 1.0), (2.0, 3.0)]);
        assert_eq!(t.runs, 2);
        assert!((t.pearson.unwrap() - 1.0).abs() < 1e-12);
    }
}
