//! What one hop of the partition costs on this machine: a `Tick` sent with
//! [`sc_bus::Publisher::send`] (sample + event) to a second process that sleeps in a
//! [`sc_bus::Waiter`] and echoes it back. Measures the round trip (two hops) at a
//! given period, so that the receiver is as cold as the partition's processes are
//! between ticks.
//!
//! ```sh
//! cargo run --release -p sc-bus --bin sc-bus-hop-cost -- --n 300 --period-us 100000 --cpus 1,1 --fifo 50
//! ```
//!
//! Options: `--n` round trips (default 300), `--period-us` pause between them
//! (default 100000: the partition's 10 Hz), `--cpus A,B` pin the sender to A and the
//! echo to B, `--fifo P` SCHED_FIFO priority P for both (needs CAP_SYS_NICE),
//! `--cpu-wakeup-latency-us L` hold Linux PM QoS at L µs during the measurement (as
//! the partition's launcher does; needs root), `--touch-kib K` the echo reads K KiB of
//! its own memory on each wake-up (stands for a process's working set),
//! `--prewarm-us W` a warm-up round trip W µs before each measured one (the
//! partition's pre-tick warm-up).

use sc_bus::{Participant, Publisher, RunScope, ServiceSettings, Subscriber, WaitOutcome, Waiter};
use sc_icd::{Tick, services};
use std::process::ExitCode;
use std::time::{Duration, Instant};

struct Opts {
    n: usize,
    period: Duration,
    cpus: Option<(usize, usize)>,
    fifo: i32,
    touch_kib: usize,
    prewarm: Duration,
    wakeup_latency_us: Option<i32>,
}

fn parse() -> Result<Opts, String> {
    let mut o = Opts {
        n: 300,
        period: Duration::from_micros(100_000),
        cpus: None,
        fifo: 0,
        touch_kib: 0,
        prewarm: Duration::ZERO,
        wakeup_latency_us: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut val = || args.next().ok_or(format!("{a} needs a value"));
        let num = |s: String| s.parse::<u64>().map_err(|e| format!("{s}: {e}"));
        match a.as_str() {
            "--n" => o.n = num(val()?)? as usize,
            "--period-us" => o.period = Duration::from_micros(num(val()?)?),
            "--fifo" => o.fifo = num(val()?)? as i32,
            "--touch-kib" => o.touch_kib = num(val()?)? as usize,
            "--prewarm-us" => o.prewarm = Duration::from_micros(num(val()?)?),
            "--cpu-wakeup-latency-us" => o.wakeup_latency_us = Some(num(val()?)? as i32),
            "--cpus" => {
                let v = val()?;
                let (a, b) = v.split_once(',').ok_or("--cpus A,B")?;
                o.cpus = Some((num(a.into())? as usize, num(b.into())? as usize));
            }
            "--echo" => {} // internal: this process is the echo (started by the sender)
            other => return Err(format!("unknown argument {other}")),
        }
    }
    Ok(o)
}

fn place(cpu: Option<usize>, fifo: i32) {
    // SAFETY: plain libc calls on this process with initialised arguments.
    unsafe {
        if let Some(c) = cpu {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            libc::CPU_SET(c, &mut set);
            libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
        }
        if fifo > 0 {
            let p = libc::sched_param {
                sched_priority: fifo,
            };
            libc::sched_setscheduler(0, libc::SCHED_FIFO, &p);
        }
    }
}

fn echo(run_id: &str, o: &Opts) -> sc_bus::Result<()> {
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
        if waiter.wait_once(Duration::from_secs(5), |_| {})? != WaitOutcome::Handled {
            return Ok(());
        }
        ping.drain_events()?;
        while let Some(t) = ping.try_receive()? {
            if t.command == 1 {
                return Ok(());
            }
            let mut s = 0u64;
            for b in work.iter().step_by(64) {
                s = s.wrapping_add(*b as u64);
            }
            pong.send(&Tick {
                tick: t.tick,
                _pad0: s as u32,
                ..t
            })?;
        }
    }
}

