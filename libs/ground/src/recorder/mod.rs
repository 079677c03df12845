//! The telemetry recorder (a ground tool, not flight software), as a component of the
//! partition's runner: it rebuilds every step's `StepRecord` from the messages and writes
//! the same telemetry.csv / timing.csv / summary.json as `safe-capture run`, plus
//! latency.csv (the stamps of every hop), recording.mcap (every message, for Foxglove)
//! and recorder.json (what it got, what was missing or late).
//!
//! It wakes only on step results: every message of a tick was sent before its step
//! result, so it drains them all then, once per tick and off the critical path. A
//! result whose tick misses a required message waits briefly (a publisher delivers to
//! its subscribers one after the other, so the simulator may have answered before the
//! same sample reached the recorder's queue). After each step it reports its progress
//! to the scheduler (lock-step flow control).

mod sink;
mod step;

pub use sink::{FileSink, RecordSink, SinkError, path_in_out};
pub use step::Tickset;

use sc_cbf::SafetyLayer;
use sc_flight::component::{Component, Env, Finish, Message, Next, Outbox, WakeSet, Wakeup};
use sc_flight::process::Proc;
use sc_icd::services::{self, ServiceName};
use sc_icd::{Health, Role, RoleKind, SimState, StepResult, end, health_state, tick_command};
use sc_mission::{MissionEnd, StepRecord, summarize};
use std::collections::{BTreeMap, BTreeSet, VecDeque};

/// Messages recorded per service, written to `recorder.json`.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct RecorderReport {
    /// Samples received per service.
    pub recorded: BTreeMap<String, u64>,
    /// Samples the schedule requires per service: one state and one step result per
    /// step, one nominal and one safe command per step in which the subsystem is due.
    pub expected: BTreeMap<String, u64>,
    /// Required samples that never reached the recorder (lost or never sent, e.g.
    /// a dead producer), per service.
    pub missing: BTreeMap<String, u64>,
    /// Required samples that reached the recorder only after their step was written
    /// (in recording.mcap, not in that step's telemetry row), per service: e.g. the
    /// nominal command of a subsystem the simulator had already put on its fallback.
    #[serde(default)]
    pub late: BTreeMap<String, u64>,
    /// Steps written to telemetry.csv.
    pub steps: u64,
    /// Steps with a subsystem on the simulator's fallback (missing safe command).
    pub fallback_steps: u64,
    /// Steps whose records carry an UPSTREAM_MISSING flag.
    pub upstream_missing_steps: u64,
    pub end: String,
}

/// The columns of latency.csv: the stamps of every hop of a tick [ns] and its masks.
pub const LATENCY_CSV_HEADER: &str = "tick,tick_send_ns,sim_recv_ns,state_publish_ns,nom_t_publish_ns,nom_a_publish_ns,nom_r_publish_ns,safe_t_recv_ns,safe_t_publish_ns,safe_a_recv_ns,safe_a_publish_ns,safe_r_recv_ns,safe_r_publish_ns,sim_safe_recv_ns,result_publish_ns,fallback_mask,held_mask,upstream_missing_mask";

/// Name of the MCAP `Metadata` record describing the run.
pub const MCAP_METADATA_NAME: &str = "safe-capture";

/// How long an incomplete step result waits for the rest of its tick [ns].
const INCOMPLETE_WAIT_NS: u64 = 200_000_000;
/// While a result waits, the recorder looks again this often [ns].
const INCOMPLETE_RECHECK_NS: u64 = 1_000_000;

const WAKE: &[WakeSet] = &[WakeSet {
    on: &[services::STEP_RESULT],
    lazy: false,
}];

