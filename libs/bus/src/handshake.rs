//! Start-up handshake: nothing is sent before every participant's ports exist
//! (iceoryx2 drops samples and notifications sent before the peer's port exists).
//!
//! Two payload-less event services under a base name (default
//! [`sc_icd::services::HANDSHAKE`]):
//! - `<base>/ready`: each participant notifies event id `HANDSHAKE_ID_OFFSET + id`,
//!   repeatedly (every `announce_period`) until it hears `go`;
//! - `<base>/go`: the coordinator notifies once it has seen every expected id.
//!
//! A participant creates its `go` listener *before* announcing, so the `go` cannot
//! be lost. Participants create all their data ports before calling
//! [`Participant::announce_and_wait`].
//!
//! ```no_run
//! use sc_bus::{Coordinator, Participant, RunScope};
//! use sc_icd::{Role, RoleKind, services};
//! use std::time::Duration;
//! let run = RunScope::unique("doc")?;
//! // scheduler process:
//! let node = run.node("scheduler")?;
//! let (simulator, recorder) = (Role::of(RoleKind::Simulator).id(), Role::of(RoleKind::Recorder).id());
//! let coord = Coordinator::new(&node, services::HANDSHAKE, &[simulator, recorder])?;
//! coord.wait_all(Duration::from_secs(10))?;   // Err(HandshakeTimeout { missing }) otherwise
//! // each other process (after creating its ports):
//! let p = Participant::new(&node, services::HANDSHAKE, simulator)?;
//! p.announce_and_wait(Duration::from_secs(10))?;
//! # Ok::<(), sc_bus::BusError>(())
//! ```

use crate::error::{BusError, Result, reason};
use crate::pubsub::open_event;
use crate::run::BusNode;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::event::PortFactory as EventFactory;
use sc_icd::ServiceName;
use std::time::{Duration, Instant};

/// Event ids 0..8 are reserved (iceoryx2 notifier created/dropped/dead events);
/// participant `id` announces with event id `HANDSHAKE_ID_OFFSET + id`.
pub const HANDSHAKE_ID_OFFSET: usize = 8;
/// Participant ids are `0..MAX_PARTICIPANT_ID`.
pub const MAX_PARTICIPANT_ID: u32 = 64;
/// Event id of the coordinator's `go`.
pub const EVENT_GO: usize = 3;
const MAX_PORTS: usize = 32;
const MAX_NODES: usize = 40;
const ID_MAX: usize = HANDSHAKE_ID_OFFSET + MAX_PARTICIPANT_ID as usize;
/// How often a participant repeats its announcement while waiting for `go`.
pub const ANNOUNCE_PERIOD: Duration = Duration::from_millis(20);

fn port_err<'a>(port: &'static str, service: &'a str) -> impl Fn(String) -> BusError + 'a {
    move |reason| BusError::Port {
        port,
        service: service.to_string(),
        reason,
    }
}

/// The side that waits for everyone (the scheduler).
pub struct Coordinator {
    ready_name: String,
    expected: Vec<u32>,
    listener: Listener<ipc::Service>,
    go: Notifier<ipc::Service>,
    _ready: EventFactory<ipc::Service>,
    _go: EventFactory<ipc::Service>,
}

impl Coordinator {
    /// Expects the participant ids `expected` (e.g. role ids).
    pub fn new(node: &BusNode, base: ServiceName, expected: &[u32]) -> Result<Self> {
        if let Some(&id) = expected.iter().find(|&&id| id >= MAX_PARTICIPANT_ID) {
            return Err(BusError::ParticipantOutOfRange {
                id,
                max: MAX_PARTICIPANT_ID,
            });
        }
        let ready_name = format!("{base}/ready");
        let go_name = format!("{base}/go");
        let ready = open_event(node, &ready_name, MAX_PORTS, MAX_NODES, ID_MAX)?;
        let go_f = open_event(node, &go_name, MAX_PORTS, MAX_NODES, ID_MAX)?;
        let listener = ready
            .listener_builder()
            .create()
            .map_err(|e| port_err("listener", &ready_name)(reason(e)))?;
        let go = go_f
            .notifier_builder()
            .default_event_id(EventId::new(EVENT_GO))
            .create()
            .map_err(|e| port_err("notifier", &go_name)(reason(e)))?;
        Ok(Self {
            ready_name,
            expected: expected.to_vec(),
            listener,
            go,
            _ready: ready,
            _go: go_f,
        })
    }