fn main() -> ExitCode {
    let o = match parse() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("sc-bus-hop-cost: {e}");
            return ExitCode::from(2);
        }
    };
    let argv: Vec<String> = std::env::args().collect();
    if argv.iter().any(|a| a == "--echo") {
        place(o.cpus.map(|c| c.1), o.fifo);
        let run_id = std::env::var(sc_bus::RUN_ID_ENV).unwrap_or_default();
        return match echo(&run_id, &o) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("echo: {e}");
                ExitCode::FAILURE
            }
        };
    }
    match measure(&o, &argv) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sc-bus-hop-cost: {e}");
            ExitCode::FAILURE
        }
    }
}

fn measure(o: &Opts, argv: &[String]) -> Result<(), Box<dyn std::error::Error>> {
    place(o.cpus.map(|c| c.0), o.fifo);
    // PM QoS: held while the device stays open (binary s32, native byte order)
    let _pm_qos = match o.wakeup_latency_us {
        Some(us) => {
            use std::io::Write;
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .open("/dev/cpu_dma_latency")?;
            f.write_all(&us.to_ne_bytes())?;
            Some(f)
        }
        None => None,
    };
    let scope = RunScope::unique("hopcost")?;
    let node = scope.node("sender")?;
    let q = ServiceSettings::lock_step();
    let ping = Publisher::<Tick>::with_name(&node, "hop/ping", &q)?;
    let pong = Subscriber::<Tick>::with_name(&node, "hop/pong", &q)?;
    let coord = sc_bus::Coordinator::new(&node, services::HANDSHAKE, &[1])?;
    let mut child = std::process::Command::new(&argv[0])
        .args(&argv[1..])
        .arg("--echo")
        .env(sc_bus::RUN_ID_ENV, scope.run_id())
        .spawn()?;
    coord.wait_all(Duration::from_secs(20))?;
    let waiter = Waiter::new()?;
    let _a = waiter.attach(&pong)?;
    let mut rt = Vec::with_capacity(o.n);
    for k in 0..o.n as u64 + 10 {
        if o.prewarm.is_zero() {
            std::thread::sleep(o.period);
        } else {
            // a warm-up round trip `prewarm` before the measured one
            std::thread::sleep(o.period.saturating_sub(o.prewarm));
            ping.send(&Tick {
                tick: u64::MAX,
                ..Default::default()
            })?;
            let w0 = Instant::now();
            while w0.elapsed() < Duration::from_secs(1) {
                waiter.wait_once(Duration::from_secs(1), |_| {})?;
                pong.drain_events()?;
                if pong.try_receive()?.is_some_and(|t| t.tick == u64::MAX) {
                    break;
                }
            }
            std::thread::sleep(o.prewarm.saturating_sub(w0.elapsed()));
        }
        let t0 = Instant::now();
        ping.send(&Tick {
            tick: k,
            ..Default::default()
        })?;
        loop {
            waiter.wait_once(Duration::from_secs(1), |_| {})?;
            pong.drain_events()?;
            if pong.try_receive()?.is_some_and(|t| t.tick == k) {
                break;
            }
            if t0.elapsed() > Duration::from_secs(2) {
                return Err("no echo".into());
            }
        }
        if k >= 10 {
            rt.push(t0.elapsed().as_secs_f64() * 1e6);
        }
    }
    ping.send(&Tick {
        command: 1,
        ..Default::default()
    })?;
    child.wait()?;
    drop(_a);
    drop(waiter);
    drop((ping, pong, coord, node));
    scope.teardown()?;
    rt.sort_by(f64::total_cmp);
    let p = |q: f64| rt[((rt.len() - 1) as f64 * q).round() as usize];
    println!(
        "round trip (2 hops), {} samples, period {:?}: min {:.1} p50 {:.1} p90 {:.1} p99 {:.1} max {:.1} us",
        rt.len(),
        o.period,
        rt[0],
        p(0.5),
        p(0.9),
        p(0.99),
        rt[rt.len() - 1]
    );
    Ok(())
}
