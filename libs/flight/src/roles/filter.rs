//! A safety filter: waits for its state, nominal command and upstream safe commands up
//! to its stage deadline, runs its QP (on the substitute nominal when the nominal is
//! missing or invalid, on the upstream backup when an upstream command is missing or
//! would be refused), publishes the safe command.
//!
//! Wake-ups (docs/PARTITION.md, "Who wakes whom"): normally on the nominal command and
//! the immediately upstream safe command only — the state of the tick was published
//! before either, so it is read without waking on it — and always on the scheduler's
//! stage-deadline watchdog. While an input is absent (a dead or late producer), or a
//! command of a tick whose state is not here yet shows that one is in flight, on every
//! input including the state. The queues are read in reverse causal order (the upstream
//! attitude command before the translational one it was computed from, the commands
//! before the state): a message published while they are read is then never seen
//! without the messages it depends on.

use super::{LOST_STOP_WAKEUP, deadline_from, keep_for_tick};
use crate::admission;
use crate::component::{Component, Env, Finish, Message, Next, Outbox, WakeSet, Wakeup, Woke};
use crate::convert::{self, Coupling};
use crate::error::FlightError;
use crate::process::Proc;
use nalgebra::{SVector, Vector3};
use sc_cbf::SafetyLayer;
use sc_cbf::chain::flag_missing;
use sc_core::Subsystem;
use sc_icd::services::{self, ServiceName};
use sc_icd::{Role, RoleKind, SafeAttitude, SafeTranslational, SimState, tick_command};
use sc_scenario::Scenario;
use std::collections::VecDeque;

/// A nominal command as the filter keeps it, whatever its subsystem.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Nominal {
    tick: u64,
    valid: u32,
    /// The command's components (the first 3 or 7 are used).
    u: [f64; 7],
}

impl Nominal {
    /// The nominal command of subsystem `s` carried by `m`, if it is one.
    fn of(s: Subsystem, m: &Message) -> Option<Self> {
        let pad3 = |a: &[f64; 3]| [a[0], a[1], a[2], 0.0, 0.0, 0.0, 0.0];
        match (s, m) {
            (Subsystem::Translational, Message::NominalTranslational(n)) => {
                Some(Self::new(n.tick, n.valid, pad3(&n.f_h)))
            }
            (Subsystem::Attitude, Message::NominalAttitude(n)) => {
                Some(Self::new(n.tick, n.valid, pad3(&n.tau_b)))
            }
            (Subsystem::Robotic, Message::NominalRobotic(n)) => {
                Some(Self::new(n.tick, n.valid, n.tau_m))
            }
            _ => None,
        }
    }

    fn new(tick: u64, valid: u32, u: [f64; 7]) -> Self {
        Self { tick, valid, u }
    }

    fn vec<const M: usize>(&self) -> SVector<f64, M> {
        SVector::from_column_slice(&self.u[..M])
    }
}

/// Inputs found missing at a deadline: not waited for again until they reappear.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Absent {
    nominal: bool,
    translational: bool,
    attitude: bool,
}

impl Absent {
    fn any(&self) -> bool {
        self.nominal || self.translational || self.attitude
    }
}

/// The tick being awaited: its state and stage deadline.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pending {
    state: SimState,
    until_ns: u64,
}

/// Which inputs of a tick are here (or not awaited).
#[derive(Debug, Clone, Copy)]
struct Have {
    nominal: bool,
    translational: bool,
    attitude: bool,
    /// The attitude command is due in this tick.
    need_attitude: bool,
}

impl Have {
    fn all(&self) -> bool {
        self.nominal && self.translational && self.attitude
    }
}

/// The wake sets: normally, and on every input while one is absent or late.
const NORMAL: usize = 0;
const ANY: usize = 1;

/// One safety filter.
pub struct FilterRole {
    subsystem: Subsystem,
    name: &'static str,
    layer: SafetyLayer,
    scenario: Scenario,
    deadline_ns: u64,
    states: VecDeque<SimState>,
    last_state: Option<SimState>,
    pending: Option<Pending>,
    nominal: Option<Nominal>,
    up_t: Option<SafeTranslational>,
    up_a: Option<SafeAttitude>,
    absent: Absent,
    stop: bool,
    rehearse: bool,
    misses: u64,
    /// The deadline counts from this process's own receipt of the state, not from the
    /// simulator's stamp: away from the simulator's host the two monotonic clocks are
    /// unrelated ([`Self::on_another_host`]).
    own_clock: bool,
}

