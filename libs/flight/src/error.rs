//! Why a role process cannot go on (one line each; the process prints it and exits 2).

use crate::config::ConfigError;

/// Everything that stops a role process.
#[derive(Debug, thiserror::Error)]
pub enum FlightError {
    /// The shared-memory transport failed (a service, a port, a wait).
    #[error(transparent)]
    Bus(#[from] sc_bus::BusError),
    /// The partition config is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The scenario or the servicer model cannot be loaded.
    #[error(transparent)]
    Setup(#[from] sc_mission::SetupError),
    /// The nominal controllers cannot be built from the scenario.
    #[error(transparent)]
    Nominal(#[from] sc_nominal::NominalError),
    /// The simulator cannot be built, or its plant cannot be started.
    #[error("simulator: {0}")]
    Simulator(String),
    /// The process was started wrongly (arguments, environment).
    #[error("{0}")]
    Usage(String),
    /// Roles that never joined the start-up handshake.
    #[error("handshake timed out after {timeout:?}: never joined: {missing} (see their logs)")]
    HandshakeTimeout {
        timeout: std::time::Duration,
        missing: String,
    },
    /// A file of the run could not be written.
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    /// A service this runner has no message type for (a role table entry without its
    /// port in `runner::ports`).
    #[error("service `{0}`: no message type known to the runner")]
    UnknownService(&'static str),
    /// A component asked to publish a message on a service of another type.
    #[error("service `{0}`: a message of another type was sent on it")]
    WrongMessage(&'static str),
    /// A component named a service its role has no port for.
    #[error("service `{0}` is not a port of this role")]
    NoPort(&'static str),
}
