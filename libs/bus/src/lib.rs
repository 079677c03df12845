//! sc-bus: the only crate of safe-capture that touches iceoryx2 (0.10).
//!
//! Small building blocks, each with one job:
//! - [`RunScope`]: one iceoryx2 `global.prefix` per run (isolation of parallel
//!   runs/tests), node creation, teardown of every file the prefix left behind;
//! - [`Publisher`] / [`Subscriber`]: pub/sub + same-name event service;
//!   `send` = loan, write, send, notify; subscribers block on the event;
//! - [`SignalSender`] / [`SignalListener`]: payload-less wake-ups (the stage-deadline watchdog);
//! - [`Waiter`]: one thread sleeps on several subscribers, deadlines and intervals;
//! - [`PeerMonitor`] / [`reap_dead_nodes`]: detect peers that died (e.g. SIGKILL);
//! - [`Coordinator`] / [`Participant`]: start-up handshake before the first tick.
//!
//! ```no_run
//! use sc_bus::{Publisher, RunScope, ServiceSettings, Subscriber};
//! use sc_icd::{services, Tick};
//! use std::time::Duration;
//! let run = RunScope::from_env().unwrap_or_else(|| RunScope::unique("dev"))?;
//! let node = run.node("scheduler")?;
//! let qos = ServiceSettings::lock_step();
//! let tick_tx = Publisher::<Tick>::new(&node, services::TICK, &qos)?;
//! let tick_rx = Subscriber::<Tick>::new(&node, services::TICK, &qos)?;
//! tick_tx.send(&Tick { tick: 1, ..Default::default() })?;
//! tick_rx.wait(Duration::from_millis(100))?;
//! assert_eq!(tick_rx.receive_latest()?.map(|t| t.tick), Some(1));
//! # Ok::<(), sc_bus::BusError>(())
//! ```

mod error;
pub mod handshake;
pub mod liveness;
pub mod pubsub;
pub mod run;
pub mod signal;
pub mod waiter;

pub use error::{BusError, Result};
pub use handshake::{Coordinator, Participant};
pub use liveness::{NodeReport, PeerInfo, PeerMonitor, reap_dead_nodes};
pub use pubsub::{Events, ExpectedPublisher, Publisher, ServiceSettings, Subscriber};
pub use run::{BusNode, RUN_ID_ENV, RunScope};
pub use signal::{SignalListener, SignalSender};
pub use waiter::{Attachment, WaitOutcome, Waitable, Waiter, Wake};

/// Message bound of the bus: what sc-icd's messages derive.
pub use iceoryx2::prelude::ZeroCopySend;

/// The iceoryx2 type name of `T`.
pub fn type_name_of<T: ZeroCopySend>() -> &'static str {
    sc_icd::type_name_of::<T>()
}

/// Sets the iceoryx2 log level from `IOX2_LOG_LEVEL`, default warnings only.
pub fn init_logging() {
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Warn);
}
