//! One step's record rebuilt from the messages of its tick: what the filters computed,
//! what the simulator applied (the backup where it applied one), the nominal commands the
//! filters ran on — the same `StepRecord` `safe-capture run` writes.

use sc_cbf::{FilterOutput, SafetyLayer, faults};
use sc_core::Subsystem;
use sc_flight::convert::{self, SafeMsg};
use sc_icd::{
    NominalAttitude, NominalRobotic, NominalTranslational, SafeAttitude, SafeRobotic,
    SafeTranslational, SimState, StepResult, fault,
};
use sc_mission::StepRecord;

/// The messages of one tick (or the ones held for slower rate groups).
#[derive(Debug, Default, Clone, Copy)]
pub struct Tickset {
    /// The state the controllers and filters got (the estimate with a declared
    /// uncertainty).
    pub state: Option<SimState>,
    /// With a declared uncertainty: the truth and the realised navigation errors.
    pub truth: Option<SimState>,
    pub navigation: Option<sc_icd::NavigationError>,
    pub nt: Option<NominalTranslational>,
    pub na: Option<NominalAttitude>,
    pub nr: Option<NominalRobotic>,
    pub st: Option<SafeTranslational>,
    pub sa: Option<SafeAttitude>,
    pub sr: Option<SafeRobotic>,
}

impl Tickset {
    /// The tick's due subsystem `s` has what its step needs: its safe command (unless the
    /// simulator used the backup) and its nominal command (unless the filter flagged it
    /// missing); with `knowledge` (a declared uncertainty) also the truth and the
    /// navigation errors.
    pub fn complete(&self, r: &StepResult, knowledge: bool) -> bool {
        let Some(st) = self.state else { return false };
        if knowledge && (self.truth.is_none() || self.navigation.is_none()) {
            return false;
        }
        let missing_flag = faults::UPSTREAM_MISSING | faults::NOMINAL_MISSING;
        let need = |s: Subsystem, nom: bool, safe: Option<u32>| {
            st.due_mask & s.bit() == 0
                || r.fallback_mask & s.bit() != 0
                || safe.is_some_and(|f| nom || f & missing_flag != 0)
        };
        need(
            Subsystem::Translational,
            self.nt.is_some(),
            self.st.map(|m| m.fault_flags),
        ) && need(
            Subsystem::Attitude,
            self.na.is_some(),
            self.sa.map(|m| m.fault_flags),
        ) && need(
            Subsystem::Robotic,
            self.nr.is_some(),
            self.sr.map(|m| m.fault_flags),
        )
    }
}

/// What the simulator applied for one subsystem, as a filter output: the backup when the
/// simulator applied the backup (the command was missing at its deadline, or it refused
/// the one that came; then held), else the tick's safe command (then held), else the held
/// one of a slower group, else the backup.
fn applied_output<T: SafeMsg, const M: usize, const N: usize>(
    fresh: Option<T>,
    held: &mut Option<T>,
    fell_back: bool,
    backup: impl FnOnce() -> FilterOutput<M, N>,
) -> FilterOutput<M, N> {
    if fell_back {
        // the simulator holds the backup until the group is due again
        let out = backup();
        *held = Some(convert::safe_msg(
            &out,
            &convert::Coupling::default(),
            0,
            0.0,
            0,
        ));
        return out;
    }
    match fresh {
        Some(m) => {
            *held = Some(m);
            convert::filter_output(&m)
        }
        None => held
            .map(|m| convert::filter_output(&m))
            .unwrap_or_else(backup),
    }
}

/// The nominal command a filter ran on, as the record holds it: the message's values,
/// or NaN when the filter flagged the nominal missing (absent, late, for another tick,
/// marked invalid) and ran on its substitute nominal.
fn nominal_seen<const D: usize>(
    msg: Option<nalgebra::SVector<f64, D>>,
    faults: u32,
) -> nalgebra::SVector<f64, D> {
    match msg {
        Some(v) if faults & sc_cbf::faults::NOMINAL_MISSING == 0 => v,
        _ => nalgebra::SVector::from_element(f64::NAN),
    }
}

