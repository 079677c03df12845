//! A role of the partition as a component: events in, actions out, no transport.
//!
//! A component never touches shared memory, the clock or the file system. The runner
//! ([`crate::runner`]) sleeps on the inputs the component names ([`Next`]), drains every
//! input of the role in the component's read order, and hands them over with the time
//! ([`Wakeup`]); the component decides — a deadline passed, a command for another tick,
//! a refused command, a missing upstream command, the stop, a dead peer — and answers
//! with actions ([`Outbox`]): messages to publish, signals, log lines, files. Its unit
//! tests drive it with made-up wake-ups, without starting a process.

use sc_icd::services::ServiceName;
use sc_icd::{
    Health, NavState, NavigationError, NominalAttitude, NominalRobotic, NominalTranslational,
    SafeAttitude, SafeRobotic, SafeTranslational, SimState, StepResult, Tick,
};

/// One message of the ICD as a role receives or publishes it, tagged with its service.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Message {
    /// `safe_capture/scheduler/tick`.
    Tick(Tick),
    /// `safe_capture/scheduler/control` (the stop).
    Control(Tick),
    /// `safe_capture/sim/state` (the flight side).
    State(SimState),
    /// `safe_capture/partner/state` (the nominal controllers' copy).
    PartnerState(SimState),
    /// `safe_capture/sim/truth` (the recorder; with a declared uncertainty only).
    Truth(SimState),
    /// `safe_capture/sim/navigation_error` (the recorder; with a declared uncertainty).
    NavigationError(NavigationError),
    /// `safe_capture/sim/measurement` (the navigation).
    Measurement(NavState),
    /// `safe_capture/navigation/estimate` (the simulator).
    Estimate(NavState),
    NominalTranslational(NominalTranslational),
    NominalAttitude(NominalAttitude),
    NominalRobotic(NominalRobotic),
    SafeTranslational(SafeTranslational),
    SafeAttitude(SafeAttitude),
    SafeRobotic(SafeRobotic),
    StepResult(StepResult),
    Health(Health),
}

impl Message {
    /// The service it travels on.
    pub fn service(&self) -> ServiceName {
        use sc_icd::services::*;
        match self {
            Message::Tick(_) => TICK,
            Message::Control(_) => CONTROL,
            Message::State(_) => SIM_STATE,
            Message::PartnerState(_) => PARTNER_STATE,
            Message::Truth(_) => TRUTH,
            Message::NavigationError(_) => NAVIGATION_ERROR,
            Message::Measurement(_) => MEASUREMENT,
            Message::Estimate(_) => ESTIMATE,
            Message::NominalTranslational(_) => NOMINAL_TRANSLATIONAL,
            Message::NominalAttitude(_) => NOMINAL_ATTITUDE,
            Message::NominalRobotic(_) => NOMINAL_ROBOTIC,
            Message::SafeTranslational(_) => SAFE_TRANSLATIONAL,
            Message::SafeAttitude(_) => SAFE_ATTITUDE,
            Message::SafeRobotic(_) => SAFE_ROBOTIC,
            Message::StepResult(_) => STEP_RESULT,
            Message::Health(_) => HEALTH,
        }
    }

    /// Stamps the message's publish time [monotonic ns] (the runner, just before it
    /// sends; messages without a publish stamp are left as they are).
    pub fn stamp_publish(&mut self, ns: u64) {
        match self {
            Message::Tick(m) | Message::Control(m) => m.send_ns = ns,
            Message::State(m) | Message::PartnerState(m) | Message::Truth(m) => m.publish_ns = ns,
            Message::NavigationError(_) => {}
            Message::Measurement(m) | Message::Estimate(m) => m.publish_ns = ns,
            Message::NominalTranslational(m) => m.publish_ns = ns,
            Message::NominalAttitude(m) => m.publish_ns = ns,
            Message::NominalRobotic(m) => m.publish_ns = ns,
            Message::SafeTranslational(m) => m.publish_ns = ns,
            Message::SafeAttitude(m) => m.publish_ns = ns,
            Message::SafeRobotic(m) => m.publish_ns = ns,
            Message::StepResult(m) => m.publish_ns = ns,
            Message::Health(m) => m.publish_ns = ns,
        }
    }
}

