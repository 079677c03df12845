//! Interface control document (ICD) of the safe-capture partition: the fixed-size
//! messages that the processes exchange over iceoryx2 shared memory, the constants
//! a partner needs, the services and the role table.
//!
//! **One source.** Each message is declared once here, with the unit, frame and
//! meaning of every field; the declaration gives both the Rust type and its
//! description ([`spec::Message::SPEC`], all of them in [`MESSAGES`]). The same holds
//! for the constant groups ([`CONSTANT_GROUPS`]) and the services
//! ([`services::SERVICES`]). The ground crate `sc-icd-gen` renders these descriptions
//! and the role table [`ROLES`] as the C header `include/safe_capture_icd.h`, the
//! Python module `scripts/python/sc_partner/_icd.py`, the MCAP JSON schemas of the
//! recorder and the tables of docs/ICD.md (checked in; `SC_WRITE_ICD=1 cargo test -p
//! sc-icd-gen` rewrites them).
//!
//! Rules every message follows (checked by compile-time guards here, by
//! `tests/python_layout.rs` against the Python module and by sc-icd-gen's C test):
//! - `#[repr(C)]`, `Copy`, derives `ZeroCopySend` with an explicit, versioned
//!   `#[type_name("safe_capture::v1::...")]` (the name iceoryx2 uses to match types
//!   across processes and languages; a mismatch fails cleanly at open time).
//! - only `f64`, `u64`, `u32`, `i32` and fixed arrays of them; no `bool`, no enum,
//!   no pointer. Flags are `u32` (0 = false, 1 = true) or bitsets.
//! - every `u32` has a partner so that no implicit padding appears; explicit
//!   `_pad*` fields are always zero.
//! - times: `t` is simulation time [s]; `*_ns` are `CLOCK_MONOTONIC` stamps [ns]
//!   of the machine (see [`monotonic_ns`]).
//!
//! Frames ([`spec::Frame`]): F_I Earth-centred inertial frame, F_H Hill (LVLH) frame of the target orbit, F_R reference
//! frame, F_B servicer base (body) frame, F_T target body frame, M manipulator joint
//! space. Quaternions are scalar-first `[w, x, y, z]`; `q_XY` rotates F_Y vectors into F_X.
//!
//! To add a field: append it before the end, keep 8-byte alignment, bump the size
//! guard, regenerate the artefacts. To change meaning or order: create a `v2` type name.

use iceoryx2::prelude::ZeroCopySend;

#[macro_use]
mod macros;
pub mod roles;
pub mod services;
pub mod spec;
pub use roles::{ROLES, Rate, Role, RoleKind};
pub use sc_core::Subsystem;
use sc_core::SubsystemSet;
pub use services::ServiceName;
pub use spec::Message;

icd_constants! {
    /// Array lengths of the messages.
    pub mod lengths: usize = "" {
        /// Number of manipulator joints.
        N_JOINTS = 7,
        /// Number of translational safety constraints: AC (approach corridor), CAZ
        /// (collision-avoidance zone).
        N_CONSTRAINTS_TRANSLATIONAL = 2,
        /// Number of attitude safety constraints: ATT (pointing), ω1..3 upper, ω1..3 lower.
        N_CONSTRAINTS_ATTITUDE = 7,
        /// Number of robotic safety constraints: θ limits 7, θ̇ upper 7, θ̇ lower 7,
        /// link-base 21, link-target 21.
        N_CONSTRAINTS_ROBOTIC = 63,
        /// Number of barriers only the safety monitor evaluates: the base's collision zone
        /// against the target's body (implied by the collision-avoidance zone).
        N_BARRIERS_MONITORED = 1,
        /// Number of barriers of the whole safety layer (translational, attitude, robotic,
        /// then the monitored ones).
        N_BARRIERS = N_CONSTRAINTS_TRANSLATIONAL + N_CONSTRAINTS_ATTITUDE + N_CONSTRAINTS_ROBOTIC + N_BARRIERS_MONITORED,
    }
}
pub use lengths::{
    N_BARRIERS, N_BARRIERS_MONITORED, N_CONSTRAINTS_ATTITUDE, N_CONSTRAINTS_ROBOTIC,
    N_CONSTRAINTS_TRANSLATIONAL, N_JOINTS,
};

icd_constants! {
    /// Event ids of the partition's event services (`sc_bus::pubsub`,
    /// `sc_bus::handshake`; `libs/bus/tests/icd_constants.rs` checks them against sc-bus).
    pub mod events: u32 = "EVENT" {
        /// A publisher notifies this after each send.
        SAMPLE = 0,
        /// iceoryx2 emits it when dead-node clean-up removes a crashed publisher's notifier.
        NOTIFIER_DEAD = 1,
        /// iceoryx2 emits it when a publisher's notifier is dropped (it left).
        NOTIFIER_DROPPED = 2,
        /// Largest event id on a data service.
        ID_MAX = 7,
        /// The coordinator's `go` on `<HANDSHAKE>/go`.
        GO = 3,
        /// A participant notifies `<HANDSHAKE>/ready` with this + its role id.
        HANDSHAKE_ID_OFFSET = 8,
    }
}