/// The record of step result `r` with the state and messages of its tick (`set`), the
/// messages held from earlier ticks (`held`, updated) and the scenario's phases. With a
/// declared uncertainty `state` is what the filters knew (the backups are computed on it,
/// its barriers are those on knowledge) and `set.truth` the truth the record holds.
pub fn record(
    layer: &mut SafetyLayer,
    scenario: &sc_scenario::Scenario,
    r: &StepResult,
    state: &SimState,
    set: &Tickset,
    held: &mut Tickset,
) -> StepRecord {
    let o = convert::observation(state);
    let truth = set.truth.as_ref().unwrap_or(state);
    // a declared uncertainty whose truth never came: the estimate is no truth — its
    // barriers are recorded as not evaluated (NaN counts as violated), never as the truth's
    let unknown = [f64::NAN; sc_icd::N_BARRIERS];
    let (barriers, between) = if scenario.uncertainty.is_some() && set.truth.is_none() {
        (unknown, unknown)
    } else {
        (truth.barriers, truth.barriers_between)
    };
    held.nt = set.nt.or(held.nt);
    held.na = set.na.or(held.na);
    held.nr = set.nr.or(held.nr);
    let applied = convert::applied(r);
    let fell_back = |s: Subsystem| r.fallback_mask & s.bit() != 0;
    let tr = applied_output(
        set.st,
        &mut held.st,
        fell_back(Subsystem::Translational),
        || layer.backup_translational(&o),
    );
    let at = applied_output(set.sa, &mut held.sa, fell_back(Subsystem::Attitude), || {
        layer.backup_attitude(&o, &applied.force_b)
    });
    let rb = applied_output(set.sr, &mut held.sr, fell_back(Subsystem::Robotic), || {
        layer.backup_robotic(&o, &applied.force_b, &applied.torque_b)
    });
    StepRecord {
        step: o.step,
        t: o.t,
        // the mission's own schedule, as the simulator decides it
        phase: scenario.phase_index(o.t),
        obs: convert::observation(truth),
        navigation_error: set.navigation.as_ref().map(convert::navigation_error_of),
        knowledge_barriers: set.truth.map(|_| state.barriers),
        navigation_rejected: r.fault_flags & fault::NAVIGATION_REJECTED != 0,
        // what the filter got: NaN where it ran on the substitute nominal (as in
        // process), never a message of another tick or one marked invalid
        f_h_nom: nominal_seen(held.nt.map(|m| convert::vec3(&m.f_h)), tr.report.faults),
        tau_b_nom: nominal_seen(held.na.map(|m| convert::vec3(&m.tau_b)), at.report.faults),
        tau_m_nom: nominal_seen(held.nr.map(|m| convert::vec7(&m.tau_m)), rb.report.faults),
        translational: tr,
        attitude: at,
        robotic: rb,
        applied,
        barriers,
        barriers_between: between,
    }
}

/// The subsystems whose filter ran without its nominal or its upstream command at a
/// deadline (`due` bits).
pub fn upstream_missing_mask(rec: &StepRecord) -> u32 {
    let missing = |faults: u32, s: Subsystem| {
        if faults & (faults::UPSTREAM_MISSING | faults::NOMINAL_MISSING) != 0 {
            s.bit()
        } else {
            0
        }
    };
    missing(rec.translational.report.faults, Subsystem::Translational)
        | missing(rec.attitude.report.faults, Subsystem::Attitude)
        | missing(rec.robotic.report.faults, Subsystem::Robotic)
}

/// The line of `latency.csv` of step result `r` (columns [`super::LATENCY_CSV_HEADER`]).
pub fn latency_line(
    r: &StepResult,
    state: &SimState,
    set: &Tickset,
    upstream_missing: u32,
) -> String {
    let ns = |o: Option<u64>| o.map(|x| x.to_string()).unwrap_or_default();
    let safe_recv = if r.safe_recv_ns > 0 {
        r.safe_recv_ns.to_string()
    } else {
        String::new()
    };
    [
        r.tick.to_string(),
        state.tick_send_ns.to_string(),
        state.recv_ns.to_string(),
        state.publish_ns.to_string(),
        ns(set.nt.map(|m| m.publish_ns)),
        ns(set.na.map(|m| m.publish_ns)),
        ns(set.nr.map(|m| m.publish_ns)),
        ns(set.st.map(|m| m.recv_ns)),
        ns(set.st.map(|m| m.publish_ns)),
        ns(set.sa.map(|m| m.recv_ns)),
        ns(set.sa.map(|m| m.publish_ns)),
        ns(set.sr.map(|m| m.recv_ns)),
        ns(set.sr.map(|m| m.publish_ns)),
        safe_recv,
        r.publish_ns.to_string(),
        r.fallback_mask.to_string(),
        r.held_mask.to_string(),
        upstream_missing.to_string(),
    ]
    .join(",")
}
