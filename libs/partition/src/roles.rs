//! The loop of every process. Each wakes on iceoryx2 events only (WaitSet), no
//! busy polling; deadlines are timed waits.

use crate::config::ClockMode;
use crate::convert;
use crate::fallback;
use crate::process::{
    LOST_STOP_WAKEUP, Proc, partner_qos, prepare_listener, qos, send, wait, wait_outcome,
    warmup_enabled,
};
use anyhow::Context;
use nalgebra::Vector3;
use sc_bus::{
    PeerMonitor, Publisher, SignalListener, SignalSender, Subscriber, WaitOutcome, Waitable, Waiter,
};
use sc_cbf::SafetyLayer;
use sc_icd::*;
use sc_mission::stages;
use sc_nominal::{NominalControllers, Subsystems};
use sc_sim::{Command, Simulator};
use std::time::{Duration, Instant};

fn now() -> u64 {
    monotonic_ns()
}

/// Drains a subscriber's events and returns its queued samples.
fn drain<T: core::fmt::Debug + sc_bus::ZeroCopySend + Copy + 'static>(
    s: &Subscriber<T>,
) -> anyhow::Result<Vec<T>> {
    s.drain_events()?;
    let mut v = Vec::new();
    s.receive_all(&mut v)?;
    Ok(v)
}

/// Drains an optional subscriber (a role's input that this process may not have)
/// and returns its newest sample, if any came.
fn newest<T: core::fmt::Debug + sc_bus::ZeroCopySend + Copy + 'static>(
    s: Option<&Subscriber<T>>,
) -> anyhow::Result<Option<T>> {
    Ok(match s {
        Some(s) => drain(s)?.pop(),
        None => None,
    })
}

/// Drains a partner's nominal-command subscriber into `held`: a command for the awaited
/// tick `want` is never replaced by one for another tick (a partner bursting commands
/// with other ticks cannot hide the one the filter waits for); among several for the
/// same tick the newest wins. Returns whether anything came.
fn keep_for_tick<T: core::fmt::Debug + sc_bus::ZeroCopySend + Copy + 'static>(
    s: Option<&Subscriber<T>>,
    held: &mut Option<T>,
    want: Option<u64>,
    tick: impl Fn(&T) -> u64,
) -> anyhow::Result<bool> {
    let Some(s) = s else {
        return Ok(false);
    };
    let got = drain(s)?;
    for m in &got {
        let holds_wanted = held.as_ref().is_some_and(|h| Some(tick(h)) == want);
        if Some(tick(m)) == want || !holds_wanted {
            *held = Some(*m);
        }
    }
    Ok(!got.is_empty())
}

/// The `Instant` of a monotonic time stamp `ns` of another process (same clock).
fn instant_of(ns: u64) -> Instant {
    let t = Instant::now();
    if ns == 0 {
        return t; // no stamp: count from now
    }
    let ago = Duration::from_nanos(now().saturating_sub(ns));
    t.checked_sub(ago).unwrap_or(t)
}

fn stop_seen(ticks: &[Tick]) -> bool {
    ticks.iter().any(|t| t.command == tick_command::STOP)
}

