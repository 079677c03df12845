//! `Publisher<T>` / `Subscriber<T>`: a pub/sub service plus an event service of
//! the same name. `send` = loan, write, send, notify; the subscriber sleeps on the
//! event (timeout, deadline or inside a [`crate::Waiter`]) and then drains samples.
//!
//! ```no_run
//! use sc_bus::{Publisher, RunScope, ServiceSettings, Subscriber};
//! use sc_icd::{services, Tick};
//! use std::time::Duration;
//! let run = RunScope::unique("doc")?;
//! let node = run.node("scheduler")?;
//! let tx = Publisher::<Tick>::new(&node, services::TICK, &ServiceSettings::lock_step())?;
//! let rx = Subscriber::<Tick>::new(&node, services::TICK, &ServiceSettings::lock_step())?;
//! tx.send(&Tick::default())?;
//! if rx.wait(Duration::from_millis(10))?.notifications > 0 {
//!     let latest = rx.receive_latest()?;
//! }
//! # Ok::<(), sc_bus::BusError>(())
//! ```

use crate::error::{BusError, Result, reason};
use crate::run::BusNode;
use iceoryx2::identifiers::UniqueNodeId;
use iceoryx2::node::{NodeState, NodeView};
use iceoryx2::port::BackpressureAction;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeOpenError, PublishSubscribeOpenOrCreateError,
};
use iceoryx2::service::port_factory::event::PortFactory as EventFactory;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory as PubSubFactory;
use sc_icd::ServiceName as IcdServiceName;
use std::fmt::Debug;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Event id a publisher notifies with after each send.
pub const EVENT_SAMPLE: usize = 0;
/// Event id iceoryx2 emits when dead-node cleanup removes a notifier of a dead
/// process (the peer died without saying goodbye).
pub const EVENT_NOTIFIER_DEAD: usize = 1;
/// Event id iceoryx2 emits when a notifier is dropped normally (peer left).
pub const EVENT_NOTIFIER_DROPPED: usize = 2;
/// A subscriber that stayed full for the backpressure timeout is dropped at once
/// (no wait) for this many timeouts before it gets the full wait again.
pub const STUCK_HOLD_FACTOR: u32 = 20;
/// Highest event id used on data services.
pub const EVENT_ID_MAX: usize = 7;

/// Service settings. Both sides of a service should use the same values; the
/// process that creates the service fixes them, later openers must ask for no more.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ServiceSettings {
    /// Samples a subscriber can hold queued before the publisher sees backpressure.
    pub subscriber_buffer: usize,
    /// Samples replayed to a late subscriber (0 = none: a late joiner must not act on stale commands).
    pub history: usize,
    /// Max publishers on the service.
    pub max_publishers: usize,
    /// Max subscribers on the service.
    pub max_subscribers: usize,
    /// Max nodes attached to the service.
    pub max_nodes: usize,
    /// `true`: a full subscriber buffer overwrites its oldest sample (loss possible, never blocks).
    /// `false`: the publisher waits for space (no loss) up to `backpressure_timeout`.
    pub safe_overflow: bool,
    /// With `safe_overflow == false`: how long `send` waits for a full
    /// subscriber before dropping the sample for it and failing with
    /// [`BusError::Backpressure`]. Bounds the damage a dead/stuck subscriber can do.
    pub backpressure_timeout: Duration,
}

impl ServiceSettings {
    /// Lock-step control loop where no sample may be lost.
    ///
    /// - `safe_overflow = false`: a sample is never silently overwritten.
    /// - `subscriber_buffer = 4`: lock-step needs 1 (one sample in flight per
    ///   tick); 4 absorbs a consumer that is a few ticks late without stalling.
    /// - `history = 0`: the start-up handshake guarantees every port exists before
    ///   the first tick, so no replay is needed and nothing stale is replayed.
    /// - `max_publishers = 2`: the owner plus one replacement (e.g. a Python
    ///   controller started while the Rust one is being stopped). A subscriber still
    ///   accepts samples only from the first publisher it heard; the partition's
    ///   settings (`sc_flight::process::qos`) allow exactly one.
    /// - `max_subscribers = 8`: the consumers, recorder and debug tools.
    /// - `backpressure_timeout = 50 ms`: far above a tick's work, small enough
    ///   that a SIGKILLed subscriber cannot stall the loop for long.
    pub fn lock_step() -> Self {
        Self {
            subscriber_buffer: 4,
            history: 0,
            max_publishers: 2,
            max_subscribers: 8,
            max_nodes: 16,
            safe_overflow: false,
            backpressure_timeout: Duration::from_millis(50),
        }
    }