impl FilterRole {
    /// The filter of `subsystem` on `scenario`'s safety layer with its stage deadline.
    pub fn new(
        subsystem: Subsystem,
        layer: SafetyLayer,
        scenario: Scenario,
        deadline_ns: u64,
    ) -> Self {
        Self {
            subsystem,
            name: Role::of(RoleKind::Filter(subsystem)).name,
            layer,
            scenario,
            deadline_ns,
            states: VecDeque::new(),
            last_state: None,
            pending: None,
            nominal: None,
            up_t: None,
            up_a: None,
            absent: Absent::default(),
            stop: false,
            rehearse: false,
            misses: 0,
            own_clock: false,
        }
    }

    /// Across hosts, on another host than the simulator's: the stage deadline counts
    /// from this filter's receipt of the state (the budget then excludes the hop across
    /// the link), since the simulator's stamp is another computer's monotonic clock.
    pub fn on_another_host(mut self) -> Self {
        self.own_clock = true;
        self
    }

    /// From the process's config: the scenario's safety layer with every subsystem's
    /// command (and backup) certified for its rate group's hold, the stage deadline of
    /// `[deadlines]` in the run's clock mode.
    pub fn from_process(subsystem: Subsystem, p: &Proc) -> Result<Self, FlightError> {
        let s = &p.setup.scenario;
        let layer = SafetyLayer::with_holds(s, p.setup.robot.clone(), &p.schedule.period_s);
        let deadline = p.deadline(p.cfg.deadlines.filter_ms(subsystem));
        let ns = deadline.as_nanos().min(u128::from(u64::MAX)) as u64;
        let f = Self::new(subsystem, layer, s.clone(), ns);
        let simulator = Role::of(RoleKind::Simulator).name;
        Ok(if p.cfg.host_of(p.role) != p.cfg.host_of(simulator) {
            f.on_another_host()
        } else {
            f
        })
    }

    /// The tick whose nominal command this filter waits for: the pending state's, else
    /// the next state's.
    fn awaited(&self) -> Option<u64> {
        match &self.pending {
            Some(p) => Some(p.state.tick),
            None => self
                .states
                .front()
                .or(self.last_state.as_ref())
                .map(|s| s.tick + u64::from(self.states.is_empty())),
        }
    }

    /// Takes the inputs of one wake-up (in the role's read order).
    fn absorb(&mut self, w: &Wakeup, inputs: &[Message]) {
        self.rehearse |= w.prepare > 0;
        let awaited = self.awaited();
        let mut got = Vec::new();
        for m in inputs {
            match m {
                Message::Control(t) => self.stop |= t.command == tick_command::STOP,
                Message::SafeAttitude(a) => {
                    self.up_a = Some(*a);
                    self.absent.attitude = false;
                }
                Message::SafeTranslational(t) => {
                    self.up_t = Some(*t);
                    self.absent.translational = false;
                }
                Message::State(s) if s.due_mask & self.subsystem.bit() != 0 => {
                    self.states.push_back(*s)
                }
                m => got.extend(Nominal::of(self.subsystem, m)),
            }
        }
        // judged once the states its commands may answer are known
        let known = self
            .states
            .back()
            .or(self.last_state.as_ref())
            .map(|s| s.tick);
        if keep_for_tick(got, &mut self.nominal, awaited, known, |m| m.tick) {
            self.absent.nominal = false;
        }
    }

    /// Which inputs of the pending tick `s` are here (or found absent before).
    fn have(&self, s: &SimState) -> Have {
        let k = s.tick;
        let need_t = self.subsystem > Subsystem::Translational
            && s.due_mask & Subsystem::Translational.bit() != 0;
        let need_a =
            self.subsystem == Subsystem::Robotic && s.due_mask & Subsystem::Attitude.bit() != 0;
        Have {
            nominal: self.absent.nominal || self.nominal.is_some_and(|m| m.tick == k),
            translational: !need_t
                || self.absent.translational
                || self.up_t.is_some_and(|m| m.tick == k),
            attitude: !need_a || self.absent.attitude || self.up_a.is_some_and(|m| m.tick == k),
            need_attitude: need_a,
        }
    }