// ---------------------------------------------------------------- scheduler

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
    let peers: Vec<&str> = crate::config::ROLES[1..].to_vec();
    let ids: Vec<u32> = (1..crate::config::ROLES.len() as u32).collect();
    let coord = sc_bus::Coordinator::new(&p.node, services::HANDSHAKE, &ids)?;
    coord.wait_all(Duration::from_secs_f64(p.cfg.handshake_timeout_s))?;
    eprintln!("scheduler: all {} processes ready", ids.len());
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
                if h.role == sc_icd::role::RECORDER {
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

// ---------------------------------------------------------------- simulator

/// The simulator: publishes the state of each tick, applies the safe commands
/// (held for slower rate groups, the filter's fallback when missing), ends the
/// mission on capture/timeout.
pub fn simulator() -> anyhow::Result<i32> {
    let p = Proc::start("simulator")?;
    let q = qos();
    let tick_rx = Subscriber::<Tick>::new(&p.node, services::TICK, &q)?;
    let st_rx = Subscriber::<SafeTranslational>::polled(&p.node, services::SAFE_TRANSLATIONAL, &q)?;
    let sa_rx = Subscriber::<SafeAttitude>::polled(&p.node, services::SAFE_ATTITUDE, &q)?;
    let sr_rx = Subscriber::<SafeRobotic>::new(&p.node, services::SAFE_ROBOTIC, &q)?;
    let state_tx = Publisher::<SimState>::new(&p.node, services::SIM_STATE, &q)?;
    let result_tx = Publisher::<StepResult>::new(&p.node, services::STEP_RESULT, &q)?;
    // Wake-ups (docs/PARTITION.md, "Who wakes whom"): between ticks on the tick only;
    // within a tick on the robotic safe command, the last of the causal chain (the
    // earlier ones were sent before it). While a filter is absent (dead or late: its
    // command may never come) or the robotic group is not due, on every safe
    // command: their listeners are created then, so that in a healthy run the
    // translational and attitude filters wake only their downstream filter.
    let on_tick = Waiter::new()?;
    let _a0 = on_tick.attach(&tick_rx)?;
    // real time: the pre-tick warm-up (docs/PARTITION.md, "What a hop costs")
    let prepare = prepare_listener(&p)?;
    let _a2 = prepare.as_ref().map(|l| on_tick.attach(l)).transpose()?;
    let on_robotic = Waiter::new()?;
    let _a1 = [on_robotic.attach(&tick_rx)?, on_robotic.attach(&sr_rx)?];
    let on_any = Waiter::new()?;
    let mut any_attached = Vec::new();
    let scenario = p.scenario_with_period(p.schedule.base_period_s);
    let mut sim =
        Simulator::new(&scenario, p.setup.robot.clone()).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut layer = SafetyLayer::from_scenario(&scenario, p.setup.robot.clone());
    let robot = p.setup.robot.clone();
    let monitor = sc_cbf::monitor::Monitor::from_scenario(&scenario, robot.clone());
    let mut between: Option<sc_cbf::monitor::Barriers> = None;
    let deadline = p.deadline(p.cfg.deadlines.simulator_ms);
    let keep_going = p.cfg.max_ticks > 0;
    p.handshake()?;
    let mut ticks: Vec<Tick> = Vec::new();
    let (mut got_t, mut got_a, mut got_r): (
        Option<SafeTranslational>,
        Option<SafeAttitude>,
        Option<SafeRobotic>,
    ) = (None, None, None);
    let mut absent = [false; 3];
    let mut held = Command::zero();
    let mut held_f_h = Vector3::zeros();
    let mut ended = false;
    let mut misses = 0u64;
    loop {
        if ticks.is_empty() {
            if !wait(&on_tick, None)? {
                break;
            }
            if let Some(l) = &prepare
                && l.drain()? > 0
            {
                // rehearse the start of a tick on the current state; nothing is sent
                p.rehearse(|| {
                    std::hint::black_box(convert::sim_state(&sim.observe()));
                    state_tx.warm()
                })?;
            }
            ticks.extend(drain(&tick_rx)?);
            // keep only the newest safe commands; tick-matched below (read in
            // reverse causal order, as in the loop below)
            got_r = newest(Some(&sr_rx))?.or(got_r);
            got_a = newest(Some(&sa_rx))?.or(got_a);
            got_t = newest(Some(&st_rx))?.or(got_t);
            continue;
        }
        let tick = ticks.remove(0);
        if tick.command == tick_command::STOP {
            // wake the consumers once so that they see the stop too
            state_tx.notify()?;
            result_tx.notify()?;
            break;
        }
        if ended {
            continue;
        }
        let recv_ns = now();
        let o = sim.observe();
        let mut msg = convert::sim_state(&o);
        let barriers = monitor.evaluate(&stages::monitor_state(&o));
        msg.barriers = barriers;
        msg.barriers_between = between.unwrap_or(barriers);
        // the phase is the mission's own schedule, never a partner's report
        let phase = scenario.phase_index(o.t);
        msg.tick = tick.tick;
        msg.due_mask = tick.due_mask;
        msg.tick_send_ns = tick.send_ns;
        msg.recv_ns = recv_ns;
        msg.publish_ns = now();
        send(&state_tx, &msg)?;
        let k = tick.tick;
        let due = tick.due_mask;
        let until = Instant::now() + deadline;
        let mut safe_recv_ns = 0;
        loop {
            let have = |bit: u32, ok: bool, i: usize| due & bit == 0 || ok || absent[i];
            let ok_t = got_t.is_some_and(|m| m.tick == k);
            let ok_a = got_a.is_some_and(|m| m.tick == k);
            let ok_r = got_r.is_some_and(|m| m.tick == k);
            if have(due::TRANSLATIONAL, ok_t, 0)
                && have(due::ATTITUDE, ok_a, 1)
                && have(due::ROBOTIC, ok_r, 2)
            {
                break;
            }
            if Instant::now() >= until {
                misses += 1;
                break;
            }
            // On every safe command while one is absent, in a tick where the robotic
            // group is not due, and when the robotic command of the tick is here
            // without an earlier one of the chain (its filter was preempted between
            // the downstream filter's queue and the simulator's).
            let wake_on_any = absent.iter().any(|a| *a) || due & due::ROBOTIC == 0 || ok_r;
            if wake_on_any && any_attached.is_empty() {
                any_attached = vec![
                    on_any.attach(&tick_rx)?,
                    on_any.attach(&st_rx)?,
                    on_any.attach(&sa_rx)?,
                    on_any.attach(&sr_rx)?,
                ];
                // no wait this time: what came before the listeners existed is read now
            } else if !wait(if wake_on_any { &on_any } else { &on_robotic }, Some(until))? {
                return Ok(0);
            }
            // Reverse causal order (docs/PARTITION.md, "Who wakes whom"): a command
            // published while the queues are read is never seen without the earlier
            // commands of its tick, which do not wake the simulator.
            ticks.extend(drain(&tick_rx)?);
            for m in drain(&sr_rx)? {
                if m.tick == k {
                    // delivered: the simulator holds the tick's last safe command
                    safe_recv_ns = now();
                }
                got_r = Some(m);
                absent[2] = false;
            }
            if let Some(m) = newest(Some(&sa_rx))? {
                got_a = Some(m);
                absent[1] = false;
            }
            if let Some(m) = newest(Some(&st_rx))? {
                got_t = Some(m);
                absent[0] = false;
            }
        }
        let mut fallback_mask = 0;
        let mut held_mask = 0;
        let mut flags = 0;
        // translational
        let fresh_t = got_t.filter(|m| m.tick == k);
        if due & due::TRANSLATIONAL != 0 || absent[0] {
            if let Some(m) = fresh_t {
                held.force_b = convert::vec3(&m.actuated);
                held_f_h = convert::vec3(&m.u);
            } else {
                let f = fallback::translational(&mut layer, &o);
                held.force_b = f.actuated;
                held_f_h = f.u;
                fallback_mask |= due::TRANSLATIONAL;
                if !absent[0] {
                    eprintln!(
                        "simulator: FAULT tick {k}: translational safe command missing, fallback applied"
                    );
                }
                absent[0] = true;
                flags |= fault::DEADLINE_MISS;
            }
        } else {
            held_mask |= due::TRANSLATIONAL;
        }
        let _ = held_f_h;
        let fresh_a = got_a.filter(|m| m.tick == k);
        if due & due::ATTITUDE != 0 || absent[1] {
            if let Some(m) = fresh_a {
                held.torque_b = convert::vec3(&m.u);
            } else {
                held.torque_b = fallback::attitude(&mut layer, &o, &robot, &held.force_b).u;
                fallback_mask |= due::ATTITUDE;
                if !absent[1] {
                    eprintln!(
                        "simulator: FAULT tick {k}: attitude safe command missing, fallback applied"
                    );
                }
                absent[1] = true;
                flags |= fault::DEADLINE_MISS;
            }
        } else {
            held_mask |= due::ATTITUDE;
        }
        let fresh_r = got_r.filter(|m| m.tick == k);
        if due & due::ROBOTIC != 0 || absent[2] {
            if let Some(m) = fresh_r {
                held.tau = convert::vec7(&m.u);
            } else {
                held.tau =
                    fallback::robotic(&mut layer, &o, &robot, &held.force_b, &held.torque_b).u;
                fallback_mask |= due::ROBOTIC;
                if !absent[2] {
                    eprintln!(
                        "simulator: FAULT tick {k}: robotic safe command missing, fallback applied"
                    );
                }
                absent[2] = true;
                flags |= fault::DEADLINE_MISS;
            }
        } else {
            held_mask |= due::ROBOTIC;
        }
        let mut res = StepResult {
            tick: k,
            t: o.t,
            fallback_mask,
            held_mask,
            fault_flags: flags,
            safe_recv_ns,
            ..Default::default()
        };
        convert::set_applied(&mut res, &held);
        let captured = sc_mission::capture_check(&scenario, phase, &o)
            && sc_mission::all_hold(&msg.barriers)
            && sc_mission::all_hold(&msg.barriers_between);
        res.end = if captured {
            end::CAPTURED
        } else if sc_mission::timeout_check(&scenario, o.t) {
            end::TIMEOUT
        } else {
            end::RUNNING
        };
        // with max_ticks (benchmarks, soak runs) the physics goes on after the end
        // and the scheduler stops after exactly max_ticks
        if res.end == end::RUNNING || keep_going {
            let mut min: sc_cbf::monitor::Barriers = [f64::INFINITY; sc_cbf::monitor::N_ALL];
            let stepped = sim.step_with(&held, |b| {
                sc_cbf::monitor::min_into(
                    &mut min,
                    &monitor.evaluate(&stages::monitor_state_between(b)),
                )
            });
            between = Some(min);
            if let Err(e) = stepped {
                eprintln!("simulator: {e}");
                res.end = end::SIMULATOR_FAILED;
            }
        }
        ended = res.end == end::SIMULATOR_FAILED || (res.end != end::RUNNING && !keep_going);
        res.publish_ns = now();
        send(&result_tx, &res)?;
    }
    eprintln!(
        "simulator: done at step {}, {misses} deadline misses",
        sim.step_count()
    );
    Ok(0)
}

// ---------------------------------------------------------------- nominal

/// One nominal controller process (`which` = 0 translational, 1 attitude, 2 robotic).
pub fn nominal(which: usize) -> anyhow::Result<i32> {
    let role = [
        "nominal_translational",
        "nominal_attitude",
        "nominal_robotic",
    ][which];
    let p = Proc::start(role)?;
    let q = qos();
    let partner_q = partner_qos();
    let tick_rx = Subscriber::<Tick>::polled(&p.node, services::CONTROL, &q)?;
    let state_rx = Subscriber::<SimState>::new(&p.node, services::SIM_STATE, &q)?;
    let tx_t = (which == 0)
        .then(|| {
            Publisher::<NominalTranslational>::new(
                &p.node,
                services::NOMINAL_TRANSLATIONAL,
                &partner_q,
            )
        })
        .transpose()?;
    let tx_a = (which == 1)
        .then(|| Publisher::<NominalAttitude>::new(&p.node, services::NOMINAL_ATTITUDE, &partner_q))
        .transpose()?;
    let tx_r = (which == 2)
        .then(|| Publisher::<NominalRobotic>::new(&p.node, services::NOMINAL_ROBOTIC, &partner_q))
        .transpose()?;
    // Wakes on states only; the tick queue is read at every wake-up for the stop
    // (the simulator wakes its consumers once when it stops).
    let waiter = Waiter::new()?;
    let _a = waiter.attach(&state_rx)?;
    // real time: the pre-tick warm-up (docs/PARTITION.md, "What a hop costs")
    let prepare = prepare_listener(&p)?;
    let _a1 = prepare.as_ref().map(|l| waiter.attach(l)).transpose()?;
    let mut last_state: Option<SimState> = None;
    let scenario = p.scenario_with_period(p.schedule.period_s[which]);
    let ctl = NominalControllers::new(&scenario, (*p.setup.robot).clone())?;
    let subsystems = [
        Subsystems::TRANSLATIONAL,
        Subsystems::ATTITUDE,
        Subsystems::ROBOTIC,
    ][which];
    let bit = 1u32 << which;
    p.handshake()?;
    let mut handled = 0u64;
    'run: loop {
        let woke = wait_outcome(&waiter, None)?;
        if woke == WaitOutcome::TerminationRequest {
            break;
        }
        if let Some(l) = &prepare
            && l.drain()? > 0
            && let Some(s) = &last_state
        {
            // rehearse the last step (the controllers are pure); nothing is sent
            p.rehearse(|| {
                let o = convert::observation(s);
                std::hint::black_box(
                    ctl.command_subsystems(&stages::nominal_input(&o), subsystems),
                );
                match which {
                    0 => tx_t.as_ref().context("publisher")?.warm(),
                    1 => tx_a.as_ref().context("publisher")?.warm(),
                    _ => tx_r.as_ref().context("publisher")?.warm(),
                }
                .map_err(anyhow::Error::from)
            })?;
        }
        for s in drain(&state_rx)? {
            if s.due_mask & bit == 0 {
                continue;
            }
            last_state = Some(s);
            let recv_ns = now();
            let o = convert::observation(&s);
            let out = ctl.command_subsystems(&stages::nominal_input(&o), subsystems);
            let status = [out.translational, out.attitude, out.robotic][which];
            let valid = (status != sc_nominal::SubsystemStatus::InvalidInput) as u32;
            let phase = out.phase as u32;
            match which {
                0 => send(
                    tx_t.as_ref().context("publisher")?,
                    &NominalTranslational {
                        tick: s.tick,
                        t: s.t,
                        valid,
                        phase,
                        recv_ns,
                        publish_ns: now(),
                        f_h: convert::arr3(&out.f_h),
                    },
                )?,
                1 => send(
                    tx_a.as_ref().context("publisher")?,
                    &NominalAttitude {
                        tick: s.tick,
                        t: s.t,
                        valid,
                        phase,
                        recv_ns,
                        publish_ns: now(),
                        tau_b: convert::arr3(&out.tau_b),
                    },
                )?,
                _ => send(
                    tx_r.as_ref().context("publisher")?,
                    &NominalRobotic {
                        tick: s.tick,
                        t: s.t,
                        valid,
                        phase,
                        recv_ns,
                        publish_ns: now(),
                        tau_m: convert::arr7(&out.tau_m),
                    },
                )?,
            }
            handled += 1;
        }
        if stop_seen(&drain(&tick_rx)?) {
            if woke == WaitOutcome::Timeout {
                eprintln!("{role}: {LOST_STOP_WAKEUP}");
            }
            // wake the filter once so that it sees the stop too
            match which {
                0 => tx_t.as_ref().context("publisher")?.notify()?,
                1 => tx_a.as_ref().context("publisher")?.notify()?,
                _ => tx_r.as_ref().context("publisher")?.notify()?,
            }
            break 'run;
        }
    }
    eprintln!("{role}: handled {handled} states");
    Ok(0)
}

