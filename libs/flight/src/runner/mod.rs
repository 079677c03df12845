//! The one iceoryx2 runner that drives any role's [`Component`]: it opens the role's
//! ports from the role table (`sc_icd::ROLES`), joins the start-up handshake, then
//! sleeps on the wake set the component names, drains every input in the component's
//! read order, hands the wake-up over, and carries out the actions — publishing (with
//! the publish stamp), signals, log lines, files, the pre-tick rehearsal.
//!
//! A role's executable is one line: `sc_flight::runner::main(RoleKind::…, Component::new)`.

pub mod ports;

use crate::component::{Component, Env, Finish, LostPeer, Message, Next, Outbox, Wakeup, Woke};
use crate::error::FlightError;
use crate::process::{Proc, warmup_enabled};
use ports::{InPort, OutPort};
use sc_bus::{Attachment, PeerMonitor, WaitOutcome, Waiter};
use sc_icd::services::{self, ServiceName};
use sc_icd::{Role, RoleKind, monotonic_ns};
use std::time::Duration;

/// The longest a role sleeps without a deadline before it looks again.
const RECHECK: Duration = Duration::from_secs(1);

/// Runs the role of `kind` with the component `make` builds, as the process's `main`:
/// errors are printed as one line and exit 2.
pub fn main<C: Component>(
    kind: RoleKind,
    make: impl FnOnce(&Proc) -> Result<C, FlightError>,
) -> std::process::ExitCode {
    match run(kind, make) {
        Ok(code) => std::process::ExitCode::from(code.clamp(0, 255) as u8),
        Err(e) => {
            eprintln!("error: {}", e.to_string().replace('\n', " "));
            std::process::ExitCode::from(2)
        }
    }
}

/// The ports of one role, opened from the component's inputs and the role's outputs.
pub struct Ports {
    inputs: Vec<Box<dyn InPort>>,
    outputs: Vec<Box<dyn OutPort>>,
}

impl Ports {
    /// Opens `inputs` and `outputs` on `node` (the pre-tick warm-up's only when the run
    /// has it; the handshake's are the handshake's own).
    pub fn open(
        node: &sc_bus::BusNode,
        inputs: &[ServiceName],
        outputs: &[ServiceName],
        warmup: bool,
        qos: &crate::process::Qos,
    ) -> Result<Self, FlightError> {
        let keep =
            |s: &&ServiceName| **s != services::HANDSHAKE && (warmup || **s != services::PREPARE);
        Ok(Self {
            inputs: inputs
                .iter()
                .filter(keep)
                .map(|s| ports::open_input(node, *s, qos))
                .collect::<Result<_, _>>()?,
            outputs: outputs
                .iter()
                .filter(keep)
                .map(|s| ports::open_output(node, *s, qos))
                .collect::<Result<_, _>>()?,
        })
    }

    fn input(&self, s: ServiceName) -> Option<&dyn InPort> {
        self.inputs.iter().find(|p| p.service() == s).map(|b| &**b)
    }

    fn output(&self, s: ServiceName) -> Result<&dyn OutPort, FlightError> {
        self.outputs
            .iter()
            .find(|p| p.service() == s)
            .map(|b| &**b)
            .ok_or(FlightError::NoPort(s.as_str()))
    }

    /// Drains every input in order: the messages, and the signals' counts.
    fn drain(&self, msgs: &mut Vec<Message>) -> Result<(u64, u64), FlightError> {
        let (mut deadline, mut prepare) = (0, 0);
        for p in &self.inputs {
            let n = p.drain(msgs)?;
            match p.service() {
                services::STAGE_DEADLINE => deadline += n,
                services::PREPARE => prepare += n,
                _ => {}
            }
        }
        Ok((deadline, prepare))
    }

    /// Samples from a second publisher dropped, per input service.
    pub fn impostors(&self) -> Vec<(ServiceName, u64)> {
        self.inputs
            .iter()
            .map(|p| (p.service(), p.impostors()))
            .collect()
    }
}

/// The liveness of the role's peers (every other role of the table).
struct Peers<'a> {
    proc: &'a Proc,
    monitor: Option<PeerMonitor>,
    error: Option<FlightError>,
}

impl Env for Peers<'_> {
    fn lost_peers(&mut self) -> Vec<LostPeer> {
        let Some(m) = self.monitor.as_mut() else {
            return Vec::new();
        };
        match m.poll(&self.proc.run) {
            Ok(lost) => lost
                .into_iter()
                .map(|p| LostPeer {
                    name: p.name,
                    pid: p.pid,
                })
                .collect(),
            Err(e) => {
                self.error.get_or_insert(e.into());
                Vec::new()
            }
        }
    }
}