    /// Computes every tick whose inputs are complete or whose deadline passed.
    fn process(&mut self, now_ns: u64, out: &mut Outbox) {
        loop {
            if self.pending.is_none() {
                let Some(s) = self.states.pop_front() else {
                    return;
                };
                self.last_state = Some(s);
                // from the tick (the simulator's receipt of it), like the navigation's and
                // the simulator's deadlines: the wait for the estimate does not shift it
                let stamp = if self.own_clock { 0 } else { s.recv_ns };
                let until_ns = deadline_from(stamp, now_ns, self.deadline_ns);
                self.pending = Some(Pending { state: s, until_ns });
            }
            let Some(p) = self.pending else { return };
            let have = self.have(&p.state);
            if !have.all() {
                if now_ns < p.until_ns {
                    return;
                }
                self.deadline_passed(p.state.tick, &have, out);
            }
            self.pending = None;
            out.send(self.compute(&p.state, now_ns));
        }
    }

    /// The stage deadline of tick `k` passed with inputs missing: each is flagged absent
    /// (not waited for again until it reappears) and named in the log.
    fn deadline_passed(&mut self, k: u64, have: &Have, out: &mut Outbox) {
        self.misses += 1;
        let name = self.name;
        if !have.nominal {
            out.log(format!(
                "{name}: FAULT tick {k}: nominal command missing at the deadline"
            ));
            self.absent.nominal = true;
        }
        if !have.translational {
            out.log(format!(
                "{name}: FAULT tick {k}: translational safe command missing at the deadline"
            ));
            self.absent.translational = true;
        }
        if !have.attitude {
            out.log(format!(
                "{name}: FAULT tick {k}: attitude safe command missing at the deadline"
            ));
            self.absent.attitude = true;
        }
    }

    /// The upstream safe force of tick `s` [N, F_B]: this tick's, or — missing, dead
    /// upstream, or one the simulator would refuse — the upstream backup, which is what the
    /// simulator applies (`true`: the backup). While the translational group is not due,
    /// the force the simulator holds, published with the state.
    fn upstream_force(&mut self, s: &SimState, o: &sc_core::Observation) -> (Vector3<f64>, bool) {
        if s.due_mask & Subsystem::Translational.bit() == 0 {
            return (convert::vec3(&s.held_f_b), false);
        }
        let lim = &self.scenario.limits;
        match self
            .up_t
            .filter(|m| m.tick == s.tick)
            .filter(|m| admission::translational(m, lim))
        {
            Some(m) => (convert::vec3(&m.actuated), false),
            None => (self.layer.backup_translational(o).actuated, true),
        }
    }

    /// This tick's attitude command if it passes the simulator's admission; `None` when it
    /// is missing or refused.
    fn upstream_attitude(&self, s: &SimState) -> Option<SafeAttitude> {
        self.up_a
            .filter(|m| m.tick == s.tick)
            .filter(|m| admission::attitude(m, &self.scenario.limits))
    }

    /// What this filter certifies against at tick `s` (the paper's ξ) and whether a
    /// backup stands in for an upstream command.
    fn coupling(&mut self, s: &SimState, o: &sc_core::Observation) -> (Coupling, bool) {
        match self.subsystem {
            Subsystem::Translational => (Coupling::default(), false),
            Subsystem::Attitude => {
                let (force_b, backup) = self.upstream_force(s, o);
                let torque_b = Vector3::zeros();
                (Coupling { force_b, torque_b }, backup)
            }
            Subsystem::Robotic => self.robotic_coupling(s, o),
        }
    }

    /// The robotic filter's coupling: the attitude command together with the force it
    /// was certified against — the translational command, or its backup when the
    /// attitude filter gave up on a translational command that came later — so that the
    /// chain the simulator applies is one the filters certified link by link. An attitude
    /// command certified against any other force, or a missing or refused one, is
    /// replaced by the attitude backup with the translational command in force.
    fn robotic_coupling(&mut self, s: &SimState, o: &sc_core::Observation) -> (Coupling, bool) {
        let (force_b, backup) = self.upstream_force(s, o);
        if s.due_mask & Subsystem::Attitude.bit() == 0 {
            // not due: the torque the simulator holds (the translational group is not due
            // either: a downstream group's period divides its upstream's)
            let torque_b = convert::vec3(&s.held_tau_b);
            return (Coupling { force_b, torque_b }, backup);
        }
        if let Some(a) = self.upstream_attitude(s) {
            let xi = convert::vec3(&a.xi_f_b);
            let torque_b = convert::vec3(&a.u);
            if xi == force_b {
                return (Coupling { force_b, torque_b }, backup);
            }
            let force_b = self.layer.backup_translational(o).actuated;
            if xi == force_b {
                return (Coupling { force_b, torque_b }, true);
            }
        }
        let torque_b = self.layer.backup_attitude(o, &force_b).u;
        (Coupling { force_b, torque_b }, true)
    }