    /// Blocks until every expected participant announced (then sends `go`), or
    /// fails after `timeout` naming the missing ids.
    pub fn wait_all(&self, timeout: Duration) -> Result<()> {
        let deadline = Instant::now() + timeout;
        let mut seen = vec![false; self.expected.len()];
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let mut mark = |a: iceoryx2::port::EventActivation| {
                let v = a.id.as_value();
                if v >= HANDSHAKE_ID_OFFSET {
                    let id = (v - HANDSHAKE_ID_OFFSET) as u32;
                    for (i, e) in self.expected.iter().enumerate() {
                        if *e == id {
                            seen[i] = true;
                        }
                    }
                }
            };
            let r = if left.is_zero() {
                self.listener.try_wait(&mut mark)
            } else {
                self.listener.timed_wait(&mut mark, left)
            };
            r.map_err(|e| BusError::Event {
                op: "wait",
                service: self.ready_name.clone(),
                reason: reason(e),
            })?;
            if seen.iter().all(|s| *s) {
                break;
            }
            if Instant::now() >= deadline {
                let missing = self
                    .expected
                    .iter()
                    .zip(&seen)
                    .filter(|(_, s)| !**s)
                    .map(|(e, _)| *e)
                    .collect();
                return Err(BusError::HandshakeTimeout { timeout, missing });
            }
        }
        self.send_go()
    }

    fn send_go(&self) -> Result<()> {
        self.go.notify().map_err(|e| BusError::Event {
            op: "notify",
            service: self.ready_name.replace("/ready", "/go"),
            reason: reason(e),
        })?;
        Ok(())
    }

    /// After [`wait_all`](Self::wait_all): sends the `go` again every
    /// [`ANNOUNCE_PERIOD`] until no participant has announced itself for `quiet` (a
    /// participant announces until it hears a `go`), or fails at `limit` naming those
    /// still announcing. On one host no `go` is lost; across hosts (iceoryx2's link) an
    /// event sent while the other host's end of its bridge is not up — or is being
    /// re-opened — is, and the participants there would wait for ever. Returns how many
    /// `go`s it sent again.
    pub fn settle(&self, quiet: Duration, limit: Duration) -> Result<u32> {
        let start = Instant::now();
        let mut last_heard = start;
        let mut still: Vec<u32> = Vec::new();
        let mut resent = 0;
        while last_heard.elapsed() < quiet {
            if start.elapsed() >= limit {
                still.sort_unstable();
                still.dedup();
                return Err(BusError::HandshakeTimeout {
                    timeout: limit,
                    missing: still,
                });
            }
            self.send_go()?;
            resent += 1;
            let mut heard: Vec<u32> = Vec::new();
            self.listener
                .timed_wait(
                    // announcements only: a participant leaving (iceoryx2's
                    // notifier-dropped event) is none
                    |a| {
                        let id = a.id.as_value();
                        if id >= HANDSHAKE_ID_OFFSET {
                            heard.push((id - HANDSHAKE_ID_OFFSET) as u32);
                        }
                    },
                    ANNOUNCE_PERIOD,
                )
                .map_err(|e| BusError::Event {
                    op: "wait",
                    service: self.ready_name.clone(),
                    reason: reason(e),
                })?;
            if !heard.is_empty() {
                last_heard = Instant::now();
                still = heard;
            }
        }
        Ok(resent)
    }
}

/// One process taking part in the start-up.
pub struct Participant {
    id: u32,
    go_name: String,
    go: Listener<ipc::Service>,
    ready: Notifier<ipc::Service>,
    _ready: EventFactory<ipc::Service>,
    _go: EventFactory<ipc::Service>,
}

impl Participant {
    /// Participant with id `id` (< [`MAX_PARTICIPANT_ID`]).
    pub fn new(node: &BusNode, base: ServiceName, id: u32) -> Result<Self> {
        if id >= MAX_PARTICIPANT_ID {
            return Err(BusError::ParticipantOutOfRange {
                id,
                max: MAX_PARTICIPANT_ID,
            });
        }
        let ready_name = format!("{base}/ready");
        let go_name = format!("{base}/go");
        let ready_f = open_event(node, &ready_name, MAX_PORTS, MAX_NODES, ID_MAX)?;
        let go_f = open_event(node, &go_name, MAX_PORTS, MAX_NODES, ID_MAX)?;
        // Listener first: a `go` sent after our first announcement is never lost.
        let go = go_f
            .listener_builder()
            .create()
            .map_err(|e| port_err("listener", &go_name)(reason(e)))?;
        let ready = ready_f
            .notifier_builder()
            .default_event_id(EventId::new(HANDSHAKE_ID_OFFSET + id as usize))
            .create()
            .map_err(|e| port_err("notifier", &ready_name)(reason(e)))?;
        Ok(Self {
            id,
            go_name,
            go,
            ready,
            _ready: ready_f,
            _go: go_f,
        })
    }

    /// This participant's id.
    pub fn id(&self) -> u32 {
        self.id
    }

    /// Announces readiness every [`ANNOUNCE_PERIOD`] until the coordinator's `go`
    /// arrives; fails with [`BusError::HandshakeTimeout`] after `timeout`.
    pub fn announce_and_wait(&self, timeout: Duration) -> Result<()> {
        let deadline = Instant::now() + timeout;
        loop {
            self.ready.notify().map_err(|e| BusError::Event {
                op: "notify",
                service: self.go_name.replace("/go", "/ready"),
                reason: reason(e),
            })?;
            let mut go = false;
            let wait = ANNOUNCE_PERIOD.min(deadline.saturating_duration_since(Instant::now()));
            self.go
                .timed_wait(
                    |a| {
                        if a.id.as_value() == EVENT_GO {
                            go = true
                        }
                    },
                    wait,
                )
                .map_err(|e| BusError::Event {
                    op: "wait",
                    service: self.go_name.clone(),
                    reason: reason(e),
                })?;
            if go {
                return Ok(());
            }
            if Instant::now() >= deadline {
                return Err(BusError::HandshakeTimeout {
                    timeout,
                    missing: vec![self.id],
                });
            }
        }
    }
}