    /// Monitoring streams (health, telemetry taps): latest value wins, never blocks.
    pub fn monitoring() -> Self {
        Self {
            subscriber_buffer: 16,
            history: 1,
            max_publishers: 16,
            max_subscribers: 8,
            max_nodes: 24,
            safe_overflow: true,
            backpressure_timeout: Duration::ZERO,
        }
    }
}

impl Default for ServiceSettings {
    fn default() -> Self {
        Self::lock_step()
    }
}

pub(crate) fn service_name(name: &str) -> Result<iceoryx2::service::service_name::ServiceName> {
    iceoryx2::service::service_name::ServiceName::new(name).map_err(|e| BusError::InvalidName {
        what: "service",
        name: name.to_string(),
        reason: reason(e),
    })
}

/// Opens or creates the event service `name` with the project's event settings.
pub(crate) fn open_event(
    node: &BusNode,
    name: &str,
    max_ports: usize,
    max_nodes: usize,
    event_id_max: usize,
) -> Result<EventFactory<ipc::Service>> {
    node.service_builder(&service_name(name)?)
        .event()
        .max_notifiers(max_ports)
        .max_listeners(max_ports)
        .max_nodes(max_nodes)
        .event_id_max_value(event_id_max)
        .notifier_dead_event(EventId::new(EVENT_NOTIFIER_DEAD))
        .notifier_dropped_event(EventId::new(EVENT_NOTIFIER_DROPPED))
        .open_or_create()
        .map_err(|e| BusError::Service {
            kind: "event",
            service: name.to_string(),
            reason: reason(e),
        })
}

/// The event service beside a data service (or a payload-less signal) `name`,
/// sized by the data service's settings.
pub(crate) fn data_event(
    node: &BusNode,
    name: &str,
    s: &ServiceSettings,
) -> Result<EventFactory<ipc::Service>> {
    open_event(
        node,
        name,
        s.max_publishers + s.max_subscribers,
        s.max_nodes,
        EVENT_ID_MAX,
    )
}

/// A notifier on `event` that notifies [`EVENT_SAMPLE`].
pub(crate) fn sample_notifier(
    event: &EventFactory<ipc::Service>,
    name: &str,
) -> Result<Notifier<ipc::Service>> {
    event
        .notifier_builder()
        .default_event_id(EventId::new(EVENT_SAMPLE))
        .create()
        .map_err(|e| BusError::Port {
            port: "notifier",
            service: name.to_string(),
            reason: reason(e),
        })
}

/// A listener on `event`.
pub(crate) fn listener(
    event: &EventFactory<ipc::Service>,
    name: &str,
) -> Result<Listener<ipc::Service>> {
    event
        .listener_builder()
        .create()
        .map_err(|e| BusError::Port {
            port: "listener",
            service: name.to_string(),
            reason: reason(e),
        })
}

/// Wakes every listener of `notifier`'s service.
pub(crate) fn notify(notifier: &Notifier<ipc::Service>, name: &str) -> Result<()> {
    notifier.notify().map(|_| ()).map_err(|e| BusError::Event {
        op: "notify",
        service: name.to_string(),
        reason: reason(e),
    })
}

