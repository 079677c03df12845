//! The doorbell: a sample that crossed the link wakes its subscribers only once it is
//! there.
//!
//! Every data service of the partition is a pub/sub service with an event service of
//! the same name: the publisher writes the sample, then notifies
//! [`sc_bus::pubsub::EVENT_SAMPLE`], and a subscriber sleeps on the event. The link
//! bridges the two separately. When the link's pass falls between the publisher's
//! sample and its notification, the notification crosses first, the subscriber on the
//! other host wakes to an empty queue, and the sample that follows wakes no one
//! (measured: `sc-hop-cost` across the link lost its 214th round trip of 300 that
//! way). So each host's link rings the event itself after every pass in which it
//! published a sample from the other host: it reads every bridged pub/sub service with
//! a subscriber of its own (untyped, as the link's own ports are) and notifies when a
//! sample there came from the link's node. The notification the link relays as well
//! is then at most an early, empty wake.

use anyhow::{Context, Result, anyhow};
use iceoryx2::identifiers::UniqueNodeId;
use iceoryx2::node::Node;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use iceoryx2::service::messaging_pattern::MessagingPattern;
use iceoryx2::service::service_hash::ServiceHash;
use iceoryx2::service::static_config::messaging_pattern::MessagingPattern as StaticPattern;
use iceoryx2_link_backend::wire::publish_subscribe::{Header, Payload, Subscriber};
use std::collections::{BTreeMap, BTreeSet};

/// One pub/sub service's doorbell: a subscriber that sees what the link published,
/// a notifier on the service's event.
struct Doorbell {
    subscriber: Subscriber<ipc::Service>,
    notifier: Notifier<ipc::Service>,
}

/// The doorbells of every bridged pub/sub service that has an event of its name.
#[derive(Default)]
pub struct Doorbells {
    by_service: BTreeMap<String, Doorbell>,
    /// Services whose doorbell could not be opened (said once each, retried).
    refused: BTreeSet<String>,
}

impl Doorbells {
    /// Adds a doorbell for every pub/sub service on this host that the link bridges
    /// (`bridged`, by service hash) and that has an event service of the same name, and
    /// has none yet.
    pub fn discover(
        &mut self,
        node: &Node<ipc::Service>,
        bridged: &dyn Fn(&ServiceHash) -> bool,
    ) -> Result<()> {
        let mut found = Vec::new();
        ipc::Service::list(node.config(), |s| {
            let config = &s.static_details;
            let pubsub = matches!(
                config.messaging_pattern(),
                StaticPattern::PublishSubscribe(_)
            );
            if pubsub && bridged(config.service_hash()) {
                found.push(*config.name());
            }
            CallbackProgression::Continue
        })
        .map_err(|e| anyhow!("{e:?}"))
        .context("listing this host's services")?;
        for name in found {
            let key = name.as_str().to_string();
            if self.by_service.contains_key(&key) || !has_event(node, &name) {
                continue;
            }
            match Doorbell::open(node, &name) {
                Ok(d) => {
                    self.refused.remove(&key);
                    self.by_service.insert(key, d);
                }
                Err(e) => {
                    if self.refused.insert(key) {
                        eprintln!("sc-link: no doorbell on {name} (yet): {e:#}");
                    }
                }
            }
        }
        Ok(())
    }

    /// Reads every doorbell's queue and rings those where `link` published a sample.
    /// One that fails does not keep the others from being read (their queues would fill
    /// and their publishers report drops): the first failure is returned after all.
    pub fn ring(&self, link: &UniqueNodeId) -> Result<usize> {
        let mut rung = 0;
        let mut first_failure = None;
        for (name, d) in &self.by_service {
            match Self::ring_one(name, d, link) {
                Ok(true) => rung += 1,
                Ok(false) => {}
                Err(e) => {
                    first_failure.get_or_insert(e);
                }
            }
        }
        first_failure.map_or(Ok(rung), Err)
    }

    fn ring_one(name: &str, d: &Doorbell, link: &UniqueNodeId) -> Result<bool> {
        if !d
            .drain(link)
            .with_context(|| format!("doorbell of {name}"))?
        {
            return Ok(false);
        }
        // not to the link's own listener on this event: that would send the ring back
        // to the other host (as the link's own ports skip themselves)
        d.notifier
            .__internal_notify(EventId::new(sc_bus::pubsub::EVENT_SAMPLE), true)
            .map_err(|e| anyhow!("{e:?}"))
            .with_context(|| format!("ringing {name}"))?;
        Ok(true)
    }

    /// How many services have one.
    pub fn len(&self) -> usize {
        self.by_service.len()
    }
}

fn has_event(node: &Node<ipc::Service>, name: &ServiceName) -> bool {
    ipc::Service::does_exist(name, node.config(), MessagingPattern::Event).unwrap_or(false)
}

impl Doorbell {
    fn open(node: &Node<ipc::Service>, name: &ServiceName) -> Result<Self> {
        let details =
            ipc::Service::details(name, node.config(), MessagingPattern::PublishSubscribe)
                .map_err(|e| anyhow!("{e:?}"))?
                .ok_or_else(|| anyhow!("it is gone"))?;
        let types = *details
            .static_details
            .publish_subscribe()
            .message_type_details();
        // SAFETY: the type details are those of this very service, read from its static
        // configuration, so the untyped markers stand in for its real types — as the
        // link opens its own ports (iceoryx2_link::ports::publish_subscribe). Samples are
        // only counted, never read.
        let builder = unsafe {
            node.service_builder(name)
                .publish_subscribe::<Payload>()
                .user_header::<Header>()
                .__internal_set_user_header_type_details(&types.user_header)
                .__internal_set_payload_type_details(&types.payload)
        };
        let service = builder.open().map_err(|e| anyhow!("{e:?}"))?;
        let subscriber = service
            .subscriber_builder()
            .create()
            .map_err(|e| anyhow!("{e:?}"))?;
        let event = node
            .service_builder(name)
            .event()
            .open()
            .map_err(|e| anyhow!("{e:?}"))?;
        let notifier = event
            .notifier_builder()
            .default_event_id(EventId::new(sc_bus::pubsub::EVENT_SAMPLE))
            .create()
            .map_err(|e| anyhow!("{e:?}"))?;
        Ok(Self {
            subscriber,
            notifier,
        })
    }

    /// Empties the queue; whether a sample in it was published by `link`.
    fn drain(&self, link: &UniqueNodeId) -> Result<bool> {
        let mut crossed = false;
        while let Some(sample) = self.subscriber.receive().map_err(|e| anyhow!("{e:?}"))? {
            crossed |= sample.header().node_id() == *link;
        }
        Ok(crossed)
    }
}