    /// This filter's safe command for tick `s`, received complete (or at its deadline) at
    /// `now_ns`.
    fn compute(&mut self, s: &SimState, now_ns: u64) -> Message {
        let o = convert::observation(s);
        // the mission's own schedule (a nominal's report of its phase is not trusted)
        let phase = self.scenario.phase_index(o.t);
        let (xi, missing) = self.coupling(s, &o);
        // a command for another tick, or one its sender marks invalid, is no command:
        // the filter runs its QP on the substitute nominal
        let nominal = self.nominal.filter(|m| m.tick == s.tick && m.valid != 0);
        let (k, t) = (s.tick, s.t);
        let (f_b, tau_b) = (&xi.force_b, &xi.torque_b);
        let mut msg = match self.subsystem {
            Subsystem::Translational => {
                let out = self
                    .layer
                    .translational_stage(&o, nominal.map(|n| n.vec()).as_ref());
                let out = flagged(out, missing);
                Message::SafeTranslational(convert::safe_msg(&out, &xi, k, t, phase))
            }
            Subsystem::Attitude => {
                let out = self
                    .layer
                    .attitude_stage(&o, f_b, nominal.map(|n| n.vec()).as_ref());
                let out = flagged(out, missing);
                Message::SafeAttitude(convert::safe_msg(&out, &xi, k, t, phase))
            }
            Subsystem::Robotic => {
                let nom = nominal.map(|n| n.vec());
                let out = self.layer.robotic_stage(&o, f_b, tau_b, nom.as_ref());
                let out = flagged(out, missing);
                Message::SafeRobotic(convert::safe_msg(&out, &xi, k, t, phase))
            }
        };
        set_recv_ns(&mut msg, now_ns);
        msg
    }

    /// The safe command's service.
    fn output(&self) -> &'static [ServiceName] {
        match self.subsystem {
            Subsystem::Translational => &[services::SAFE_TRANSLATIONAL],
            Subsystem::Attitude => &[services::SAFE_ATTITUDE],
            Subsystem::Robotic => &[services::SAFE_ROBOTIC],
        }
    }
}

/// `out`, flagged [`sc_cbf::faults::UPSTREAM_MISSING`] when an upstream command was
/// replaced by its backup.
fn flagged<const M: usize, const N: usize>(
    out: sc_cbf::FilterOutput<M, N>,
    missing: bool,
) -> sc_cbf::FilterOutput<M, N> {
    if missing { flag_missing(out) } else { out }
}

/// The stamp at which the last input of the tick arrived.
fn set_recv_ns(m: &mut Message, ns: u64) {
    match m {
        Message::SafeTranslational(x) => x.recv_ns = ns,
        Message::SafeAttitude(x) => x.recv_ns = ns,
        Message::SafeRobotic(x) => x.recv_ns = ns,
        _ => {}
    }
}

/// Per subsystem: the wake sets and the read order (reverse causal order).
mod wiring {
    use super::{ServiceName, WakeSet, services::*};

    pub const TRANSLATIONAL_WAKE: &[WakeSet] = &[
        WakeSet {
            on: &[STAGE_DEADLINE, PREPARE, NOMINAL_TRANSLATIONAL],
            lazy: false,
        },
        WakeSet {
            on: &[STAGE_DEADLINE, PREPARE, SIM_STATE, NOMINAL_TRANSLATIONAL],
            lazy: true,
        },
    ];
    pub const ATTITUDE_WAKE: &[WakeSet] = &[
        WakeSet {
            on: &[
                STAGE_DEADLINE,
                PREPARE,
                NOMINAL_ATTITUDE,
                SAFE_TRANSLATIONAL,
            ],
            lazy: false,
        },
        WakeSet {
            on: &[
                STAGE_DEADLINE,
                PREPARE,
                SIM_STATE,
                NOMINAL_ATTITUDE,
                SAFE_TRANSLATIONAL,
            ],
            lazy: true,
        },
    ];
    // the translational command wakes only its direct downstream, the attitude filter
    pub const ROBOTIC_WAKE: &[WakeSet] = &[
        WakeSet {
            on: &[STAGE_DEADLINE, PREPARE, NOMINAL_ROBOTIC, SAFE_ATTITUDE],
            lazy: false,
        },
        WakeSet {
            on: &[
                STAGE_DEADLINE,
                PREPARE,
                SIM_STATE,
                NOMINAL_ROBOTIC,
                SAFE_TRANSLATIONAL,
                SAFE_ATTITUDE,
            ],
            lazy: true,
        },
    ];
    pub const TRANSLATIONAL_IN: &[ServiceName] = &[
        STAGE_DEADLINE,
        PREPARE,
        CONTROL,
        NOMINAL_TRANSLATIONAL,
        SIM_STATE,
    ];
    pub const ATTITUDE_IN: &[ServiceName] = &[
        STAGE_DEADLINE,
        PREPARE,
        CONTROL,
        SAFE_TRANSLATIONAL,
        NOMINAL_ATTITUDE,
        SIM_STATE,
    ];
    pub const ROBOTIC_IN: &[ServiceName] = &[
        STAGE_DEADLINE,
        PREPARE,
        CONTROL,
        SAFE_ATTITUDE,
        SAFE_TRANSLATIONAL,
        NOMINAL_ROBOTIC,
        SIM_STATE,
    ];
}