fn open_pubsub<T: Debug + ZeroCopySend + Copy>(
    node: &BusNode,
    name: &str,
    s: &ServiceSettings,
) -> Result<PubSubFactory<ipc::Service, T, ()>> {
    let factory = node
        .service_builder(&service_name(name)?)
        .publish_subscribe::<T>()
        .subscriber_max_buffer_size(s.subscriber_buffer)
        .history_size(s.history)
        .max_publishers(s.max_publishers)
        .max_subscribers(s.max_subscribers)
        .max_nodes(s.max_nodes)
        .enable_safe_overflow(s.safe_overflow)
        .subscriber_max_borrowed_samples(2)
        .open_or_create()
        .map_err(|e| match e {
            PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(
                PublishSubscribeOpenError::IncompatibleTypes,
            ) => BusError::IncompatibleType {
                service: name.to_string(),
                type_name: crate::type_name_of::<T>(),
            },
            e => BusError::Service {
                kind: "pub/sub",
                service: name.to_string(),
                reason: reason(e),
            },
        })?;
    // iceoryx2 opens a service that allows *at least* the requested publishers; one
    // created by a process outside the ICD with more is refused (impersonation)
    let allowed = factory.static_config().max_publishers();
    if allowed != s.max_publishers {
        return Err(BusError::Service {
            kind: "pub/sub",
            service: name.to_string(),
            reason: format!(
                "it allows {allowed} publishers where the settings say {}: created by a process with other settings",
                s.max_publishers
            ),
        });
    }
    Ok(factory)
}

/// Publishing side of one service.
pub struct Publisher<T: Debug + ZeroCopySend + Copy + 'static> {
    name: String,
    timeout: Duration,
    // Field order matters for drop order: ports before their factories.
    publisher: iceoryx2::port::publisher::Publisher<ipc::Service, T, ()>,
    notifier: Notifier<ipc::Service>,
    _pubsub: PubSubFactory<ipc::Service, T, ()>,
    _event: EventFactory<ipc::Service>,
}

impl<T: Debug + ZeroCopySend + Copy + 'static> Publisher<T> {
    /// Opens/creates service `name` (pub/sub + event) and a publisher and notifier on it.
    pub fn new(node: &BusNode, name: IcdServiceName, settings: &ServiceSettings) -> Result<Self> {
        Self::with_name(node, name.as_str(), settings)
    }

    /// Like [`new`](Self::new) with a free-form service name (tests, tools).
    pub fn with_name(node: &BusNode, name: &str, settings: &ServiceSettings) -> Result<Self> {
        let pubsub = open_pubsub::<T>(node, name, settings)?;
        let event = data_event(node, name, settings)?;
        let timeout = settings.backpressure_timeout;
        let mut builder = pubsub.publisher_builder().max_loaned_samples(2);
        if !settings.safe_overflow {
            // Retry while the subscriber may still drain; after `timeout` drop the
            // sample for that subscriber only and report it (never block forever).
            // A subscriber that stayed full for `timeout` (hung or dead) is *stuck*
            // for the next `STUCK_HOLD_FACTOR × timeout`: sends drop its samples at
            // once instead of stalling every send by `timeout`; then it gets the full
            // wait again. Only that subscriber: the others (e.g. a recorder that is
            // momentarily behind) keep the lossless wait.
            let stuck: Mutex<Vec<(u128, Instant)>> = Mutex::new(Vec::new());
            let hold = timeout * STUCK_HOLD_FACTOR;
            builder =
                builder.set_backpressure_handler(move |info: &iceoryx2::port::BackpressureInfo| {
                    let now = Instant::now();
                    let mut stuck = stuck.lock().unwrap_or_else(|p| p.into_inner());
                    stuck.retain(|(_, since)| now.duration_since(*since) < hold);
                    if stuck.iter().any(|(id, _)| *id == info.receiver_port_id) {
                        BackpressureAction::DiscardDataAndFail
                    } else if info.elapsed_time < timeout {
                        BackpressureAction::Retry
                    } else {
                        stuck.push((info.receiver_port_id, now));
                        BackpressureAction::DiscardDataAndFail
                    }
                });
        }
        let publisher = builder.create().map_err(|e| BusError::Port {
            port: "publisher",
            service: name.to_string(),
            reason: reason(e),
        })?;
        let notifier = sample_notifier(&event, name)?;
        Ok(Self {
            name: name.to_string(),
            timeout,
            publisher,
            notifier,
            _pubsub: pubsub,
            _event: event,
        })
    }

    /// Service name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Loans a sample, writes `msg`, sends it, then wakes the listeners.
    /// Returns the number of subscribers that received the sample.
    pub fn send(&self, msg: &T) -> Result<usize> {
        let sample = self.publisher.loan_uninit().map_err(|e| BusError::Send {
            service: self.name.clone(),
            reason: reason(e),
        })?;
        let sample = sample.write_payload(*msg);
        let delivered = match sample.send() {
            Ok(n) => n,
            Err(iceoryx2::port::SendError::UnableToDeliver) => {
                // Still wake the subscribers that did get it before reporting.
                let _ = self.notifier.notify();
                return Err(BusError::Backpressure {
                    service: self.name.clone(),
                    timeout: self.timeout,
                });
            }
            Err(e) => {
                return Err(BusError::Send {
                    service: self.name.clone(),
                    reason: reason(e),
                });
            }
        };
        self.notify()?;
        Ok(delivered)
    }

    /// Loans a sample and returns it unsent: touches the publisher's loan path and
    /// data segment, so that the next [`send`](Self::send) finds them in the caches
    /// (the partition's pre-tick warm-up). Subscribers see nothing.
    pub fn warm(&self) -> Result<()> {
        let sample = self.publisher.loan_uninit().map_err(|e| BusError::Send {
            service: self.name.clone(),
            reason: reason(e),
        })?;
        drop(std::hint::black_box(sample));
        Ok(())
    }

    /// Wakes the listeners without sending (e.g. after a batch of `send`s).
    pub fn notify(&self) -> Result<()> {
        notify(&self.notifier, &self.name)
    }
}

