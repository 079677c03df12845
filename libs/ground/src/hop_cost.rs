//! What one hop of the partition costs on this machine: a `Tick` sent with
//! [`sc_bus::Publisher::send`] (sample + event) to a second process that sleeps in a
//! [`sc_bus::Waiter`] and echoes it back. The round trip (two hops) is measured at a
//! given period, so that the echo is as cold as the partition's processes are between
//! ticks; with the partition's own placement (CPU pinning, SCHED_FIFO, PM QoS) and,
//! optionally, a warm-up round trip before each measured one (the partition's
//! pre-tick warm-up). The binary is `sc-hop-cost` (docs/PARTITION.md).

use crate::error::BenchError;
use crate::pm_qos::CpuWakeupLatency;
use sc_bus::{Coordinator, Participant, Publisher, RunScope, ServiceSettings, Subscriber, Waiter};
use sc_flight::process::{set_cpus, set_fifo};
use sc_icd::{Tick, services};
use std::time::{Duration, Instant};

/// Command-line usage of `sc-hop-cost`.
pub const USAGE: &str = "usage: sc-hop-cost [--n N] [--period-us P] [--cpus A,B] [--fifo PRIO] \
[--cpu-wakeup-latency-us L] [--touch-kib K] [--prewarm-us W] [--remote-echo RUN_ID]";

/// The longest a round trip may take before the measurement fails.
const ECHO_TIMEOUT: Duration = Duration::from_secs(2);

/// Ticks of the measured and of the warm-up round trips, and the stop.
const WARM_TICK: u64 = u64::MAX - 1;
const STOP_TICK: u64 = u64::MAX;

/// What to measure.
#[derive(Debug, Clone, PartialEq)]
pub struct HopCostOptions {
    /// Measured round trips (after 10 unmeasured ones).
    pub n: usize,
    /// Pause before each round trip (the partition's period: 100 ms).
    pub period: Duration,
    /// CPUs of the sender and of the echo.
    pub cpus: Option<(usize, usize)>,
    /// SCHED_FIFO priority of both (0 = normal scheduling).
    pub fifo: u32,
    /// Linux PM QoS CPU wake-up latency held during the measurement [µs].
    pub cpu_wakeup_latency_us: Option<u32>,
    /// KiB of its own memory the echo reads on each wake-up (a working set).
    pub touch_kib: usize,
    /// A warm-up round trip this long before each measured one (zero = none).
    pub prewarm: Duration,
    /// This process is the echo (set on the child the sender starts).
    pub echo: bool,
    /// The echo runs elsewhere — another host, across the link (`sc-link`) — in this
    /// run, started there as `SC_RUN_ID=<id> sc-hop-cost --echo`: the sender joins the
    /// run and starts no echo of its own.
    pub remote_echo: Option<String>,
}

impl Default for HopCostOptions {
    fn default() -> Self {
        Self {
            n: 300,
            period: Duration::from_millis(100),
            cpus: None,
            fifo: 0,
            cpu_wakeup_latency_us: None,
            touch_kib: 0,
            prewarm: Duration::ZERO,
            echo: false,
            remote_echo: None,
        }
    }
}

impl HopCostOptions {
    /// Parses the arguments (without the program name).
    pub fn parse(args: &[String]) -> Result<Self, BenchError> {
        let usage = |what: String| BenchError::Data(what);
        let mut o = Self::default();
        let mut it = args.iter();
        while let Some(a) = it.next() {
            let mut val = || {
                it.next()
                    .ok_or(usage(format!("{a} needs a value ({USAGE})")))
            };
            let num = |s: &str| s.parse::<u64>().map_err(|e| usage(format!("{a} {s}: {e}")));
            match a.as_str() {
                "--n" => o.n = num(val()?)? as usize,
                "--period-us" => o.period = Duration::from_micros(num(val()?)?),
                "--fifo" => o.fifo = num(val()?)? as u32,
                "--cpu-wakeup-latency-us" => o.cpu_wakeup_latency_us = Some(num(val()?)? as u32),
                "--touch-kib" => o.touch_kib = num(val()?)? as usize,
                "--prewarm-us" => o.prewarm = Duration::from_micros(num(val()?)?),
                "--cpus" => {
                    let v = val()?;
                    let (a, b) = v
                        .split_once(',')
                        .ok_or(usage(format!("--cpus A,B ({USAGE})")))?;
                    o.cpus = Some((num(a)? as usize, num(b)? as usize));
                }
                "--echo" => o.echo = true,
                "--remote-echo" => o.remote_echo = Some(val()?.clone()),
                other => return Err(usage(format!("unknown argument {other} ({USAGE})"))),
            }
        }
        if o.n == 0 {
            return Err(usage("--n must be at least 1".into()));
        }
        Ok(o)
    }
}

