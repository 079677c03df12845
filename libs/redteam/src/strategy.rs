//! The adversarial strategies and the subsystems they attack, with stable names for the
//! command line and reports (`toward:approach_corridor`, `random:3`, `nonfinite`, …).

use serde::{Deserialize, Serialize};
use std::fmt;

/// Which nominal controller the adversary replaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Target {
    Translational,
    Attitude,
    Robotic,
    /// All three at once.
    All,
}

impl Target {
    pub const ALL: [Target; 4] = [
        Target::Translational,
        Target::Attitude,
        Target::Robotic,
        Target::All,
    ];

    /// Stable name.
    pub fn name(&self) -> &'static str {
        match self {
            Target::Translational => "translational",
            Target::Attitude => "attitude",
            Target::Robotic => "robotic",
            Target::All => "all",
        }
    }

    /// Parses [`Self::name`].
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == s)
    }

    /// True if the adversary replaces subsystem `i` (0 translational, 1 attitude, 2 robotic).
    pub fn covers(&self, i: usize) -> bool {
        matches!(
            (self, i),
            (Target::All, _)
                | (Target::Translational, 0)
                | (Target::Attitude, 1)
                | (Target::Robotic, 2)
        )
    }

    /// The constraint names of the subsystem (empty for [`Target::All`]).
    pub fn barrier_names(&self) -> &'static [&'static str] {
        match self {
            Target::Translational => &sc_cbf::names::TRANSLATIONAL,
            Target::Attitude => &sc_cbf::names::ATTITUDE,
            Target::Robotic => &sc_cbf::names::ROBOTIC,
            Target::All => &[],
        }
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What the adversarial nominal controller sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
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
    pub fn parse(s: &str, target: Target) -> Result<Self, String> {
        let bad = || {
            format!(
                "unknown strategy `{s}` (expected toward:<barrier>, greedy, random:<seed>, nonfinite, huge, frozen, stale or silent)"
            )
        };
        if let Some(b) = s.strip_prefix("toward:") {
            let names = target.barrier_names();
            return names
                .iter()
                .position(|n| *n == b)
                .map(Strategy::Toward)
                .ok_or_else(|| {
                    if names.is_empty() {
                        format!("toward:<barrier> needs one subsystem, not `{target}`")
                    } else {
                        format!(
                            "`{b}` is not a barrier of the {target} subsystem ({})",
                            names.join(", ")
                        )
                    }
                });
        }
        if let Some(seed) = s.strip_prefix("random:") {
            return seed
                .parse()
                .map(Strategy::Random)
                .map_err(|_| format!("random:<seed> needs an integer seed, not `{seed}`"));
        }
        Ok(match s {
            "greedy" => Strategy::Greedy,
            "nonfinite" => Strategy::NonFinite,
            "huge" => Strategy::Huge,
            "frozen" => Strategy::Frozen,
            "stale" => Strategy::Stale,
            "silent" => Strategy::Silent,
            _ => return Err(bad()),
        })
    }
}

/// One red-team case: a strategy against a target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Case {
    pub target: Target,
    pub strategy: Strategy,
}

/// What names a case in the reports: its target and its strategy's name. In-process
/// cases are [`Case`]s; the partition's hostile partner processes
/// (`safe-capture redteam --partition`) have strategies of their own.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
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
    pub fn parse(s: &str) -> Result<Self, String> {
        let (t, st) = s
            .split_once('/')
            .ok_or_else(|| format!("`{s}`: expected <target>/<strategy>, e.g. all/greedy"))?;
        let target = Target::parse(t).ok_or_else(|| {
            format!("`{t}` is not a target (translational, attitude, robotic, all)")
        })?;
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
        assert_eq!(Case::all(5).len(), 2 + 7 + 42 + 4 * 11);
    }
}