fn run<C: Component>(
    kind: RoleKind,
    make: impl FnOnce(&Proc) -> Result<C, FlightError>,
) -> Result<i32, FlightError> {
    let role = Role::of(kind);
    let p = Proc::start(role.name)?;
    let mut c = make(&p)?;
    let qos = crate::process::Qos::of(&p.cfg, role.name);
    let ports = Ports::open(
        &p.node,
        c.inputs(),
        role.publishes,
        warmup_enabled(&p.cfg),
        &qos,
    )?;
    let sets = c.wake_sets();
    let waiters: Vec<Waiter> = sets
        .iter()
        .map(|_| Waiter::new())
        .collect::<Result<_, _>>()?;
    let mut attached: Vec<Vec<Attachment>> = sets.iter().map(|_| Vec::new()).collect();
    for (i, set) in sets.iter().enumerate().filter(|(_, s)| !s.lazy) {
        attached[i] = attach(&waiters[i], &ports, set.on)?;
    }
    let mut env = Peers {
        proc: &p,
        monitor: None,
        error: None,
    };
    handshake(&p, role, &mut env)?;
    let why = run_loop(&mut c, &p, &ports, &waiters, &mut attached, &mut env)?;
    let mut out = Outbox::default();
    let code = c.finish(why, &ports.impostors(), &mut out);
    let last = out.send.clone();
    perform(&mut c, &p, &ports, out)?;
    if p.cfg.across_hosts() {
        linger(&ports, &last)?;
    }
    Ok(code)
}

/// Across hosts: the last messages (the scheduler's stop) again every
/// [`LINGER_PERIOD`], [`LINGER_SENDS`] times, before the ports close. The link bridges a
/// service only while a process of its host holds a port on it, and a bridge can be
/// re-opened (iceoryx2-link re-resolves a service when a listing pass misses it), losing
/// what was in flight: a stop lost that way left the other host's roles waiting for ever
/// (measured: 1 of 4 split runs). A role ends on the first stop; the others are ignored.
fn linger(ports: &Ports, last: &[Message]) -> Result<(), FlightError> {
    if last.is_empty() {
        return Ok(());
    }
    for _ in 0..LINGER_SENDS {
        std::thread::sleep(LINGER_PERIOD);
        for m in last {
            let mut m = *m;
            m.stamp_publish(monotonic_ns());
            // best effort: the first send's result is the one that counts
            let _ = ports.output(m.service())?.send(&m);
        }
    }
    Ok(())
}

/// See [`linger`].
const LINGER_PERIOD: Duration = Duration::from_millis(100);
/// See [`linger`].
const LINGER_SENDS: u32 = 10;

/// Sleeps, drains, hands over, acts — until the component is done or a signal ends it.
fn run_loop<'w, 'p, C: Component>(
    c: &mut C,
    p: &Proc,
    ports: &'p Ports,
    waiters: &'w [Waiter],
    attached: &mut [Vec<Attachment<'w, 'p>>],
    env: &mut Peers,
) -> Result<Finish, FlightError> {
    let sets = c.wake_sets();
    let mut inputs = Vec::new();
    loop {
        let (set, until_ns) = match c.next(monotonic_ns()) {
            Next::Exit => return Ok(Finish::Done),
            Next::Wait { set, until_ns } => (set, until_ns),
        };
        let why = if attached[set].is_empty() {
            // first use of a lazy set: no wait, read what came before its listeners
            attached[set] = attach(&waiters[set], ports, sets[set].on)?;
            Woke::Attached
        } else {
            match wait(&waiters[set], until_ns)? {
                WaitOutcome::TerminationRequest => return Ok(Finish::Terminated),
                WaitOutcome::Handled => Woke::Event,
                WaitOutcome::Timeout => Woke::Timeout,
            }
        };
        inputs.clear();
        let (stage_deadline, prepare) = ports.drain(&mut inputs)?;
        let w = Wakeup {
            now_ns: monotonic_ns(),
            why,
            stage_deadline,
            prepare,
        };
        let mut out = Outbox::default();
        c.handle(&w, &inputs, env, &mut out);
        if let Some(e) = env.error.take() {
            return Err(e);
        }
        perform(c, p, ports, out)?;
    }
}

/// Attaches the inputs `on` (those this role has) to `waiter`.
fn attach<'w, 'p>(
    waiter: &'w Waiter,
    ports: &'p Ports,
    on: &[ServiceName],
) -> Result<Vec<Attachment<'w, 'p>>, FlightError> {
    on.iter()
        .filter_map(|s| ports.input(*s))
        .map(|port| Ok(waiter.attach(port.waitable())?))
        .collect()
}

