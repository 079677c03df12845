//! The host's load while a campaign ran: wall-clock numbers (solve-time maxima, wall
//! time) are only comparable between campaigns run under similar load.

use serde::{Deserialize, Serialize};

/// Where Linux publishes the load averages (first field: 1 minute).
const LOADAVG_PATH: &str = "/proc/loadavg";

/// The host's load at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HostSample {
    /// 1-minute load average (runnable and uninterruptible threads; absent where
    /// `/proc/loadavg` cannot be read).
    pub load_avg_1min: Option<f64>,
    /// CPUs this process may run on.
    pub cpus: usize,
}

impl HostSample {
    /// The load now.
    pub fn now() -> Self {
        Self {
            load_avg_1min: std::fs::read_to_string(LOADAVG_PATH)
                .ok()
                .as_deref()
                .and_then(parse_loadavg),
            cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// The 1-minute load average from the text of `/proc/loadavg`.
pub fn parse_loadavg(text: &str) -> Option<f64> {
    text.split_whitespace()
        .next()?
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
}

/// The host's load at the start and the end of one session of a campaign (the
/// campaign, a shard of a merge, an interrupted campaign or its resume).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HostLoad {
    pub start: HostSample,
    pub end: HostSample,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_field_is_the_one_minute_average() {
        assert_eq!(parse_loadavg("0.52 0.58 0.59 1/389 12345\n"), Some(0.52));
        assert_eq!(parse_loadavg(""), None);
        assert_eq!(parse_loadavg("x 1 2"), None);
        assert_eq!(parse_loadavg("-1 1 2"), None);
    }

    #[test]
    fn a_sample_counts_at_least_one_cpu() {
        assert!(HostSample::now().cpus >= 1);
    }
}