/// What woke a subscriber / what its event queue held.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Events {
    /// "sample sent" notifications (coalesced count).
    pub notifications: u64,
    /// A publisher's process died (reported when dead-node cleanup ran, see
    /// [`crate::liveness`]).
    pub publisher_died: bool,
    /// A publisher left normally.
    pub publisher_left: bool,
}

impl Events {
    fn add(&mut self, id: usize, count: u64) {
        match id {
            EVENT_NOTIFIER_DEAD => self.publisher_died = true,
            EVENT_NOTIFIER_DROPPED => self.publisher_left = true,
            _ => self.notifications += count,
        }
    }

    /// True if nothing happened (timeout).
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }
}

/// Who may publish on a subscriber's service ([`Subscriber::expect_publisher`]): the
/// node's name and, when known, its process. The first publisher a subscriber hears is
/// pinned only if its node is this one; samples of any other are dropped and counted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExpectedPublisher {
    /// The node name of the publisher (the owner role's name, or the link's).
    pub node_name: String,
    /// Its process id, if known (the link's: the launcher starts it first).
    pub pid: Option<i32>,
}

impl ExpectedPublisher {
    /// Whether the alive node `id` of the run `config` is this publisher.
    fn is(&self, config: &iceoryx2::config::Config, id: &UniqueNodeId) -> bool {
        let mut found = false;
        let listed = Node::<ipc::Service>::list(config, |state| {
            if let NodeState::Alive(view) = &state
                && view.id() == id
            {
                found = view.details().as_ref().is_some_and(|d| {
                    d.name().as_str() == self.node_name
                        && self.pid.is_none_or(|p| d.process_id().value() == p)
                });
                return CallbackProgression::Stop;
            }
            CallbackProgression::Continue
        });
        listed.is_ok() && found
    }
}

