//! The role table: every process role of the partition, once. Config validation, the
//! launcher's start order, the preflight, the handshake ids, the C header's and the
//! Python module's role constants and the docs' role table all come from [`ROLES`].
//!
//! Adding a role is one row here, one component (its logic) and one executable that runs
//! it (docs/ARCHITECTURE.md, "Adding a role").

use crate::services::{self, ServiceName};
use sc_core::Subsystem;

/// What a role does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RoleKind {
    /// Rate groups, the ticks, the handshake, the end of the run, the peers' liveness.
    Scheduler,
    /// The plant in the loop: applies the safe commands, measures the state, admits the
    /// navigation's estimate and publishes the knowledge derived from it.
    Simulator,
    /// The navigation: turns the measurements into the estimate the controllers and
    /// filters act on; replaceable by a partner's estimator.
    Navigation,
    /// A nominal controller; replaceable by a partner's process.
    Nominal(Subsystem),
    /// A safety filter.
    Filter(Subsystem),
    /// The telemetry recorder (a ground tool: CSV, MCAP, summary).
    Recorder,
}

/// How often a role works.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rate {
    /// Every tick of the fastest rate group (the simulator's step).
    Base,
    /// At the period of the subsystem's rate group.
    Group(Subsystem),
}

/// One row of the role table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Role {
    /// Config key (`[roles.<name>]`), iceoryx2 node name, log file name.
    pub name: &'static str,
    pub kind: RoleKind,
    /// The executable that serves the role unless the partition config names another.
    pub exec: &'static str,
    /// Services it publishes (pub/sub and events).
    pub publishes: &'static [ServiceName],
    /// Services it subscribes to.
    pub subscribes: &'static [ServiceName],
    pub rate: Rate,
    /// Part of the flight software (false: a ground tool, e.g. the recorder).
    pub flight: bool,
    /// A partner may replace it with a process of its own (docs/PARTNER.md).
    pub partner: bool,
    /// One line on what it is.
    pub doc: &'static str,
}

impl Role {
    /// The role's id: its position in [`ROLES`] (the start order); the handshake
    /// participant id and `Health::role`.
    pub fn id(&self) -> u32 {
        ROLES
            .iter()
            .position(|r| r.name == self.name)
            .map_or(u32::MAX, |i| i as u32)
    }

    /// The subsystem it serves, if any.
    pub fn subsystem(&self) -> Option<Subsystem> {
        match self.kind {
            RoleKind::Nominal(s) | RoleKind::Filter(s) => Some(s),
            _ => None,
        }
    }

    /// The role of `kind` (every kind has exactly one row; checked by a test).
    pub fn of(kind: RoleKind) -> &'static Role {
        ROLES.iter().find(|r| r.kind == kind).unwrap_or(&ROLES[0])
    }

    /// The role named `name`.
    pub fn named(name: &str) -> Option<&'static Role> {
        ROLES.iter().find(|r| r.name == name)
    }

    /// The role with id `id`.
    pub fn with_id(id: u32) -> Option<&'static Role> {
        ROLES.get(id as usize)
    }

    /// The name in upper snake case (C and Python constants: `ROLE_<NAME>`).
    pub fn constant_name(&self) -> String {
        self.name.to_ascii_uppercase()
    }
}

use services::{
    CONTROL, ESTIMATE, HANDSHAKE, HEALTH, MEASUREMENT, NAVIGATION_ERROR, NOMINAL_ATTITUDE,
    NOMINAL_ROBOTIC, NOMINAL_TRANSLATIONAL, PARTNER_STATE, PREPARE, SAFE_ATTITUDE, SAFE_ROBOTIC,
    SAFE_TRANSLATIONAL, SIM_STATE, STAGE_DEADLINE, STEP_RESULT, TICK, TRUTH,
};

