//! Host steal time as a time series, sampled beside a benchmark run.
//!
//! On a virtual machine the hypervisor sometimes runs something else while a vCPU
//! wants to run ("steal", `/proc/stat`). A process of the partition then stalls
//! although nothing on the guest is in its way. Sampling the steal counter every
//! 100 ms on the same monotonic clock as the partition's time stamps tells, for each
//! tick, whether the host stole time around it, so a latency report can show whether
//! its tail follows the host.
//!
//! Linux counts steal in clock ticks (10 ms with `USER_HZ = 100`), so a window shows
//! steal once a whole tick of it has accumulated: a window with no steal had less
//! than that, not necessarily none.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// One reading: monotonic time [ns] (the clock of the partition's stamps) and the
/// steal time of all CPUs since boot [s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StealSample {
    pub t_ns: u64,
    pub steal_s: f64,
}

/// Steal time of all CPUs since boot [s] (`/proc/stat`, line `cpu`, 8th value);
/// None where the kernel does not report it.
pub fn steal_time_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/stat").ok()?;
    let line = stat.lines().find(|l| l.starts_with("cpu "))?;
    let jiffies: f64 = line.split_whitespace().nth(8)?.parse().ok()?;
    // SAFETY: sysconf has no preconditions.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
    (hz > 0).then(|| jiffies / hz as f64)
}

/// A thread that reads the steal counter every `period` until [`finish`](Self::finish).
pub struct StealSampler {
    stop: Arc<AtomicBool>,
    handle: std::thread::JoinHandle<Vec<StealSample>>,
}

impl StealSampler {
    /// Starts sampling (nothing is recorded where the kernel reports no steal).
    pub fn start(period: Duration) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let handle = std::thread::spawn(move || {
            let mut v = Vec::new();
            loop {
                if let Some(s) = steal_time_s() {
                    v.push(StealSample {
                        t_ns: sc_icd::monotonic_ns(),
                        steal_s: s,
                    });
                }
                if flag.load(Ordering::Relaxed) {
                    return v;
                }
                std::thread::sleep(period);
            }
        });
        Self { stop, handle }
    }

    /// Takes a last reading and returns the series.
    pub fn finish(self) -> Vec<StealSample> {
        self.stop.store(true, Ordering::Relaxed);
        self.handle.join().unwrap_or_default()
    }
}

/// Steal [s] over the sampling intervals that cover `[a_ns, b_ns]`: the reading at or
/// after `b_ns` minus the one at or before `a_ns`. None if the series does not cover
/// the interval.
pub fn steal_around(series: &[StealSample], a_ns: u64, b_ns: u64) -> Option<f64> {
    let before = series.iter().rev().find(|s| s.t_ns <= a_ns)?;
    let after = series.iter().find(|s| s.t_ns >= b_ns)?;
    Some((after.steal_s - before.steal_s).max(0.0))
}

/// Writes the series as `t_ns,steal_s`.
pub fn write_csv(path: &Path, series: &[StealSample]) -> std::io::Result<()> {
    let mut s = String::from("t_ns,steal_s\n");
    for x in series {
        s += &format!("{},{}\n", x.t_ns, x.steal_s);
    }
    std::fs::write(path, s)
}

/// Reads a series written by [`write_csv`]; None if the file is absent.
pub fn read_csv(path: &Path) -> Result<Option<Vec<StealSample>>, crate::error::BenchError> {
    let Ok(text) = std::fs::read_to_string(path) else {
        return Ok(None);
    };
    let mut v = Vec::new();
    for (i, l) in text.lines().enumerate().skip(1) {
        let bad = || {
            crate::error::BenchError::Data(format!(
                "{}: line {}: expected t_ns,steal_s",
                path.display(),
                i + 1
            ))
        };
        let (t, s) = l.split_once(',').ok_or_else(bad)?;
        v.push(StealSample {
            t_ns: t.parse().map_err(|_| bad())?,
            steal_s: s.parse().map_err(|_| bad())?,
        });
    }
    Ok(Some(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(t_ns: u64, steal_s: f64) -> StealSample {
        StealSample { t_ns, steal_s }
    }

    #[test]
    fn steal_around_takes_the_covering_readings() {
        let v = [s(100, 1.0), s(200, 1.0), s(300, 1.02), s(400, 1.05)];
        assert_eq!(steal_around(&v, 150, 160), Some(0.0));
        assert!((steal_around(&v, 250, 260).unwrap() - 0.02).abs() < 1e-12);
        assert!((steal_around(&v, 200, 350).unwrap() - 0.05).abs() < 1e-12);
        assert_eq!(steal_around(&v, 50, 160), None, "before the first reading");
        assert_eq!(steal_around(&v, 350, 450), None, "after the last reading");
    }

    #[test]
    fn csv_round_trip_and_sampler() {
        let dir = std::env::temp_dir().join(format!("sc-steal-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let v = vec![s(1, 0.5), s(2, 0.75)];
        write_csv(&dir.join("steal.csv"), &v).unwrap();
        assert_eq!(read_csv(&dir.join("steal.csv")).unwrap(), Some(v));
        assert_eq!(read_csv(&dir.join("absent.csv")).unwrap(), None);
        std::fs::write(dir.join("bad.csv"), "t_ns,steal_s\n1;2\n").unwrap();
        assert!(read_csv(&dir.join("bad.csv")).is_err());
        std::fs::remove_dir_all(&dir).ok();
        // Linux reports steal: a short sampling gives increasing times and a
        // non-decreasing counter
        let r = StealSampler::start(Duration::from_millis(5));
        std::thread::sleep(Duration::from_millis(30));
        let v = r.finish();
        if steal_time_s().is_some() {
            assert!(v.len() >= 2, "{v:?}");
            assert!(
                v.windows(2)
                    .all(|w| w[0].t_ns < w[1].t_ns && w[0].steal_s <= w[1].steal_s)
            );
        }
    }
}
