//! The partition's red team: hostile partner processes (`scripts/python/hostile_nominal.py`)
//! in place of the nominal controllers. A case names the process's `--strategy`, which is
//! `<values>[+<behaviour>…]`: what it sends (bang-bang towards a boundary, random
//! saturating, non-finite, huge) and how it misbehaves as a process (crash, hang, silence,
//! bursts, late, stale or wrong ticks, garbage fields). The script's docstring defines each.
//!
//! A case runs through the process partition ([`HostilePartners`] gives its nominal
//! source, `sc_ground::executor::Partition` runs it) and is measured by
//! [`crate::campaign::measure`], the same as in process.

use crate::strategy::{CaseLabel, CaseNameError, Target};
use sc_core::Subsystem;
use sc_mission::{NominalSource, PartnerProcess};
use std::path::PathBuf;

/// The value strategies that aim at a subsystem's own boundaries (1.5 × the input bound).
fn bangs(target: Target) -> &'static [&'static str] {
    match target {
        Target::One(Subsystem::Translational) => &["toward_zone", "off_corridor"],
        Target::One(Subsystem::Attitude) => &["spin:x", "spin:-y", "spin:z"],
        Target::One(Subsystem::Robotic) => &["joints:1", "joints:-1", "joint:7", "joint:-2"],
        // one process per role: only the values every role understands
        Target::All => &[],
    }
}

/// Every case of the partition campaign, `seeds` random ones per target: each target's
/// bang-bang strategies; random, non-finite and huge values; and the process faults —
/// silence, a crash and a hang mid-run, bursts of 40 messages per state, answers
/// 250 ms late every 50th state, frozen and stale values, old and future tick labels,
/// garbage `valid`/`phase`/`t` fields, and an attempt to publish on its filter's
/// safe-command service (impersonation). `ticks` is the run's length (the faults happen
/// at a quarter of it).
pub fn partition_cases(seeds: u64, ticks: u64) -> Vec<CaseLabel> {
    let at = (ticks / 4).max(1);
    let mut v = Vec::new();
    for target in Target::ALL {
        let aim = bangs(target).first().copied().unwrap_or("random:1");
        let mut s: Vec<String> = bangs(target).iter().map(|b| b.to_string()).collect();
        s.extend((1..=seeds).map(|k| format!("random:{k}")));
        s.extend(["nonfinite".into(), "huge".into(), "silent".into()]);
        s.extend([
            format!("{aim}+crash:{at}"),
            format!("{aim}+hang:{at}"),
            format!("{aim}+burst:40"),
            format!("{aim}+late:250:50"),
            format!("{aim}+frozen"),
            format!("{aim}+stale:10"),
            format!("{aim}+old_tick:10"),
            format!("{aim}+future_tick"),
            format!("{aim}+garbage"),
            format!("{aim}+impersonate"),
        ]);
        v.extend(s.into_iter().map(|strategy| CaseLabel { target, strategy }));
    }
    v
}

/// Parses `<target>/<strategy>` of a partition case (the strategy itself is checked by
/// the hostile process, `hostile_nominal.py --check`).
pub fn parse_partition_case(s: &str) -> Result<CaseLabel, CaseNameError> {
    let (t, st) = s
        .split_once('/')
        .ok_or_else(|| CaseNameError::Form(s.into(), "all/random:1+burst:40"))?;
    let target = Target::parse(t).ok_or_else(|| CaseNameError::Target(t.into()))?;
    if st.is_empty() || st.contains(char::is_whitespace) {
        return Err(CaseNameError::PartnerStrategy(s.into()));
    }
    Ok(CaseLabel {
        target,
        strategy: st.into(),
    })
}

/// The hostile partner program: `python script --role <subsystem> --strategy <s>`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostilePartners {
    /// Python interpreter with the `iceoryx2` package.
    pub python: PathBuf,
    /// `hostile_nominal.py`.
    pub script: PathBuf,
}

impl HostilePartners {
    /// The script's arguments for the nominal controller of `s` playing `strategy`.
    pub fn args(&self, s: Subsystem, strategy: &str) -> Vec<String> {
        vec![
            self.script.display().to_string(),
            "--role".into(),
            s.name().into(),
            "--strategy".into(),
            strategy.into(),
        ]
    }

    /// One hostile process per subsystem the case attacks, in causal order.
    pub fn processes(&self, case: &CaseLabel) -> Vec<PartnerProcess> {
        case.target
            .subsystems()
            .iter()
            .map(|s| PartnerProcess {
                subsystem: s,
                program: self.python.clone(),
                args: self.args(s, &case.strategy),
            })
            .collect()
    }

    /// The case's nominal source: its hostile processes.
    pub fn nominals(&self, case: &CaseLabel) -> NominalSource {
        NominalSource::Partners(self.processes(case))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_campaign_covers_every_target_with_process_faults() {
        let cases = partition_cases(2, 2400);
        for target in Target::ALL {
            for fault in [
                "silent",
                "crash:600",
                "hang:600",
                "burst:",
                "late:",
                "frozen",
                "stale:",
                "old_tick:",
                "future_tick",
                "garbage",
                "impersonate",
                "nonfinite",
                "huge",
                "random:2",
            ] {
                assert!(
                    cases
                        .iter()
                        .any(|c| c.target == target && c.strategy.contains(fault)),
                    "{target}: no case with {fault}"
                );
            }
        }
        for c in &cases {
            assert_eq!(parse_partition_case(&c.name()).unwrap(), *c);
        }
        assert!(parse_partition_case("nowhere/zero").is_err());
        assert!(parse_partition_case("all/").is_err());
        assert!(parse_partition_case("robotic").is_err());
    }
}