/// The recorder role writing into `S`.
pub struct RecorderRole<S: RecordSink> {
    sink: S,
    layer: SafetyLayer,
    scenario: sc_scenario::Scenario,
    /// The declared model (the uncertainty summary draws the realisation from it).
    robot: std::sync::Arc<sc_multibody::Robot>,
    /// Mission time of a tick: tick × base period [ns].
    period_ns: u64,
    pid: u32,
    rep: RecorderReport,
    /// Messages by tick, until the tick's step is written.
    pending: BTreeMap<u64, Tickset>,
    /// Step results waiting for the rest of their tick, and since when.
    queued: VecDeque<StepResult>,
    queued_since_ns: Option<u64>,
    /// Held values for slower rate groups.
    held: Tickset,
    records: Vec<StepRecord>,
    end: Option<MissionEnd>,
    last_t: f64,
    /// Required (service, tick) pairs not there when their step was written.
    absent_at_write: BTreeSet<(&'static str, u64)>,
    /// The newest tick the simulator published something of (that the recorder read): a
    /// message labelled more than [`FUTURE_TICKS`] later is recorded (at that tick's time)
    /// but not filed, so that a hostile label cannot grow the recorder's memory.
    newest_tick: Option<u64>,
    started: bool,
    stop: bool,
    final_pass: bool,
    done: bool,
    error: Option<SinkError>,
}

impl<S: RecordSink> RecorderRole<S> {
    pub fn new(sink: S, setup: &sc_mission::Setup, base_period_s: f64, pid: u32) -> Self {
        Self {
            sink,
            layer: SafetyLayer::from_scenario(&setup.scenario, setup.robot.clone()),
            scenario: setup.scenario.clone(),
            robot: setup.robot.clone(),
            period_ns: (base_period_s * 1e9).round() as u64,
            pid,
            rep: RecorderReport::default(),
            pending: BTreeMap::new(),
            queued: VecDeque::new(),
            queued_since_ns: None,
            held: Tickset::default(),
            records: Vec::new(),
            end: None,
            last_t: 0.0,
            absent_at_write: BTreeSet::new(),
            newest_tick: None,
            started: false,
            stop: false,
            final_pass: false,
            done: false,
            error: None,
        }
    }

    /// The MCAP log time of tick `k`: the mission's own clock, so that a recording plays
    /// back at mission time in Foxglove (the host's clock stays in `publish_time`).
    fn mission_ns(&self, k: u64) -> u64 {
        k.saturating_mul(self.period_ns)
    }

    fn keep(&mut self, r: Result<(), SinkError>) {
        if let Err(e) = r {
            self.error.get_or_insert(e);
        }
    }

    /// Records one message as it arrives (MCAP, counts, lateness) and files it by tick.
    fn absorb(&mut self, m: &Message) {
        let svc = m.service().as_str();
        *self.rep.recorded.entry(svc.to_string()).or_default() += 1;
        match m {
            Message::StepResult(r) => return self.queued.push_back(*r),
            Message::Tick(t) => {
                self.stop |= t.command == tick_command::STOP;
                let r = self.sink.message(self.mission_ns(t.tick), m);
                return self.keep(r);
            }
            _ => {}
        }
        let Some(tick) = tick_of(m) else { return };
        let newest = self.newest_tick.unwrap_or(0);
        if from_simulator(m) {
            self.newest_tick = self.newest_tick.max(Some(tick));
        } else if tick > newest.saturating_add(FUTURE_TICKS) {
            let at = newest;
            let r = self.sink.message(self.mission_ns(at), m);
            return self.keep(r);
        }
        if self.absent_at_write.remove(&(svc, tick)) {
            *self.rep.late.entry(svc.into()).or_default() += 1;
        }
        let r = self.sink.message(self.mission_ns(tick), m);
        self.keep(r);
        file(self.pending.entry(tick).or_default(), m);
    }

    /// The queued step results that may be written now: complete, waited long enough,
    /// or the run is stopping.
    fn ready(&mut self, now_ns: u64) -> Vec<StepResult> {
        let mut results = Vec::new();
        while let Some(r) = self.queued.front().copied() {
            let complete = self
                .pending
                .get(&r.tick)
                .is_some_and(|set| set.complete(&r, self.scenario.uncertainty.is_some()));
            let waited = self
                .queued_since_ns
                .is_some_and(|t| now_ns.saturating_sub(t) > INCOMPLETE_WAIT_NS);
            if complete || waited || self.stop || self.final_pass {
                results.push(r);
                self.queued.pop_front();
                self.queued_since_ns = None;
            } else {
                self.queued_since_ns.get_or_insert(now_ns);
                break;
            }
        }
        results
    }

