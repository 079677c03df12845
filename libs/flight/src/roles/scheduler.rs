//! The scheduler: ticks by rate group (lock-step or paced in real time), the stage
//! deadlines' watchdog, the end of the run, the liveness of the peers.
//!
//! One tick: in real time, wait for the slot (signalling the pre-tick warm-up
//! `warmup_lead_us` before it); in lock-step, stay at most `recorder_window_ticks` ahead
//! of the recorder (flow control: its queues never fill); send the tick; wait for its
//! step result, waking the filters at each stage deadline that passes with the tick
//! unfinished. A peer that dies is a fault; the simulator's or the recorder's ends the
//! run. The start-up handshake is the runner's (the scheduler is its coordinator).

use crate::component::{Component, Env, Finish, Message, Next, Outbox, WakeSet, Wakeup, Woke};
use crate::config::{ClockMode, PartitionConfig, Schedule};
use crate::error::FlightError;
use crate::process::{Proc, warmup_enabled};
use sc_core::Subsystem;
use sc_icd::services::{self, ServiceName};
use sc_icd::{Role, RoleKind, StepResult, Tick, clock_mode, end, tick_command};
use std::time::Duration;

/// Statistics the scheduler writes to `scheduler.json`.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct SchedulerReport {
    pub clock: String,
    pub base_period_s: f64,
    pub ticks: u64,
    pub cycle_slips: u64,
    /// Stage deadlines that passed with the tick unfinished (each woke the filters).
    #[serde(default)]
    pub watchdog_wakeups: u64,
    pub end: String,
    pub lost_peers: Vec<String>,
    pub aborted: bool,
    pub wall_s: f64,
}

/// The timing of the schedule [ns] and its options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    pub schedule: Schedule,
    pub real_time: bool,
    pub period_ns: u64,
    /// The pre-tick warm-up's lead (real time, `warmup_lead_us > 0`).
    pub warmup_lead_ns: Option<u64>,
    /// Stage deadlines of the three filters, from the tick.
    pub stage_deadline_ns: [u64; 3],
    /// How long a tick may go without its step result before it is a fault.
    pub step_timeout_ns: u64,
    /// Lock-step flow control: ticks the scheduler may be ahead of the recorder.
    pub recorder_window: u64,
    /// Stop after this many ticks (0: at the mission's end).
    pub max_ticks: u64,
}

fn ns(d: Duration) -> u64 {
    d.as_nanos().min(u128::from(u64::MAX)) as u64
}

/// Lost-step-result faults end the run after this many step timeouts.
const STEP_TIMEOUTS_TO_ABORT: u64 = 5;
/// Liveness is checked when a wait has lasted this long, and every this many ticks.
const LIVENESS_AFTER_NS: u64 = 1_000_000_000;
const LIVENESS_EVERY_TICKS: u64 = 50;
/// The step timeout: this many simulator deadlines plus a grace.
const STEP_TIMEOUT_DEADLINES: u32 = 3;
const STEP_TIMEOUT_GRACE: Duration = Duration::from_secs(2);

impl Timing {
    /// From the partition config in its clock mode.
    pub fn from_config(cfg: &PartitionConfig, schedule: Schedule) -> Self {
        let deadline = |ms| Duration::from_secs_f64(cfg.deadline_s(ms));
        let real_time = cfg.clock == ClockMode::RealTime;
        Self {
            schedule,
            real_time,
            period_ns: ns(Duration::from_secs_f64(schedule.base_period_s)),
            warmup_lead_ns: warmup_enabled(cfg)
                .then(|| ns(Duration::from_micros(u64::from(cfg.warmup_lead_us)))),
            stage_deadline_ns: Subsystem::ALL.map(|s| ns(deadline(cfg.deadlines.filter_ms(s)))),
            step_timeout_ns: ns(
                deadline(cfg.deadlines.simulator_ms) * STEP_TIMEOUT_DEADLINES + STEP_TIMEOUT_GRACE,
            ),
            recorder_window: cfg.lock_step.recorder_window_ticks,
            max_ticks: cfg.max_ticks,
        }
    }
}