/// Sleeps on `waiter` until an event or `until_ns` (at most [`RECHECK`] at a time).
fn wait(waiter: &Waiter, until_ns: Option<u64>) -> Result<WaitOutcome, FlightError> {
    let left = match until_ns {
        Some(u) => Duration::from_nanos(u.saturating_sub(monotonic_ns())),
        None => RECHECK,
    }
    .min(RECHECK);
    if left.is_zero() {
        return Ok(WaitOutcome::Timeout);
    }
    Ok(waiter.wait_once(left, |_| {})?)
}

/// Carries out a component's actions, in the order: log lines, messages, signals,
/// files, the rehearsal.
fn perform<C: Component>(
    c: &mut C,
    p: &Proc,
    ports: &Ports,
    out: Outbox,
) -> Result<(), FlightError> {
    for line in &out.log {
        eprintln!("{line}");
    }
    for mut m in out.send {
        m.stamp_publish(monotonic_ns());
        ports.output(m.service())?.send(&m)?;
    }
    for s in out.notify {
        ports.output(s)?.notify()?;
    }
    for (name, bytes) in out.files {
        write_file(p, &name, &bytes)?;
    }
    if out.rehearse {
        // one SCHED_FIFO priority below the role's own: the tick preempts it
        p.rehearse(|| -> Result<(), FlightError> {
            c.rehearse();
            c.warm().iter().try_for_each(|s| ports.output(*s)?.warm())
        })?;
    }
    Ok(())
}

/// Writes a file of the run into its output folder.
fn write_file(p: &Proc, name: &str, bytes: &[u8]) -> Result<(), FlightError> {
    let io = |source| FlightError::Io {
        path: p.out.join(name).display().to_string(),
        source,
    };
    std::fs::create_dir_all(&p.out).map_err(io)?;
    std::fs::write(p.out.join(name), bytes).map_err(io)
}

/// The start-up handshake: the coordinator (the first role of the table, the
/// scheduler) waits for every other role, writes [`crate::ALL_READY`] and starts
/// watching them; every other role announces itself and waits for the `go`.
fn handshake(p: &Proc, role: &Role, env: &mut Peers) -> Result<(), FlightError> {
    let timeout = Duration::from_secs_f64(p.cfg.handshake_timeout_s);
    if role.id() != 0 {
        let part = sc_bus::Participant::new(&p.node, services::HANDSHAKE, role.id())?;
        part.announce_and_wait(timeout + HANDSHAKE_GRACE)?;
        // away from the home host the scheduler's mark is in another host's folder: the
        // `go` says the same to this host's launcher
        if p.cfg
            .hosts
            .as_ref()
            .is_some_and(|h| p.cfg.host_of(role.name) != h.home)
        {
            write_file(p, crate::ALL_READY, b"")?;
        }
        return Ok(());
    }
    let peers = &sc_icd::ROLES[1..];
    let ids: Vec<u32> = peers.iter().map(|r| r.id()).collect();
    let coord = sc_bus::Coordinator::new(&p.node, services::HANDSHAKE, &ids)?;
    coord.wait_all(timeout).map_err(|e| match e {
        // name the roles that never joined (the bus only knows their ids)
        sc_bus::BusError::HandshakeTimeout { timeout, missing } => {
            let names: Vec<&str> = missing
                .iter()
                .map(|&id| Role::with_id(id).map_or("?", |r| r.name))
                .collect();
            FlightError::HandshakeTimeout {
                timeout,
                missing: names.join(", "),
            }
        }
        e => e.into(),
    })?;
    if p.cfg.across_hosts() {
        // a `go` that crossed before the other host's end of its bridge was up is lost
        let resent = coord.settle(LINK_SETTLE, timeout)?;
        eprintln!(
            "{}: the `go` sent {resent} more times across hosts",
            role.name
        );
    }
    eprintln!("{}: all {} processes ready", role.name, ids.len());
    // from now on a process that dies is a degraded mode, not a failed start
    write_file(p, crate::ALL_READY, b"")?;
    let names: Vec<&str> = peers.iter().map(|r| r.name).collect();
    let mut monitor = PeerMonitor::new(&names);
    monitor.poll(&p.run)?;
    env.monitor = Some(monitor);
    Ok(())
}

/// A participant waits this much longer for the `go` than the coordinator waits for it.
const HANDSHAKE_GRACE: Duration = Duration::from_secs(5);

/// Across hosts the first tick waits until no participant has announced itself for this
/// long after the `go` ([`sc_bus::Coordinator::settle`]): every participant heard it, and
/// the link (which lists the services every 20 ms, `sc-link --discover-ms`) has had 25
/// rounds to bridge every service created before the announcements.
const LINK_SETTLE: Duration = Duration::from_millis(500);
