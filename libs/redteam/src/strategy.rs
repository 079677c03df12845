//! The adversarial strategies and the subsystems they attack, with stable names for the
//! command line and reports (`toward:approach_corridor`, `random:3`, `nonfinite`, …).

use sc_core::{Subsystem, SubsystemSet};
use std::fmt;

/// Which nominal controller(s) the adversary replaces: one subsystem's, or all three.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Target {
    One(Subsystem),
    /// All three at once.
    All,
}

impl Target {
    pub const ALL: [Target; 4] = [
        Target::One(Subsystem::Translational),
        Target::One(Subsystem::Attitude),
        Target::One(Subsystem::Robotic),
        Target::All,
    ];

    /// Stable name: the subsystem's, or `all`.
    pub fn name(&self) -> &'static str {
        match self {
            Target::One(s) => s.name(),
            Target::All => "all",
        }
    }

    /// Parses [`Self::name`].
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == s)
    }

    /// The subsystems whose nominal controllers the adversary replaces.
    pub fn subsystems(&self) -> SubsystemSet {
        match self {
            Target::One(s) => SubsystemSet::only(*s),
            Target::All => SubsystemSet::ALL,
        }
    }

    /// True if the adversary replaces the nominal controller of `s`.
    pub fn attacks(&self, s: Subsystem) -> bool {
        self.subsystems().contains(s)
    }

    /// The constraint names of the subsystem (empty for [`Target::All`]).
    pub fn barrier_names(&self) -> &'static [&'static str] {
        match self {
            Target::One(s) => barrier_names(*s),
            Target::All => &[],
        }
    }
}

/// The constraint names of subsystem `s`, in telemetry order.
pub fn barrier_names(s: Subsystem) -> &'static [&'static str] {
    match s {
        Subsystem::Translational => &sc_cbf::names::TRANSLATIONAL,
        Subsystem::Attitude => &sc_cbf::names::ATTITUDE,
        Subsystem::Robotic => &sc_cbf::names::ROBOTIC,
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a case's name was refused. One line each.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CaseNameError {
    #[error("`{0}`: expected <target>/<strategy>, e.g. {1}")]
    Form(String, &'static str),
    #[error("`{0}` is not a target (translational, attitude, robotic, all)")]
    Target(String),
    #[error(
        "unknown strategy `{0}` (expected toward:<barrier>, greedy, random:<seed>, nonfinite, huge, frozen, stale or silent)"
    )]
    Strategy(String),
    #[error("toward:<barrier> needs one subsystem, not `{0}`")]
    TowardAll(Target),
    #[error("`{barrier}` is not a barrier of the {target} subsystem ({})", .names.join(", "))]
    Barrier {
        barrier: String,
        target: Target,
        names: &'static [&'static str],
    },
    #[error("random:<seed> needs an integer seed, not `{0}`")]
    Seed(String),
    #[error("`{0}`: empty strategy or one with spaces")]
    PartnerStrategy(String),
}

/// What the adversarial nominal controller sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Strategy {
    /// Bang-bang towards one boundary: every step the command (1.5 × the input bound)
    /// that decreases barrier `i` of the subsystem fastest (index into its names).
    Toward(usize),
    /// Towards whichever of the subsystem's barriers is closest to its boundary now
    /// (distance-normalised), switching as the state moves.
    Greedy,
    /// Random saturating: every component ±1.5 × the bound at random each step (seeded).
    Random(u64),
    /// NaN, +∞, −∞ and a single NaN component, in turn.
    NonFinite,
    /// 1e300, then 1000 × the bound, then −1e300, in the greedy direction.
    Huge,
    /// The greedy command of the first step, repeated for ever (a frozen partner).
    Frozen,
    /// The greedy command computed on the observation 10 control steps old (stale).
    Stale,
    /// Nothing at all (a silent or dead partner).
    Silent,
}

/// Control steps by which [`Strategy::Stale`] lags.
pub const STALE_LAG: usize = 10;

impl Strategy {
    /// The strategies that apply to every target (not [`Strategy::Toward`]), with
    /// `seeds` random ones.
    pub fn common(seeds: u64) -> Vec<Strategy> {
        let mut v = vec![Strategy::Greedy];
        v.extend((1..=seeds).map(Strategy::Random));
        v.extend([
            Strategy::NonFinite,
            Strategy::Huge,
            Strategy::Frozen,
            Strategy::Stale,
            Strategy::Silent,
        ]);
        v
    }

    /// Stable name (`toward:<barrier>` needs the target for the barrier's name).
    pub fn name(&self, target: Target) -> String {
        match self {
            Strategy::Toward(i) => format!(
                "toward:{}",
                target.barrier_names().get(*i).copied().unwrap_or("?")
            ),
            Strategy::Greedy => "greedy".into(),
            Strategy::Random(s) => format!("random:{s}"),
            Strategy::NonFinite => "nonfinite".into(),
            Strategy::Huge => "huge".into(),
            Strategy::Frozen => "frozen".into(),
            Strategy::Stale => "stale".into(),
            Strategy::Silent => "silent".into(),
        }
    }