/// Every role of the partition, in start order (the scheduler, the handshake's
/// coordinator, first). A role's id is its position.
/// New roles are appended: the ids of the others stay those partners' processes were
/// built with.
pub const ROLES: [Role; 10] = [
    Role {
        name: "scheduler",
        kind: RoleKind::Scheduler,
        exec: "sc-scheduler",
        publishes: &[TICK, CONTROL, STAGE_DEADLINE, PREPARE, HANDSHAKE],
        subscribes: &[STEP_RESULT, HEALTH],
        rate: Rate::Base,
        flight: true,
        partner: false,
        doc: "rate groups, ticks (lock-step or real time), the end of the run, liveness of the peers",
    },
    Role {
        name: "simulator",
        kind: RoleKind::Simulator,
        exec: "sc-simulator",
        publishes: &[
            TRUTH,
            MEASUREMENT,
            NAVIGATION_ERROR,
            SIM_STATE,
            PARTNER_STATE,
            STEP_RESULT,
        ],
        subscribes: &[
            TICK,
            PREPARE,
            ESTIMATE,
            SAFE_TRANSLATIONAL,
            SAFE_ATTITUDE,
            SAFE_ROBOTIC,
        ],
        rate: Rate::Base,
        flight: true,
        partner: false,
        doc: "the plant: measures the state, admits the navigation's estimate (its own navigation when that is missing or rejected) and publishes the knowledge derived from it, applies the re-validated safe commands (the backup when one is missing or rejected)",
    },
    nominal(Subsystem::Translational, "sc-nominal-translational"),
    nominal(Subsystem::Attitude, "sc-nominal-attitude"),
    nominal(Subsystem::Robotic, "sc-nominal-robotic"),
    Role {
        name: "safety_translational",
        kind: RoleKind::Filter(Subsystem::Translational),
        exec: "sc-safety-translational",
        publishes: &[SAFE_TRANSLATIONAL],
        subscribes: &[
            CONTROL,
            SIM_STATE,
            NOMINAL_TRANSLATIONAL,
            STAGE_DEADLINE,
            PREPARE,
        ],
        rate: Rate::Group(Subsystem::Translational),
        flight: true,
        partner: false,
        doc: "the translational safety filter (approach corridor, collision-avoidance zone)",
    },
    Role {
        name: "safety_attitude",
        kind: RoleKind::Filter(Subsystem::Attitude),
        exec: "sc-safety-attitude",
        publishes: &[SAFE_ATTITUDE],
        subscribes: &[
            CONTROL,
            SIM_STATE,
            NOMINAL_ATTITUDE,
            SAFE_TRANSLATIONAL,
            STAGE_DEADLINE,
            PREPARE,
        ],
        rate: Rate::Group(Subsystem::Attitude),
        flight: true,
        partner: false,
        doc: "the attitude safety filter (line of sight, body-rate limits), ξ = the translational safe force",
    },
    Role {
        name: "safety_robotic",
        kind: RoleKind::Filter(Subsystem::Robotic),
        exec: "sc-safety-robotic",
        publishes: &[SAFE_ROBOTIC],
        subscribes: &[
            CONTROL,
            SIM_STATE,
            NOMINAL_ROBOTIC,
            SAFE_TRANSLATIONAL,
            SAFE_ATTITUDE,
            STAGE_DEADLINE,
            PREPARE,
        ],
        rate: Rate::Group(Subsystem::Robotic),
        flight: true,
        partner: false,
        doc: "the robotic safety filter (joint angles and rates, link–base spheres), ξ = the translational and attitude safe commands",
    },
    Role {
        name: "recorder",
        kind: RoleKind::Recorder,
        exec: "sc-recorder",
        publishes: &[HEALTH],
        subscribes: &[
            TICK,
            TRUTH,
            MEASUREMENT,
            ESTIMATE,
            NAVIGATION_ERROR,
            SIM_STATE,
            NOMINAL_TRANSLATIONAL,
            NOMINAL_ATTITUDE,
            NOMINAL_ROBOTIC,
            SAFE_TRANSLATIONAL,
            SAFE_ATTITUDE,
            SAFE_ROBOTIC,
            STEP_RESULT,
        ],
        rate: Rate::Base,
        flight: false,
        partner: false,
        doc: "telemetry: the same telemetry.csv, timing.csv and summary.json as `safe-capture run`, plus recording.mcap and latency.csv",
    },
    Role {
        name: "navigation",
        kind: RoleKind::Navigation,
        exec: "sc-navigation",
        publishes: &[ESTIMATE],
        subscribes: &[CONTROL, MEASUREMENT, PREPARE],
        rate: Rate::Base,
        flight: true,
        partner: true,
        doc: "the navigation: the estimate of each tick's state from the measurements (the declared error model), replaceable by a partner's estimator",
    },
];

/// The row of a nominal controller (the processes partners replace).
const fn nominal(s: Subsystem, exec: &'static str) -> Role {
    Role {
        name: match s {
            Subsystem::Translational => "nominal_translational",
            Subsystem::Attitude => "nominal_attitude",
            Subsystem::Robotic => "nominal_robotic",
        },
        kind: RoleKind::Nominal(s),
        exec,
        publishes: match s {
            Subsystem::Translational => &[NOMINAL_TRANSLATIONAL],
            Subsystem::Attitude => &[NOMINAL_ATTITUDE],
            Subsystem::Robotic => &[NOMINAL_ROBOTIC],
        },
        subscribes: &[CONTROL, PARTNER_STATE, PREPARE],
        rate: Rate::Group(s),
        flight: true,
        partner: true,
        doc: match s {
            Subsystem::Translational => {
                "the nominal translational controller (MPC), replaceable by a partner's"
            }
            Subsystem::Attitude => {
                "the nominal attitude controller (MPC), replaceable by a partner's"
            }
            Subsystem::Robotic => {
                "the nominal robotic controller (joint-space PD), replaceable by a partner's"
            }
        },
    }
}

/// The names of every role, in start order.
pub fn names() -> impl Iterator<Item = &'static str> {
    ROLES.iter().map(|r| r.name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_has_one_row_and_ids_are_positions() {
        let mut kinds = vec![
            RoleKind::Scheduler,
            RoleKind::Simulator,
            RoleKind::Navigation,
            RoleKind::Recorder,
        ];
        for s in Subsystem::ALL {
            kinds.push(RoleKind::Nominal(s));
            kinds.push(RoleKind::Filter(s));
        }
        assert_eq!(kinds.len(), ROLES.len());
        for k in kinds {
            assert_eq!(ROLES.iter().filter(|r| r.kind == k).count(), 1, "{k:?}");
            assert_eq!(Role::of(k).kind, k);
        }
        for (i, r) in ROLES.iter().enumerate() {
            assert_eq!(r.id(), i as u32);
            assert_eq!(Role::named(r.name), Some(r));
            assert_eq!(Role::with_id(i as u32), Some(r));
        }
        assert_eq!(
            ROLES[0].kind,
            RoleKind::Scheduler,
            "the coordinator starts first"
        );
    }

    #[test]
    fn every_service_has_a_publisher_and_a_reader() {
        for s in services::SERVICES.iter().filter(|s| s.message.is_some()) {
            let svc = s.name;
            assert_eq!(s.publishers().count(), 1, "{svc}: one publisher");
            assert!(s.subscribers().next().is_some(), "{svc}: nobody reads it");
        }
    }
}