    /// Counts what the schedule required of tick `r.tick` and notes what was absent.
    fn account(&mut self, r: &StepResult, state: &SimState, set: &Tickset) {
        use sc_core::Subsystem::{Attitude, Robotic, Translational};
        let required = [
            (services::SIM_STATE, None, true),
            (services::STEP_RESULT, None, true),
            (
                services::NOMINAL_TRANSLATIONAL,
                Some(Translational),
                set.nt.is_some(),
            ),
            (services::NOMINAL_ATTITUDE, Some(Attitude), set.na.is_some()),
            (services::NOMINAL_ROBOTIC, Some(Robotic), set.nr.is_some()),
            (
                services::SAFE_TRANSLATIONAL,
                Some(Translational),
                set.st.is_some(),
            ),
            (services::SAFE_ATTITUDE, Some(Attitude), set.sa.is_some()),
            (services::SAFE_ROBOTIC, Some(Robotic), set.sr.is_some()),
        ];
        // with a declared uncertainty the truth and the navigation errors too
        let knowledge = [
            (services::TRUTH, None, set.truth.is_some()),
            (services::NAVIGATION_ERROR, None, set.navigation.is_some()),
        ];
        let declared = self.scenario.uncertainty.is_some();
        let required = required
            .into_iter()
            .chain(knowledge.into_iter().filter(|_| declared));
        for (svc, s, present) in required {
            if s.is_none_or(|s| state.due_mask & s.bit() != 0) {
                *self.rep.expected.entry(svc.as_str().into()).or_default() += 1;
                self.rep.missing.entry(svc.as_str().into()).or_default();
                if !present {
                    self.absent_at_write.insert((svc.as_str(), r.tick));
                }
            }
        }
    }

    /// Writes the step of result `r`, reports progress to the scheduler.
    fn write_step(&mut self, r: StepResult, out: &mut Outbox) {
        let res = self
            .sink
            .message(self.mission_ns(r.tick), &Message::StepResult(r));
        self.keep(res);
        let set = self.pending.remove(&r.tick).unwrap_or_default();
        // this step is taken care of (written below, or skipped and reported)
        out.send(Message::Health(self.progress(&r)));
        // drop anything older (late messages of steps already written)
        self.pending.retain(|k, _| *k > r.tick);
        let Some(state) = set.state else {
            out.log(format!(
                "recorder: FAULT tick {}: no state recorded, step skipped",
                r.tick
            ));
            return;
        };
        self.account(&r, &state, &set);
        let rec = step::record(
            &mut self.layer,
            &self.scenario,
            &r,
            &state,
            &set,
            &mut self.held,
        );
        let missing = step::upstream_missing_mask(&rec);
        let res = self
            .sink
            .step(&rec, &step::latency_line(&r, &state, &set, missing));
        self.keep(res);
        self.rep.steps += 1;
        self.rep.fallback_steps += u64::from(r.fallback_mask != 0);
        self.rep.upstream_missing_steps += u64::from(missing != 0);
        self.records.push(rec);
        self.last_t = r.t;
        // the first end counts (with max_ticks the run goes on after it)
        self.end = self.end.take().or_else(|| end_of(&r));
    }

