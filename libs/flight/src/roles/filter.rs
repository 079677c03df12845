//! A safety filter process: waits for its state, nominal command and upstream safe
//! commands up to its stage deadline, runs its QP (on the substitute nominal when the
//! nominal is missing or invalid), publishes the safe command.

use crate::admission;
use crate::convert;

use crate::process::{
    LOST_STOP_WAKEUP, Proc, partner_qos, prepare_listener, qos, send, wait, wait_outcome,
};
use anyhow::Context;
use nalgebra::Vector3;
use sc_bus::{Publisher, SignalListener, Subscriber, WaitOutcome, Waitable, Waiter};
use sc_cbf::SafetyLayer;
use sc_icd::*;
use std::time::Instant;

use super::*;

/// One safety filter process.
pub fn filter(subsystem: Subsystem) -> anyhow::Result<i32> {
    let which = subsystem.position();
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
            // judged once the states it may answer are known
            let (got_t, got_a, got_r) = (
                drain_opt(nt_rx.as_ref())?,
                drain_opt(na_rx.as_ref())?,
                drain_opt(nr_rx.as_ref())?,
            );
            states.extend(
                drain(&state_rx)?
                    .into_iter()
                    .filter(|s| s.due_mask & bit != 0),
            );
            let known = states.last().or(last_state.as_ref()).map(|s| s.tick);
            if keep_for_tick(got_t, &mut nom_t, awaited, known, |m| m.tick)
                | keep_for_tick(got_a, &mut nom_a, awaited, known, |m| m.tick)
                | keep_for_tick(got_r, &mut nom_r, awaited, known, |m| m.tick)
            {
                absent[0] = false;
            }
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
                                std::hint::black_box(
                                    layer.translational_stage(&o, Some(&convert::vec3(&n.f_h))),
                                );
                            }
                            tx_t.as_ref().context("publisher")?.warm()?;
                        }
                        1 => {
                            if let Some(n) = nom_a {
                                std::hint::black_box(layer.attitude_stage(
                                    &o,
                                    &f_b,
                                    Some(&convert::vec3(&n.tau_b)),
                                ));
                            }
                            tx_a.as_ref().context("publisher")?.warm()?;
                        }
                        _ => {
                            if let Some(n) = nom_r {
                                std::hint::black_box(layer.robotic_stage(
                                    &o,
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
        // (missing / dead upstream, or one the simulator would reject) the upstream
        // fallback, which is what the simulator applies
        let mut upstream_missing = false;
        let lim = &p.setup.scenario.limits;
        let f_b: Vector3<f64> = if which >= 1 {
            match up_t
                .filter(|m| if need_t { m.tick == k } else { !absent[1] })
                .filter(|m| admission::translational(m, lim))
            {
                Some(m) => convert::vec3(&m.actuated),
                None => {
                    upstream_missing = true;
                    layer.backup_translational(&o).actuated
                }
            }
        } else {
            Vector3::zeros()
        };
        let tau_b: Vector3<f64> = if which == 2 {
            match up_a
                .filter(|m| if need_a { m.tick == k } else { !absent[2] })
                .filter(|m| admission::attitude(m, lim))
            {
                Some(m) => convert::vec3(&m.u),
                None => {
                    upstream_missing = true;
                    layer.backup_attitude(&o, &f_b).u
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
                let mut out = layer.translational_stage(&o, f.as_ref());
                if upstream_missing {
                    out = sc_cbf::chain::flag_missing(out);
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
                let mut out = layer.attitude_stage(&o, &f_b, t.as_ref());
                if upstream_missing {
                    out = sc_cbf::chain::flag_missing(out);
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
                let mut out = layer.robotic_stage(&o, &f_b, &tau_b, t.as_ref());
                if upstream_missing {
                    out = sc_cbf::chain::flag_missing(out);
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
    let impostors = nt_rx.as_ref().map_or(0, |s| s.rejected())
        + na_rx.as_ref().map_or(0, |s| s.rejected())
        + nr_rx.as_ref().map_or(0, |s| s.rejected())
        + st_rx.as_ref().map_or(0, |s| s.rejected())
        + sa_rx.as_ref().map_or(0, |s| s.rejected());
    eprintln!(
        "{role}: done, {misses} deadline misses, {impostors} samples from a second publisher dropped"
    );
    Ok(0)
}