/// Why the runner handed over a wake-up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Woke {
    /// An input of the wake set fired.
    Event,
    /// The deadline (or the 1 s re-check) passed without an event.
    Timeout,
    /// A wake set was attached for the first time: no wait, so that what arrived
    /// before its listeners existed is read now.
    Attached,
}

/// One wake-up: the time, why, and the payload-less signals that came.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Wakeup {
    /// Monotonic clock after the inputs were drained [ns] (the machine's
    /// `CLOCK_MONOTONIC`, shared by all processes: `sc_icd::monotonic_ns`).
    pub now_ns: u64,
    pub why: Woke,
    /// Stage-deadline watchdog signals since the last wake-up.
    pub stage_deadline: u64,
    /// Pre-tick warm-up signals since the last wake-up.
    pub prepare: u64,
}

/// How the runner continues after a wake-up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Next {
    /// Sleep on wake set `set` ([`Component::wake_sets`]) until an input fires or
    /// `until_ns` [monotonic ns] passes (`None`: re-check after at most 1 s).
    Wait { set: usize, until_ns: Option<u64> },
    /// The role is done: the runner calls [`Component::finish`] and exits.
    Exit,
}

/// The inputs that wake a role when it sleeps on them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WakeSet {
    /// Services (pub/sub or signals) whose events wake.
    pub on: &'static [ServiceName],
    /// Listeners created only when the set is first used (a role's degraded wake-ups:
    /// every listener costs each publisher's notify on the critical path).
    pub lazy: bool,
}

/// What a component asks the runner to do.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Outbox {
    /// Messages to publish, in order (the runner stamps their publish time).
    pub send: Vec<Message>,
    /// Services to notify without a sample (signals; a publisher's wake-up of its
    /// subscribers so that they see the stop).
    pub notify: Vec<ServiceName>,
    /// Lines for the role's log (stderr).
    pub log: Vec<String>,
    /// Files to write into the run's output folder (name, contents).
    pub files: Vec<(String, Vec<u8>)>,
    /// Rehearse now ([`Component::rehearse`]): the pre-tick warm-up.
    pub rehearse: bool,
}

impl Outbox {
    /// Queues a message.
    pub fn send(&mut self, m: Message) {
        self.send.push(m);
    }

    /// Queues a log line.
    pub fn log(&mut self, line: impl Into<String>) {
        self.log.push(line.into());
    }
}

/// A peer that died, as the liveness check reports it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LostPeer {
    pub name: String,
    pub pid: i32,
}

/// What a component may ask of the world synchronously (only the scheduler does).
pub trait Env {
    /// Peers found dead since the last call (each reported once).
    fn lost_peers(&mut self) -> Vec<LostPeer>;
}

/// An [`Env`] with no peers (roles that do not watch any, and tests).
#[derive(Debug, Default)]
pub struct NoPeers;

impl Env for NoPeers {
    fn lost_peers(&mut self) -> Vec<LostPeer> {
        Vec::new()
    }
}

/// How a run ends for a role.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Finish {
    /// The component asked to exit ([`Next::Exit`]).
    Done,
    /// SIGINT/SIGTERM arrived while it slept.
    Terminated,
}

/// A role: its inputs, its decisions, its outputs.
pub trait Component {
    /// The wake sets it sleeps on ([`Next::Wait::set`] indexes them). Set 0 is
    /// attached before the start-up handshake.
    fn wake_sets(&self) -> &'static [WakeSet];

    /// Every service it subscribes to, in the order the runner drains them at each
    /// wake-up (the role's read order), signals included.
    fn inputs(&self) -> &'static [ServiceName];

    /// Publishers whose memory the pre-tick warm-up touches.
    fn warm(&self) -> &'static [ServiceName] {
        &[]
    }

    /// How to sleep next, at monotonic time `now_ns`.
    fn next(&mut self, now_ns: u64) -> Next;

    /// Everything that arrived (in [`Self::inputs`] order) at one wake-up.
    fn handle(&mut self, w: &Wakeup, inputs: &[Message], env: &mut dyn Env, out: &mut Outbox);

    /// The pre-tick warm-up: the role's step on its latest inputs, output dropped.
    fn rehearse(&mut self) {}

    /// The run ends: final words and files; returns the process's exit code.
    /// `impostors`: per input service, the samples its subscriber dropped because they
    /// came from a second publisher (docs/PARTITION.md, "Threat model").
    fn finish(&mut self, why: Finish, impostors: &[(ServiceName, u64)], out: &mut Outbox) -> i32;
}