    /// Parses [`Self::name`] for `target`.
    pub fn parse(s: &str, target: Target) -> Result<Self, CaseNameError> {
        if let Some(b) = s.strip_prefix("toward:") {
            let names = target.barrier_names();
            return names
                .iter()
                .position(|n| *n == b)
                .map(Strategy::Toward)
                .ok_or_else(|| match target {
                    Target::All => CaseNameError::TowardAll(target),
                    Target::One(_) => CaseNameError::Barrier {
                        barrier: b.into(),
                        target,
                        names,
                    },
                });
        }
        if let Some(seed) = s.strip_prefix("random:") {
            return seed
                .parse()
                .map(Strategy::Random)
                .map_err(|_| CaseNameError::Seed(seed.into()));
        }
        Ok(match s {
            "greedy" => Strategy::Greedy,
            "nonfinite" => Strategy::NonFinite,
            "huge" => Strategy::Huge,
            "frozen" => Strategy::Frozen,
            "stale" => Strategy::Stale,
            "silent" => Strategy::Silent,
            _ => return Err(CaseNameError::Strategy(s.into())),
        })
    }
}

/// One red-team case: a strategy against a target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Case {
    pub target: Target,
    pub strategy: Strategy,
}

/// What names a case in the reports: its target and its strategy's name. In-process
/// cases are [`Case`]s; the partition's hostile partner processes
/// (`safe-capture redteam --partition`) have strategies of their own.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CaseLabel {
    pub target: Target,
    pub strategy: String,
}

impl CaseLabel {
    /// `<target>/<strategy>`.
    pub fn name(&self) -> String {
        format!("{}/{}", self.target, self.strategy)
    }

    /// The case's directory name under `OUT/cases/` (`/` and `:` are awkward in paths).
    pub fn dir_name(&self) -> String {
        self.name()
            .chars()
            .map(|c| match c {
                '/' => '_',
                ':' => '=',
                c => c,
            })
            .collect()
    }
}

impl Case {
    /// `<target>/<strategy>`, e.g. `robotic/toward:theta_dot_max_7`.
    pub fn name(&self) -> String {
        self.label().name()
    }

    /// The case's name parts.
    pub fn label(&self) -> CaseLabel {
        CaseLabel {
            target: self.target,
            strategy: self.strategy.name(self.target),
        }
    }

    /// Parses [`Self::name`].
    pub fn parse(s: &str) -> Result<Self, CaseNameError> {
        let (t, st) = s
            .split_once('/')
            .ok_or_else(|| CaseNameError::Form(s.into(), "all/greedy"))?;
        let target = Target::parse(t).ok_or_else(|| CaseNameError::Target(t.into()))?;
        Ok(Self {
            target,
            strategy: Strategy::parse(st, target)?,
        })
    }

    /// Every case of the full campaign: each barrier's bang-bang on its subsystem, and the
    /// common strategies (with `seeds` random ones) on each subsystem and on all three.
    pub fn all(seeds: u64) -> Vec<Case> {
        let mut v = Vec::new();
        for target in Target::ALL {
            for i in 0..target.barrier_names().len() {
                v.push(Case {
                    target,
                    strategy: Strategy::Toward(i),
                });
            }
            for strategy in Strategy::common(seeds) {
                v.push(Case { target, strategy });
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for c in Case::all(3) {
            assert_eq!(Case::parse(&c.name()).unwrap(), c, "{}", c.name());
        }
        assert!(Case::parse("all/toward:theta_1").is_err());
        assert!(Case::parse("robotic/toward:approach_corridor").is_err());
        assert!(Case::parse("robotic/random:x").is_err());
        assert!(Case::parse("nowhere/greedy").is_err());
        assert_eq!(Case::all(5).len(), 2 + 7 + 63 + 4 * 11);
    }

    #[test]
    fn a_target_is_one_subsystem_or_all_of_them() {
        for t in Target::ALL {
            assert_eq!(Target::parse(t.name()), Some(t));
        }
        let attitude = Target::parse("attitude").unwrap();
        assert_eq!(attitude, Target::One(Subsystem::Attitude));
        assert!(attitude.attacks(Subsystem::Attitude));
        assert!(!attitude.attacks(Subsystem::Robotic));
        assert_eq!(Target::All.subsystems(), SubsystemSet::ALL);
        assert!(Target::All.barrier_names().is_empty());
        assert_eq!(attitude.barrier_names(), &sc_cbf::names::ATTITUDE);
        let e = Strategy::parse("toward:nothing", attitude).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("`nothing` is not a barrier of the attitude subsystem (")
        );
    }
}
