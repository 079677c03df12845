//! The telemetry recorder: rebuilds every step's `StepRecord` from the messages and
//! writes the same telemetry.csv / timing.csv / summary.json as `safe-capture run`,
//! plus latency.csv (the stamps of every hop) and recorder.json (counts).

use anyhow::Context;
use sc_bus::{Subscriber, Waiter};
use sc_cbf::{AttitudeOutput, RoboticOutput, SafetyLayer, TranslationalOutput};
use sc_flight::convert;

use sc_flight::process::{Proc, partner_qos, qos, wait};
use sc_icd::*;
use sc_mission::{MissionEnd, StepRecord, TelemetryWriter, summarize};
use std::collections::BTreeMap;
use std::io::Write;
use std::time::{Duration, Instant};

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

#[derive(Default)]
struct Tickset {
    state: Option<SimState>,
    nt: Option<NominalTranslational>,
    na: Option<NominalAttitude>,
    nr: Option<NominalRobotic>,
    st: Option<SafeTranslational>,
    sa: Option<SafeAttitude>,
    sr: Option<SafeRobotic>,
}

/// The columns of latency.csv: the stamps of every hop of a tick [ns] and its masks.
pub const LATENCY_CSV_HEADER: &str = "tick,tick_send_ns,sim_recv_ns,state_publish_ns,nom_t_publish_ns,nom_a_publish_ns,nom_r_publish_ns,safe_t_recv_ns,safe_t_publish_ns,safe_a_recv_ns,safe_a_publish_ns,safe_r_recv_ns,safe_r_publish_ns,sim_safe_recv_ns,result_publish_ns,fallback_mask,held_mask,upstream_missing_mask";

/// Name of the MCAP `Metadata` record describing the run ([`run_metadata`]).
pub const MCAP_METADATA_NAME: &str = "safe-capture";

/// The run as MCAP metadata: the build (`version`, `git_commit`), the scenario (its
/// resolved path and full text, so a recording replays without the file) and the
/// partition config (its path and full text).
fn run_metadata(p: &Proc) -> anyhow::Result<BTreeMap<String, String>> {
    let build = sc_mission::build::current();
    let scenario_path = p.cfg.scenario_path();
    let read = |path: &std::path::Path| {
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
    };
    Ok(BTreeMap::from([
        ("version".to_string(), build.version),
        ("git_commit".to_string(), build.git_commit),
        (
            "scenario_path".to_string(),
            scenario_path.display().to_string(),
        ),
        ("scenario".to_string(), read(&scenario_path)?),
        (
            "partition_config_path".to_string(),
            path_in_out(&p.config_path, &p.out),
        ),
        ("partition_config".to_string(), read(&p.config_path)?),
    ]))
}

/// `path` as the recording names it: relative to the output folder `out` when it is in
/// it (the launcher's effective config), since the launcher renames that folder after
/// the run (`OUT.incomplete` → `OUT`); as given otherwise.
fn path_in_out(path: &std::path::Path, out: &std::path::Path) -> String {
    path.strip_prefix(out).unwrap_or(path).display().to_string()
}

