//! The simulator process: the plant in the loop. It applies the safe commands of each
//! tick after re-validating them (`crate::admission`), the filter's backup when one is
//! missing or rejected, and publishes the state with the monitored barriers.

use crate::admission;
use crate::convert;

use crate::process::{Proc, partner_qos, prepare_listener, qos, send, wait};
use nalgebra::Vector3;
use sc_bus::{Publisher, Subscriber, Waiter};
use sc_cbf::SafetyLayer;
use sc_icd::*;
use sc_sim::{Command, Simulator};
use std::time::Instant;

use super::*;

/// The simulator: publishes the state of each tick, applies the safe commands
/// (held for slower rate groups, the filter's fallback when missing), ends the
/// mission on capture/timeout.
/// A tick-matched safe command if the simulator may apply it (`ok`); `true` with `None`
/// when one came and was rejected.
fn admit<T>(fresh: Option<T>, ok: impl Fn(&T) -> bool) -> (Option<T>, bool) {
    match fresh {
        Some(m) if ok(&m) => (Some(m), false),
        Some(_) => (None, true),
        None => (None, false),
    }
}

pub fn simulator() -> anyhow::Result<i32> {
    let p = Proc::start("simulator")?;
    let q = qos();
    let tick_rx = Subscriber::<Tick>::new(&p.node, services::TICK, &q)?;
    let st_rx = Subscriber::<SafeTranslational>::polled(&p.node, services::SAFE_TRANSLATIONAL, &q)?;
    let sa_rx = Subscriber::<SafeAttitude>::polled(&p.node, services::SAFE_ATTITUDE, &q)?;
    let sr_rx = Subscriber::<SafeRobotic>::new(&p.node, services::SAFE_ROBOTIC, &q)?;
    let state_tx = Publisher::<SimState>::new(&p.node, services::SIM_STATE, &q)?;
    // the nominal controllers' copy: newest wins, a partner cannot hold the tick up
    let partner_state_tx =
        Publisher::<SimState>::new(&p.node, services::PARTNER_STATE, &partner_qos())?;
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
    // another propagator behind this role (e.g. Basilisk), started before the handshake
    let mut plant = match p.cfg.simulator.plant.split_first() {
        Some((program, args)) => {
            let mut args = args.to_vec();
            args.push("--scenario".into());
            args.push(p.cfg.scenario_path().display().to_string());
            let mut child = sc_sim::ProcessPlant::spawn(std::path::Path::new(program), &args)?;
            sc_sim::Plant::start(&mut child, sim.state())
                .map_err(|e| anyhow::anyhow!("simulator: {e}"))?;
            eprintln!(
                "simulator: the plant `{}` propagates",
                p.cfg.simulator.plant.join(" ")
            );
            Some(child)
        }
        None => None,
    };
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
    // safe commands the simulator refused to apply, per filter (admission.rs)
    let mut rejected = [0u64; 3];
    let lim = &scenario.limits;
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
                    partner_state_tx.warm()?;
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
            partner_state_tx.notify()?;
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
        let barriers = monitor.evaluate(&o.barrier_state());
        msg.barriers = barriers;
        msg.barriers_between = between.unwrap_or(barriers);
        // the phase is the mission's own schedule, never a partner's report
        let phase = scenario.phase_index(o.t);
        msg.tick = tick.tick;
        msg.due_mask = tick.due_mask;
        msg.tick_send_ns = tick.send_ns;
        msg.recv_ns = recv_ns;
        msg.publish_ns = now();
        // flight side first: a nominal command can then never reach a filter before
        // the state it answers (the filters drop commands for states they have not
        // seen as lies about the tick)
        send(&state_tx, &msg)?;
        send(&partner_state_tx, &msg)?;
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
        let (fresh_t, rejected_t) = admit(got_t.filter(|m| m.tick == k), |m| {
            admission::translational(m, lim)
        });
        if due & due::TRANSLATIONAL != 0 || absent[0] {
            if let Some(m) = fresh_t {
                held.force_b = convert::vec3(&m.actuated);
                held_f_h = convert::vec3(&m.u);
            } else {
                let f = layer.backup_translational(&o);
                held.force_b = f.actuated;
                held_f_h = f.u;
                fallback_mask |= due::TRANSLATIONAL;
                if rejected_t {
                    rejected[0] += 1;
                    eprintln!(
                        "simulator: FAULT tick {k}: translational safe command rejected (not finite or beyond the input bounds), backup applied"
                    );
                    flags |= fault::REJECTED_COMMAND;
                } else {
                    if !absent[0] {
                        eprintln!(
                            "simulator: FAULT tick {k}: translational safe command missing, fallback applied"
                        );
                    }
                    absent[0] = true;
                    flags |= fault::DEADLINE_MISS;
                }
            }
        } else {
            held_mask |= due::TRANSLATIONAL;
        }
        let _ = held_f_h;
        let (fresh_a, rejected_a) = admit(got_a.filter(|m| m.tick == k), |m| {
            admission::attitude(m, lim)
        });
        if due & due::ATTITUDE != 0 || absent[1] {
            if let Some(m) = fresh_a {
                held.torque_b = convert::vec3(&m.u);
            } else {
                held.torque_b = layer.backup_attitude(&o, &held.force_b).u;
                fallback_mask |= due::ATTITUDE;
                if rejected_a {
                    rejected[1] += 1;
                    eprintln!(
                        "simulator: FAULT tick {k}: attitude safe command rejected (not finite or beyond the input bounds), backup applied"
                    );
                    flags |= fault::REJECTED_COMMAND;
                } else {
                    if !absent[1] {
                        eprintln!(
                            "simulator: FAULT tick {k}: attitude safe command missing, fallback applied"
                        );
                    }
                    absent[1] = true;
                    flags |= fault::DEADLINE_MISS;
                }
            }
        } else {
            held_mask |= due::ATTITUDE;
        }
        let (fresh_r, rejected_r) = admit(got_r.filter(|m| m.tick == k), |m| {
            admission::robotic(m, lim)
        });
        if due & due::ROBOTIC != 0 || absent[2] {
            if let Some(m) = fresh_r {
                held.tau = convert::vec7(&m.u);
            } else {
                held.tau = layer.backup_robotic(&o, &held.force_b, &held.torque_b).u;
                fallback_mask |= due::ROBOTIC;
                if rejected_r {
                    rejected[2] += 1;
                    eprintln!(
                        "simulator: FAULT tick {k}: robotic safe command rejected (not finite or beyond the input bounds), backup applied"
                    );
                    flags |= fault::REJECTED_COMMAND;
                } else {
                    if !absent[2] {
                        eprintln!(
                            "simulator: FAULT tick {k}: robotic safe command missing, fallback applied"
                        );
                    }
                    absent[2] = true;
                    flags |= fault::DEADLINE_MISS;
                }
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
            let at_physics_step = |b: &sc_sim::BarrierState| {
                sc_cbf::monitor::min_into(&mut min, &monitor.evaluate(b))
            };
            let stepped = match plant.as_mut() {
                Some(pl) => sim.step_with_plant(pl, &held, at_physics_step),
                None => sim.step_with(&held, at_physics_step),
            };
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
    let impostors = [st_rx.rejected(), sa_rx.rejected(), sr_rx.rejected()];
    eprintln!(
        "simulator: done at step {}, {misses} deadline misses, safe commands rejected (translational, attitude, robotic) {rejected:?}, samples from a second publisher dropped {impostors:?}",
        sim.step_count()
    );
    Ok(0)
}