icd_constants! {
    /// Bits of the `due_mask` fields (Tick, SimState; also `StepResult.fallback_mask`
    /// and `held_mask`): which subsystems' rate groups run in a tick
    /// (`sc_core::Subsystem::bit`).
    pub mod due: u32 = "DUE" {
        /// Translational nominal controller and safety filter.
        TRANSLATIONAL = Subsystem::Translational.bit(),
        /// Attitude nominal controller and safety filter.
        ATTITUDE = Subsystem::Attitude.bit(),
        /// Robotic nominal controller and safety filter.
        ROBOTIC = Subsystem::Robotic.bit(),
        /// All three.
        ALL = SubsystemSet::ALL.bits(),
    }
}

icd_constants! {
    /// Values of `Tick.command`.
    pub mod tick_command: u32 = "TICK" {
        /// Run one control step.
        STEP = 0,
        /// The run is over: every process finishes its outputs and exits.
        STOP = 1,
    }
}

icd_constants! {
    /// Values of `Tick.clock_mode`.
    pub mod clock_mode: u32 = "CLOCK" {
        /// Lock-step: the next tick is sent as soon as the previous one completed.
        LOCK_STEP = 0,
        /// Real time: ticks paced by the wall clock at the rate-group period.
        REAL_TIME = 1,
        /// Scaled real time: paced at a configured multiple of real time.
        SCALED = 2,
    }
}

icd_constants! {
    /// Values of `StepResult.end`.
    pub mod end: u32 = "END" {
        /// The mission goes on.
        RUNNING = 0,
        /// Captured: end-effector on the grasping point within tolerance.
        CAPTURED = 1,
        /// The configured duration elapsed.
        TIMEOUT = 2,
        /// The simulator failed (non-finite state or command).
        SIMULATOR_FAILED = 3,
    }
}

icd_constants! {
    /// Bits of `StepResult.fault_flags` and `Health.last_fault_flags`.
    pub mod fault: u32 = "FAULT" {
        /// Input older than one tick (stale state).
        STALE_INPUT = 1 << 0,
        /// Non-finite number in an input.
        NON_FINITE_INPUT = 1 << 1,
        /// QP solver failed; output falls back to the backup law.
        SOLVER_FAILED = 1 << 2,
        /// QP infeasible; constraints relaxed.
        INFEASIBLE = 1 << 3,
        /// Output saturated at actuator limits.
        SATURATED = 1 << 4,
        /// Nominal command missing or invalid; filter used zero nominal input.
        NOMINAL_MISSING = 1 << 5,
        /// Deadline missed.
        DEADLINE_MISS = 1 << 6,
        /// A peer process was detected dead.
        PEER_DEAD = 1 << 7,
        /// The simulator rejected a safe command (not finite or beyond the input bounds,
        /// `sc_flight::admission`) and applied the filter's backup instead.
        REJECTED_COMMAND = 1 << 8,
        /// The navigation's estimate was missing at the navigation deadline or rejected
        /// (not finite, not current, a quaternion off the unit sphere, or farther from
        /// the measurement than the declared navigation bounds, `sc_sim::navigation`);
        /// the simulator's own navigation (the declared error model) was substituted.
        NAVIGATION_REJECTED = 1 << 9,
        /// A safe command was not applied because it does not fit the chain the filters
        /// certified: it was certified against other upstream commands than those acting,
        /// or it came after the downstream filters had given up on it and certified
        /// against its backup; the backup acts instead (docs/PARTITION.md).
        COUPLING_MISMATCH = 1 << 10,
    }
}

icd_constants! {
    /// Values of `Health.state`.
    pub mod health_state: u32 = "HEALTH" {
        /// Process started, ports being created.
        STARTING = 0,
        /// Ports exist, handshake announced.
        READY = 1,
        /// Handling ticks.
        RUNNING = 2,
        /// A fault was detected; see `last_fault_flags`.
        FAULTED = 3,
        /// Shutting down.
        STOPPING = 4,
    }
}

/// Every constant group of the ICD, in the order of the C header and docs/ICD.md.
pub const CONSTANT_GROUPS: [&spec::ConstGroup; 8] = [
    &lengths::GROUP,
    &events::GROUP,
    &due::GROUP,
    &tick_command::GROUP,
    &clock_mode::GROUP,
    &end::GROUP,
    &fault::GROUP,
    &health_state::GROUP,
];

/// Monotonic clock stamp in ns (`CLOCK_MONOTONIC` of this machine, shared by all processes).
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes into the provided, valid timespec.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    if rc != 0 {
        return 0;
    }
    (ts.tv_sec as u64)
        .saturating_mul(1_000_000_000)
        .saturating_add(ts.tv_nsec as u64)
}