/// Where the scheduler is in a tick.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Not started: the first wake-up starts the clock.
    Init,
    /// At the top of a tick.
    Top,
    /// Real time: waiting until the warm-up signal at `at_ns`, then the tick at `target_ns`.
    Warmup { at_ns: u64, target_ns: u64 },
    /// Real time: waiting for the tick's slot.
    Pace { target_ns: u64 },
    /// Lock-step flow control: waiting for the recorder since `since_ns`.
    Flow { since_ns: u64, waited: bool },
    /// Waiting for the step result of the tick sent at `sent_ns`.
    Await {
        sent_ns: u64,
        next_stage: usize,
        done: Option<StepResult>,
    },
    /// The run is over.
    Done,
}

/// The wake sets: the step results; the recorder's progress (lock-step flow control).
const RESULTS: usize = 0;
const RECORDER: usize = 1;
const WAKE: &[WakeSet] = &[
    WakeSet {
        on: &[services::STEP_RESULT],
        lazy: false,
    },
    WakeSet {
        on: &[services::HEALTH],
        lazy: true,
    },
];

/// The scheduler role.
pub struct SchedulerRole {
    timing: Timing,
    phase: Phase,
    started_ns: u64,
    /// The time of the latest wake-up [monotonic ns].
    now_ns: u64,
    /// The tick being run (its index).
    k: u64,
    /// Real-time slots passed.
    slot: u64,
    /// Step results the recorder has taken.
    recorder_taken: u64,
    code: i32,
    rep: SchedulerReport,
}

impl SchedulerRole {
    pub fn new(timing: Timing, clock: &str) -> Self {
        Self {
            timing,
            phase: Phase::Init,
            started_ns: 0,
            now_ns: 0,
            k: 0,
            slot: 0,
            recorder_taken: 0,
            code: 0,
            rep: SchedulerReport {
                clock: clock.into(),
                base_period_s: timing.schedule.base_period_s,
                ..Default::default()
            },
        }
    }

    pub fn from_process(p: &Proc) -> Result<Self, FlightError> {
        let timing = Timing::from_config(&p.cfg, p.schedule);
        Ok(Self::new(timing, &format!("{:?}", p.cfg.clock)))
    }

    /// The scheduler's report so far.
    pub fn report(&self) -> &SchedulerReport {
        &self.rep
    }

    /// Polls the peers; true if one the run cannot go on without died.
    fn lost_essential(&mut self, env: &mut dyn Env, out: &mut Outbox) -> bool {
        let essential = [
            Role::of(RoleKind::Simulator).name,
            Role::of(RoleKind::Recorder).name,
        ];
        let mut fatal = false;
        for lost in env.lost_peers() {
            out.log(format!(
                "scheduler: FAULT peer `{}` (pid {}) died",
                lost.name, lost.pid
            ));
            fatal |= essential.contains(&lost.name.as_str());
            self.rep.lost_peers.push(lost.name);
        }
        fatal
    }

    fn abort(&mut self) {
        self.code = 3;
        self.rep.aborted = true;
        self.phase = Phase::Done;
    }

    /// The top of a tick: the end of the run, or the pacing of its start.
    fn top(&mut self, now_ns: u64) {
        if self.timing.max_ticks > 0 && self.k >= self.timing.max_ticks {
            self.rep.end = "max_ticks".into();
            self.phase = Phase::Done;
            return;
        }
        if !self.timing.real_time {
            self.phase = Phase::Flow {
                since_ns: now_ns,
                waited: false,
            };
            return;
        }
        let target_ns = self.started_ns + self.timing.period_ns * self.slot;
        self.phase = match self.timing.warmup_lead_ns {
            Some(lead) if now_ns < target_ns.saturating_sub(lead) => Phase::Warmup {
                at_ns: target_ns.saturating_sub(lead),
                target_ns,
            },
            _ => Phase::Pace { target_ns },
        };
    }

    /// Sends tick `k`.
    fn send_tick(&mut self, now_ns: u64, out: &mut Outbox) {
        let k = self.k;
        out.send(Message::Tick(Tick {
            tick: k,
            due_mask: self.timing.schedule.due_mask(k),
            clock_mode: if self.timing.real_time {
                clock_mode::REAL_TIME
            } else {
                clock_mode::LOCK_STEP
            },
            t: k as f64 * self.timing.schedule.base_period_s,
            send_ns: 0,
            command: tick_command::STEP,
            _pad0: 0,
        }));
        self.phase = Phase::Await {
            sent_ns: now_ns,
            next_stage: 0,
            done: None,
        };
    }