// ---------------------------------------------------------------- filters

/// One safety filter process (`which` = 0 translational, 1 attitude, 2 robotic).
pub fn filter(which: usize) -> anyhow::Result<i32> {
    let role = ["safety_translational", "safety_attitude", "safety_robotic"][which];
    let p = Proc::start(role)?;
    let q = qos();
    let partner_q = partner_qos();
    // Subscribers without a listener until needed (see the wake-ups below).
    let tick_rx = Subscriber::<Tick>::polled(&p.node, services::CONTROL, &q)?;
    let state_rx = Subscriber::<SimState>::polled(&p.node, services::SIM_STATE, &q)?;
    let nt_rx = (which == 0)
        .then(|| {
            Subscriber::<NominalTranslational>::new(
                &p.node,
                services::NOMINAL_TRANSLATIONAL,
                &partner_q,
            )
        })
        .transpose()?;
    let na_rx = (which == 1)
        .then(|| {
            Subscriber::<NominalAttitude>::new(&p.node, services::NOMINAL_ATTITUDE, &partner_q)
        })
        .transpose()?;
    let nr_rx = (which == 2)
        .then(|| Subscriber::<NominalRobotic>::new(&p.node, services::NOMINAL_ROBOTIC, &partner_q))
        .transpose()?;
    let st_rx = (which >= 1)
        .then(|| Subscriber::<SafeTranslational>::polled(&p.node, services::SAFE_TRANSLATIONAL, &q))
        .transpose()?;
    let sa_rx = (which == 2)
        .then(|| Subscriber::<SafeAttitude>::new(&p.node, services::SAFE_ATTITUDE, &q))
        .transpose()?;
    let tx_t = (which == 0)
        .then(|| Publisher::<SafeTranslational>::new(&p.node, services::SAFE_TRANSLATIONAL, &q))
        .transpose()?;
    let tx_a = (which == 1)
        .then(|| Publisher::<SafeAttitude>::new(&p.node, services::SAFE_ATTITUDE, &q))
        .transpose()?;
    let tx_r = (which == 2)
        .then(|| Publisher::<SafeRobotic>::new(&p.node, services::SAFE_ROBOTIC, &q))
        .transpose()?;
    let watchdog = SignalListener::new(&p.node, services::STAGE_DEADLINE.as_str(), &q)?;
    // real time: the pre-tick warm-up (docs/PARTITION.md, "What a hop costs")
    let prepare = prepare_listener(&p)?;
    // Wake-ups (docs/PARTITION.md, "Who wakes whom"). Normally on the nominal
    // command and the immediately upstream safe command only: the state of the tick
    // was published before either, so it is read without waking on it. While an
    // input is absent (dead or late producer), on every input including the state.
    // Always on the scheduler's stage-deadline watchdog. The tick queue is read at
    // every wake-up for the stop.
    // the command inputs of this filter, and whether each wakes it normally (the
    // translational command wakes only the attitude filter, its direct downstream)
    let inputs: Vec<(&dyn Waitable, bool)> = [
        (nt_rx.as_ref().map(|s| s as &dyn Waitable), true),
        (na_rx.as_ref().map(|s| s as &dyn Waitable), true),
        (nr_rx.as_ref().map(|s| s as &dyn Waitable), true),
        (st_rx.as_ref().map(|s| s as &dyn Waitable), which == 1),
        (sa_rx.as_ref().map(|s| s as &dyn Waitable), true),
    ]
    .into_iter()
    .filter_map(|(s, wakes)| Some((s?, wakes)))
    .collect();
    let on_inputs = Waiter::new()?;
    let mut att = vec![on_inputs.attach(&watchdog)?];
    if let Some(l) = &prepare {
        att.push(on_inputs.attach(l)?);
    }
    for (s, _) in inputs.iter().filter(|(_, wakes)| *wakes) {
        att.push(on_inputs.attach(*s)?);
    }
    // attached on first need (creates the listeners of the state and of the
    // translational command at the robotic filter then)
    let on_any = Waiter::new()?;
    let mut any_attached = Vec::new();
    macro_rules! attach_any {
        () => {{
            if any_attached.is_empty() {
                any_attached.push(on_any.attach(&watchdog)?);
                if let Some(l) = &prepare {
                    any_attached.push(on_any.attach(l)?);
                }
                any_attached.push(on_any.attach(&state_rx)?);
                for (s, _) in &inputs {
                    any_attached.push(on_any.attach(*s)?);
                }
                true
            } else {
                false
            }
        }};
    }
    let mut layer = SafetyLayer::from_scenario(&p.setup.scenario, p.setup.robot.clone());
    let robot = p.setup.robot.clone();
    let d = &p.cfg.deadlines;
    let deadline = p.deadline(
        [
            d.safety_translational_ms,
            d.safety_attitude_ms,
            d.safety_robotic_ms,
        ][which],
    );
    let bit = 1u32 << which;
    p.handshake()?;
    let mut states: Vec<SimState> = Vec::new();
    let mut nom_t: Option<NominalTranslational> = None;
    let mut nom_a: Option<NominalAttitude> = None;
    let mut nom_r: Option<NominalRobotic> = None;
    let mut up_t: Option<SafeTranslational> = None;
    let mut up_a: Option<SafeAttitude> = None;
    // inputs found missing at a deadline are not waited for again until they reappear
    let mut absent = [false; 3]; // nominal, upstream translational, upstream attitude
    // the tick whose nominal command this filter waits for (the next state's)
    let mut awaited: Option<u64>;
    let mut misses = 0u64;
    let mut stop = false;
    let mut last_state: Option<SimState> = None;
    let mut rehearse = false;
    // The queues are read in reverse causal order (docs/PARTITION.md, "Who wakes
    // whom"): the upstream attitude command before the translational one it was
    // computed from, the commands before the state. A message published while the
    // pump runs is then never seen without the messages it depends on: seeing the
    // attitude command of tick k while the translational command of k was missed
    // would leave this filter asleep on an input that does not wake it.
    macro_rules! pump {
        () => {{
            watchdog.drain()?;
            if let Some(l) = &prepare {
                rehearse |= l.drain()? > 0;
            }
            stop |= stop_seen(&drain(&tick_rx)?);
            if let Some(m) = newest(sa_rx.as_ref())? {
                up_a = Some(m);
                absent[2] = false;
            }
            if let Some(m) = newest(st_rx.as_ref())? {
                up_t = Some(m);
                absent[1] = false;
            }
            // this filter's nominal command (only one of the three subscribers exists),
            // the one for the awaited tick kept
            if keep_for_tick(nt_rx.as_ref(), &mut nom_t, awaited, |m| m.tick)?
                | keep_for_tick(na_rx.as_ref(), &mut nom_a, awaited, |m| m.tick)?
                | keep_for_tick(nr_rx.as_ref(), &mut nom_r, awaited, |m| m.tick)?
            {
                absent[0] = false;
            }
            states.extend(
                drain(&state_rx)?
                    .into_iter()
                    .filter(|s| s.due_mask & bit != 0),
            );
        }};
    }
    loop {
        awaited = states
            .first()
            .or(last_state.as_ref())
            .map(|s| s.tick + u64::from(states.is_empty()));
        if states.is_empty() {
            if stop {
                break;
            }
            // A command of a tick whose state is not queued: the state was sent
            // before it, so its sender was preempted between this filter's queue and
            // the others'. The state does not wake this filter: wake on every input.
            let newest = [
                nom_t.map(|m| m.tick),
                nom_a.map(|m| m.tick),
                nom_r.map(|m| m.tick),
                up_t.map(|m| m.tick),
                up_a.map(|m| m.tick),
            ]
            .into_iter()
            .flatten()
            .max();
            let state_in_flight = newest > last_state.map(|s| s.tick);
            let wake_on_any = absent.iter().any(|a| *a) || state_in_flight;
            // just attached: no wait, read what came before the listeners existed
            let fresh = wake_on_any && attach_any!();
            let woke = if fresh {
                WaitOutcome::Handled
            } else {
                wait_outcome(if wake_on_any { &on_any } else { &on_inputs }, None)?
            };
            if woke == WaitOutcome::TerminationRequest {
                break;
            }
            pump!();
            if stop && states.is_empty() && woke == WaitOutcome::Timeout {
                eprintln!("{role}: {LOST_STOP_WAKEUP}");
            }
            if std::mem::take(&mut rehearse)
                && states.is_empty()
                && let Some(s) = &last_state
            {
                // the pre-tick warm-up: this filter's step on the last tick's inputs
                // (the filters are memoryless); the output is dropped, nothing is sent
                p.rehearse(|| -> anyhow::Result<()> {
                    let o = convert::observation(s);
                    let f_b = up_t.map_or_else(Vector3::zeros, |m| convert::vec3(&m.actuated));
                    let tau_b = up_a.map_or_else(Vector3::zeros, |m| convert::vec3(&m.u));
                    match which {
                        0 => {
                            if let Some(n) = nom_t {
                                std::hint::black_box(layer.translational.filter_with(
                                    &stages::translational_input(&o),
                                    Some(&convert::vec3(&n.f_h)),
                                ));
                            }
                            tx_t.as_ref().context("publisher")?.warm()?;
                        }
                        1 => {
                            if let Some(n) = nom_a {
                                std::hint::black_box(layer.attitude.filter_with(
                                    &stages::attitude_input(&o, &robot, &f_b),
                                    Some(&convert::vec3(&n.tau_b)),
                                ));
                            }
                            tx_a.as_ref().context("publisher")?.warm()?;
                        }
                        _ => {
                            if let Some(n) = nom_r {
                                std::hint::black_box(stages::robotic_step(
                                    &mut layer.robotic,
                                    &o,
                                    &robot,
                                    &f_b,
                                    &tau_b,
                                    Some(&convert::vec7(&n.tau_m)),
                                ));
                            }
                            tx_r.as_ref().context("publisher")?.warm()?;
                        }
                    }
                    Ok(())
                })?;
            }
            continue;
        }
        let s = states.remove(0);
        last_state = Some(s);
        let k = s.tick;
        awaited = Some(k);
        // the stage deadline counts from the publication of the state
        let until = instant_of(s.publish_ns) + deadline;
        let need_t = which >= 1 && s.due_mask & due::TRANSLATIONAL != 0;
        let need_a = which == 2 && s.due_mask & due::ATTITUDE != 0;
        let mut fresh = false;
        loop {
            let nom_ok = absent[0]
                || match which {
                    0 => nom_t.is_some_and(|m| m.tick == k),
                    1 => nom_a.is_some_and(|m| m.tick == k),
                    _ => nom_r.is_some_and(|m| m.tick == k),
                };
            let t_ok = !need_t || absent[1] || up_t.is_some_and(|m| m.tick == k);
            let a_ok = !need_a || absent[2] || up_a.is_some_and(|m| m.tick == k);
            if nom_ok && t_ok && a_ok {
                break;
            }
            if Instant::now() >= until {
                misses += 1;
                if !nom_ok {
                    eprintln!("{role}: FAULT tick {k}: nominal command missing at the deadline");
                    absent[0] = true;
                }
                if !t_ok {
                    eprintln!(
                        "{role}: FAULT tick {k}: translational safe command missing at the deadline"
                    );
                    absent[1] = true;
                }
                if !a_ok {
                    eprintln!(
                        "{role}: FAULT tick {k}: attitude safe command missing at the deadline"
                    );
                    absent[2] = true;
                }
                break;
            }
            // The robotic filter does not wake on the translational command. It
            // waits for it on every input in a tick where only the translational
            // group is due upstream, and when the attitude command of the tick is
            // already here without it (the translational filter was preempted between
            // the attitude filter's queue and this one's).
            let t_unwoken = which == 2 && !t_ok && (!need_a || up_a.is_some_and(|m| m.tick == k));
            let wake_on_any = absent.iter().any(|a| *a) || t_unwoken;
            if wake_on_any && attach_any!() {
                fresh = true; // just attached: no wait, read what came before
            }
            if !fresh && !wait(if wake_on_any { &on_any } else { &on_inputs }, Some(until))? {
                return Ok(0);
            }
            fresh = false;
            pump!();
        }
        let recv_ns = now();
        let o = convert::observation(&s);
        // the mission's own schedule (a nominal's report of its phase is not trusted)
        let phase = p.setup.scenario.phase_index(o.t);
        // upstream safe commands: this tick's, the held one of a slower group, or
        // (missing / dead upstream) the upstream fallback, which is what the simulator applies
        let mut upstream_missing = false;
        let f_b: Vector3<f64> = if which >= 1 {
            match up_t.filter(|m| if need_t { m.tick == k } else { !absent[1] }) {
                Some(m) => convert::vec3(&m.actuated),
                None => {
                    upstream_missing = true;
                    fallback::translational(&mut layer, &o).actuated
                }
            }
        } else {
            Vector3::zeros()
        };
        let tau_b: Vector3<f64> = if which == 2 {
            match up_a.filter(|m| if need_a { m.tick == k } else { !absent[2] }) {
                Some(m) => convert::vec3(&m.u),
                None => {
                    upstream_missing = true;
                    fallback::attitude(&mut layer, &o, &robot, &f_b).u
                }
            }
        } else {
            Vector3::zeros()
        };
        let publish_ns;
        match which {
            0 => {
                // a command for another tick, or one its sender marks invalid, is no
                // command: the filter runs its QP on the substitute nominal
                let nom = nom_t.filter(|m| m.tick == k && m.valid != 0);
                let f = nom.map(|n| convert::vec3(&n.f_h));
                let mut out = layer
                    .translational
                    .filter_with(&stages::translational_input(&o), f.as_ref());
                if upstream_missing {
                    out = fallback::flag_missing(out);
                }
                let mut m: SafeTranslational = convert::safe_msg(&out, k, s.t, phase);
                m.recv_ns = recv_ns;
                publish_ns = now();
                m.publish_ns = publish_ns;
                send(tx_t.as_ref().context("publisher")?, &m)?;
            }
            1 => {
                let nom = nom_a.filter(|m| m.tick == k && m.valid != 0);
                let t = nom.map(|n| convert::vec3(&n.tau_b));
                let mut out = layer
                    .attitude
                    .filter_with(&stages::attitude_input(&o, &robot, &f_b), t.as_ref());
                if upstream_missing {
                    out = fallback::flag_missing(out);
                }
                let mut m: SafeAttitude = convert::safe_msg(&out, k, s.t, phase);
                m.recv_ns = recv_ns;
                publish_ns = now();
                m.publish_ns = publish_ns;
                send(tx_a.as_ref().context("publisher")?, &m)?;
            }
            _ => {
                let nom = nom_r.filter(|m| m.tick == k && m.valid != 0);
                let t = nom.map(|n| convert::vec7(&n.tau_m));
                let mut out =
                    stages::robotic_step(&mut layer.robotic, &o, &robot, &f_b, &tau_b, t.as_ref());
                if upstream_missing {
                    out = fallback::flag_missing(out);
                }
                let mut m: SafeRobotic = convert::safe_msg(&out, k, s.t, phase);
                m.recv_ns = recv_ns;
                publish_ns = now();
                m.publish_ns = publish_ns;
                send(tx_r.as_ref().context("publisher")?, &m)?;
            }
        }
        let _ = publish_ns;
    }
    drop(att);
    // wake the downstream filter (and the simulator) once so that they see the stop
    match which {
        0 => tx_t.as_ref().context("publisher")?.notify()?,
        1 => tx_a.as_ref().context("publisher")?.notify()?,
        _ => tx_r.as_ref().context("publisher")?.notify()?,
    }
    eprintln!("{role}: done, {misses} deadline misses");
    Ok(0)
}
