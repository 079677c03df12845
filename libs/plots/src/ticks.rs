//! Axis ticks and their labels, computed here rather than left to plotters so that every
//! axis has at least [`MIN_TICKS`] ticks and labels read as people write numbers: `50`
//! not `50.0`, `0` not `-0.0`, `1e7` not `10000000.0`.

/// Fewest ticks an axis gets.
pub const MIN_TICKS: usize = 3;

/// Tick steps tried within a decade, as multiples of its power of ten.
const NICE_STEPS: [f64; 4] = [1.0, 2.0, 2.5, 5.0];

/// Significant digits a label keeps (hides float noise such as 0.30000000000000004).
const LABEL_DIGITS: i32 = 6;

/// Decades between which log-axis labels are plain numbers (0.01 … 1000); outside, `1e7`.
const PLAIN_DECADES: std::ops::RangeInclusive<i32> = -2..=3;

/// Multiples of 10^k (besides 1) tried in turn when a log axis spans too few decades.
const LOG_SUBDIVISIONS: [&[f64]; 2] = [&[2.0, 5.0], &[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]];

/// Multiples of `step` = `m` × 10^`e` within `[lo, hi]` (with a little slack for
/// rounding), computed so that 3 × 0.2 is 0.6, not 0.6000000000000001.
fn multiples_of(lo: f64, hi: f64, m: f64, e: i32) -> Vec<f64> {
    let step = m * 10f64.powi(e);
    let slack = 1e-9 * step;
    let first = ((lo - slack) / step).ceil() as i64;
    let last = ((hi + slack) / step).floor() as i64;
    let scale = 10f64.powi(e.abs());
    (first..=last)
        .map(|k| {
            if e < 0 {
                k as f64 * m / scale
            } else {
                k as f64 * m * scale
            }
        })
        .collect()
}

/// Multiples of `step` within `[lo, hi]`.
fn multiples(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    multiples_of(lo, hi, step, 0)
}

/// Round ticks of `[lo, hi]`: the finest step of 1, 2, 2.5 or 5 × 10^k that gives at
/// most `max_n` ticks, and at least [`MIN_TICKS`] (more than `max_n` if it must). Empty
/// for a non-finite or empty range.
pub fn linear_ticks(lo: f64, hi: f64, max_n: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return Vec::new();
    }
    let max_n = max_n.max(MIN_TICKS);
    // from a step that gives many ticks up to one that gives at most one
    let top = (hi - lo).log10().ceil() as i32;
    let mut fewest: Vec<f64> = Vec::new();
    for k in top - 3..=top {
        for m in NICE_STEPS {
            let t = multiples_of(lo, hi, m, k);
            if t.len() < MIN_TICKS {
                continue;
            }
            if t.len() <= max_n {
                return t;
            }
            if fewest.is_empty() || t.len() < fewest.len() {
                fewest = t;
            }
        }
    }
    fewest
}

/// The label of a linear tick `v` on an axis whose ticks are `step` apart.
pub fn linear_label(v: f64, step: f64) -> String {
    if !v.is_finite() {
        return String::new();
    }
    let step = step.abs();
    if step > 0.0 && v.abs() < 1e-9 * step {
        return "0".into();
    }
    let big = v.abs() >= 1e6;
    let small = v.abs() < 1e-4;
    if big || small {
        return exponent_label(v);
    }
    let decimals = if step > 0.0 && step.is_finite() {
        (-step.log10().floor()).clamp(0.0, 12.0) as usize + 1
    } else {
        LABEL_DIGITS as usize
    };
    trim(format!("{v:.decimals$}"))
}

/// `2.5e-7`, `1e7`: the mantissa with up to [`LABEL_DIGITS`] significant digits.
fn exponent_label(v: f64) -> String {
    let k = v.abs().log10().floor() as i32;
    let m = v / 10f64.powi(k);
    // 9.9999999 rounds to 10: carry into the exponent
    let digits = (LABEL_DIGITS - 1) as usize;
    let mut ms = trim(format!("{m:.digits$}"));
    let mut k = k;
    if ms == "10" || ms == "-10" {
        ms = if m < 0.0 { "-1".into() } else { "1".into() };
        k += 1;
    }
    format!("{ms}e{k}")
}

/// Drops trailing zeros of a decimal and a `-` before zero.
fn trim(s: String) -> String {
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s.chars().all(|c| c == '-' || c == '0') {
        "0".into()
    } else {
        s
    }
}

/// Ticks of a log axis over `[lo, hi]` (both > 0): the powers of ten, then 2 and 5 ×
/// 10^k, then every integer × 10^k as needed for [`MIN_TICKS`]; failing that (a range of
/// less than a few per cent), round linear ticks. At most `max_n` decades are labelled:
/// on a wide range only every n-th power of ten.
pub fn log_ticks(lo: f64, hi: f64, max_n: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Vec::new();
    }
    let max_n = max_n.max(MIN_TICKS);
    let (a, b) = (lo.log10(), hi.log10());
    let decades = multiples(a, b, 1.0);
    if decades.len() >= MIN_TICKS {
        let every = decades.len().div_ceil(max_n).max(1);
        return decades
            .iter()
            .filter(|k| (k.round() as i64).rem_euclid(every as i64) == 0)
            .map(|k| 10f64.powi(k.round() as i32))
            .collect();
    }
    for subs in LOG_SUBDIVISIONS {
        let mut t = Vec::new();
        for k in (a.floor() as i32)..=(b.ceil() as i32) {
            let p = 10f64.powi(k);
            for m in std::iter::once(&1.0).chain(subs.iter()) {
                let v = m * p;
                if v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9) {
                    t.push(v);
                }
            }
        }
        if t.len() >= MIN_TICKS {
            return t;
        }
    }
    linear_ticks(lo, hi, max_n)
}