/// Round-trip percentiles [µs].
#[derive(Debug, Clone, PartialEq)]
pub struct RoundTrips {
    pub n: usize,
    pub min_us: f64,
    pub p50_us: f64,
    pub p90_us: f64,
    pub p99_us: f64,
    pub max_us: f64,
}

impl std::fmt::Display for RoundTrips {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "round trip (2 hops), {} samples: min {:.1} p50 {:.1} p90 {:.1} p99 {:.1} max {:.1} us",
            self.n, self.min_us, self.p50_us, self.p90_us, self.p99_us, self.max_us
        )
    }
}

fn place(o: &HopCostOptions, cpu: Option<usize>) {
    if let Some(c) = cpu {
        set_cpus("hop-cost", &[c]);
    }
    if o.fifo > 0 {
        set_fifo("hop-cost", o.fifo);
    }
}

/// The echo process of the run named in the environment (`SC_RUN_ID`, set by the
/// sender that started it).
pub fn echo_from_env(o: &HopCostOptions) -> Result<(), BenchError> {
    let run_id = std::env::var(sc_bus::RUN_ID_ENV).unwrap_or_default();
    echo(&run_id, o)
}

/// The echo process: answers every ping until the stop.
pub fn echo(run_id: &str, o: &HopCostOptions) -> Result<(), BenchError> {
    place(o, o.cpus.map(|c| c.1));
    let scope = RunScope::new(run_id)?;
    let node = scope.node("echo")?;
    let q = ServiceSettings::lock_step();
    let ping = Subscriber::<Tick>::with_name(&node, "hop/ping", &q)?;
    let pong = Publisher::<Tick>::with_name(&node, "hop/pong", &q)?;
    let work = vec![1u8; o.touch_kib * 1024];
    Participant::new(&node, services::HANDSHAKE, 1)?.announce_and_wait(Duration::from_secs(20))?;
    let waiter = Waiter::new()?;
    let _a = waiter.attach(&ping)?;
    loop {
        if waiter.wait_once(Duration::from_secs(5), |_| {})? != sc_bus::WaitOutcome::Handled {
            return Ok(());
        }
        ping.drain_events()?;
        while let Some(t) = ping.try_receive()? {
            if t.tick == STOP_TICK {
                return Ok(());
            }
            // one byte per cache line of the working set
            let s = work
                .iter()
                .step_by(64)
                .fold(0u32, |s, b| s.wrapping_add(u32::from(*b)));
            pong.send(&Tick { _pad0: s, ..t })?;
        }
    }
}

/// Sends `tick` and waits for its echo (at most 2 s).
fn round_trip(
    ping: &Publisher<Tick>,
    pong: &Subscriber<Tick>,
    waiter: &Waiter,
    tick: u64,
) -> Result<Duration, BenchError> {
    let t0 = Instant::now();
    ping.send(&Tick {
        tick,
        ..Default::default()
    })?;
    loop {
        waiter.wait_once(Duration::from_secs(1), |_| {})?;
        pong.drain_events()?;
        if pong.try_receive()?.is_some_and(|t| t.tick == tick) {
            return Ok(t0.elapsed());
        }
        if t0.elapsed() >= ECHO_TIMEOUT {
            return Err(BenchError::Data(format!("no echo of tick {tick}")));
        }
    }
}