    /// Lock-step flow control: the tick goes out once the recorder is close enough.
    fn flow(
        &mut self,
        w: &Wakeup,
        since_ns: u64,
        waited: bool,
        env: &mut dyn Env,
        out: &mut Outbox,
    ) {
        let waited_ns = w.now_ns.saturating_sub(since_ns);
        if waited && waited_ns > LIVENESS_AFTER_NS && self.lost_essential(env, out) {
            return self.abort();
        }
        if waited && waited_ns > self.timing.step_timeout_ns * STEP_TIMEOUTS_TO_ABORT {
            out.log(format!(
                "scheduler: FAULT the recorder took no step result for {:?} (at tick {} of {})",
                Duration::from_nanos(waited_ns),
                self.recorder_taken,
                self.k
            ));
            return self.abort();
        }
        if self.timing.real_time || self.recorder_taken + self.timing.recorder_window >= self.k {
            self.send_tick(w.now_ns, out);
        }
    }

    /// The deadline of the tick in progress: its slot (real time) or the step timeout.
    fn await_until(&self, sent_ns: u64) -> u64 {
        if self.timing.real_time {
            self.started_ns + self.timing.period_ns * self.slot
        } else {
            sent_ns + self.timing.step_timeout_ns
        }
    }

    /// The step result of the tick in progress came: the end of the run, or the next tick.
    fn step_done(&mut self, r: &StepResult, env: &mut dyn Env, out: &mut Outbox) {
        if r.end == end::SIMULATOR_FAILED || (r.end != end::RUNNING && self.timing.max_ticks == 0) {
            self.rep.end = match r.end {
                end::CAPTURED => "captured",
                end::TIMEOUT => "timeout",
                _ => "simulator_failed",
            }
            .into();
        }
        self.k += 1;
        self.rep.ticks = self.k;
        let running = self.rep.end.is_empty();
        self.phase = if running { Phase::Top } else { Phase::Done };
        if self.k.is_multiple_of(LIVENESS_EVERY_TICKS) && self.lost_essential(env, out) {
            self.abort();
        }
    }

    /// Waiting for the step result: the stage deadlines' watchdog, the result, faults.
    fn await_result(
        &mut self,
        w: &Wakeup,
        sent_ns: u64,
        mut next_stage: usize,
        done: Option<StepResult>,
        env: &mut dyn Env,
        out: &mut Outbox,
    ) {
        let elapsed = w.now_ns.saturating_sub(sent_ns);
        while done.is_none()
            && self
                .timing
                .stage_deadline_ns
                .get(next_stage)
                .is_some_and(|d| elapsed >= *d)
        {
            out.notify.push(services::STAGE_DEADLINE);
            self.rep.watchdog_wakeups += 1;
            next_stage += 1;
        }
        if let Some(r) = done {
            return self.step_done(&r, env, out);
        }
        self.phase = Phase::Await {
            sent_ns,
            next_stage,
            done: None,
        };
        if elapsed > LIVENESS_AFTER_NS && self.lost_essential(env, out) {
            // the simulator or the recorder died: the run cannot go on
            return self.abort();
        }
        if w.now_ns < self.await_until(sent_ns) {
            return;
        }
        if self.timing.real_time {
            // the next tick is due while this one is unfinished: a cycle slip
            self.rep.cycle_slips += 1;
            self.slot += 1;
            if self.lost_essential(env, out) {
                return self.abort();
            }
            if elapsed < self.timing.step_timeout_ns {
                return;
            }
        }
        out.log(format!(
            "scheduler: FAULT no step result for tick {} within {:?}",
            self.k,
            Duration::from_nanos(elapsed)
        ));
        if self.lost_essential(env, out)
            || elapsed > self.timing.step_timeout_ns * STEP_TIMEOUTS_TO_ABORT
        {
            self.abort();
        }
    }

