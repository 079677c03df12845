//! A role's iceoryx2 ports, opened from its services: one typed subscriber or signal
//! listener per input, one publisher or signal sender per output. The message type and
//! the service settings of each service are written here once.

use crate::component::Message;
use crate::error::FlightError;
use crate::process::Qos;
use sc_bus::{
    BusNode, Publisher, ServiceSettings, SignalListener, SignalSender, Subscriber, Waitable,
    ZeroCopySend,
};
use sc_icd::services::{self, ServiceName};
use sc_icd::{Health, SimState, StepResult, Tick};

/// An input: a subscriber or a signal listener.
pub trait InPort {
    fn service(&self) -> ServiceName;
    /// Drains its events and appends its queued samples to `out`; a signal returns the
    /// number of signals instead.
    fn drain(&self, out: &mut Vec<Message>) -> Result<u64, FlightError>;
    /// Samples dropped because they came from a second publisher.
    fn impostors(&self) -> u64;
    /// What a waiter sleeps on.
    fn waitable(&self) -> &dyn Waitable;
}

struct SubPort<T: core::fmt::Debug + ZeroCopySend + Copy + 'static> {
    service: ServiceName,
    sub: Subscriber<T>,
    wrap: fn(T) -> Message,
}

impl<T: core::fmt::Debug + ZeroCopySend + Copy + 'static> InPort for SubPort<T> {
    fn service(&self) -> ServiceName {
        self.service
    }
    fn drain(&self, out: &mut Vec<Message>) -> Result<u64, FlightError> {
        self.sub.drain_events()?;
        let mut v = Vec::new();
        let n = self.sub.receive_all(&mut v)?;
        out.extend(v.into_iter().map(self.wrap));
        Ok(n as u64)
    }
    fn impostors(&self) -> u64 {
        self.sub.rejected()
    }
    fn waitable(&self) -> &dyn Waitable {
        &self.sub
    }
}

struct SignalPort {
    service: ServiceName,
    listener: SignalListener,
}

impl InPort for SignalPort {
    fn service(&self) -> ServiceName {
        self.service
    }
    fn drain(&self, _: &mut Vec<Message>) -> Result<u64, FlightError> {
        Ok(self.listener.drain()?)
    }
    fn impostors(&self) -> u64 {
        0
    }
    fn waitable(&self) -> &dyn Waitable {
        &self.listener
    }
}

fn sub<T: core::fmt::Debug + ZeroCopySend + Copy + 'static>(
    node: &BusNode,
    service: ServiceName,
    settings: &ServiceSettings,
    wrap: fn(T) -> Message,
    expected: Option<&sc_bus::ExpectedPublisher>,
) -> Result<Box<dyn InPort>, FlightError> {
    let mut sub = Subscriber::<T>::polled(node, service, settings)?;
    if let Some(e) = expected {
        sub.expect_publisher(node, e.clone());
    }
    Ok(Box::new(SubPort { service, sub, wrap }))
}

/// Opens the input on `service` (its listener is created when a waiter first needs it).
pub fn open_input(
    node: &BusNode,
    service: ServiceName,
    qos: &Qos,
) -> Result<Box<dyn InPort>, FlightError> {
    use services::*;
    let (q, p) = (&qos.flight, &qos.partner);
    let e = qos.expected(service);
    match service {
        TICK => sub::<Tick>(node, service, q, Message::Tick, e),
        CONTROL => sub::<Tick>(node, service, q, Message::Control, e),
        SIM_STATE => sub::<SimState>(node, service, q, Message::State, e),
        PARTNER_STATE => sub::<SimState>(node, service, p, Message::PartnerState, e),
        TRUTH => sub::<SimState>(node, service, q, Message::Truth, e),
        NAVIGATION_ERROR => sub(node, service, q, Message::NavigationError, e),
        MEASUREMENT => sub(node, service, p, Message::Measurement, e),
        ESTIMATE => sub(node, service, p, Message::Estimate, e),
        NOMINAL_TRANSLATIONAL => sub(node, service, p, Message::NominalTranslational, e),
        NOMINAL_ATTITUDE => sub(node, service, p, Message::NominalAttitude, e),
        NOMINAL_ROBOTIC => sub(node, service, p, Message::NominalRobotic, e),
        SAFE_TRANSLATIONAL => sub(node, service, q, Message::SafeTranslational, e),
        SAFE_ATTITUDE => sub(node, service, q, Message::SafeAttitude, e),
        SAFE_ROBOTIC => sub(node, service, q, Message::SafeRobotic, e),
        STEP_RESULT => sub::<StepResult>(node, service, q, Message::StepResult, e),
        HEALTH => sub::<Health>(node, service, q, Message::Health, e),
        STAGE_DEADLINE | PREPARE => Ok(Box::new(SignalPort {
            service,
            listener: SignalListener::new(node, service.as_str(), q)?,
        })),
        other => Err(FlightError::UnknownService(other.as_str())),
    }
}

