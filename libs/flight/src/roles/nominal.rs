//! A nominal controller process (the reference controllers of `sc_nominal`); a partner
//! replaces it with its own process (docs/PARTITION.md).

use crate::convert;
use crate::process::{
    LOST_STOP_WAKEUP, Proc, partner_qos, prepare_listener, qos, send, wait_outcome,
};
use anyhow::Context;
use sc_bus::{Publisher, Subscriber, WaitOutcome, Waiter};
use sc_core::SubsystemSet;
use sc_icd::*;
use sc_mission::stages;
use sc_nominal::NominalControllers;

use super::*;

/// One nominal controller process.
pub fn nominal(subsystem: Subsystem) -> anyhow::Result<i32> {
    let which = subsystem.position();
    let role = [
        "nominal_translational",
        "nominal_attitude",
        "nominal_robotic",
    ][which];
    let p = Proc::start(role)?;
    let q = qos();
    let partner_q = partner_qos();
    let tick_rx = Subscriber::<Tick>::polled(&p.node, services::CONTROL, &q)?;
    let state_rx = Subscriber::<SimState>::new(&p.node, services::PARTNER_STATE, &partner_q)?;
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
    let scenario = p.scenario_with_period(p.schedule.period_s[subsystem]);
    let ctl = NominalControllers::new(&scenario, (*p.setup.robot).clone())?;
    let subsystems = SubsystemSet::only(subsystem);
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
