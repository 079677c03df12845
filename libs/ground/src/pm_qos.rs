//! CPU wake-up latency through Linux PM QoS (`/dev/cpu_dma_latency`): while the
//! file stays open with a value written to it, no CPU enters an idle state whose
//! exit latency exceeds that value (what cyclictest does during a measurement).
//! With 0 an idle CPU polls instead of halting, so that the wake-ups of a tick's
//! causal chain do not each pay the exit from a halted (virtual) CPU.

use std::io::Write;

/// The PM QoS device of the CPU wake-up latency.
pub const DEVICE: &str = "/dev/cpu_dma_latency";

/// A held request; dropping it (closing the device) restores the system default.
#[derive(Debug)]
pub struct CpuWakeupLatency {
    _device: std::fs::File,
    us: u32,
}

impl CpuWakeupLatency {
    /// Requests at most `us` µs of idle-state exit latency on every CPU.
    pub fn request(us: u32) -> std::io::Result<Self> {
        let mut f = std::fs::OpenOptions::new().write(true).open(DEVICE)?;
        // the device takes a binary s32 in native byte order
        let v = i32::try_from(us).map_err(|_| std::io::Error::other("value out of range"))?;
        f.write_all(&v.to_ne_bytes())?;
        Ok(Self { _device: f, us })
    }

    /// The requested latency [µs].
    pub fn us(&self) -> u32 {
        self.us
    }
}

/// What the launcher did about the CPU wake-up latency, for launch.json and reports.
pub fn describe(
    requested: Option<u32>,
    held: &Option<std::io::Result<CpuWakeupLatency>>,
) -> String {
    match (requested, held) {
        (Some(_), Some(Ok(h))) => format!("{} us (PM QoS held for the run)", h.us()),
        (Some(us), Some(Err(e))) => format!("system default ({us} us refused: {DEVICE}: {e})"),
        _ => "system default (not requested)".into(),
    }
}
