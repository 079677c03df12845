//! The scheduler: handshake, ticks by rate group (lock-step or real time), the end of
//! the mission, liveness of the peers.

use crate::config::ClockMode;
use crate::process::{Proc, qos, send, wait, warmup_enabled};
use anyhow::Context;
use sc_bus::{PeerMonitor, Publisher, SignalSender, Subscriber, Waiter};
use sc_icd::*;
use std::time::{Duration, Instant};

use super::*;

/// Statistics the scheduler writes to `scheduler.json`.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct SchedulerReport {
    pub clock: String,
    pub base_period_s: f64,
    pub ticks: u64,
    pub cycle_slips: u64,
    /// Stage deadlines that passed with the tick unfinished (each woke the filters).
    #[serde(default)]
    pub watchdog_wakeups: u64,
    pub end: String,
    pub lost_peers: Vec<String>,
    pub aborted: bool,
    pub wall_s: f64,
}

/// Rate-group driver: handshake, ticks (lock-step or real time), end of mission,
/// liveness of the peers.
pub fn scheduler() -> anyhow::Result<i32> {
    let p = Proc::start("scheduler")?;
    let q = qos();
    let tick_tx = Publisher::<Tick>::new(&p.node, services::TICK, &q)?;
    let control_tx = Publisher::<Tick>::new(&p.node, services::CONTROL, &q)?;
    let result_rx = Subscriber::<StepResult>::new(&p.node, services::STEP_RESULT, &q)?;
    let watchdog = SignalSender::new(&p.node, services::STAGE_DEADLINE.as_str(), &q)?;
    // real time: the pre-tick warm-up signal, `warmup_lead_us` before each tick
    let lead = Duration::from_micros(u64::from(p.cfg.warmup_lead_us));
    let prepare = warmup_enabled(&p)
        .then(|| SignalSender::new(&p.node, services::PREPARE.as_str(), &q))
        .transpose()?;
    // lock-step flow control: the recorder's progress (listener created on first wait)
    let recorder_rx = Subscriber::<Health>::polled(&p.node, services::HEALTH, &q)?;
    let on_recorder = Waiter::new()?;
    let mut recorder_attached = Vec::new();
    let mut recorder_taken: u64 = 0; // step results the recorder has taken
    let window = p.cfg.lock_step.recorder_window_ticks;
    let waiter = Waiter::new()?;
    let _a = waiter.attach(&result_rx)?;
    let d = &p.cfg.deadlines;
    // The filters wake on their inputs only; the watchdog wakes them when a stage
    // deadline of an unfinished tick passed, so that they apply their fallback.
    let stage_deadlines = [
        p.deadline(d.safety_translational_ms),
        p.deadline(d.safety_attitude_ms),
        p.deadline(d.safety_robotic_ms),
    ];
    let peers: Vec<&str> = sc_icd::ROLES[1..].iter().map(|r| r.name).collect();
    let ids: Vec<u32> = sc_icd::ROLES[1..].iter().map(|r| r.id()).collect();
    let coord = sc_bus::Coordinator::new(&p.node, services::HANDSHAKE, &ids)?;
    coord
        .wait_all(Duration::from_secs_f64(p.cfg.handshake_timeout_s))
        .map_err(|e| match e {
            // name the roles that never joined (the bus only knows their ids)
            sc_bus::BusError::HandshakeTimeout { timeout, missing } => {
                let names: Vec<&str> = missing
                    .iter()
                    .map(|&id| sc_icd::Role::with_id(id).map_or("?", |r| r.name))
                    .collect();
                anyhow::anyhow!(
                    "handshake timed out after {timeout:?}: never joined: {} (see their logs)",
                    names.join(", ")
                )
            }
            e => e.into(),
        })?;
    eprintln!("scheduler: all {} processes ready", ids.len());
    // from now on a process that dies is a degraded mode, not a failed start
    let ready = p.out.join(crate::ALL_READY);
    std::fs::write(&ready, "").with_context(|| format!("cannot write {}", ready.display()))?;
    let mut monitor = PeerMonitor::new(&peers);
    monitor.poll(&p.run)?;
    let base = p.schedule.base_period_s;
    let period = Duration::from_secs_f64(base);
    let clock_mode = match p.cfg.clock {
        ClockMode::LockStep => clock_mode::LOCK_STEP,
        ClockMode::RealTime => clock_mode::REAL_TIME,
    };
    let step_timeout = p.deadline(p.cfg.deadlines.simulator_ms) * 3 + Duration::from_secs(2);
    let mut rep = SchedulerReport {
        clock: format!("{:?}", p.cfg.clock),
        base_period_s: base,
        ..Default::default()
    };
    let started = Instant::now();
    let mut k: u64 = 0;
    let mut slot: u32 = 0;
    let mut code = 0;
    let mut running = true;
    let check = |monitor: &mut PeerMonitor, rep: &mut SchedulerReport| -> anyhow::Result<bool> {
        let mut fatal = false;
        for lost in monitor.poll(&p.run)? {
            eprintln!(
                "scheduler: FAULT peer `{}` (pid {}) died",
                lost.name, lost.pid
            );
            if matches!(lost.name.as_str(), "simulator" | "recorder") {
                fatal = true;
            }
            rep.lost_peers.push(lost.name);
        }
        Ok(fatal)
    };
    'ticks: while running {
        if p.cfg.max_ticks > 0 && k >= p.cfg.max_ticks {
            rep.end = "max_ticks".into();
            break;
        }
        if clock_mode == clock_mode::REAL_TIME {
            let target = started + period * slot;
            if let Some(prepare) = &prepare {
                let at = target.checked_sub(lead).unwrap_or(target);
                if Instant::now() < at {
                    while Instant::now() < at {
                        if !wait(&waiter, Some(at))? {
                            rep.end = "interrupted".into();
                            break 'ticks;
                        }
                        drain(&result_rx)?;
                    }
                    prepare.notify()?;
                }
            }
            while Instant::now() < target {
                if !wait(&waiter, Some(target))? {
                    rep.end = "interrupted".into();
                    break 'ticks;
                }
                drain(&result_rx)?;
            }
            slot += 1;
        }
        // the recorder's progress (drained in every mode: its queue must not fill);
        // lock-step: stay at most `window` ticks ahead of the recorder, so that its
        // queues never fill and nothing is lost on a loaded machine
        let since = Instant::now();
        loop {
            for h in drain(&recorder_rx)? {
                if h.role == sc_icd::Role::of(sc_icd::RoleKind::Recorder).id() {
                    recorder_taken = recorder_taken.max(h.last_tick + 1);
                }
            }
            if clock_mode != clock_mode::LOCK_STEP || recorder_taken + window >= k {
                break;
            }
            if recorder_attached.is_empty() {
                recorder_attached.push(on_recorder.attach(&recorder_rx)?);
                continue; // read what came before the listener existed
            }
            if !wait(&on_recorder, Some(Instant::now() + Duration::from_secs(1)))? {
                rep.end = "interrupted".into();
                break 'ticks;
            }
            if since.elapsed() > Duration::from_secs(1) && check(&mut monitor, &mut rep)? {
                code = 3;
                rep.aborted = true;
                break 'ticks;
            }
            if since.elapsed() > step_timeout * 5 {
                eprintln!(
                    "scheduler: FAULT the recorder took no step result for {:?} (at tick {recorder_taken} of {k})",
                    since.elapsed()
                );
                code = 3;
                rep.aborted = true;
                break 'ticks;
            }
        }
        let tick = Tick {
            tick: k,
            due_mask: p.schedule.due_mask(k),
            clock_mode,
            t: k as f64 * base,
            send_ns: now(),
            command: tick_command::STEP,
            _pad0: 0,
        };
        send(&tick_tx, &tick)?;
        let sent = Instant::now();
        let mut next_stage = 0;
        // wait for the step result of tick k
        loop {
            let until = match clock_mode {
                clock_mode::REAL_TIME => started + period * slot,
                _ => sent + step_timeout,
            };
            let wake = match stage_deadlines.get(next_stage) {
                Some(d) => until.min(sent + *d),
                None => until,
            };
            if !wait(&waiter, Some(wake))? {
                rep.end = "interrupted".into();
                break 'ticks;
            }
            let mut done = None;
            for r in drain(&result_rx)? {
                if r.tick == k {
                    done = Some(r);
                }
            }
            while stage_deadlines
                .get(next_stage)
                .is_some_and(|d| done.is_none() && sent.elapsed() >= *d)
            {
                watchdog.notify()?;
                rep.watchdog_wakeups += 1;
                next_stage += 1;
            }
            if let Some(r) = done {
                if r.end == end::SIMULATOR_FAILED || (r.end != end::RUNNING && p.cfg.max_ticks == 0)
                {
                    rep.end = match r.end {
                        end::CAPTURED => "captured",
                        end::TIMEOUT => "timeout",
                        _ => "simulator_failed",
                    }
                    .into();
                    running = false;
                }
                break;
            }
            if sent.elapsed() > Duration::from_secs(1) && check(&mut monitor, &mut rep)? {
                // the simulator or the recorder died: the run cannot go on
                code = 3;
                rep.aborted = true;
                break 'ticks;
            }
            if Instant::now() >= until {
                if clock_mode == clock_mode::REAL_TIME {
                    // the next tick is due while this one is unfinished: a cycle slip
                    rep.cycle_slips += 1;
                    slot += 1;
                    if check(&mut monitor, &mut rep)? {
                        code = 3;
                        rep.aborted = true;
                        break 'ticks;
                    }
                    if sent.elapsed() < step_timeout {
                        continue;
                    }
                }
                eprintln!(
                    "scheduler: FAULT no step result for tick {k} within {:?}",
                    sent.elapsed()
                );
                if check(&mut monitor, &mut rep)? || sent.elapsed() > step_timeout * 5 {
                    code = 3;
                    rep.aborted = true;
                    break 'ticks;
                }
            }
        }
        k += 1;
        rep.ticks = k;
        if k.is_multiple_of(50) && check(&mut monitor, &mut rep)? {
            code = 3;
            rep.aborted = true;
            break;
        }
    }
    if rep.end.is_empty() {
        rep.end = "aborted".into();
    }
    rep.wall_s = started.elapsed().as_secs_f64();
    let stop = Tick {
        tick: k,
        command: tick_command::STOP,
        send_ns: now(),
        ..Default::default()
    };
    // Control first: the simulator wakes on the tick and wakes the others, who
    // then look for the stop on the control service, which must be there already.
    send(&control_tx, &stop)?;
    send(&tick_tx, &stop)?;
    eprintln!(
        "scheduler: {} after {} ticks, {} cycle slips, lost peers {:?}, wall {:.2} s",
        rep.end, rep.ticks, rep.cycle_slips, rep.lost_peers, rep.wall_s
    );
    std::fs::create_dir_all(&p.out).ok();
    std::fs::write(
        p.out.join("scheduler.json"),
        serde_json::to_string_pretty(&rep)? + "\n",
    )
    .context("writing scheduler.json")?;
    Ok(code)
}