pub fn recorder() -> anyhow::Result<i32> {
    let p = Proc::start("recorder")?;
    // MCAP log time: the mission's own clock (tick × base period), so that a recording
    // plays back at mission time in Foxglove; the host's clock stays in publish_time
    let period_ns = (p.schedule.base_period_s * 1e9).round() as u64;
    let mission_ns = move |tick: u64| tick.saturating_mul(period_ns);
    let q = qos();
    let partner_q = partner_qos();
    let tick_rx = Subscriber::<Tick>::polled(&p.node, services::TICK, &q)?;
    let state_rx = Subscriber::<SimState>::polled(&p.node, services::SIM_STATE, &q)?;
    let nt_rx = Subscriber::<NominalTranslational>::polled(
        &p.node,
        services::NOMINAL_TRANSLATIONAL,
        &partner_q,
    )?;
    let na_rx =
        Subscriber::<NominalAttitude>::polled(&p.node, services::NOMINAL_ATTITUDE, &partner_q)?;
    let nr_rx =
        Subscriber::<NominalRobotic>::polled(&p.node, services::NOMINAL_ROBOTIC, &partner_q)?;
    let st_rx = Subscriber::<SafeTranslational>::polled(&p.node, services::SAFE_TRANSLATIONAL, &q)?;
    let sa_rx = Subscriber::<SafeAttitude>::polled(&p.node, services::SAFE_ATTITUDE, &q)?;
    let sr_rx = Subscriber::<SafeRobotic>::polled(&p.node, services::SAFE_ROBOTIC, &q)?;
    let res_rx = Subscriber::<StepResult>::new(&p.node, services::STEP_RESULT, &q)?;
    // progress for the scheduler's lock-step flow control
    let health_tx = sc_bus::Publisher::<Health>::new(&p.node, services::HEALTH, &q)?;
    let waiter = Waiter::new()?;
    // Wake only on step results: every message of a tick was sent before its step
    // result, so the recorder drains them all then, once per tick and off the
    // critical path of the tick (the buffers of 16 hold them). The tick queue (for
    // the stop) is read at every wake-up; the simulator wakes it once when it stops.
    let _a = waiter.attach(&res_rx)?;
    std::fs::create_dir_all(&p.out)
        .with_context(|| format!("cannot create {}", p.out.display()))?;
    let open = |name: &str| -> anyhow::Result<std::io::BufWriter<std::fs::File>> {
        let path = p.out.join(name);
        Ok(std::io::BufWriter::new(
            std::fs::File::create(&path)
                .with_context(|| format!("cannot create {}", path.display()))?,
        ))
    };
    let mut writer = TelemetryWriter::new(open("telemetry.csv")?, open("timing.csv")?)?;
    let mut latency = open("latency.csv")?;
    writeln!(latency, "{LATENCY_CSV_HEADER}")?;
    let mut layer = SafetyLayer::from_scenario(&p.setup.scenario, p.setup.robot.clone());
    let phase_names: Vec<String> = p
        .setup
        .scenario
        .mission
        .phases
        .iter()
        .map(|x| x.name.clone())
        .collect();
    p.handshake()?;
    // The MCAP is created only once the partition has started: a start that fails
    // (or a recorder killed in the handshake) leaves no recording.mcap behind, rather
    // than an empty one (its header sits in the write buffer until the first chunk).
    let mut mcap = crate::mcap_out::McapOut::create(&p.out.join("recording.mcap"))?;
    mcap.write_metadata(MCAP_METADATA_NAME, run_metadata(&p)?)?;
    // the scenario's corridor, zone, line of sight and grasping point for the 3D panel
    mcap.set_scene(&p.setup.scenario);
    let mut rep = RecorderReport::default();
    let mut pending: BTreeMap<u64, Tickset> = BTreeMap::new();
    let mut queued: Vec<StepResult> = Vec::new();
    let mut queued_since: Option<Instant> = None;
    let mut records: Vec<StepRecord> = Vec::new();
    let mut end: Option<MissionEnd> = None;
    let mut last_t = 0.0;
    // held values for slower rate groups
    let mut h = Tickset::default();
    let mut stop = false;
    let mut final_pass = false;
    // required (service, tick) pairs not there when their step was written
    let mut absent_at_write: std::collections::BTreeSet<(&'static str, u64)> = Default::default();
    let count = |rep: &mut RecorderReport, s: &str, n: usize| {
        *rep.recorded.entry(s.to_string()).or_default() += n as u64
    };
    loop {
        // a result whose tick misses a required message waits briefly: a publisher
        // delivers to its subscribers one after the other, so the simulator may have
        // answered before the same sample reached the recorder's queue
        let until = (!queued.is_empty()).then(|| Instant::now() + Duration::from_millis(1));
        if !final_pass && !stop && !wait(&waiter, until)? {
            break;
        }
        // step results first: everything of their tick was sent before them
        res_rx.drain_events()?;
        let n_before = queued.len();
        res_rx.receive_all(&mut queued)?;
        count(
            &mut rep,
            services::STEP_RESULT.as_str(),
            queued.len() - n_before,
        );
        macro_rules! take {
            ($rx:expr, $field:ident, $svc:expr $(, $also:ident)?) => {{
                $rx.drain_events()?;
                let mut v = Vec::new();
                $rx.receive_all(&mut v)?;
                count(&mut rep, $svc.as_str(), v.len());
                for m in v {
                    if absent_at_write.remove(&($svc.as_str(), m.tick)) {
                        *rep.late.entry($svc.as_str().into()).or_default() += 1;
                    }
                    mcap.write($svc.as_str(), mission_ns(m.tick), m.publish_ns, &m)?;
                    $( mcap.$also(mission_ns(m.tick), m.publish_ns, &m)?; )?
                    pending.entry(m.tick).or_default().$field = Some(m);
                }
            }};
        }
        // the 3D panel's frames (and scene), from each state
        take!(state_rx, state, services::SIM_STATE, write_3d);
        take!(nt_rx, nt, services::NOMINAL_TRANSLATIONAL);
        take!(na_rx, na, services::NOMINAL_ATTITUDE);
        take!(nr_rx, nr, services::NOMINAL_ROBOTIC);
        take!(st_rx, st, services::SAFE_TRANSLATIONAL);
        take!(sa_rx, sa, services::SAFE_ATTITUDE);
        take!(sr_rx, sr, services::SAFE_ROBOTIC);
        tick_rx.drain_events()?;
        let mut ticks = Vec::new();
        tick_rx.receive_all(&mut ticks)?;
        count(&mut rep, services::TICK.as_str(), ticks.len());
        for t in &ticks {
            mcap.write(services::TICK.as_str(), mission_ns(t.tick), t.send_ns, t)?;
            if t.command == tick_command::STOP {
                stop = true;
            }
        }
        let mut results = Vec::new();
        while let Some(r) = queued.first().copied() {
            let complete = pending.get(&r.tick).is_some_and(|set| {
                let Some(st) = set.state else { return false };
                // due subsystem: its safe command (unless the simulator used the
                // backup) and its nominal command (unless the filter flagged it missing)
                let missing_flag =
                    sc_cbf::faults::UPSTREAM_MISSING | sc_cbf::faults::NOMINAL_MISSING;
                let need = |bit: u32, nom: bool, safe: Option<u32>| {
                    st.due_mask & bit == 0
                        || r.fallback_mask & bit != 0
                        || safe.is_some_and(|f| nom || f & missing_flag != 0)
                };
                need(
                    due::TRANSLATIONAL,
                    set.nt.is_some(),
                    set.st.map(|m| m.fault_flags),
                ) && need(
                    due::ATTITUDE,
                    set.na.is_some(),
                    set.sa.map(|m| m.fault_flags),
                ) && need(
                    due::ROBOTIC,
                    set.nr.is_some(),
                    set.sr.map(|m| m.fault_flags),
                )
            });
            let waited =
                queued_since.is_some_and(|t: Instant| t.elapsed() > Duration::from_millis(200));
            if complete || waited || stop || final_pass {
                results.push(r);
                queued.remove(0);
                queued_since = None;
            } else {
                queued_since.get_or_insert_with(Instant::now);
                break;
            }
        }
        for r in results {
            mcap.write(
                services::STEP_RESULT.as_str(),
                mission_ns(r.tick),
                r.publish_ns,
                &r,
            )?;
            let set = pending.remove(&r.tick).unwrap_or_default();
            // this step is taken care of (written below, or skipped and reported)
            sc_flight::process::send(
                &health_tx,
                &Health {
                    role: Role::of(RoleKind::Recorder).id(),
                    pid: std::process::id(),
                    state: health_state::RUNNING,
                    last_fault_flags: 0,
                    ticks_handled: rep.steps + 1,
                    deadline_misses: 0,
                    cycle_slips: 0,
                    last_tick: r.tick,
                    publish_ns: monotonic_ns(),
                },
            )?;
            // drop anything older (late messages of steps already written)
            pending.retain(|k, _| *k > r.tick);
            let Some(state) = set.state else {
                eprintln!(
                    "recorder: FAULT tick {}: no state recorded, step skipped",
                    r.tick
                );
                continue;
            };
            let o = convert::observation(&state);
            {
                let due = state.due_mask;
                let mut need = |svc: ServiceName, due_bit: u32, present: bool| {
                    if due_bit == 0 || due & due_bit != 0 {
                        *rep.expected.entry(svc.as_str().into()).or_default() += 1;
                        rep.missing.entry(svc.as_str().into()).or_default();
                        if !present {
                            absent_at_write.insert((svc.as_str(), r.tick));
                        }
                    }
                };
                need(services::SIM_STATE, 0, true);
                need(services::STEP_RESULT, 0, true);
                need(
                    services::NOMINAL_TRANSLATIONAL,
                    due::TRANSLATIONAL,
                    set.nt.is_some(),
                );
                need(services::NOMINAL_ATTITUDE, due::ATTITUDE, set.na.is_some());
                need(services::NOMINAL_ROBOTIC, due::ROBOTIC, set.nr.is_some());
                need(
                    services::SAFE_TRANSLATIONAL,
                    due::TRANSLATIONAL,
                    set.st.is_some(),
                );
                need(services::SAFE_ATTITUDE, due::ATTITUDE, set.sa.is_some());
                need(services::SAFE_ROBOTIC, due::ROBOTIC, set.sr.is_some());
            }
            if let Some(x) = set.nt {
                h.nt = Some(x);
            }
            if let Some(x) = set.na {
                h.na = Some(x);
            }
            if let Some(x) = set.nr {
                h.nr = Some(x);
            }
            let applied = convert::applied(&r);
            let tr: TranslationalOutput = match set.st {
                // the simulator applied the backup (the command was missing at its
                // deadline, or it rejected the one that came): that is what was applied
                _ if r.fallback_mask & due::TRANSLATIONAL != 0 => layer.backup_translational(&o),
                Some(m) => {
                    h.st = Some(m);
                    convert::filter_output(&m)
                }
                None => {
                    h.st.map(|m| convert::filter_output(&m))
                        .unwrap_or_else(|| layer.backup_translational(&o))
                }
            };
            let at: AttitudeOutput = match set.sa {
                // the simulator applied the backup (the command was missing at its
                // deadline, or it rejected the one that came): that is what was applied
                _ if r.fallback_mask & due::ATTITUDE != 0 => {
                    layer.backup_attitude(&o, &applied.force_b)
                }
                Some(m) => {
                    h.sa = Some(m);
                    convert::filter_output(&m)
                }
                None => {
                    h.sa.map(|m| convert::filter_output(&m))
                        .unwrap_or_else(|| layer.backup_attitude(&o, &applied.force_b))
                }
            };
            let rb: RoboticOutput = match set.sr {
                // the simulator applied the backup (the command was missing at its
                // deadline, or it rejected the one that came): that is what was applied
                _ if r.fallback_mask & due::ROBOTIC != 0 => {
                    layer.backup_robotic(&o, &applied.force_b, &applied.torque_b)
                }
                Some(m) => {
                    h.sr = Some(m);
                    convert::filter_output(&m)
                }
                None => h.sr.map(|m| convert::filter_output(&m)).unwrap_or_else(|| {
                    layer.backup_robotic(&o, &applied.force_b, &applied.torque_b)
                }),
            };
            // the mission's own schedule, as the simulator decides it
            let phase = p.setup.scenario.phase_index(o.t);
            let rec = StepRecord {
                step: o.step,
                t: o.t,
                phase,
                obs: o,
                // what the filter got: NaN where it ran on the substitute nominal (as
                // in process), never a message of another tick or one marked invalid
                f_h_nom: nominal_seen(h.nt.map(|m| convert::vec3(&m.f_h)), tr.report.faults),
                tau_b_nom: nominal_seen(h.na.map(|m| convert::vec3(&m.tau_b)), at.report.faults),
                tau_m_nom: nominal_seen(h.nr.map(|m| convert::vec7(&m.tau_m)), rb.report.faults),
                translational: tr,
                attitude: at,
                robotic: rb,
                applied,
                barriers: state.barriers,
                barriers_between: state.barriers_between,
            };
            writer.write(&rec)?;
            writer.flush()?;
            rep.steps += 1;
            if r.fallback_mask != 0 {
                rep.fallback_steps += 1;
            }
            if (tr.report.faults | at.report.faults | rb.report.faults)
                & sc_cbf::faults::UPSTREAM_MISSING
                != 0
            {
                rep.upstream_missing_steps += 1;
            }
            let ns = |o: Option<u64>| o.map(|x| x.to_string()).unwrap_or_default();
            // the filters that used a fallback for an input missing at their deadline
            // a filter that ran without its nominal or its upstream command at a deadline
            let missing = |faults: u32, bit: u32| {
                if faults & (sc_cbf::faults::UPSTREAM_MISSING | sc_cbf::faults::NOMINAL_MISSING)
                    != 0
                {
                    bit
                } else {
                    0
                }
            };
            let upstream_missing_mask = missing(tr.report.faults, due::TRANSLATIONAL)
                | missing(at.report.faults, due::ATTITUDE)
                | missing(rb.report.faults, due::ROBOTIC);
            writeln!(
                latency,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                r.tick,
                state.tick_send_ns,
                state.recv_ns,
                state.publish_ns,
                ns(set.nt.map(|m| m.publish_ns)),
                ns(set.na.map(|m| m.publish_ns)),
                ns(set.nr.map(|m| m.publish_ns)),
                ns(set.st.map(|m| m.recv_ns)),
                ns(set.st.map(|m| m.publish_ns)),
                ns(set.sa.map(|m| m.recv_ns)),
                ns(set.sa.map(|m| m.publish_ns)),
                ns(set.sr.map(|m| m.recv_ns)),
                ns(set.sr.map(|m| m.publish_ns)),
                if r.safe_recv_ns > 0 {
                    r.safe_recv_ns.to_string()
                } else {
                    String::new()
                },
                r.publish_ns,
                r.fallback_mask,
                r.held_mask,
                upstream_missing_mask
            )?;
            records.push(rec);
            last_t = r.t;
            // the first end counts (with max_ticks the run goes on after it)
            end = end.or(match r.end {
                end::CAPTURED => Some(MissionEnd::Captured { t: r.t }),
                end::TIMEOUT => Some(MissionEnd::Timeout { t: r.t }),
                end::SIMULATOR_FAILED => Some(MissionEnd::SimulatorFailed {
                    t: r.t,
                    message: "simulator failed".into(),
                }),
                _ => None,
            });
        }
        if final_pass {
            break;
        }
        if stop {
            // one more pass: a step result sent just before the stop is not lost
            final_pass = true;
        }
    }
    for (svc, _) in &absent_at_write {
        *rep.missing.entry((*svc).into()).or_default() += 1;
    }
    writer.flush()?;
    latency.flush()?;
    mcap.finish()?;
    // no end of the mission: the run was stopped before it (the scheduler's stop tick
    // at --max-ticks or after losing a process, or the launcher's teardown); the
    // launcher, which knows whether it was interrupted, says so (`mark_interrupted`)
    let end = end.unwrap_or(MissionEnd::Stopped { t: last_t });
    let summary = summarize(&records, &end, &phase_names, true);
    std::fs::write(
        p.out.join("summary.json"),
        serde_json::to_string_pretty(&summary)? + "\n",
    )
    .context("writing summary.json")?;
    rep.end = summary.end.clone();
    std::fs::write(
        p.out.join("recorder.json"),
        serde_json::to_string_pretty(&rep)? + "\n",
    )
    .context("writing recorder.json")?;
    let safe = summary.violated_constraints.is_empty() && summary.fault_count == 0;
    let missing: u64 = rep.missing.values().sum();
    let late: u64 = rep.late.values().sum();
    eprintln!(
        "recorder: recorded per service {:?}; missing {missing} of the samples the schedule requires, {late} late",
        rep.recorded
    );
    eprintln!(
        "recorder: {} steps, {} at t = {:.1} s; min margin {} = {:.3e}; faults {}",
        rep.steps,
        summary.end,
        summary.final_time_s,
        summary.min_margin.0,
        summary.min_margin.1,
        summary.fault_count
    );
    Ok(if safe && summary.captured { 0 } else { 1 })
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

#[cfg(test)]
mod tests {
    use super::path_in_out;
    use std::path::Path;

    /// The effective config is named relative to the output folder, which the launcher
    /// renames after the run; a file elsewhere keeps its path.
    #[test]
    fn a_path_in_the_output_folder_is_relative_to_it() {
        let out = Path::new("/runs/out.incomplete");
        assert_eq!(
            path_in_out(&out.join("partition.effective.toml"), out),
            "partition.effective.toml"
        );
        assert_eq!(
            path_in_out(Path::new("/etc/partition.toml"), out),
            "/etc/partition.toml"
        );
        // a sibling whose name starts like the folder's is not in it
        assert_eq!(
            path_in_out(Path::new("/runs/out.incomplete2/p.toml"), out),
            "/runs/out.incomplete2/p.toml"
        );
    }
}