/// An output: a publisher or a signal sender.
pub trait OutPort {
    fn service(&self) -> ServiceName;
    /// Publishes `m` (which travels on this port's service).
    fn send(&self, m: &Message) -> Result<(), FlightError>;
    /// Wakes its listeners without a sample.
    fn notify(&self) -> Result<(), FlightError>;
    /// Touches its memory (the pre-tick warm-up).
    fn warm(&self) -> Result<(), FlightError>;
}

struct PubPort<T: core::fmt::Debug + ZeroCopySend + Copy + 'static> {
    service: ServiceName,
    publisher: Publisher<T>,
    unwrap: fn(&Message) -> Option<&T>,
}

impl<T: core::fmt::Debug + ZeroCopySend + Copy + 'static> OutPort for PubPort<T> {
    fn service(&self) -> ServiceName {
        self.service
    }
    fn send(&self, m: &Message) -> Result<(), FlightError> {
        let msg = (self.unwrap)(m).ok_or(FlightError::WrongMessage(self.service.as_str()))?;
        match self.publisher.send(msg) {
            Ok(_) => Ok(()),
            // a full subscriber (dead, hung or never reading) loses the sample, alone,
            // without delaying the send (`process::qos`); reported, the run goes on
            Err(e @ sc_bus::BusError::Backpressure { .. }) => {
                eprintln!("warning: {e}");
                Ok(())
            }
            Err(e) => Err(e.into()),
        }
    }
    fn notify(&self) -> Result<(), FlightError> {
        Ok(self.publisher.notify()?)
    }
    fn warm(&self) -> Result<(), FlightError> {
        Ok(self.publisher.warm()?)
    }
}

struct SignalOut {
    service: ServiceName,
    sender: SignalSender,
}

impl OutPort for SignalOut {
    fn service(&self) -> ServiceName {
        self.service
    }
    fn send(&self, _: &Message) -> Result<(), FlightError> {
        Err(FlightError::WrongMessage(self.service.as_str()))
    }
    fn notify(&self) -> Result<(), FlightError> {
        Ok(self.sender.notify()?)
    }
    fn warm(&self) -> Result<(), FlightError> {
        Ok(())
    }
}

fn publ<T: core::fmt::Debug + ZeroCopySend + Copy + 'static>(
    node: &BusNode,
    service: ServiceName,
    settings: &ServiceSettings,
    unwrap: fn(&Message) -> Option<&T>,
) -> Result<Box<dyn OutPort>, FlightError> {
    Ok(Box::new(PubPort {
        service,
        publisher: Publisher::<T>::new(node, service, settings)?,
        unwrap,
    }))
}

/// Opens the output on `service`.
pub fn open_output(
    node: &BusNode,
    service: ServiceName,
    qos: &Qos,
) -> Result<Box<dyn OutPort>, FlightError> {
    use services::*;
    let (q, p) = (&qos.flight, &qos.partner);
    macro_rules! out {
        ($variant:ident, $settings:expr) => {
            publ(node, service, $settings, |m| match m {
                Message::$variant(x) => Some(x),
                _ => None,
            })
        };
    }
    match service {
        TICK => out!(Tick, q),
        CONTROL => out!(Control, q),
        SIM_STATE => out!(State, q),
        PARTNER_STATE => out!(PartnerState, p),
        TRUTH => out!(Truth, q),
        NAVIGATION_ERROR => out!(NavigationError, q),
        MEASUREMENT => out!(Measurement, p),
        ESTIMATE => out!(Estimate, p),
        NOMINAL_TRANSLATIONAL => out!(NominalTranslational, p),
        NOMINAL_ATTITUDE => out!(NominalAttitude, p),
        NOMINAL_ROBOTIC => out!(NominalRobotic, p),
        SAFE_TRANSLATIONAL => out!(SafeTranslational, q),
        SAFE_ATTITUDE => out!(SafeAttitude, q),
        SAFE_ROBOTIC => out!(SafeRobotic, q),
        STEP_RESULT => out!(StepResult, q),
        HEALTH => out!(Health, q),
        STAGE_DEADLINE | PREPARE => Ok(Box::new(SignalOut {
            service,
            sender: SignalSender::new(node, service.as_str(), q)?,
        })),
        other => Err(FlightError::UnknownService(other.as_str())),
    }
}