/// Subscribing side of one service.
///
/// Its event listener is what a publisher's `notify` wakes: every listener of a
/// service costs the publisher one wake-up message per send, on the critical path
/// of a control loop. A subscriber that only reads the service when something else
/// woke it is created with [`polled`](Self::polled) and has no listener until it
/// is first attached to a [`crate::Waiter`] or waited on.
pub struct Subscriber<T: Debug + ZeroCopySend + Copy + 'static> {
    name: String,
    subscriber: iceoryx2::port::subscriber::Subscriber<ipc::Service, T, ()>,
    // ports before their factories (drop order)
    listener: std::cell::OnceCell<Listener<ipc::Service>>,
    _pubsub: PubSubFactory<ipc::Service, T, ()>,
    event: EventFactory<ipc::Service>,
    /// The publisher this subscriber accepts samples from: the first one it received a
    /// sample from (the owner — the handshake makes every port exist before the first
    /// tick, and the partition's services take one publisher).
    pinned: std::cell::Cell<Option<iceoryx2::identifiers::UniquePublisherId>>,
    /// Samples from any other publisher, dropped.
    rejected: std::cell::Cell<u64>,
    /// Only this publisher may be pinned (with the run's config to look its node up).
    expected: Option<(ExpectedPublisher, iceoryx2::config::Config)>,
    /// Nodes found not to be the expected publisher (not looked up again).
    not_expected: std::cell::RefCell<Vec<UniqueNodeId>>,
}

