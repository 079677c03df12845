//! Typed errors of sc-bus. Every variant names the service/node involved and the
//! iceoryx2 failure (its `Debug` form, e.g. `IncompatibleTypes`).

use std::time::Duration;

/// Everything that can go wrong in sc-bus.
#[derive(Debug, thiserror::Error)]
pub enum BusError {
    /// The run id contains no usable character or is too long.
    #[error("invalid run id {run_id:?}: {reason}")]
    InvalidRunId {
        /// The rejected id.
        run_id: String,
        /// Why.
        reason: &'static str,
    },
    /// A name (node, service, prefix) is not accepted by iceoryx2.
    #[error("invalid {what} name {name:?}: {reason}")]
    InvalidName {
        /// "node", "service" or "prefix".
        what: &'static str,
        /// The rejected name.
        name: String,
        /// The iceoryx2 reason.
        reason: String,
    },
    /// The node could not be created.
    #[error("cannot create node {node:?}: {reason}")]
    NodeCreate {
        /// Node name.
        node: String,
        /// The iceoryx2 reason.
        reason: String,
    },
    /// The service exists with another payload type (type name or layout differ).
    #[error("service {service:?} exists with another payload type than {type_name:?}")]
    IncompatibleType {
        /// Service name.
        service: String,
        /// The type name this process asked for.
        type_name: &'static str,
    },
    /// A service could not be opened or created.
    #[error("cannot open/create {kind} service {service:?}: {reason}")]
    Service {
        /// "pub/sub" or "event".
        kind: &'static str,
        /// Service name.
        service: String,
        /// The iceoryx2 reason.
        reason: String,
    },
    /// A port (publisher, subscriber, notifier, listener) could not be created.
    #[error("cannot create {port} on {service:?}: {reason}")]
    Port {
        /// Port kind.
        port: &'static str,
        /// Service name.
        service: String,
        /// The iceoryx2 reason.
        reason: String,
    },
    /// Loan/send failed.
    #[error("send on {service:?} failed: {reason}")]
    Send {
        /// Service name.
        service: String,
        /// The iceoryx2 reason.
        reason: String,
    },
    /// A subscriber did not take the sample within the backpressure timeout
    /// (it is stuck or dead); the sample was dropped for that subscriber only.
    #[error(
        "send on {service:?}: a subscriber's queue stayed full (waited {timeout:?}); the sample was dropped for it alone"
    )]
    Backpressure {
        /// Service name.
        service: String,
        /// Configured timeout.
        timeout: Duration,
    },
    /// Receive failed.
    #[error("receive on {service:?} failed: {reason}")]
    Receive {
        /// Service name.
        service: String,
        /// The iceoryx2 reason.
        reason: String,
    },
    /// Notify or wait on an event failed.
    #[error("event {op} on {service:?} failed: {reason}")]
    Event {
        /// "notify" or "wait".
        op: &'static str,
        /// Service name.
        service: String,
        /// The iceoryx2 reason.
        reason: String,
    },
    /// WaitSet creation, attachment or wait failed.
    #[error("waitset {op} failed: {reason}")]
    WaitSet {
        /// What was attempted.
        op: &'static str,
        /// The iceoryx2 reason.
        reason: String,
    },
    /// Listing the nodes of the run failed.
    #[error("cannot list nodes of prefix {prefix:?}: {reason}")]
    NodeList {
        /// The run prefix.
        prefix: String,
        /// The iceoryx2 reason.
        reason: String,
    },
    /// The handshake did not see every participant in time.
    #[error("handshake timed out after {timeout:?}: missing participants {missing:?}")]
    HandshakeTimeout {
        /// Timeout used.
        timeout: Duration,
        /// Participant ids never seen.
        missing: Vec<u32>,
    },
    /// A participant id is outside the handshake's range.
    #[error("participant id {id} out of range 0..{max}")]
    ParticipantOutOfRange {
        /// Offending id.
        id: u32,
        /// Exclusive upper bound.
        max: u32,
    },
    /// Teardown refused: nodes of this prefix are still alive.
    #[error("teardown of prefix {prefix:?} refused: {alive} node(s) still alive")]
    NodesStillAlive {
        /// The run prefix.
        prefix: String,
        /// Number of live nodes.
        alive: usize,
    },
    /// File-system error while removing leftovers.
    #[error("cannot remove {path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
}

/// Shorthand.
pub type Result<T> = core::result::Result<T, BusError>;

pub(crate) fn reason<E: core::fmt::Debug>(e: E) -> String {
    format!("{e:?}")
}