    /// The recorder's progress for the scheduler's flow control.
    fn progress(&self, r: &StepResult) -> Health {
        Health {
            role: Role::of(RoleKind::Recorder).id(),
            pid: self.pid,
            state: health_state::RUNNING,
            last_fault_flags: 0,
            ticks_handled: self.rep.steps + 1,
            deadline_misses: 0,
            cycle_slips: 0,
            last_tick: r.tick,
            publish_ns: 0,
        }
    }
}

/// How the mission ended by step result `r`, if it did.
fn end_of(r: &StepResult) -> Option<MissionEnd> {
    match r.end {
        end::CAPTURED => Some(MissionEnd::Captured { t: r.t }),
        end::TIMEOUT => Some(MissionEnd::Timeout { t: r.t }),
        end::SIMULATOR_FAILED => Some(MissionEnd::SimulatorFailed {
            t: r.t,
            message: "simulator failed".into(),
        }),
        _ => None,
    }
}

/// The tick a message of a tick answers.
fn tick_of(m: &Message) -> Option<u64> {
    Some(match m {
        Message::State(x) | Message::Truth(x) => x.tick,
        Message::NavigationError(x) => x.tick,
        Message::Measurement(x) | Message::Estimate(x) => x.tick,
        Message::NominalTranslational(x) => x.tick,
        Message::NominalAttitude(x) => x.tick,
        Message::NominalRobotic(x) => x.tick,
        Message::SafeTranslational(x) => x.tick,
        Message::SafeAttitude(x) => x.tick,
        Message::SafeRobotic(x) => x.tick,
        _ => return None,
    })
}

/// How far ahead of the newest simulator tick read a message's tick may be and still be
/// filed: more than any queue the recorder reads holds (16 samples), so that a genuine
/// message read before its tick's state (another queue, the same wake-up) is never lost.
pub const FUTURE_TICKS: u64 = 64;

/// Published by the simulator (its tick is the run's, not a partner's label).
fn from_simulator(m: &Message) -> bool {
    matches!(
        m,
        Message::State(_)
            | Message::Truth(_)
            | Message::NavigationError(_)
            | Message::Measurement(_)
    )
}

/// Files a message of a tick into the tick's set.
fn file(set: &mut Tickset, m: &Message) {
    match *m {
        Message::State(x) => set.state = Some(x),
        Message::Truth(x) => set.truth = Some(x),
        Message::NavigationError(x) => set.navigation = Some(x),
        Message::NominalTranslational(x) => set.nt = Some(x),
        Message::NominalAttitude(x) => set.na = Some(x),
        Message::NominalRobotic(x) => set.nr = Some(x),
        Message::SafeTranslational(x) => set.st = Some(x),
        Message::SafeAttitude(x) => set.sa = Some(x),
        Message::SafeRobotic(x) => set.sr = Some(x),
        _ => {}
    }
}

impl RecorderRole<FileSink> {
    /// From the process's config, writing into its output folder.
    pub fn from_process(p: &Proc) -> Result<Self, sc_flight::FlightError> {
        let sink = FileSink::new(p).map_err(|e| sc_flight::FlightError::Usage(e.to_string()))?;
        let mut role = Self::new(sink, &p.setup, p.schedule.base_period_s, std::process::id());
        // the backups as the simulator computes them: certified for their group's hold
        role.layer = SafetyLayer::with_holds(
            &p.setup.scenario,
            p.setup.robot.clone(),
            &p.schedule.period_s,
        );
        Ok(role)
    }
}

impl<S: RecordSink> Component for RecorderRole<S> {
    fn wake_sets(&self) -> &'static [WakeSet] {
        WAKE
    }

