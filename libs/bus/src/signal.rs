//! Payload-less event services: a wake-up that means one thing, e.g. the
//! scheduler's stage-deadline watchdog ("a stage deadline of the current tick
//! passed and the tick is unfinished: look at your inputs").
//!
//! ```no_run
//! use sc_bus::{RunScope, ServiceSettings, SignalListener, SignalSender, Waiter};
//! use std::time::Duration;
//! let run = RunScope::unique("doc")?;
//! let node = run.node("scheduler")?;
//! let qos = ServiceSettings::lock_step();
//! let tx = SignalSender::new(&node, "safe_capture/scheduler/deadline", &qos)?;
//! let rx = SignalListener::new(&node, "safe_capture/scheduler/deadline", &qos)?;
//! let waiter = Waiter::new()?;
//! let _a = waiter.attach(&rx)?;
//! tx.notify()?;
//! waiter.wait_once(Duration::from_millis(100), |_| {})?;
//! assert!(rx.drain()? > 0);
//! # Ok::<(), sc_bus::BusError>(())
//! ```

use crate::error::{BusError, Result, reason};
use crate::pubsub::{EVENT_SAMPLE, ServiceSettings, data_event, listener, notify, sample_notifier};
use crate::run::BusNode;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::event::PortFactory as EventFactory;

/// Notifying side of a signal.
pub struct SignalSender {
    name: String,
    // ports before their factory (drop order)
    notifier: Notifier<ipc::Service>,
    _event: EventFactory<ipc::Service>,
}

impl SignalSender {
    /// Opens/creates the event service `name` and a notifier on it.
    pub fn new(node: &BusNode, name: &str, settings: &ServiceSettings) -> Result<Self> {
        let ev = data_event(node, name, settings)?;
        let notifier = sample_notifier(&ev, name)?;
        Ok(Self {
            name: name.to_string(),
            notifier,
            _event: ev,
        })
    }

    /// Wakes every listener of the signal.
    pub fn notify(&self) -> Result<()> {
        notify(&self.notifier, &self.name)
    }
}

/// Listening side of a signal; attach it to a [`crate::Waiter`].
pub struct SignalListener {
    name: String,
    listener: Listener<ipc::Service>,
    _event: EventFactory<ipc::Service>,
}

impl SignalListener {
    /// Opens/creates the event service `name` and a listener on it.
    pub fn new(node: &BusNode, name: &str, settings: &ServiceSettings) -> Result<Self> {
        let ev = data_event(node, name, settings)?;
        Ok(Self {
            name: name.to_string(),
            listener: listener(&ev, name)?,
            _event: ev,
        })
    }

    /// Takes the pending notifications without blocking; returns how many
    /// (coalesced) signals were pending.
    pub fn drain(&self) -> Result<u64> {
        let mut n = 0;
        self.listener
            .try_wait(|a| {
                if a.id.as_value() == EVENT_SAMPLE {
                    n += a.count
                }
            })
            .map_err(|e| BusError::Event {
                op: "wait",
                service: self.name.clone(),
                reason: reason(e),
            })?;
        Ok(n)
    }
}

impl crate::Waitable for SignalListener {
    fn listener(&self) -> Result<&Listener<ipc::Service>> {
        Ok(&self.listener)
    }
}