/// The label of a log-axis tick: 0.01, 0.1, 1, 10, 1000, then `1e4`, `2e7` (never
/// `10000000.0`); empty for a non-positive or non-finite value.
pub fn log_label(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return String::new();
    }
    let k = v.log10().floor() as i32;
    if PLAIN_DECADES.contains(&k) {
        // LABEL_DIGITS significant digits, no trailing zeros
        let decimals = (LABEL_DIGITS - 1 - k).max(0) as usize;
        trim(format!("{v:.decimals$}"))
    } else {
        exponent_label(v)
    }
}

/// Spacing of evenly spaced ticks (0 when fewer than two).
pub fn step_of(ticks: &[f64]) -> f64 {
    match ticks {
        [a, b, ..] => b - a,
        _ => 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_ticks_are_round_and_at_least_three() {
        assert_eq!(linear_ticks(0.0, 1.0, 6), [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        let t = linear_ticks(-0.031, 0.029, 6);
        assert!(t.len() >= MIN_TICKS && t.len() <= 6, "{t:?}");
        for (lo, hi) in [
            (0.0, 1e-9),
            (7.83, 7.84),
            (1e5, 1e7),
            (-3.0, -2.99),
            (0.1, 0.11),
        ] {
            let t = linear_ticks(lo, hi, 4);
            assert!(t.len() >= MIN_TICKS, "{lo}..{hi}: {t:?}");
            let slack = 1e-9 * (hi - lo);
            assert!(
                t.iter().all(|v| *v >= lo - slack && *v <= hi + slack),
                "{lo}..{hi}: {t:?}"
            );
        }
        assert!(linear_ticks(1.0, 1.0, 6).is_empty());
        assert!(linear_ticks(f64::NAN, 1.0, 6).is_empty());
    }

    #[test]
    fn linear_labels_read_like_numbers() {
        let l = |v, s| linear_label(v, s);
        assert_eq!(l(50.0, 50.0), "50");
        assert_eq!(l(-0.0, 0.01), "0");
        assert_eq!(l(1e-17, 0.01), "0");
        assert_eq!(l(0.30000000000000004, 0.1), "0.3");
        assert_eq!(l(0.02, 0.01), "0.02");
        assert_eq!(l(7.835, 0.005), "7.835");
        assert_eq!(l(2.5e7, 5e6), "2.5e7");
        assert_eq!(l(3e-5, 1e-5), "3e-5");
        assert_eq!(l(f64::NAN, 1.0), "");
    }

    #[test]
    fn log_ticks_cover_short_and_long_ranges() {
        assert_eq!(log_ticks(0.5, 2000.0, 8), [1.0, 10.0, 100.0, 1000.0]);
        // less than a decade: 2 and 5 × 10^k
        // less than a decade: 2 and 5 × 10^k give too few here, so every integer × 10^k
        assert_eq!(
            log_ticks(150.0, 900.0, 8),
            [200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0, 900.0]
        );
        assert_eq!(log_ticks(0.15, 6.0, 8), [0.2, 0.5, 1.0, 2.0, 5.0]);
        // many decades: every other power of ten
        assert_eq!(log_ticks(1e-18, 1.0, 6).len(), 5);
        for (lo, hi) in [
            (150.0, 900.0),
            (1.0, 3.0),
            (100.0, 104.0),
            (1e-18, 1e-3),
            (3e5, 2e7),
        ] {
            let t = log_ticks(lo, hi, 6);
            assert!(t.len() >= MIN_TICKS, "{lo}..{hi}: {t:?}");
            assert!(t.len() <= 9, "{lo}..{hi}: {t:?}");
        }
        assert!(log_ticks(0.0, 1.0, 6).is_empty());
    }

    #[test]
    fn log_labels_have_no_long_zeros() {
        let t: Vec<String> = [
            0.01,
            0.1,
            1.0,
            10.0,
            1000.0,
            1e4,
            1e7,
            2e7,
            2.0,
            0.0,
            f64::NAN,
        ]
        .iter()
        .map(|v| log_label(*v))
        .collect();
        assert_eq!(
            t,
            [
                "0.01", "0.1", "1", "10", "1000", "1e4", "1e7", "2e7", "2", "", ""
            ]
        );
        assert_eq!(log_label(10f64.powf(7.0f64.log10() + 1e-13) * 1e6), "7e6");
        assert_eq!(log_label(9.9999999999e6), "1e7");
        assert_eq!(log_label(1e-18), "1e-18");
    }
}