    /// Moves through the phases until one must wait.
    fn advance(&mut self, w: &Wakeup, env: &mut dyn Env, out: &mut Outbox) {
        loop {
            let before = self.phase;
            match self.phase {
                Phase::Init => {
                    self.started_ns = w.now_ns;
                    self.phase = Phase::Top;
                }
                Phase::Top => self.top(w.now_ns),
                Phase::Warmup { at_ns, target_ns } if w.now_ns >= at_ns => {
                    out.notify.push(services::PREPARE);
                    self.phase = Phase::Pace { target_ns };
                }
                Phase::Pace { target_ns } if w.now_ns >= target_ns => {
                    self.slot += 1;
                    self.phase = Phase::Flow {
                        since_ns: w.now_ns,
                        waited: false,
                    };
                }
                Phase::Flow { since_ns, waited } => self.flow(w, since_ns, waited, env, out),
                Phase::Await {
                    sent_ns,
                    next_stage,
                    done,
                } => {
                    self.await_result(w, sent_ns, next_stage, done, env, out);
                    // a result handled moves on at once; waiting needs a wake-up first
                    if matches!(self.phase, Phase::Await { .. }) {
                        return;
                    }
                }
                Phase::Warmup { .. } | Phase::Pace { .. } | Phase::Done => return,
            }
            if self.phase == before || matches!(self.phase, Phase::Await { .. }) {
                return;
            }
        }
    }
}