impl Component for FilterRole {
    fn wake_sets(&self) -> &'static [WakeSet] {
        match self.subsystem {
            Subsystem::Translational => wiring::TRANSLATIONAL_WAKE,
            Subsystem::Attitude => wiring::ATTITUDE_WAKE,
            Subsystem::Robotic => wiring::ROBOTIC_WAKE,
        }
    }

    fn inputs(&self) -> &'static [ServiceName] {
        match self.subsystem {
            Subsystem::Translational => wiring::TRANSLATIONAL_IN,
            Subsystem::Attitude => wiring::ATTITUDE_IN,
            Subsystem::Robotic => wiring::ROBOTIC_IN,
        }
    }

    fn warm(&self) -> &'static [ServiceName] {
        self.output()
    }

    fn next(&mut self, _: u64) -> Next {
        if let Some(p) = &self.pending {
            let have = self.have(&p.state);
            // the robotic filter does not wake on the translational command: it waits
            // for it on every input when only the translational group is due upstream,
            // or when the attitude command of the tick is here without it (the
            // translational filter was preempted between the two queues)
            let unwoken = self.subsystem == Subsystem::Robotic
                && !have.translational
                && (!have.need_attitude || self.up_a.is_some_and(|m| m.tick == p.state.tick));
            let set = if self.absent.any() || unwoken {
                ANY
            } else {
                NORMAL
            };
            return Next::Wait {
                set,
                until_ns: Some(p.until_ns),
            };
        }
        if self.stop {
            return Next::Exit;
        }
        // a command of a tick whose state is not here: the state was sent before it
        // (its sender was preempted between this filter's queue and the others'), and
        // the state does not wake this filter
        let newest = [
            self.nominal.map(|m| m.tick),
            self.up_t.map(|m| m.tick),
            self.up_a.map(|m| m.tick),
        ]
        .into_iter()
        .flatten()
        .max();
        let in_flight = newest > self.last_state.map(|s| s.tick);
        let set = if self.absent.any() || in_flight {
            ANY
        } else {
            NORMAL
        };
        Next::Wait {
            set,
            until_ns: None,
        }
    }

    fn handle(&mut self, w: &Wakeup, inputs: &[Message], _: &mut dyn Env, out: &mut Outbox) {
        let idle = self.pending.is_none();
        self.absorb(w, inputs);
        if idle {
            if self.stop && self.states.is_empty() && w.why == Woke::Timeout {
                out.log(format!("{}: {LOST_STOP_WAKEUP}", self.name));
            }
            // the pre-tick warm-up: only between ticks
            out.rehearse = std::mem::take(&mut self.rehearse)
                && self.states.is_empty()
                && self.last_state.is_some();
        }
        self.process(w.now_ns, out);
    }

    /// This filter's step on the last tick's inputs (the filters are memoryless).
    fn rehearse(&mut self) {
        let (Some(s), Some(n)) = (self.last_state, self.nominal) else {
            return;
        };
        let o = convert::observation(&s);
        let f_b = self
            .up_t
            .map_or_else(Vector3::zeros, |m| convert::vec3(&m.actuated));
        let tau_b = self
            .up_a
            .map_or_else(Vector3::zeros, |m| convert::vec3(&m.u));
        match self.subsystem {
            Subsystem::Translational => {
                std::hint::black_box(self.layer.translational_stage(&o, Some(&n.vec())));
            }
            Subsystem::Attitude => {
                std::hint::black_box(self.layer.attitude_stage(&o, &f_b, Some(&n.vec())));
            }
            Subsystem::Robotic => {
                std::hint::black_box(self.layer.robotic_stage(&o, &f_b, &tau_b, Some(&n.vec())));
            }
        }
    }

    fn finish(&mut self, why: Finish, impostors: &[(ServiceName, u64)], out: &mut Outbox) -> i32 {
        if why == Finish::Terminated && self.pending.is_some() {
            return 0;
        }
        // wake the downstream filter (and the simulator) once so that they see the stop
        out.notify.extend_from_slice(self.output());
        let dropped: u64 = impostors.iter().map(|(_, n)| n).sum();
        out.log(format!(
            "{}: done, {} deadline misses, {dropped} samples from a second publisher dropped",
            self.name, self.misses
        ));
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::component::NoPeers;
    use crate::roles::testing::{setup, state, wakeup};
    use sc_cbf::faults;
    use sc_core::SubsystemSet;
    use sc_icd::{NominalAttitude, NominalRobotic, NominalTranslational, Tick};

    const DEADLINE_NS: u64 = 40_000_000;
    const PUBLISHED_NS: u64 = 1_000;
    /// When the simulator received the tick: the stage deadlines count from it.
    const TICK_RECV_NS: u64 = 500;

    fn role(s: Subsystem) -> FilterRole {
        let su = setup();
        let layer = SafetyLayer::from_scenario(&su.scenario, su.robot.clone());
        FilterRole::new(s, layer, su.scenario, DEADLINE_NS)
    }

    fn tick_state(k: u64) -> Message {
        let mut s = state(k, SubsystemSet::ALL.bits());
        s.publish_ns = PUBLISHED_NS;
        s.recv_ns = TICK_RECV_NS;
        Message::State(s)
    }

    fn nominal(s: Subsystem, tick: u64, valid: u32) -> Message {
        let (t, phase, recv_ns, publish_ns) = (0.0, 0, 0, 0);
        match s {
            Subsystem::Translational => Message::NominalTranslational(NominalTranslational {
                tick,
                t,
                valid,
                phase,
                recv_ns,
                publish_ns,
                f_h: [0.1, 0.0, 0.0],
            }),
            Subsystem::Attitude => Message::NominalAttitude(NominalAttitude {
                tick,
                t,
                valid,
                phase,
                recv_ns,
                publish_ns,
                tau_b: [0.0, 0.01, 0.0],
            }),
            Subsystem::Robotic => Message::NominalRobotic(NominalRobotic {
                tick,
                t,
                valid,
                phase,
                recv_ns,
                publish_ns,
                tau_m: [0.0; 7],
            }),
        }
    }

    /// The fault flags of the one safe command sent.
    fn sent_faults(out: &Outbox) -> u32 {
        match out.send.as_slice() {
            [Message::SafeTranslational(m)] => m.fault_flags,
            [Message::SafeAttitude(m)] => m.fault_flags,
            [Message::SafeRobotic(m)] => m.fault_flags,
            other => panic!("expected one safe command, got {other:?}"),
        }
    }

    fn handle(r: &mut FilterRole, now: u64, why: Woke, inputs: &[Message]) -> Outbox {
        let mut out = Outbox::default();
        r.handle(&wakeup(now, why), inputs, &mut NoPeers, &mut out);
        out
    }

    #[test]
    fn a_complete_tick_is_filtered_at_once() {
        let mut r = role(Subsystem::Translational);
        let out = handle(
            &mut r,
            2_000,
            Woke::Event,
            &[nominal(Subsystem::Translational, 0, 1), tick_state(0)],
        );
        assert_eq!(sent_faults(&out) & faults::NOMINAL_MISSING, 0);
        let Message::SafeTranslational(m) = out.send[0] else {
            panic!()
        };
        assert_eq!((m.tick, m.recv_ns), (0, 2_000));
        assert_eq!(
            r.next(0),
            Next::Wait {
                set: NORMAL,
                until_ns: None
            }
        );
    }

    #[test]
    fn at_the_deadline_it_runs_on_the_substitute_and_stops_waiting_for_the_nominal() {
        let mut r = role(Subsystem::Translational);
        let out = handle(&mut r, 2_000, Woke::Event, &[tick_state(0)]);
        assert!(
            out.send.is_empty(),
            "waits for its nominal until the deadline"
        );
        let until = TICK_RECV_NS + DEADLINE_NS;
        assert_eq!(
            r.next(2_000),
            Next::Wait {
                set: NORMAL,
                until_ns: Some(until)
            }
        );
        let out = handle(&mut r, until, Woke::Timeout, &[]);
        assert_ne!(sent_faults(&out) & faults::NOMINAL_MISSING, 0);
        assert!(out.log[0].contains("FAULT tick 0: nominal command missing at the deadline"));
        // absent: the next tick is not waited for, and every input wakes the filter
        assert_eq!(
            r.next(until).clone(),
            Next::Wait {
                set: ANY,
                until_ns: None
            }
        );
        let out = handle(&mut r, until + 1, Woke::Event, &[tick_state(1)]);
        assert_eq!(out.send.len(), 1, "tick 1 filtered without waiting");
        assert_eq!(r.misses, 1);
    }

    #[test]
    fn on_another_host_the_deadline_counts_from_its_own_receipt() {
        // the simulator's stamp is another computer's clock: here far ahead of ours
        let mut r = role(Subsystem::Translational).on_another_host();
        let mut s = state(0, SubsystemSet::ALL.bits());
        s.recv_ns = 10 * DEADLINE_NS;
        let out = handle(&mut r, 2_000, Woke::Event, &[Message::State(s)]);
        assert!(out.send.is_empty(), "waits for its nominal");
        assert_eq!(
            r.next(2_000),
            Next::Wait {
                set: NORMAL,
                until_ns: Some(2_000 + DEADLINE_NS)
            }
        );
        // a stamp far behind ours would have put the deadline in the past
        let mut r = role(Subsystem::Translational).on_another_host();
        let late = 100 * DEADLINE_NS;
        let out = handle(&mut r, late, Woke::Event, &[tick_state(0)]);
        assert!(out.send.is_empty(), "still waits for its nominal");
    }

    #[test]
    fn a_command_for_another_tick_or_marked_invalid_is_no_command() {
        let mut r = role(Subsystem::Attitude);
        let up = Message::SafeTranslational(SafeTranslational {
            tick: 0,
            ..Default::default()
        });
        // labelled for a tick whose state does not exist yet: a lie, dropped
        let out = handle(
            &mut r,
            10,
            Woke::Event,
            &[up, nominal(Subsystem::Attitude, 5, 1), tick_state(0)],
        );
        assert!(out.send.is_empty());
        assert_eq!(r.nominal, None);
        let out = handle(
            &mut r,
            20,
            Woke::Event,
            &[nominal(Subsystem::Attitude, 0, 0)],
        );
        assert_ne!(
            sent_faults(&out) & faults::NOMINAL_MISSING,
            0,
            "an invalid nominal is not filtered"
        );
    }

    #[test]
    fn a_refused_upstream_command_is_replaced_by_the_upstream_backup() {
        let mut r = role(Subsystem::Robotic);
        let lim = setup().scenario.limits;
        let mut bad = SafeAttitude {
            tick: 0,
            ..Default::default()
        };
        bad.u[1] = 10.0 * lim.torque_max_nm;
        let ok = SafeTranslational {
            tick: 0,
            ..Default::default()
        };
        let inputs = [
            Message::SafeAttitude(bad),
            Message::SafeTranslational(ok),
            nominal(Subsystem::Robotic, 0, 1),
            tick_state(0),
        ];
        let out = handle(&mut r, 10, Woke::Event, &inputs);
        assert_ne!(sent_faults(&out) & faults::UPSTREAM_MISSING, 0);
    }

    #[test]
    fn a_missing_upstream_command_is_waited_for_then_replaced_by_its_backup() {
        let mut r = role(Subsystem::Attitude);
        let out = handle(
            &mut r,
            10,
            Woke::Event,
            &[nominal(Subsystem::Attitude, 0, 1), tick_state(0)],
        );
        assert!(out.send.is_empty(), "waits for the translational command");
        let until = TICK_RECV_NS + DEADLINE_NS;
        let out = handle(&mut r, until, Woke::Timeout, &[]);
        assert!(out.log[0].contains("translational safe command missing at the deadline"));
        assert_ne!(sent_faults(&out) & faults::UPSTREAM_MISSING, 0);
        assert!(r.absent.translational);
        // the dead upstream comes back: no longer absent
        let up = Message::SafeTranslational(SafeTranslational {
            tick: 1,
            ..Default::default()
        });
        handle(&mut r, until + 1, Woke::Event, &[up]);
        assert!(!r.absent.translational);
    }

    /// The coupling the robotic filter's command `out` says it was certified against.
    fn sent_coupling(out: &Outbox) -> Coupling {
        match out.send.as_slice() {
            [Message::SafeRobotic(m)] => Coupling::of(m),
            other => panic!("expected one robotic command, got {other:?}"),
        }
    }

    /// The robotic filter certifies against the force the attitude command was certified
    /// against: the translational command, or its backup when the attitude filter gave
    /// up on it; an attitude command certified against any other force is replaced by
    /// the attitude backup.
    #[test]
    fn the_robotic_filter_takes_the_force_the_attitude_command_assumed() {
        let su = setup();
        let mut layer = SafetyLayer::from_scenario(&su.scenario, su.robot.clone());
        let Message::State(st) = tick_state(0) else {
            unreachable!()
        };
        let o = convert::observation(&st);
        let f = Vector3::new(0.05, 0.0, 0.0);
        let backup_f = layer.backup_translational(&o).actuated;
        let run = |xi: Vector3<f64>| {
            let mut r = role(Subsystem::Robotic);
            let t = SafeTranslational {
                tick: 0,
                actuated: f.into(),
                ..Default::default()
            };
            let a = SafeAttitude {
                tick: 0,
                u: [0.0, 0.01, 0.0],
                xi_f_b: xi.into(),
                ..Default::default()
            };
            let inputs = [
                Message::SafeAttitude(a),
                Message::SafeTranslational(t),
                nominal(Subsystem::Robotic, 0, 1),
                tick_state(0),
            ];
            let out = handle(&mut r, 10, Woke::Event, &inputs);
            (sent_coupling(&out), sent_faults(&out))
        };
        let tau = Vector3::new(0.0, 0.01, 0.0);
        let (xi, flags) = run(f);
        assert_eq!((xi.force_b, xi.torque_b), (f, tau));
        assert_eq!(flags & faults::UPSTREAM_MISSING, 0);
        let (xi, flags) = run(backup_f);
        assert_eq!(
            (xi.force_b, xi.torque_b),
            (backup_f, tau),
            "as the attitude filter"
        );
        assert_ne!(flags & faults::UPSTREAM_MISSING, 0);
        let (xi, flags) = run(f + Vector3::new(1e-9, 0.0, 0.0));
        let backup_tau = layer.backup_attitude(&o, &f).u;
        assert_eq!((xi.force_b, xi.torque_b), (f, backup_tau), "refused");
        assert_ne!(flags & faults::UPSTREAM_MISSING, 0);
    }

    #[test]
    fn the_robotic_filter_waits_on_every_input_for_an_unwoken_translational_command() {
        let mut r = role(Subsystem::Robotic);
        let a = Message::SafeAttitude(SafeAttitude {
            tick: 0,
            ..Default::default()
        });
        handle(
            &mut r,
            10,
            Woke::Event,
            &[a, nominal(Subsystem::Robotic, 0, 1), tick_state(0)],
        );
        let Next::Wait { set, .. } = r.next(10) else {
            panic!()
        };
        assert_eq!(set, ANY, "the translational command does not wake it");
    }

    #[test]
    fn the_stop_ends_the_filter_and_wakes_its_downstream() {
        let mut r = role(Subsystem::Attitude);
        let stop = Message::Control(Tick {
            command: tick_command::STOP,
            ..Default::default()
        });
        let out = handle(&mut r, 10, Woke::Timeout, &[stop]);
        assert!(out.log[0].contains(LOST_STOP_WAKEUP));
        assert_eq!(r.next(10), Next::Exit);
        let mut fin = Outbox::default();
        assert_eq!(
            r.finish(Finish::Done, &[(services::NOMINAL_ATTITUDE, 2)], &mut fin),
            0
        );
        assert_eq!(fin.notify, vec![services::SAFE_ATTITUDE]);
        assert!(
            fin.log[0].contains("0 deadline misses, 2 samples from a second publisher dropped")
        );
    }

    #[test]
    fn a_signal_mid_tick_ends_the_filter_silently() {
        let mut r = role(Subsystem::Translational);
        handle(&mut r, 10, Woke::Event, &[tick_state(0)]);
        let mut fin = Outbox::default();
        assert_eq!(r.finish(Finish::Terminated, &[], &mut fin), 0);
        assert_eq!(fin, Outbox::default());
    }

    #[test]
    fn the_warm_up_rehearses_only_between_ticks() {
        let mut r = role(Subsystem::Translational);
        handle(
            &mut r,
            10,
            Woke::Event,
            &[nominal(Subsystem::Translational, 0, 1), tick_state(0)],
        );
        let mut w = wakeup(20, Woke::Event);
        w.prepare = 1;
        let mut out = Outbox::default();
        r.handle(&w, &[], &mut NoPeers, &mut out);
        assert!(out.rehearse);
        r.rehearse();
        let mut out = Outbox::default();
        r.handle(&w, &[tick_state(1)], &mut NoPeers, &mut out);
        assert!(!out.rehearse, "a tick is here: no rehearsal");
    }
}
