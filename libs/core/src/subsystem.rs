//! The subsystem as a type.

/// One of the three subsystems of the servicer (paper Sec. "Problem Statement"), each with
/// its nominal controller and its safety filter. The order of the variants is the causal
/// order of the safety layer: translational → attitude → robotic; each downstream filter
/// takes the upstream safe commands as its known coupling ξ (paper eq.
/// "control-affine system").
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Subsystem {
    /// Relative translational motion, input the force `f_H` (paper eq. "rel motion system").
    Translational,
    /// Attitude, input the body torque `τ_B` (paper eqs. "Attitude kinematics/dynamics").
    Attitude,
    /// The 7-DoF arm, input the joint torques `τ_M`.
    Robotic,
}

impl Subsystem {
    /// All three, in causal order.
    pub const ALL: [Subsystem; 3] = [
        Subsystem::Translational,
        Subsystem::Attitude,
        Subsystem::Robotic,
    ];

    /// The stable name (configs, telemetry, service names, the CLI).
    pub const fn name(self) -> &'static str {
        match self {
            Subsystem::Translational => "translational",
            Subsystem::Attitude => "attitude",
            Subsystem::Robotic => "robotic",
        }
    }

    /// Parses [`Self::name`].
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|x| x.name() == s)
    }

    /// Position in the causal order (0, 1, 2): the layout of arrays and bit masks that
    /// cross a process boundary or a file (the ICD's due bits, telemetry columns).
    pub const fn position(self) -> usize {
        self as usize
    }

    /// The bit of this subsystem in a [`SubsystemSet`] (and in the ICD's due masks).
    pub const fn bit(self) -> u32 {
        1 << self.position()
    }

    /// The filter whose safe command is this one's coupling input just upstream, if any.
    pub const fn upstream(self) -> Option<Subsystem> {
        match self {
            Subsystem::Translational => None,
            Subsystem::Attitude => Some(Subsystem::Translational),
            Subsystem::Robotic => Some(Subsystem::Attitude),
        }
    }

    /// Every subsystem upstream of this one, in causal order.
    pub fn upstream_all(self) -> impl Iterator<Item = Subsystem> {
        Self::ALL.into_iter().filter(move |s| *s < self)
    }

    /// Dimension of the subsystem's command: 3 (`f_H`), 3 (`τ_B`), 7 (`τ_M`).
    pub const fn command_dim(self) -> usize {
        match self {
            Subsystem::Translational | Subsystem::Attitude => 3,
            Subsystem::Robotic => 7,
        }
    }
}

impl core::fmt::Display for Subsystem {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// A set of subsystems, as a bit mask of [`Subsystem::bit`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SubsystemSet(u32);

impl SubsystemSet {
    /// No subsystem.
    pub const NONE: SubsystemSet = SubsystemSet(0);
    /// All three.
    pub const ALL: SubsystemSet = SubsystemSet(0b111);

    /// The set of one subsystem.
    pub const fn only(s: Subsystem) -> Self {
        SubsystemSet(s.bit())
    }

    /// From a bit mask (bits beyond the three subsystems are dropped).
    pub const fn from_bits(bits: u32) -> Self {
        SubsystemSet(bits & Self::ALL.0)
    }

    /// The bit mask.
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// Whether `s` is in the set.
    pub const fn contains(self, s: Subsystem) -> bool {
        self.0 & s.bit() != 0
    }

    /// The set with `s` added.
    pub const fn with(self, s: Subsystem) -> Self {
        SubsystemSet(self.0 | s.bit())
    }

    /// True for the empty set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The members, in causal order.
    pub fn iter(self) -> impl Iterator<Item = Subsystem> {
        Subsystem::ALL
            .into_iter()
            .filter(move |s| self.contains(*s))
    }
}

impl FromIterator<Subsystem> for SubsystemSet {
    fn from_iter<I: IntoIterator<Item = Subsystem>>(it: I) -> Self {
        it.into_iter().fold(SubsystemSet::NONE, SubsystemSet::with)
    }
}

/// One value per subsystem, indexed by [`Subsystem`] (the typed form of a `[T; 3]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct PerSubsystem<T>(pub [T; 3]);

impl<T> PerSubsystem<T> {
    /// `f(s)` for every subsystem.
    pub fn from_fn(mut f: impl FnMut(Subsystem) -> T) -> Self {
        PerSubsystem(Subsystem::ALL.map(&mut f))
    }

    /// The values with their subsystems, in causal order.
    pub fn iter(&self) -> impl Iterator<Item = (Subsystem, &T)> {
        Subsystem::ALL.into_iter().zip(self.0.iter())
    }

    /// Each value mapped.
    pub fn map<U>(self, f: impl FnMut(T) -> U) -> PerSubsystem<U> {
        PerSubsystem(self.0.map(f))
    }

    /// The values in causal order (the layout of files and messages).
    pub fn as_array(&self) -> &[T; 3] {
        &self.0
    }
}

impl<T> core::ops::Index<Subsystem> for PerSubsystem<T> {
    type Output = T;
    fn index(&self, s: Subsystem) -> &T {
        &self.0[s.position()]
    }
}

impl<T> core::ops::IndexMut<Subsystem> for PerSubsystem<T> {
    fn index_mut(&mut self, s: Subsystem) -> &mut T {
        &mut self.0[s.position()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_bits_and_causal_order() {
        for (i, s) in Subsystem::ALL.into_iter().enumerate() {
            assert_eq!(s.position(), i);
            assert_eq!(Subsystem::parse(s.name()), Some(s));
            assert_eq!(s.bit(), 1 << i);
            assert_eq!(s.upstream_all().count(), i);
        }
        assert_eq!(Subsystem::parse("robot"), None);
        assert_eq!(Subsystem::Robotic.upstream(), Some(Subsystem::Attitude));
        assert_eq!(Subsystem::Translational.upstream(), None);
    }

    #[test]
    fn sets_and_per_subsystem_values() {
        let s: SubsystemSet = [Subsystem::Attitude, Subsystem::Robotic]
            .into_iter()
            .collect();
        assert_eq!(s.bits(), 0b110);
        assert!(!s.contains(Subsystem::Translational));
        assert_eq!(
            s.iter().collect::<Vec<_>>(),
            vec![Subsystem::Attitude, Subsystem::Robotic]
        );
        assert_eq!(SubsystemSet::from_bits(0xff), SubsystemSet::ALL);
        let mut p = PerSubsystem::from_fn(|s| s.command_dim());
        assert_eq!(p[Subsystem::Robotic], 7);
        p[Subsystem::Attitude] += 1;
        assert_eq!(p.0, [3, 4, 7]);
    }
}
