//! Service names of the partition. Every pub/sub service has an event service of
//! the same name next to it (publish, then notify); see `docs/ICD.md`.
//!
//! The names are relative: sc-bus isolates runs by the iceoryx2 `global.prefix`,
//! not by the service name, so the same names are used in every run.

/// A service name plus the message type it carries (checked at compile time by sc-bus).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServiceName(pub &'static str);

impl ServiceName {
    /// The name as a string.
    pub const fn as_str(&self) -> &'static str {
        self.0
    }
}

impl core::fmt::Display for ServiceName {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.0)
    }
}

/// [`crate::Tick`] of the main rate group. Publisher: scheduler. Subscribers: simulator, recorder.
pub const TICK: ServiceName = ServiceName("safe_capture/scheduler/tick");
/// [`crate::Tick`] commands to every other process; today only the stop (`command ==
/// tick_command::STOP`), sent with the stop tick. Publisher: scheduler. Subscribers:
/// nominal controllers, safety filters (read at every wake-up, no listener). Kept apart
/// from [`TICK`] so that a tick is delivered to the two processes that need it, not
/// to all eight: each subscriber costs the scheduler's send, on the critical path.
pub const CONTROL: ServiceName = ServiceName("safe_capture/scheduler/control");
/// [`crate::SimState`]. Publisher: simulator. Subscribers: the three safety filters,
/// recorder (the flight side: lossless).
pub const SIM_STATE: ServiceName = ServiceName("safe_capture/sim/state");
/// The same [`crate::SimState`] for the nominal controllers — the processes partners
/// replace — on a newest-wins service: a partner that stops reading loses only its own
/// states and can never make the simulator wait. Publisher: simulator (just after
/// [`SIM_STATE`]: so the filters always have the state before any command answering it).
/// Subscribers: the three nominal controllers (woken by it).
pub const PARTNER_STATE: ServiceName = ServiceName("safe_capture/partner/state");
/// [`crate::NominalTranslational`]. Publisher: nominal translational controller.
/// Subscribers: translational safety filter, recorder.
pub const NOMINAL_TRANSLATIONAL: ServiceName = ServiceName("safe_capture/nominal/translational");
/// [`crate::NominalAttitude`]. Publisher: nominal attitude controller.
/// Subscribers: attitude safety filter, recorder.
pub const NOMINAL_ATTITUDE: ServiceName = ServiceName("safe_capture/nominal/attitude");
/// [`crate::NominalRobotic`]. Publisher: nominal robotic controller.
/// Subscribers: robotic safety filter, recorder.
pub const NOMINAL_ROBOTIC: ServiceName = ServiceName("safe_capture/nominal/robotic");
/// [`crate::SafeTranslational`]. Publisher: translational safety filter.
/// Subscribers: attitude safety filter (woken by it: causal order), robotic safety
/// filter (ξ), simulator, recorder.
pub const SAFE_TRANSLATIONAL: ServiceName = ServiceName("safe_capture/safe/translational");
/// [`crate::SafeAttitude`]. Publisher: attitude safety filter.
/// Subscribers: robotic safety filter (woken by it: causal order), simulator, recorder.
pub const SAFE_ATTITUDE: ServiceName = ServiceName("safe_capture/safe/attitude");
/// [`crate::SafeRobotic`]. Publisher: robotic safety filter.
/// Subscribers: simulator (woken by it: closes the step), recorder.
pub const SAFE_ROBOTIC: ServiceName = ServiceName("safe_capture/safe/robotic");
/// [`crate::StepResult`]. Publisher: simulator. Subscribers: scheduler (step completion), recorder.
pub const STEP_RESULT: ServiceName = ServiceName("safe_capture/sim/step_result");
/// [`crate::Health`]. Publisher: recorder (its progress: `last_tick` = the newest step
/// result it took). Subscriber: scheduler (lock-step flow control: it stays at most
/// `recorder_window_ticks` ticks ahead of the recorder).
pub const HEALTH: ServiceName = ServiceName("safe_capture/health");
/// Stage-deadline watchdog (event service, no payload). Notifier: scheduler, when a
/// stage deadline of `[deadlines]` passed (counted from the tick) and the tick is
/// unfinished. Listeners: the three safety filters, which wake on their nominal and
/// upstream commands only, never on every state, and need this wake-up to apply
/// their fallback to a tick whose nominal or upstream command is late.
pub const STAGE_DEADLINE: ServiceName = ServiceName("safe_capture/scheduler/deadline");
/// Pre-tick warm-up (event service, no payload), real-time mode only. Notifier:
/// scheduler, `warmup_lead_us` before each tick. Listeners: the simulator, the
/// nominal controllers and the safety filters, which rehearse their step on their
/// latest inputs (nothing is published) so that the tick finds their code and data
/// in the caches instead of cold after a period asleep.
pub const PREPARE: ServiceName = ServiceName("safe_capture/scheduler/prepare");
/// Start-up handshake (event services `<HANDSHAKE>/ready` and `<HANDSHAKE>/go`, no payload).
/// Participants notify `ready` with their role id + 1; the coordinator (scheduler)
/// notifies `go` once all expected participants were seen.
pub const HANDSHAKE: ServiceName = ServiceName("safe_capture/handshake");

/// All pub/sub services with their iceoryx2 type names, for tools and docs.
pub const ALL: &[(ServiceName, &str)] = &[
    (TICK, "safe_capture::v2::Tick"),
    (CONTROL, "safe_capture::v2::Tick"),
    (SIM_STATE, "safe_capture::v3::SimState"),
    (PARTNER_STATE, "safe_capture::v3::SimState"),
    (
        NOMINAL_TRANSLATIONAL,
        "safe_capture::v2::NominalTranslational",
    ),
    (NOMINAL_ATTITUDE, "safe_capture::v2::NominalAttitude"),
    (NOMINAL_ROBOTIC, "safe_capture::v2::NominalRobotic"),
    (SAFE_TRANSLATIONAL, "safe_capture::v2::SafeTranslational"),
    (SAFE_ATTITUDE, "safe_capture::v2::SafeAttitude"),
    (SAFE_ROBOTIC, "safe_capture::v2::SafeRobotic"),
    (STEP_RESULT, "safe_capture::v1::StepResult"),
    (HEALTH, "safe_capture::v1::Health"),
];
