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

icd_services! {
    pubsub {
        /// The ticks of the main rate group: each starts one control step (the simulator
        /// wakes on it), the last one (`command = tick_command::STOP`) ends the run.
        TICK = "safe_capture/scheduler/tick", Tick, Flight;
        /// Tick commands to every other process; today only the stop, sent with the stop
        /// tick (read at every wake-up, no listener). Kept apart from `TICK` so that a
        /// tick is delivered to the two processes that need it, not to all nine: each
        /// subscriber costs the scheduler's send, on the critical path.
        CONTROL = "safe_capture/scheduler/control", Tick, Flight;
        /// What the sensors measured at the start of each step, for the navigation (the
        /// process partners replace): the true state the sensors' measurement age old
        /// (`measurement_age_s` of the truth's bounds), on a newest-wins service (a navigation that stops reading can never make
        /// the simulator wait). Published when the tick starts (after the truth, with a
        /// declared uncertainty).
        MEASUREMENT = "safe_capture/sim/measurement", NavState, Partner;
        /// The navigation's estimate of the tick's state; the simulator wakes on it,
        /// admits it (or substitutes its own navigation, flagged) and publishes the
        /// knowledge derived from it as `SIM_STATE` and `PARTNER_STATE`.
        ESTIMATE = "safe_capture/navigation/estimate", NavState, Partner;
        /// The state at the start of each step, for the flight side (lossless): the
        /// admitted estimate seen through the declared model (what the controllers and
        /// filters know; the truth for the `exact` profile), its `barriers` those on
        /// knowledge.
        SIM_STATE = "safe_capture/sim/state", SimState, Flight;
        /// The same state for the nominal controllers — the processes partners replace,
        /// woken by it — on a newest-wins service: a partner that stops reading loses
        /// only its own states and can never make the simulator wait. Published just
        /// after `SIM_STATE`, so the filters always have the state before any command
        /// answering it.
        PARTNER_STATE = "safe_capture/partner/state", SimState, Partner;
        /// The true state at the start of each step, for the recorder, with a declared
        /// `[uncertainty]` only: `SIM_STATE` then carries the navigation's estimate (what
        /// the controllers and filters know), this one the truth with the monitored
        /// barriers. Published before `SIM_STATE`.
        TRUTH = "safe_capture/sim/truth", SimState, Flight;
        /// The realised navigation errors of each step's estimate, for the recorder, with a
        /// declared `[uncertainty]` only. Published with `TRUTH`.
        NAVIGATION_ERROR = "safe_capture/sim/navigation_error", NavigationError, Flight;
        /// The nominal translational command; the translational safety filter wakes on it.
        NOMINAL_TRANSLATIONAL = "safe_capture/nominal/translational", NominalTranslational, Partner;
        /// The nominal attitude command; the attitude safety filter wakes on it.
        NOMINAL_ATTITUDE = "safe_capture/nominal/attitude", NominalAttitude, Partner;
        /// The nominal robotic command; the robotic safety filter wakes on it.
        NOMINAL_ROBOTIC = "safe_capture/nominal/robotic", NominalRobotic, Partner;
        /// The translational safe command and filter report; the attitude safety filter
        /// wakes on it (causal order), the robotic one takes it as ξ.
        SAFE_TRANSLATIONAL = "safe_capture/safe/translational", SafeTranslational, Flight;
        /// The attitude safe command and filter report; the robotic safety filter wakes on
        /// it (causal order).
        SAFE_ATTITUDE = "safe_capture/safe/attitude", SafeAttitude, Flight;
        /// The robotic safe command and filter report; the simulator wakes on it (it
        /// closes the step).
        SAFE_ROBOTIC = "safe_capture/safe/robotic", SafeRobotic, Flight;
        /// The applied command and the end of each step; the scheduler (step completion)
        /// and the recorder wake on it.
        STEP_RESULT = "safe_capture/sim/step_result", StepResult, Flight;
        /// The recorder's progress (`last_tick` = the newest step result it took): the
        /// scheduler's lock-step flow control keeps it at most `recorder_window_ticks`
        /// ticks ahead of the recorder.
        HEALTH = "safe_capture/health", Health, Flight;
    }
    events {
        /// Stage-deadline watchdog (no payload): notified when a stage deadline of
        /// `[deadlines]` passed (counted from the tick) and the tick is unfinished. The
        /// safety filters wake on their nominal and upstream commands only, never on every
        /// state, and need this wake-up to apply their fallback to a tick whose nominal or
        /// upstream command is late.
        STAGE_DEADLINE = "safe_capture/scheduler/deadline", [];
        /// Pre-tick warm-up (no payload), real-time mode only: notified `warmup_lead_us`
        /// before each tick; the listeners rehearse their step on their latest inputs
        /// (nothing is published) so that the tick finds their code and data in the
        /// caches instead of cold after a period asleep (optional for a third-party process).
        PREPARE = "safe_capture/scheduler/prepare", [];
        /// Start-up handshake (event services `<HANDSHAKE>/ready` and `<HANDSHAKE>/go`, no
        /// payload): participants notify `ready` with `events::HANDSHAKE_ID_OFFSET` + their
        /// role id; the coordinator (scheduler) notifies `go` once all expected
        /// participants were seen.
        HANDSHAKE = "safe_capture/handshake", ["ready", "go"];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn services_carry_their_messages() {
        let by = |c: &str| SERVICES.iter().find(|s| s.constant == c).unwrap();
        assert_eq!(by("SIM_STATE").name, SIM_STATE);
        assert_eq!(
            by("PARTNER_STATE").message.unwrap().type_name,
            "safe_capture::v5::SimState"
        );
        assert_eq!(by("HANDSHAKE").sub_services, ["ready", "go"]);
        assert!(by("PREPARE").message.is_none());
        let mut names: Vec<&str> = SERVICES.iter().map(|s| s.name.as_str()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), SERVICES.len(), "service names are unique");
        // every message type travels on some service
        for m in crate::MESSAGES {
            assert!(
                SERVICES.iter().any(|s| s.message == Some(m)),
                "{} has no service",
                m.name
            );
        }
    }
}