/// Gives every message an all-zero value (arrays longer than 32 have no `Default`).
pub trait Zeroed: Sized + Copy {
    /// All fields zero.
    fn zeroed() -> Self;
}

icd_message! {
    /// Scheduler → simulator, every other process (stop), recorder: start one control step.
    #[type_name("safe_capture::v2::Tick")]
    pub struct Tick {
        /// Tick index, starts at 0, +1 per tick of the fastest rate group
        pub tick: u64 = ["-"],
        /// Subsystems due in this tick, bits of `due`
        pub due_mask: u32 = ["-"] => due,
        /// Clock mode, one of `clock_mode`
        pub clock_mode: u32 = ["-"] => clock_mode,
        /// Simulation time at which this step starts
        pub t: f64 = ["s"],
        /// Scheduler send stamp, host CLOCK_MONOTONIC
        pub send_ns: u64 = ["ns"],
        /// Step or stop (the run is over), one of `tick_command`
        pub command: u32 = ["-"] => tick_command,
        /// Always 0
        pub _pad0: u32 = ["-"],
    }
}

icd_message! {
    /// Simulator → nominal controllers, safety filters, recorder: the observation at
    /// the start of the step. Every field of `sc_core::Observation`, copied as f64, so
    /// that the stages compute exactly what they compute in one process.
    #[type_name("safe_capture::v5::SimState")]
    pub struct SimState {
        /// Tick index this state answers (= simulator step count at the base rate)
        pub tick: u64 = ["-"],
        /// Simulation time
        pub t: f64 = ["s"],
        /// Subsystems due in this tick, bits of `due`
        pub due_mask: u32 = ["-"] => due,
        /// Always 0
        pub _pad0: u32 = ["-"],
        /// Send stamp of the tick this state answers, host CLOCK_MONOTONIC
        pub tick_send_ns: u64 = ["ns"],
        /// Stamp at which the simulator received the tick, host CLOCK_MONOTONIC
        pub recv_ns: u64 = ["ns"],
        /// Publish stamp, host CLOCK_MONOTONIC
        pub publish_ns: u64 = ["ns"],
        /// Simulator step counter
        pub step: u64 = ["-"],
        /// Servicer base origin relative to the target CoM, r_H
        pub r_h: [f64; 3] = ["m", Hill, Xyz],
        /// Derivative of r_H in the rotating Hill frame
        pub v_h: [f64; 3] = ["m/s", Hill, Xyz],
        /// Servicer base origin relative to the target CoM, r_R
        pub r_r: [f64; 3] = ["m", Reference, Xyz],
        /// Inertial derivative of r_R
        pub v_r: [f64; 3] = ["m/s", Reference, Xyz],
        /// Attitude q_HR of F_R in F_H: rotates F_R vectors into F_H
        pub q_hr: [f64; 4] = ["-", HillFromReference, Wxyz],
        /// Angular velocity ω_H of F_H w.r.t. inertial
        pub omega_h: [f64; 3] = ["rad/s", Hill, Xyz],
        /// Angular acceleration of F_H w.r.t. inertial
        pub omega_dot_h: [f64; 3] = ["rad/s²", Hill, Xyz],
        /// Mean motion of the target orbit |ω_H|
        pub mean_motion: f64 = ["rad/s"],
        /// Servicer attitude q_RB: rotates F_B vectors into F_R
        pub q_rb: [f64; 4] = ["-", ReferenceFromBase, Wxyz],
        /// Servicer body rate ω_B w.r.t. inertial
        pub omega_b: [f64; 3] = ["rad/s", Base, Xyz],
        /// Joint angles θ
        pub theta: [f64; N_JOINTS] = ["rad", Joints, Joints],
        /// Joint rates θ̇
        pub theta_dot: [f64; N_JOINTS] = ["rad/s", Joints, Joints],
        /// Target attitude q_RT: rotates F_T vectors into F_R
        pub q_rt: [f64; 4] = ["-", ReferenceFromTarget, Wxyz],
        /// Target body rate ω_T w.r.t. inertial
        pub omega_t: [f64; 3] = ["rad/s", Target, Xyz],
        /// Derivative of ω_T
        pub omega_dot_t: [f64; 3] = ["rad/s²", Target, Xyz],
        /// Grasping point relative to the target CoM
        pub grasp_r: [f64; 3] = ["m", Reference, Xyz],
        /// Grasping point inertial velocity
        pub grasp_v_r: [f64; 3] = ["m/s", Reference, Xyz],
        /// Grasping point inertial acceleration
        pub grasp_a_r: [f64; 3] = ["m/s²", Reference, Xyz],
        /// Grasping point relative to the base origin
        pub grasp_b: [f64; 3] = ["m", Base, Xyz],
        /// End-effector position relative to the base origin
        pub ee_b: [f64; 3] = ["m", Base, Xyz],
        /// End-effector position relative to the target CoM
        pub ee_r: [f64; 3] = ["m", Reference, Xyz],
        /// End-effector inertial velocity
        pub ee_v_r: [f64; 3] = ["m/s", Reference, Xyz],
        /// Servicer system centre of mass relative to the target CoM
        pub com_h: [f64; 3] = ["m", Hill, Xyz],
        /// Derivative of com_h in the rotating Hill frame
        pub com_v_h: [f64; 3] = ["m/s", Hill, Xyz],
        /// Servicer system centre of mass relative to the target CoM
        pub com_r: [f64; 3] = ["m", Reference, Xyz],
        /// Inertial velocity of the servicer system centre of mass
        pub com_v_r: [f64; 3] = ["m/s", Reference, Xyz],
        /// Every barrier h at this state, from the simulator's own state (the safety
        /// monitor), in telemetry order; NaN (null in the MCAP) = not evaluated. With a
        /// declared `[uncertainty]` the state is the estimate and these the barriers on
        /// knowledge (the declared model on it)
        pub barriers: [f64; N_BARRIERS] = ["unit per constraint", None, Barriers],
        /// The smallest value of every barrier over the physics steps since the
        /// previous state message (this state included); with a declared
        /// `[uncertainty]` equal to `barriers` (knowledge exists at the ticks only)
        pub barriers_between: [f64; N_BARRIERS] = ["unit per constraint", None, Barriers],
        /// The base force the simulator holds from the previous step: what acts in this
        /// tick while the translational group is not due (a downstream filter certifies
        /// against it then; docs/PARTITION.md, "Only what was certified acts")
        pub held_f_b: [f64; 3] = ["N", Base, Xyz],
        /// The base torque the simulator holds from the previous step, as `held_f_b`
        pub held_tau_b: [f64; 3] = ["N·m", Base, Xyz],
    }
}