impl Component for SchedulerRole {
    fn wake_sets(&self) -> &'static [WakeSet] {
        WAKE
    }

    fn inputs(&self) -> &'static [ServiceName] {
        &[services::STEP_RESULT, services::HEALTH]
    }

    fn next(&mut self, now_ns: u64) -> Next {
        let wait = |set, until| Next::Wait {
            set,
            until_ns: Some(until),
        };
        match &mut self.phase {
            Phase::Init | Phase::Top => wait(RESULTS, now_ns),
            Phase::Warmup { at_ns, .. } => wait(RESULTS, *at_ns),
            Phase::Pace { target_ns } => wait(RESULTS, *target_ns),
            Phase::Flow { waited, .. } => {
                *waited = true;
                wait(RECORDER, now_ns + LIVENESS_AFTER_NS)
            }
            Phase::Await {
                sent_ns,
                next_stage,
                ..
            } => {
                let (sent, stage) = (*sent_ns, *next_stage);
                let until = self.await_until(sent);
                let wake = match self.timing.stage_deadline_ns.get(stage) {
                    Some(d) => until.min(sent + d),
                    None => until,
                };
                // past the step timeout in lock-step: look again once a second (each
                // look logs the fault) rather than at once
                let wake = if wake <= now_ns && !self.timing.real_time {
                    now_ns + LIVENESS_AFTER_NS
                } else {
                    wake
                };
                wait(RESULTS, wake)
            }
            Phase::Done => Next::Exit,
        }
    }

    fn handle(&mut self, w: &Wakeup, inputs: &[Message], env: &mut dyn Env, out: &mut Outbox) {
        self.now_ns = w.now_ns;
        let recorder = Role::of(RoleKind::Recorder).id();
        for m in inputs {
            match m {
                Message::Health(h) if h.role == recorder => {
                    self.recorder_taken = self.recorder_taken.max(h.last_tick + 1);
                }
                Message::StepResult(r) if r.tick == self.k => {
                    if let Phase::Await { done, .. } = &mut self.phase {
                        *done = Some(*r);
                    }
                }
                _ => {}
            }
        }
        if w.why == Woke::Attached && matches!(self.phase, Phase::Flow { .. }) {
            // the recorder's listener was just created: read before waiting
            if let Phase::Flow { waited, .. } = &mut self.phase {
                *waited = false;
            }
        }
        self.advance(w, env, out);
    }

    fn finish(&mut self, why: Finish, _: &[(ServiceName, u64)], out: &mut Outbox) -> i32 {
        if why == Finish::Terminated {
            self.rep.end = "interrupted".into();
        }
        if self.rep.end.is_empty() {
            self.rep.end = "aborted".into();
        }
        self.rep.wall_s = self.now_ns.saturating_sub(self.started_ns) as f64 * 1e-9;
        let stop = Tick {
            tick: self.k,
            command: tick_command::STOP,
            ..Default::default()
        };
        // control first: the simulator wakes on the tick and wakes the others, who then
        // look for the stop on the control service, which must be there already
        out.send(Message::Control(stop));
        out.send(Message::Tick(stop));
        let r = &self.rep;
        out.log(format!(
            "scheduler: {} after {} ticks, {} cycle slips, lost peers {:?}, wall {:.2} s",
            r.end, r.ticks, r.cycle_slips, r.lost_peers, r.wall_s
        ));
        let json = serde_json::to_string_pretty(&self.rep).unwrap_or_default() + "\n";
        out.files.push(("scheduler.json".into(), json.into_bytes()));
        self.code
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::component::LostPeer;
    use sc_core::PerSubsystem;
    use sc_icd::Health;

    const PERIOD_NS: u64 = 100_000_000;

    fn timing(real_time: bool) -> Timing {
        Timing {
            schedule: Schedule {
                base_period_s: 0.1,
                period_s: PerSubsystem([0.1; 3]),
                ratio: PerSubsystem([1; 3]),
            },
            real_time,
            period_ns: PERIOD_NS,
            warmup_lead_ns: real_time.then_some(2_000_000),
            stage_deadline_ns: [40_000_000, 60_000_000, 80_000_000],
            step_timeout_ns: 3 * 90_000_000 * 20,
            recorder_window: 2,
            max_ticks: 0,
        }
    }

    /// Peers that die when the test says so.
    #[derive(Default)]
    struct Dying(Vec<LostPeer>);

    impl Env for Dying {
        fn lost_peers(&mut self) -> Vec<LostPeer> {
            std::mem::take(&mut self.0)
        }
    }

    fn wake(now: u64, why: Woke) -> Wakeup {
        crate::roles::testing::wakeup(now, why)
    }

    fn step(s: &mut SchedulerRole, now: u64, inputs: &[Message], env: &mut dyn Env) -> Outbox {
        let mut out = Outbox::default();
        s.handle(&wake(now, Woke::Event), inputs, env, &mut out);
        out
    }

    fn result(k: u64, end: u32) -> Message {
        Message::StepResult(StepResult {
            tick: k,
            end,
            ..Default::default()
        })
    }

    fn ticks(out: &Outbox) -> Vec<u64> {
        out.send
            .iter()
            .filter_map(|m| match m {
                Message::Tick(t) if t.command == tick_command::STEP => Some(t.tick),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn lock_step_sends_the_next_tick_when_the_result_comes() {
        let mut s = SchedulerRole::new(timing(false), "LockStep");
        assert_eq!(
            s.next(5),
            Next::Wait {
                set: RESULTS,
                until_ns: Some(5)
            }
        );
        let out = step(&mut s, 5, &[], &mut Dying::default());
        assert_eq!(ticks(&out), vec![0]);
        // a result for another tick does not end this one
        assert!(
            ticks(&step(
                &mut s,
                6,
                &[result(7, end::RUNNING)],
                &mut Dying::default()
            ))
            .is_empty()
        );
        assert_eq!(
            ticks(&step(
                &mut s,
                7,
                &[result(0, end::RUNNING)],
                &mut Dying::default()
            )),
            vec![1]
        );
    }

    #[test]
    fn flow_control_waits_for_the_recorder() {
        let mut s = SchedulerRole::new(timing(false), "LockStep");
        step(&mut s, 0, &[], &mut Dying::default());
        for k in 0..3 {
            step(&mut s, 1, &[result(k, end::RUNNING)], &mut Dying::default());
        }
        assert_eq!(s.k, 3);
        assert!(
            matches!(s.phase, Phase::Flow { .. }),
            "3 ticks ahead of a window of 2"
        );
        let Next::Wait { set, .. } = s.next(1) else {
            panic!()
        };
        assert_eq!(set, RECORDER);
        let health = Message::Health(Health {
            role: Role::of(RoleKind::Recorder).id(),
            last_tick: 0,
            ..Default::default()
        });
        assert_eq!(
            ticks(&step(&mut s, 2, &[health], &mut Dying::default())),
            vec![3]
        );
    }

    #[test]
    fn the_watchdog_wakes_the_filters_at_each_stage_deadline_passed() {
        let mut s = SchedulerRole::new(timing(false), "LockStep");
        step(&mut s, 0, &[], &mut Dying::default());
        assert_eq!(
            s.next(0),
            Next::Wait {
                set: RESULTS,
                until_ns: Some(40_000_000)
            }
        );
        let out = step(&mut s, 65_000_000, &[], &mut Dying::default());
        assert_eq!(out.notify, vec![services::STAGE_DEADLINE; 2]);
        assert_eq!(s.report().watchdog_wakeups, 2);
        // the result makes the last deadline moot
        let out = step(
            &mut s,
            85_000_000,
            &[result(0, end::RUNNING)],
            &mut Dying::default(),
        );
        assert!(out.notify.is_empty());
    }

    #[test]
    fn a_dead_simulator_ends_the_run_a_dead_controller_does_not() {
        let mut s = SchedulerRole::new(timing(false), "LockStep");
        step(&mut s, 0, &[], &mut Dying::default());
        let lost = |name: &str| LostPeer {
            name: name.into(),
            pid: 1,
        };
        let mut env = Dying(vec![lost("nominal_attitude")]);
        let out = step(&mut s, 2 * LIVENESS_AFTER_NS, &[], &mut env);
        assert!(out.log[0].contains("FAULT peer `nominal_attitude` (pid 1) died"));
        assert_ne!(s.phase, Phase::Done);
        let mut env = Dying(vec![lost("simulator")]);
        step(&mut s, 3 * LIVENESS_AFTER_NS, &[], &mut env);
        assert_eq!(s.next(0), Next::Exit);
        let mut out = Outbox::default();
        assert_eq!(s.finish(Finish::Done, &[], &mut out), 3);
        assert!(
            matches!(out.send[..], [Message::Control(c), Message::Tick(t)] if c.command == tick_command::STOP && t.command == tick_command::STOP),
            "{:?}",
            out.send
        );
        let json = String::from_utf8(out.files[0].1.clone()).unwrap();
        assert!(
            json.contains("\"aborted\": true") && json.contains("\"end\": \"aborted\""),
            "{json}"
        );
        assert_eq!(s.report().lost_peers, vec!["nominal_attitude", "simulator"]);
    }

    #[test]
    fn the_mission_end_and_max_ticks_stop_the_run() {
        let mut s = SchedulerRole::new(timing(false), "LockStep");
        step(&mut s, 0, &[], &mut Dying::default());
        step(
            &mut s,
            1,
            &[result(0, end::CAPTURED)],
            &mut Dying::default(),
        );
        assert_eq!(
            (s.next(1), s.report().end.as_str()),
            (Next::Exit, "captured")
        );
        let mut t = timing(false);
        t.max_ticks = 1;
        let mut s = SchedulerRole::new(t, "LockStep");
        step(&mut s, 0, &[], &mut Dying::default());
        step(&mut s, 1, &[result(0, end::RUNNING)], &mut Dying::default());
        assert_eq!(
            (s.next(1), s.report().end.as_str()),
            (Next::Exit, "max_ticks")
        );
    }

    #[test]
    fn real_time_paces_the_ticks_and_signals_the_warm_up_before_each() {
        let mut s = SchedulerRole::new(timing(true), "RealTime");
        assert_eq!(
            ticks(&step(&mut s, 0, &[], &mut Dying::default())),
            vec![0],
            "tick 0 at once"
        );
        let out = step(
            &mut s,
            10_000_000,
            &[result(0, end::RUNNING)],
            &mut Dying::default(),
        );
        assert!(out.send.is_empty());
        assert_eq!(
            s.next(10_000_000),
            Next::Wait {
                set: RESULTS,
                until_ns: Some(98_000_000)
            }
        );
        let out = step(&mut s, 98_000_000, &[], &mut Dying::default());
        assert_eq!(out.notify, vec![services::PREPARE]);
        assert_eq!(
            ticks(&step(&mut s, 100_000_000, &[], &mut Dying::default())),
            vec![1]
        );
    }

    #[test]
    fn a_tick_past_its_slot_is_a_cycle_slip() {
        let mut s = SchedulerRole::new(timing(true), "RealTime");
        step(&mut s, 0, &[], &mut Dying::default());
        step(&mut s, PERIOD_NS + 1, &[], &mut Dying::default());
        assert_eq!(s.report().cycle_slips, 1);
        assert!(
            matches!(s.phase, Phase::Await { .. }),
            "still waiting for tick 0"
        );
    }

    #[test]
    fn a_signal_names_the_run_interrupted() {
        let mut s = SchedulerRole::new(timing(false), "LockStep");
        step(&mut s, 0, &[], &mut Dying::default());
        let mut out = Outbox::default();
        assert_eq!(s.finish(Finish::Terminated, &[], &mut out), 0);
        assert_eq!(s.report().end, "interrupted");
    }
}
