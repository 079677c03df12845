//! A minimal participant process: joins the handshake as participant 1, then
//! answers every `Tick` on `<base>/ping` with `tick + 1000` on `<base>/pong`,
//! sleeping on the event between messages. Used by the two-process tests.
//!
//! Usage: `sc-bus-peer <run id> <base service name>`; exits on tick `u64::MAX`.

use sc_bus::{Participant, Publisher, RunScope, ServiceSettings, Subscriber, WaitOutcome, Waiter};
use sc_icd::{Tick, services};
use std::process::ExitCode;
use std::time::Duration;

fn run(run_id: &str, base: &str) -> sc_bus::Result<()> {
    sc_bus::init_logging();
    let scope = RunScope::new(run_id)?;
    let node = scope.node("peer")?;
    let qos = ServiceSettings::lock_step();
    let ping = Subscriber::<Tick>::with_name(&node, &format!("{base}/ping"), &qos)?;
    let pong = Publisher::<Tick>::with_name(&node, &format!("{base}/pong"), &qos)?;
    // All ports exist: now tell the coordinator.
    Participant::new(&node, services::HANDSHAKE, 1)?.announce_and_wait(Duration::from_secs(20))?;

    let waiter = Waiter::new()?;
    let on_ping = waiter.attach(&ping)?;
    loop {
        let mut result = Ok(false);
        let outcome = waiter.wait_once(Duration::from_secs(30), |wake| {
            if on_ping.woke(&wake) {
                result = (|| {
                    ping.drain_events()?;
                    let mut got = Vec::new();
                    ping.receive_all(&mut got)?;
                    for t in got {
                        if t.tick == u64::MAX {
                            return Ok(true);
                        }
                        pong.send(&Tick {
                            tick: t.tick + 1000,
                            send_ns: sc_icd::monotonic_ns(),
                            ..t
                        })?;
                    }
                    Ok(false)
                })();
            }
        })?;
        if result? {
            return Ok(());
        }
        match outcome {
            WaitOutcome::Handled => {}
            WaitOutcome::Timeout => return Ok(()),
            WaitOutcome::TerminationRequest => return Ok(()),
        }
    }
}

/// A no-op SIGUSR1 handler: stands for the handlers of profilers, debuggers and
/// runtime libraries, whose signals interrupt a blocking wait (EINTR). The tests send
/// SIGUSR1 to check that such a wake-up is not taken for a stop.
extern "C" fn ignore_signal(_: libc::c_int) {}

fn main() -> ExitCode {
    // SAFETY: the handler does nothing, which is async-signal-safe.
    unsafe {
        libc::signal(
            libc::SIGUSR1,
            ignore_signal as *const () as libc::sighandler_t,
        )
    };
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        eprintln!("usage: sc-bus-peer <run id> <base service name>");
        return ExitCode::from(2);
    }
    match run(&args[1], &args[2]) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sc-bus-peer: {e}");
            ExitCode::FAILURE
        }
    }
}