/// The sender: starts `exe args --echo` as the echo process (with `--remote-echo`: joins
/// that run, whose echo was started on the other host), measures `o.n` round trips
/// (after 10 unmeasured ones), stops the echo and removes the run's files (not with
/// `--remote-echo`: the link's node still lives in that run; its host's `down` or the
/// last process of the run removes them).
pub fn measure(
    o: &HopCostOptions,
    exe: &std::path::Path,
    args: &[String],
) -> Result<RoundTrips, BenchError> {
    place(o, o.cpus.map(|c| c.0));
    let _pm_qos = o
        .cpu_wakeup_latency_us
        .map(CpuWakeupLatency::request)
        .transpose()
        .map_err(|e| BenchError::Data(format!("PM QoS ({}): {e}", crate::pm_qos::DEVICE)))?;
    let scope = match &o.remote_echo {
        Some(run_id) => RunScope::new(run_id)?,
        None => RunScope::unique("hopcost")?,
    };
    let mut rt = Vec::with_capacity(o.n);
    {
        let node = scope.node("sender")?;
        let q = ServiceSettings::lock_step();
        let ping = Publisher::<Tick>::with_name(&node, "hop/ping", &q)?;
        let pong = Subscriber::<Tick>::with_name(&node, "hop/pong", &q)?;
        let coord = Coordinator::new(&node, services::HANDSHAKE, &[1])?;
        let mut child = match o.remote_echo {
            Some(_) => None,
            None => Some(
                std::process::Command::new(exe)
                    .args(args)
                    .arg("--echo")
                    .env(sc_bus::RUN_ID_ENV, scope.run_id())
                    .spawn()
                    .map_err(|e| {
                        BenchError::Data(format!("cannot start {}: {e}", exe.display()))
                    })?,
            ),
        };
        coord.wait_all(Duration::from_secs(20))?;
        let waiter = Waiter::new()?;
        let _a = waiter.attach(&pong)?;
        for k in 0..o.n as u64 + 10 {
            if o.prewarm.is_zero() {
                std::thread::sleep(o.period);
            } else {
                std::thread::sleep(o.period.saturating_sub(o.prewarm));
                let w = round_trip(&ping, &pong, &waiter, WARM_TICK)?;
                std::thread::sleep(o.prewarm.saturating_sub(w));
            }
            let d = round_trip(&ping, &pong, &waiter, k)?;
            if k >= 10 {
                rt.push(d.as_secs_f64() * 1e6);
            }
        }
        ping.send(&Tick {
            tick: STOP_TICK,
            ..Default::default()
        })?;
        if let Some(child) = child.as_mut() {
            child
                .wait()
                .map_err(|e| BenchError::Data(format!("the echo process: {e}")))?;
        }
    }
    // a run of our own is ours to remove; across hosts the link's node still lives in it
    if o.remote_echo.is_none() {
        scope.teardown()?;
    }
    rt.sort_by(f64::total_cmp);
    let p = |q: f64| rt[((rt.len() - 1) as f64 * q).round() as usize];
    Ok(RoundTrips {
        n: rt.len(),
        min_us: rt[0],
        p50_us: p(0.5),
        p90_us: p(0.9),
        p99_us: p(0.99),
        max_us: rt[rt.len() - 1],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_are_parsed_and_checked() {
        let a = |s: &str| s.split_whitespace().map(String::from).collect::<Vec<_>>();
        let o = HopCostOptions::parse(&a(
            "--n 5 --period-us 2000 --cpus 1,0 --fifo 50 --cpu-wakeup-latency-us 0 --touch-kib 8 --prewarm-us 500",
        ))
        .unwrap();
        assert_eq!(o.n, 5);
        assert_eq!(o.period, Duration::from_millis(2));
        assert_eq!(o.cpus, Some((1, 0)));
        assert_eq!(
            (o.fifo, o.cpu_wakeup_latency_us, o.touch_kib),
            (50, Some(0), 8)
        );
        assert_eq!(o.prewarm, Duration::from_micros(500));
        assert!(!o.echo);
        assert!(HopCostOptions::parse(&a("--echo")).unwrap().echo);
        let remote = HopCostOptions::parse(&a("--remote-echo run7")).unwrap();
        assert_eq!(remote.remote_echo.as_deref(), Some("run7"));
        for bad in [
            "--n 0",
            "--cpus 1",
            "--period-us x",
            "--bogus",
            "--n",
            "--remote-echo",
        ] {
            assert!(HopCostOptions::parse(&a(bad)).is_err(), "{bad}");
        }
    }
}