impl<T: Debug + ZeroCopySend + Copy + 'static> Subscriber<T> {
    /// Opens/creates service `name` (pub/sub + event) and a subscriber and listener on it.
    pub fn new(node: &BusNode, name: IcdServiceName, settings: &ServiceSettings) -> Result<Self> {
        let s = Self::polled_with_name(node, name.as_str(), settings)?;
        s.ensure_listener()?;
        Ok(s)
    }

    /// Like [`new`](Self::new) with a free-form service name (tests, tools).
    pub fn with_name(node: &BusNode, name: &str, settings: &ServiceSettings) -> Result<Self> {
        let s = Self::polled_with_name(node, name, settings)?;
        s.ensure_listener()?;
        Ok(s)
    }

    /// A subscriber without an event listener (nobody wakes it; it is read when
    /// something else woke its process). The listener is created when it is first
    /// needed: attached to a [`crate::Waiter`], or [`wait`](Self::wait)ed on.
    pub fn polled(
        node: &BusNode,
        name: IcdServiceName,
        settings: &ServiceSettings,
    ) -> Result<Self> {
        Self::polled_with_name(node, name.as_str(), settings)
    }

    /// Like [`polled`](Self::polled) with a free-form service name.
    pub fn polled_with_name(
        node: &BusNode,
        name: &str,
        settings: &ServiceSettings,
    ) -> Result<Self> {
        let pubsub = open_pubsub::<T>(node, name, settings)?;
        let event = data_event(node, name, settings)?;
        let subscriber = pubsub
            .subscriber_builder()
            .buffer_size(settings.subscriber_buffer)
            .create()
            .map_err(|e| BusError::Port {
                port: "subscriber",
                service: name.to_string(),
                reason: reason(e),
            })?;
        Ok(Self {
            name: name.to_string(),
            subscriber,
            listener: std::cell::OnceCell::new(),
            _pubsub: pubsub,
            event,
            pinned: std::cell::Cell::new(None),
            rejected: std::cell::Cell::new(0),
            expected: None,
            not_expected: std::cell::RefCell::new(Vec::new()),
        })
    }

    /// Whether `node` is the expected publisher (a node found not to be is remembered).
    fn is_expected(&self, node: &UniqueNodeId) -> bool {
        let Some((e, config)) = &self.expected else {
            return true;
        };
        if self.not_expected.borrow().contains(node) {
            return false;
        }
        let yes = e.is(config, node);
        if !yes {
            self.not_expected.borrow_mut().push(*node);
        }
        yes
    }

    /// Accepts samples only from `publisher`, a node of the run of `node`: the first
    /// publisher heard is pinned only if it is that one (by default, whichever is heard
    /// first — on one host the owner, whose port exists before the first tick). A later
    /// publisher port of the same node (a re-opened bridge of the link) is accepted in
    /// the first one's place.
    pub fn expect_publisher(&mut self, node: &BusNode, publisher: ExpectedPublisher) {
        self.expected = Some((publisher, node.config().clone()));
    }

    /// Service name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Samples dropped because another publisher than the pinned one sent them (an
    /// impersonator, or a restarted owner).
    pub fn rejected(&self) -> u64 {
        self.rejected.get()
    }

    /// True if the subscriber has an event listener (publishers wake it).
    pub fn has_listener(&self) -> bool {
        self.listener.get().is_some()
    }

    /// The event listener, created on first use; to attach to a [`crate::Waiter`].
    /// Notifications sent before it existed are not seen: read the queue after
    /// creating it.
    pub fn ensure_listener(&self) -> Result<&Listener<ipc::Service>> {
        if let Some(l) = self.listener.get() {
            return Ok(l);
        }
        let l = listener(&self.event, &self.name)?;
        Ok(self.listener.get_or_init(|| l))
    }

    fn check(&self, r: core::result::Result<u64, impl Debug>) -> Result<()> {
        r.map(|_| ()).map_err(|e| BusError::Event {
            op: "wait",
            service: self.name.clone(),
            reason: reason(e),
        })
    }

    /// Takes the pending events without blocking. Call it when a [`crate::Waiter`]
    /// reports this subscriber, or the waiter wakes up again at once.
    /// Without a listener there are no events (empty).
    pub fn drain_events(&self) -> Result<Events> {
        let mut ev = Events::default();
        let Some(l) = self.listener.get() else {
            return Ok(ev);
        };
        let r = l.try_wait(|a| ev.add(a.id.as_value(), a.count));
        self.check(r)?;
        Ok(ev)
    }

    /// Blocks until an event arrives or `timeout` passes (then `Events::is_empty()`).
    /// Creates the listener if the subscriber has none yet.
    pub fn wait(&self, timeout: Duration) -> Result<Events> {
        let mut ev = Events::default();
        let r = self
            .ensure_listener()?
            .timed_wait(|a| ev.add(a.id.as_value(), a.count), timeout);
        self.check(r)?;
        Ok(ev)
    }

    /// Blocks until an event arrives or the `deadline` instant passes.
    pub fn wait_until(&self, deadline: Instant) -> Result<Events> {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return self.drain_events();
        }
        self.wait(left)
    }

    /// Oldest queued sample of the pinned publisher, if any (samples of any other
    /// publisher are dropped and counted, [`rejected`](Self::rejected)).
    pub fn try_receive(&self) -> Result<Option<T>> {
        loop {
            match self.subscriber.receive() {
                Ok(Some(sample)) => {
                    let from = sample.header().publisher_id();
                    match self.pinned.get() {
                        // told whom to accept: a new publisher port of that node (the link
                        // re-opens a bridge with a new port) is pinned again
                        p if p != Some(from) && self.expected.is_some() => {
                            if !self.is_expected(&sample.header().node_id()) {
                                self.rejected.set(self.rejected.get() + 1);
                                continue;
                            }
                            self.pinned.set(Some(from));
                        }
                        None => self.pinned.set(Some(from)),
                        Some(p) if p != from => {
                            self.rejected.set(self.rejected.get() + 1);
                            continue;
                        }
                        Some(_) => {}
                    }
                    return Ok(Some(*sample.payload()));
                }
                Ok(None) => return Ok(None),
                Err(e) => {
                    return Err(BusError::Receive {
                        service: self.name.clone(),
                        reason: reason(e),
                    });
                }
            }
        }
    }

    /// Drains the queue and returns the newest sample (older ones are discarded).
    pub fn receive_latest(&self) -> Result<Option<T>> {
        let mut latest = None;
        while let Some(v) = self.try_receive()? {
            latest = Some(v);
        }
        Ok(latest)
    }

    /// Drains the queue into `out` in arrival order; returns how many were appended.
    pub fn receive_all(&self, out: &mut Vec<T>) -> Result<usize> {
        let before = out.len();
        while let Some(v) = self.try_receive()? {
            out.push(v);
        }
        Ok(out.len() - before)
    }

    /// Waits up to `timeout` for the next sample (event wake-up, no polling loop).
    pub fn receive_timeout(&self, timeout: Duration) -> Result<Option<T>> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(v) = self.try_receive()? {
                return Ok(Some(v));
            }
            if Instant::now() >= deadline {
                return Ok(None);
            }
            self.wait_until(deadline)?;
        }
    }
}