    fn inputs(&self) -> &'static [ServiceName] {
        // step results first: everything of their tick was sent before them
        &[
            services::STEP_RESULT,
            services::TRUTH,
            services::MEASUREMENT,
            services::ESTIMATE,
            services::NAVIGATION_ERROR,
            services::SIM_STATE,
            services::NOMINAL_TRANSLATIONAL,
            services::NOMINAL_ATTITUDE,
            services::NOMINAL_ROBOTIC,
            services::SAFE_TRANSLATIONAL,
            services::SAFE_ATTITUDE,
            services::SAFE_ROBOTIC,
            services::TICK,
        ]
    }

    fn next(&mut self, now_ns: u64) -> Next {
        if self.done || self.error.is_some() {
            return Next::Exit;
        }
        let until_ns = if self.stop {
            // one more pass without waiting: a step result sent just before the stop
            // is not lost
            Some(now_ns)
        } else {
            (!self.queued.is_empty()).then(|| now_ns + INCOMPLETE_RECHECK_NS)
        };
        Next::Wait { set: 0, until_ns }
    }

    fn handle(&mut self, w: &Wakeup, inputs: &[Message], _: &mut dyn Env, out: &mut Outbox) {
        if !self.started {
            self.started = true;
            let r = self.sink.begin();
            self.keep(r);
        }
        for m in inputs {
            self.absorb(m);
        }
        for r in self.ready(w.now_ns) {
            self.write_step(r, out);
        }
        if self.final_pass {
            self.done = true;
        }
        self.final_pass |= self.stop;
    }

    fn finish(&mut self, _: Finish, _: &[(ServiceName, u64)], out: &mut Outbox) -> i32 {
        for (svc, _) in &self.absent_at_write {
            *self.rep.missing.entry((*svc).into()).or_default() += 1;
        }
        // no end of the mission: the run was stopped before it (the scheduler's stop tick
        // at --max-ticks or after losing a process, or the launcher's teardown); the
        // launcher, which knows whether it was interrupted, says so
        let end = self
            .end
            .clone()
            .unwrap_or(MissionEnd::Stopped { t: self.last_t });
        let phase_names: Vec<String> = self
            .scenario
            .mission
            .phases
            .iter()
            .map(|x| x.name.clone())
            .collect();
        let mut summary = summarize(&self.records, &end, &phase_names, true);
        summary.uncertainty =
            sc_mission::UncertaintySummary::of(&self.records, &self.scenario, &self.robot, true);
        // judged by the watch the filter processes ran (the attitude group's hold)
        summary.safe_mode =
            sc_mission::SafeModeSummary::with_watch(&self.records, &self.layer.watch);
        self.rep.end = summary.end.clone();
        let r = self.sink.finish(&self.records, &summary, &self.rep);
        self.keep(r);
        if let Some(e) = &self.error {
            out.log(format!("error: recorder: {e}"));
            return 2;
        }
        let missing: u64 = self.rep.missing.values().sum();
        let late: u64 = self.rep.late.values().sum();
        out.log(format!(
            "recorder: recorded per service {:?}; missing {missing} of the samples the schedule requires, {late} late",
            self.rep.recorded
        ));
        out.log(format!(
            "recorder: {} steps, {} at t = {:.1} s; min margin {} = {:.3e}; faults {}",
            self.rep.steps,
            summary.end,
            summary.final_time_s,
            summary.min_margin.0,
            summary.min_margin.1,
            summary.fault_count
        ));
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sc_flight::component::{NoPeers, Woke};
    use sc_icd::{
        NominalAttitude, NominalRobotic, NominalTranslational, SafeAttitude, SafeRobotic,
        SafeTranslational, Tick,
    };

    /// What the recorder wrote, kept in memory.
    #[derive(Default)]
    struct Memory {
        begun: bool,
        messages: usize,
        steps: Vec<String>,
        finished: Option<(String, RecorderReport)>,
    }

    impl RecordSink for Memory {
        fn begin(&mut self) -> Result<(), SinkError> {
            self.begun = true;
            Ok(())
        }
        fn message(&mut self, _: u64, _: &Message) -> Result<(), SinkError> {
            self.messages += 1;
            Ok(())
        }
        fn step(&mut self, _: &StepRecord, latency: &str) -> Result<(), SinkError> {
            self.steps.push(latency.to_string());
            Ok(())
        }
        fn finish(
            &mut self,
            _: &[StepRecord],
            s: &sc_mission::Summary,
            r: &RecorderReport,
        ) -> Result<(), SinkError> {
            self.finished = Some((s.end.clone(), r.clone()));
            Ok(())
        }
    }

    fn setup() -> sc_mission::Setup {
        let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../config/scenario.toml");
        sc_mission::Setup::load(std::path::Path::new(p)).unwrap()
    }

    fn role() -> RecorderRole<Memory> {
        RecorderRole::new(Memory::default(), &setup(), 0.1, 42)
    }

    /// The messages of a healthy tick `k`: its state, the nominal and safe commands.
    fn tick(k: u64) -> Vec<Message> {
        let su = setup();
        let sim = sc_sim::Simulator::new(&su.scenario, su.robot).unwrap();
        let mut state = sc_flight::convert::sim_state(&sim.observe());
        state.tick = k;
        state.due_mask = 7;
        vec![
            Message::State(state),
            Message::NominalTranslational(NominalTranslational {
                tick: k,
                ..Default::default()
            }),
            Message::NominalAttitude(NominalAttitude {
                tick: k,
                ..Default::default()
            }),
            Message::NominalRobotic(NominalRobotic {
                tick: k,
                ..Default::default()
            }),
            Message::SafeTranslational(SafeTranslational {
                tick: k,
                ..Default::default()
            }),
            Message::SafeAttitude(SafeAttitude {
                tick: k,
                ..Default::default()
            }),
            Message::SafeRobotic(SafeRobotic {
                tick: k,
                ..Default::default()
            }),
        ]
    }

    fn result(k: u64) -> Message {
        Message::StepResult(StepResult {
            tick: k,
            ..Default::default()
        })
    }

    fn handle(r: &mut RecorderRole<Memory>, now: u64, inputs: &[Message]) -> Outbox {
        let mut out = Outbox::default();
        let w = Wakeup {
            now_ns: now,
            why: Woke::Event,
            stage_deadline: 0,
            prepare: 0,
        };
        r.handle(&w, inputs, &mut NoPeers, &mut out);
        out
    }

    /// The recorder reads what the role table says it subscribes to.
    #[test]
    fn the_recorder_reads_exactly_its_table_row() {
        let role = Role::of(RoleKind::Recorder);
        let mut want: Vec<&str> = role.subscribes.iter().map(|s| s.as_str()).collect();
        let mut got: Vec<&str> = role_inputs().iter().map(|s| s.as_str()).collect();
        want.sort();
        got.sort();
        assert_eq!(got, want);
        assert!(!role.flight, "a ground tool");
    }

    fn role_inputs() -> &'static [ServiceName] {
        role().inputs()
    }

    #[test]
    fn a_complete_tick_is_written_and_reported_to_the_scheduler() {
        let mut r = role();
        let mut inputs = vec![result(0)];
        inputs.extend(tick(0));
        let out = handle(&mut r, 10, &inputs);
        assert!(r.sink.begun);
        assert_eq!(r.sink.steps.len(), 1);
        assert!(r.sink.steps[0].starts_with("0,"));
        let [Message::Health(h)] = out.send[..] else {
            panic!("{:?}", out.send)
        };
        assert_eq!((h.last_tick, h.ticks_handled, h.pid), (0, 1, 42));
        assert_eq!(
            r.next(10),
            Next::Wait {
                set: 0,
                until_ns: None
            }
        );
    }

    #[test]
    fn an_incomplete_tick_waits_briefly_then_its_missing_and_late_messages_are_counted() {
        let mut r = role();
        let mut inputs = vec![result(0)];
        inputs.extend(
            tick(0)
                .into_iter()
                .filter(|m| !matches!(m, Message::NominalAttitude(_))),
        );
        handle(&mut r, 10, &inputs);
        assert!(r.sink.steps.is_empty(), "waits for the attitude nominal");
        assert_eq!(
            r.next(10),
            Next::Wait {
                set: 0,
                until_ns: Some(10 + INCOMPLETE_RECHECK_NS)
            }
        );
        handle(&mut r, 10 + INCOMPLETE_WAIT_NS + 1, &[]);
        assert_eq!(r.sink.steps.len(), 1, "written without it after the wait");
        let late = Message::NominalAttitude(NominalAttitude {
            tick: 0,
            ..Default::default()
        });
        handle(&mut r, INCOMPLETE_WAIT_NS * 2, &[late]);
        let mut fin = Outbox::default();
        assert_eq!(r.finish(Finish::Done, &[], &mut fin), 0);
        let (end, rep) = r.sink.finished.clone().unwrap();
        assert_eq!(end, "stopped");
        assert_eq!(rep.late.get(services::NOMINAL_ATTITUDE.as_str()), Some(&1));
        assert_eq!(
            rep.missing.get(services::NOMINAL_ATTITUDE.as_str()),
            Some(&0),
            "it came"
        );
        assert_eq!(rep.expected.get(services::SIM_STATE.as_str()), Some(&1));
    }

    #[test]
    fn the_stop_takes_every_result_in_one_more_pass() {
        let mut r = role();
        let stop = Message::Tick(Tick {
            command: tick_command::STOP,
            ..Default::default()
        });
        let out = handle(&mut r, 1, &[result(0), stop]);
        assert!(
            out.log
                .iter()
                .any(|l| l.contains("FAULT tick 0: no state recorded"))
        );
        assert_eq!(
            r.next(1),
            Next::Wait {
                set: 0,
                until_ns: Some(1)
            },
            "no wait"
        );
        handle(&mut r, 2, &[]);
        assert_eq!(r.next(2), Next::Exit);
        let mut fin = Outbox::default();
        r.finish(Finish::Done, &[], &mut fin);
        assert!(
            fin.log[1].starts_with("recorder: 0 steps, stopped"),
            "{:?}",
            fin.log
        );
    }

    /// A partner labelling its messages with ticks far ahead cannot grow the recorder:
    /// they are recorded, not filed; one a few ticks ahead (read before its state, from
    /// another queue) still is.
    #[test]
    fn far_future_labels_are_recorded_not_filed() {
        let mut r = role();
        let mut inputs = tick(0);
        inputs.truncate(1);
        for k in 0..1000u64 {
            inputs.push(Message::Estimate(sc_icd::NavState {
                tick: u64::MAX - k,
                ..Default::default()
            }));
        }
        inputs.push(Message::NominalTranslational(NominalTranslational {
            tick: 3,
            ..Default::default()
        }));
        handle(&mut r, 1, &inputs);
        assert_eq!(r.sink.messages, 1002, "every message recorded");
        assert_eq!(r.pending.keys().copied().collect::<Vec<_>>(), vec![0, 3]);
    }
}