/// Declares a nominal command: the header every nominal controller fills, then the
/// command itself.
macro_rules! nominal_msg {
    (
        $(#[doc = $doc:literal])+
        $name:ident = $type_name:literal,
        $(#[doc = $cdoc:literal])+
        $field:ident: [f64; $n:expr] = [$unit:literal, $frame:ident, $comp:ident]
    ) => {
        icd_message! {
            $(#[doc = $doc])+
            #[type_name($type_name)]
            pub struct $name {
                /// Tick index this command answers
                pub tick: u64 = ["-"],
                /// Simulation time of the state used
                pub t: f64 = ["s"],
                /// 1 if the controller ran on valid inputs, 0 otherwise
                pub valid: u32 = ["-"],
                /// Index of the mission phase (0-based, scenario order)
                pub phase: u32 = ["-"],
                /// Stamp at which the state was received, host CLOCK_MONOTONIC
                pub recv_ns: u64 = ["ns"],
                /// Publish stamp, host CLOCK_MONOTONIC
                pub publish_ns: u64 = ["ns"],
                $(#[doc = $cdoc])+
                pub $field: [f64; $n] = [$unit, $frame, $comp],
            }
        }
    };
}

nominal_msg! {
    /// Nominal translational controller → translational safety filter, recorder.
    NominalTranslational = "safe_capture::v2::NominalTranslational",
    /// Commanded force f_H, unsaturated
    f_h: [f64; 3] = ["N", Hill, Xyz]
}
nominal_msg! {
    /// Nominal attitude controller → attitude safety filter, recorder.
    NominalAttitude = "safe_capture::v2::NominalAttitude",
    /// Commanded torque τ_B, unsaturated
    tau_b: [f64; 3] = ["N·m", Base, Xyz]
}
nominal_msg! {
    /// Nominal robotic controller → robotic safety filter, recorder.
    NominalRobotic = "safe_capture::v2::NominalRobotic",
    /// Commanded joint torques τ_M, unsaturated
    tau_m: [f64; N_JOINTS] = ["N·m", Joints, Joints]
}

/// Declares a safe command: the safety filter's report (timing, solver, barriers and
/// CBF conditions of its constraints), then the safe and the actuated command.
macro_rules! safe_msg {
    (
        $(#[doc = $doc:literal])+
        $name:ident = $type_name:literal, $sub:ident, $nc:expr,
        $(#[doc = $udoc:literal])+
        u: [f64; $nu:expr] = [$unit:literal, $frame:ident, $comp:ident],
        $(#[doc = $adoc:literal])+
        actuated = [$aframe:ident]
    ) => {
        icd_message! {
            $(#[doc = $doc])+
            #[type_name($type_name)]
            pub struct $name {
                /// Tick index this command answers
                pub tick: u64 = ["-"],
                /// Simulation time of the state used
                pub t: f64 = ["s"],
                /// Stamp at which the last input of this tick arrived, host CLOCK_MONOTONIC
                pub recv_ns: u64 = ["ns"],
                /// Publish stamp, host CLOCK_MONOTONIC
                pub publish_ns: u64 = ["ns"],
                /// Bit i set = constraint i active (Φ_i ≈ 0)
                pub active_mask: u64 = ["-"],
                /// Wall time of the filter call
                pub solve_ns: u64 = ["ns"],
                /// `sc_cbf::FilterStatus`: 0 skipped, 1 solved, 2 relaxed, 3 fallback
                pub solver_status: u32 = ["-"],
                /// QP solver iterations
                pub iterations: u32 = ["-"],
                /// `sc_cbf::faults` bits (5 upstream_missing, 7 nominal_missing, 9 margins_degraded, 10 safe_mode: docs/ICD.md)
                pub fault_flags: u32 = ["-"],
                /// Number of constraints in `h` and `phi`
                pub n_constraints: u32 = ["-"],
                /// Mission phase of the nominal command filtered (0-based)
                pub phase: u32 = ["-"],
                /// CPU time of the filter call on its thread, saturating at u32::MAX
                pub solve_cpu_ns: u32 = ["ns"],
                /// Slack of the relaxed QP (0 otherwise), normalised rows; for a
                /// translational step degraded under a declared uncertainty, the share
                /// of the declared margins given up (docs/SAFETY.md)
                pub slack: f64 = ["-"],
                /// Barrier values h_i the filter evaluated; NaN (null in the MCAP) = not
                /// evaluated
                pub h: [f64; $nc] = ["unit per constraint", None, Constraints($sub)],
                /// CBF conditions Φ_i at the safe command
                pub phi: [f64; $nc] = ["unit per constraint / s", None, Rates($sub)],
                $(#[doc = $udoc])+
                pub u: [f64; $nu] = [$unit, $frame, $comp],
                $(#[doc = $adoc])+
                pub actuated: [f64; $nu] = [$unit, $aframe, $comp],
                /// Coupling ξ this command was certified against: the base force f_B acting
                /// upstream (the translational command or its backup; 0 for the
                /// translational filter, which has no upstream). The simulator applies the
                /// command only with exactly this force acting (docs/PARTITION.md)
                pub xi_f_b: [f64; 3] = ["N", Base, Xyz],
                /// Coupling ξ this command was certified against: the base torque τ_B
                /// acting upstream (the attitude command or its backup; 0 for the
                /// translational and attitude filters)
                pub xi_tau_b: [f64; 3] = ["N·m", Base, Xyz],
            }
        }
    };
}

safe_msg! {
    /// Translational safety filter → attitude and robotic filters, simulator, recorder.
    /// Constraint order: AC, CAZ.
    SafeTranslational = "safe_capture::v3::SafeTranslational", Translational,
    N_CONSTRAINTS_TRANSLATIONAL,
    /// Safe force f_H
    u: [f64; 3] = ["N", Hill, Xyz],
    /// Safe force f_B = R_BH f_H (what the thrusters apply)
    actuated = [Base]
}
safe_msg! {
    /// Attitude safety filter → robotic filter, simulator, recorder.
    /// Constraint order: ATT, ω1..3 upper, ω1..3 lower.
    SafeAttitude = "safe_capture::v3::SafeAttitude", Attitude, N_CONSTRAINTS_ATTITUDE,
    /// Safe torque τ_B
    u: [f64; 3] = ["N·m", Base, Xyz],
    /// Actuated torque τ_B (equals `u`)
    actuated = [Base]
}
safe_msg! {
    /// Robotic safety filter → simulator, recorder.
    /// Constraint order: θ limits 0..7, θ̇ upper 7..14, θ̇ lower 14..21, link-base 21..42, link-target 42..63.
    SafeRobotic = "safe_capture::v4::SafeRobotic", Robotic, N_CONSTRAINTS_ROBOTIC,
    /// Safe joint torques τ_M
    u: [f64; N_JOINTS] = ["N·m", Joints, Joints],
    /// Actuated joint torques τ_M (equals `u`)
    actuated = [Joints]
}

icd_message! {
    /// Simulator → scheduler, recorder: the command applied over the step and how the
    /// step ended. Sent once all due safe commands of the tick are in (or their
    /// deadline passed and the simulator used the filter's fallback).
    #[type_name("safe_capture::v1::StepResult")]
    pub struct StepResult {
        /// Tick index
        pub tick: u64 = ["-"],
        /// Simulation time at the start of the step
        pub t: f64 = ["s"],
        /// How the step ended, one of `end`
        pub end: u32 = ["-"] => end,
        /// Subsystems (bits of `due`) whose command is the filter fallback computed by
        /// the simulator: the safe command was missing at the deadline, refused, or did
        /// not fit what acts upstream (`fault::COUPLING_MISMATCH`)
        pub fallback_mask: u32 = ["-"] => due,
        /// Subsystems (bits of `due`) whose command was held from an earlier tick
        /// (slower rate group)
        pub held_mask: u32 = ["-"] => due,
        /// Partition fault flags, bits of `fault`
        pub fault_flags: u32 = ["-"] => fault,
        /// Stamp at which the robotic safe command (the tick's last) was delivered, host
        /// CLOCK_MONOTONIC
        pub safe_recv_ns: u64 = ["ns"],
        /// Publish stamp, host CLOCK_MONOTONIC
        pub publish_ns: u64 = ["ns"],
        /// Applied base force f_B
        pub force_b: [f64; 3] = ["N", Base, Xyz],
        /// Applied base torque τ_B
        pub torque_b: [f64; 3] = ["N·m", Base, Xyz],
        /// Applied joint torques τ_M
        pub tau: [f64; N_JOINTS] = ["N·m", Joints, Joints],
    }
}

icd_message! {
    /// Simulator → recorder, with a declared `[uncertainty]` only: the realised
    /// navigation errors of the tick's estimate (the state on `SIM_STATE`) against the
    /// truth measured `measurement_age_s` before it (with an age of 0 the truth on
    /// `TRUTH`), each as in `navigation.csv` (vectors: Euclidean norm; joints: the
    /// largest of the seven).
    #[type_name("safe_capture::v1::NavigationError")]
    pub struct NavigationError {
        /// Tick index
        pub tick: u64 = ["-"],
        /// Simulation time of the estimate
        pub t: f64 = ["s"],
        /// Relative position error of the servicer base to the target CoM
        pub relative_position_m: f64 = ["m"],
        /// Relative velocity error
        pub relative_velocity_m_s: f64 = ["m/s"],
        /// Servicer attitude error (rotation angle)
        pub servicer_attitude_rad: f64 = ["rad"],
        /// Servicer body rate error
        pub servicer_rate_rad_s: f64 = ["rad/s"],
        /// Target attitude error (rotation angle)
        pub target_attitude_rad: f64 = ["rad"],
        /// Target body rate error
        pub target_rate_rad_s: f64 = ["rad/s"],
        /// Grasping point error in the target frame
        pub grasp_point_m: f64 = ["m"],
        /// Largest joint angle error
        pub joint_angle_rad: f64 = ["rad"],
        /// Largest joint rate error
        pub joint_rate_rad_s: f64 = ["rad/s"],
        /// Age of the measurement the estimate rests on
        pub measurement_age_s: f64 = ["s"],
    }
}

icd_message! {
    /// A navigation state in the inertial frame the simulator propagates in: on
    /// `MEASUREMENT` what the simulator's sensors measured (simulator → navigation), on
    /// `ESTIMATE` what the navigation estimates (navigation → simulator). The simulator
    /// admits an estimate (`sc_sim::navigation`), then derives every quantity of the
    /// `SIM_STATE` the controllers and filters get from it with the declared model.
    #[type_name("safe_capture::v1::NavState")]
    pub struct NavState {
        /// Tick index this state answers
        pub tick: u64 = ["-"],
        /// Simulation time of the tick: the time an estimate is of
        pub t: f64 = ["s"],
        /// Simulation time of the measurement the values rest on (≤ `t`: the sensors'
        /// age); an estimate carries its measurement's
        pub measured_t: f64 = ["s"],
        /// Publish stamp, host CLOCK_MONOTONIC
        pub publish_ns: u64 = ["ns"],
        /// Target CoM position from the Earth's centre
        pub target_r: [f64; 3] = ["m", Inertial, Xyz],
        /// Target CoM inertial velocity
        pub target_v: [f64; 3] = ["m/s", Inertial, Xyz],
        /// Target attitude q_IT: rotates F_T vectors into F_I
        pub q_it: [f64; 4] = ["-", InertialFromTarget, Wxyz],
        /// Target body rate ω_T w.r.t. inertial
        pub omega_t: [f64; 3] = ["rad/s", Target, Xyz],
        /// Servicer base origin relative to the target CoM
        pub r_i: [f64; 3] = ["m", Inertial, Xyz],
        /// Inertial derivative of `r_i`
        pub v_i: [f64; 3] = ["m/s", Inertial, Xyz],
        /// Servicer attitude q_IB: rotates F_B vectors into F_I
        pub q_ib: [f64; 4] = ["-", InertialFromBase, Wxyz],
        /// Servicer body rate ω_B w.r.t. inertial
        pub omega_b: [f64; 3] = ["rad/s", Base, Xyz],
        /// Joint angles θ
        pub theta: [f64; N_JOINTS] = ["rad", Joints, Joints],
        /// Joint rates θ̇
        pub theta_dot: [f64; N_JOINTS] = ["rad/s", Joints, Joints],
        /// Grasping point relative to the target CoM
        pub grasp_t: [f64; 3] = ["m", Target, Xyz],
    }
}

icd_message! {
    /// Recorder → scheduler: the recorder's progress (lock-step flow control); the
    /// fields are those of a health report any process could publish.
    #[type_name("safe_capture::v1::Health")]
    pub struct Health {
        /// Role id: the role's position in the role table `ROLES`
        pub role: u32 = ["-"],
        /// Operating-system process id
        pub pid: u32 = ["-"],
        /// State, one of `health_state`
        pub state: u32 = ["-"] => health_state,
        /// Last fault flags, bits of `fault`
        pub last_fault_flags: u32 = ["-"] => fault,
        /// Ticks handled since start
        pub ticks_handled: u64 = ["-"],
        /// Deadline misses since start
        pub deadline_misses: u64 = ["-"],
        /// Cycle slips (a tick answered late or skipped) since start
        pub cycle_slips: u64 = ["-"],
        /// Last tick index handled
        pub last_tick: u64 = ["-"],
        /// Publish stamp, host CLOCK_MONOTONIC
        pub publish_ns: u64 = ["ns"],
    }
}

/// Every message of the ICD, in the order of the C header and docs/ICD.md.
pub const MESSAGES: [&spec::MessageSpec; 12] = [
    &Tick::SPEC,
    &SimState::SPEC,
    &NominalTranslational::SPEC,
    &NominalAttitude::SPEC,
    &NominalRobotic::SPEC,
    &SafeTranslational::SPEC,
    &SafeAttitude::SPEC,
    &SafeRobotic::SPEC,
    &StepResult::SPEC,
    &NavigationError::SPEC,
    &NavState::SPEC,
    &Health::SPEC,
];

/// The iceoryx2 type name of a message (the `#[type_name]` it was derived with).
pub fn type_name_of<T: ZeroCopySend>() -> &'static str {
    // SAFETY: `type_name` is unsafe only because a wrong override could make two
    // different types look equal; reading it is harmless.
    unsafe { <T as ZeroCopySend>::type_name() }
}

// Size guards: a change of one is a change of the ICD (regenerate the artefacts with
// `SC_WRITE_ICD=1 cargo test -p sc-icd-gen`, and version the type name).
const _: () = assert!(core::mem::size_of::<Tick>() == 40);
const _: () = assert!(core::mem::size_of::<SimState>() == 1968);
const _: () = assert!(core::mem::size_of::<NominalTranslational>() == 64);
const _: () = assert!(core::mem::size_of::<NominalAttitude>() == 64);
const _: () = assert!(core::mem::size_of::<NominalRobotic>() == 96);
const _: () = assert!(core::mem::size_of::<SafeTranslational>() == 208);
const _: () = assert!(core::mem::size_of::<SafeAttitude>() == 288);
const _: () = assert!(core::mem::size_of::<SafeRobotic>() == 1248);
const _: () = assert!(core::mem::size_of::<StepResult>() == 152);
const _: () = assert!(core::mem::size_of::<NavigationError>() == 96);
const _: () = assert!(core::mem::size_of::<NavState>() == 376);
const _: () = assert!(core::mem::size_of::<Health>() == 56);
const _: () = assert!(core::mem::align_of::<SimState>() == 8);
const _: () = assert!(core::mem::align_of::<Health>() == 8);
const _: () = assert!(N_CONSTRAINTS_ROBOTIC <= 64);

#[cfg(test)]
mod tests {
    use super::*;
    use spec::{Components, Frame, Scalar, UNIT_PER_CONSTRAINT, UNIT_PER_CONSTRAINT_PER_S};

    #[test]
    fn type_names_are_versioned() {
        assert_eq!(type_name_of::<Tick>(), "safe_capture::v2::Tick");
        assert_eq!(
            type_name_of::<SafeRobotic>(),
            "safe_capture::v4::SafeRobotic"
        );
    }

    #[test]
    fn zeroed_is_zero_and_clock_runs() {
        let s = SimState::zeroed();
        assert_eq!(s.theta, [0.0; 7]);
        let a = monotonic_ns();
        let b = monotonic_ns();
        assert!(a > 0 && b >= a);
    }

    /// The spec's type name is the one iceoryx2 uses (the `#[type_name]` attribute).
    #[test]
    fn spec_type_names_are_the_derived_ones() {
        fn check<T: Message + ZeroCopySend>() {
            assert_eq!(T::SPEC.type_name, type_name_of::<T>());
            assert!(T::SPEC.type_name.ends_with(&format!("::{}", T::SPEC.name)));
        }
        check::<Tick>();
        check::<SimState>();
        check::<NominalTranslational>();
        check::<NominalAttitude>();
        check::<NominalRobotic>();
        check::<SafeTranslational>();
        check::<SafeAttitude>();
        check::<SafeRobotic>();
        check::<StepResult>();
        check::<NavigationError>();
        check::<Health>();
    }

    /// Fields read back from `as_bytes` at the spec's offsets are the struct's fields.
    #[test]
    fn spec_offsets_address_the_fields() {
        let mut s = SimState {
            tick: 11,
            due_mask: 5,
            mean_motion: 1.5e-3,
            ..Default::default()
        };
        s.theta[6] = -2.25;
        s.barriers_between[50] = 7.0;
        let b = s.as_bytes();
        assert_eq!(b.len(), SimState::SPEC.size);
        let at = |name: &str, k: usize| {
            let f = SimState::SPEC.field(name).unwrap();
            let o = f.offset + k * f.scalar.size();
            b[o..o + f.scalar.size()].to_vec()
        };
        assert_eq!(at("tick", 0), 11u64.to_ne_bytes());
        assert_eq!(at("due_mask", 0), 5u32.to_ne_bytes());
        assert_eq!(at("mean_motion", 0), 1.5e-3f64.to_ne_bytes());
        assert_eq!(at("theta", 6), (-2.25f64).to_ne_bytes());
        assert_eq!(at("barriers_between", 50), 7.0f64.to_ne_bytes());
    }

    /// Every field is described: a meaning, a unit, components that fit its length,
    /// a frame for every vector and quaternion (joint space for the joints' arrays), the
    /// constraint units on the barrier arrays.
    #[test]
    fn every_field_is_described_consistently() {
        for m in MESSAGES {
            assert!(!m.doc.is_empty(), "{}", m.name);
            assert!(m.fields_fill_every_byte(), "{}", m.name);
            for f in m.fields {
                let at = format!("{}.{}", m.name, f.name);
                assert!(!f.meaning.is_empty() && !f.unit.is_empty(), "{at}");
                assert!(!f.meaning.contains("  "), "{at}: {:?}", f.meaning);
                let want_len = match f.components {
                    Components::One => None,
                    Components::Xyz => Some(3),
                    Components::Wxyz => Some(4),
                    Components::Joints => Some(N_JOINTS),
                    Components::Barriers => Some(N_BARRIERS),
                    Components::Constraints { subsystem, .. } => Some(
                        [
                            N_CONSTRAINTS_TRANSLATIONAL,
                            N_CONSTRAINTS_ATTITUDE,
                            N_CONSTRAINTS_ROBOTIC,
                        ][subsystem.position()],
                    ),
                };
                assert_eq!(f.len, want_len, "{at}: components {:?}", f.components);
                let framed = match f.components {
                    Components::Xyz | Components::Wxyz => f.frame != Frame::None,
                    Components::Joints => f.frame == Frame::Joints,
                    _ => f.frame == Frame::None,
                };
                assert!(framed, "{at}: frame {:?}", f.frame);
                let unit = match f.components {
                    Components::Barriers
                    | Components::Constraints {
                        per_second: false, ..
                    } => Some(UNIT_PER_CONSTRAINT),
                    Components::Constraints {
                        per_second: true, ..
                    } => Some(UNIT_PER_CONSTRAINT_PER_S),
                    _ => None,
                };
                if let Some(u) = unit {
                    assert_eq!(f.unit, u, "{at}");
                }
                if f.len.is_some() {
                    assert_eq!(f.scalar, Scalar::F64, "{at}: arrays are f64");
                }
            }
        }
    }

    /// The check of the layout guard can fail: a gap is found.
    #[test]
    fn a_gap_is_found() {
        let mut fields = Tick::SPEC.fields.to_vec();
        fields.remove(1);
        let leaked: &'static [spec::FieldSpec] = Box::leak(fields.into_boxed_slice());
        let gap = spec::MessageSpec {
            fields: leaked,
            ..Tick::SPEC
        };
        assert!(!gap.fields_fill_every_byte());
    }

    #[test]
    fn constant_groups_hold_the_constants() {
        assert_eq!(due::GROUP.items[2].name, "ROBOTIC");
        assert_eq!(due::GROUP.items[2].value, 4);
        assert_eq!(due::ALL, due::TRANSLATIONAL | due::ATTITUDE | due::ROBOTIC);
        assert_eq!(lengths::GROUP.items[5].name, "N_BARRIERS");
        assert_eq!(lengths::GROUP.items[5].value, 73);
        assert_eq!(
            fault::GROUP.qualified(&fault::GROUP.items[8]),
            "FAULT_REJECTED_COMMAND"
        );
        assert_eq!(
            lengths::GROUP.qualified(&lengths::GROUP.items[0]),
            "N_JOINTS"
        );
        for g in CONSTANT_GROUPS {
            assert!(!g.doc.is_empty(), "{}", g.module);
            for c in g.items {
                assert!(!c.doc.is_empty(), "{}::{}", g.module, c.name);
            }
        }
    }
}
