//! Interface control document (ICD) of the safe-capture partition: the fixed-size
//! messages that the processes exchange over iceoryx2 shared memory.
//!
//! Rules every message follows (checked by compile-time guards here and by
//! `tests/python_layout.rs` against the Python mirror `scripts/python/sc_partner/icd.py`,
//! and by `tests/c_header.rs` against the generated C header `include/safe_capture_icd.h`):
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
//! Frames: F_H Hill (LVLH) frame of the target orbit, F_R reference frame,
//! F_B servicer base (body) frame, F_T target body frame, M manipulator joint space.
//! Quaternions are scalar-first `[w, x, y, z]`; `q_XY` rotates F_Y vectors into F_X.
//!
//! To add a field: append it before the end, keep 8-byte alignment, bump the
//! size guard, the Python mirror and `docs/ICD.md`. To change meaning or order:
//! create a `v2` type name.

use iceoryx2::prelude::ZeroCopySend;

pub mod c_header;
pub mod roles;
pub mod services;
pub use roles::{ROLES, Rate, Role, RoleKind};
pub use sc_core::Subsystem;
pub use services::ServiceName;

/// Number of manipulator joints.
pub const N_JOINTS: usize = 7;
/// Number of translational safety constraints: AC (approach corridor), CAZ (collision-avoidance zone).
pub const N_CONSTRAINTS_TRANSLATIONAL: usize = 2;
/// Number of attitude safety constraints: ATT (pointing), ω1..3 upper, ω1..3 lower.
pub const N_CONSTRAINTS_ATTITUDE: usize = 7;
/// Number of robotic safety constraints: θ limits 7, θ̇ upper 7, θ̇ lower 7, link-base 21.
pub const N_CONSTRAINTS_ROBOTIC: usize = 42;
/// Number of barriers of the whole safety layer (translational, attitude, robotic).
pub const N_BARRIERS: usize =
    N_CONSTRAINTS_TRANSLATIONAL + N_CONSTRAINTS_ATTITUDE + N_CONSTRAINTS_ROBOTIC;

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

macro_rules! zeroed {
    ($($t:ty),*) => {$(
        impl Zeroed for $t {
            fn zeroed() -> Self {
                // SAFETY: the type is repr(C) made only of integers and f64, for which
                // the all-zero bit pattern is a valid value.
                unsafe { core::mem::zeroed() }
            }
        }
        impl Default for $t {
            fn default() -> Self { <$t as Zeroed>::zeroed() }
        }
    )*};
}

/// Clock mode carried in [`Tick::clock_mode`].
pub mod clock_mode {
    /// Lock-step: the next tick is sent as soon as the previous one completed.
    pub const LOCK_STEP: u32 = 0;
    /// Real time: ticks paced by the wall clock at the rate-group period.
    pub const REAL_TIME: u32 = 1;
    /// Scaled real time: paced at a configured multiple of real time.
    pub const SCALED: u32 = 2;
}

/// Mission phase carried in [`SimState::phase`].
pub mod phase {
    /// Approach.
    pub const APPROACH: u32 = 1;
    /// Synchronisation with the tumbling target.
    pub const SYNCHRONISATION: u32 = 2;
    /// Capture (manipulator reaches for the grasping point).
    pub const CAPTURE: u32 = 3;
}

/// Values of [`Health::state`].
pub mod health_state {
    /// Process started, ports being created.
    pub const STARTING: u32 = 0;
    /// Ports exist, handshake announced.
    pub const READY: u32 = 1;
    /// Handling ticks.
    pub const RUNNING: u32 = 2;
    /// A fault was detected; see `last_fault_flags`.
    pub const FAULTED: u32 = 3;
    /// Shutting down.
    pub const STOPPING: u32 = 4;
}

/// Bits of the `fault_flags` fields.
pub mod fault {
    /// Input older than one tick (stale state).
    pub const STALE_INPUT: u32 = 1 << 0;
    /// Non-finite number in an input.
    pub const NON_FINITE_INPUT: u32 = 1 << 1;
    /// QP solver failed; output falls back to the backup law.
    pub const SOLVER_FAILED: u32 = 1 << 2;
    /// QP infeasible; constraints relaxed.
    pub const INFEASIBLE: u32 = 1 << 3;
    /// Output saturated at actuator limits.
    pub const SATURATED: u32 = 1 << 4;
    /// Nominal command missing or invalid; filter used zero nominal input.
    pub const NOMINAL_MISSING: u32 = 1 << 5;
    /// Deadline missed.
    pub const DEADLINE_MISS: u32 = 1 << 6;
    /// A peer process was detected dead.
    pub const PEER_DEAD: u32 = 1 << 7;
    /// The simulator rejected a safe command (not finite or beyond the input bounds,
    /// `sc_flight::admission`) and applied the filter's backup instead.
    pub const REJECTED_COMMAND: u32 = 1 << 8;
}

/// Values of [`Tick::command`].
pub mod tick_command {
    /// Run one control step.
    pub const STEP: u32 = 0;
    /// The run is over: every process finishes its outputs and exits.
    pub const STOP: u32 = 1;
}

/// Bits of the `due_mask` fields: which subsystems' rate groups run in a tick.
pub mod due {
    /// Translational nominal controller and safety filter.
    pub const TRANSLATIONAL: u32 = 1 << 0;
    /// Attitude nominal controller and safety filter.
    pub const ATTITUDE: u32 = 1 << 1;
    /// Robotic nominal controller and safety filter.
    pub const ROBOTIC: u32 = 1 << 2;
    /// All three.
    pub const ALL: u32 = 7;
}

/// Values of [`StepResult::end`].
pub mod end {
    /// The mission goes on.
    pub const RUNNING: u32 = 0;
    /// Captured: end-effector on the grasping point within tolerance.
    pub const CAPTURED: u32 = 1;
    /// The configured duration elapsed.
    pub const TIMEOUT: u32 = 2;
    /// The simulator failed (non-finite state or command).
    pub const SIMULATOR_FAILED: u32 = 3;
}

/// Scheduler → simulator, every other process (stop), recorder: start one control step.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v2::Tick")]
pub struct Tick {
    /// Tick index, starts at 0, +1 per tick of the fastest rate group [-].
    pub tick: u64,
    /// Subsystems due in this tick, bits of [`due`] [-].
    pub due_mask: u32,
    /// Clock mode, one of [`clock_mode`] [-].
    pub clock_mode: u32,
    /// Simulation time at which this step starts [s].
    pub t: f64,
    /// Scheduler send stamp, monotonic clock [ns].
    pub send_ns: u64,
    /// One of [`tick_command`] [-].
    pub command: u32,
    /// Always 0.
    pub _pad0: u32,
}

/// Simulator → nominal controllers, safety filters, recorder: the observation at
/// the start of the step. Every field of `sc_sim::Observation`, copied as f64, so
/// that the stages compute exactly what they compute in one process.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v3::SimState")]
pub struct SimState {
    /// Tick index this state answers (= simulator step count at the base rate) [-].
    pub tick: u64,
    /// Simulation time [s].
    pub t: f64,
    /// Subsystems due in this tick, bits of [`due`] [-].
    pub due_mask: u32,
    /// Always 0.
    pub _pad0: u32,
    /// Send stamp of the tick this state answers, monotonic clock [ns].
    pub tick_send_ns: u64,
    /// Stamp at which the simulator received the tick, monotonic clock [ns].
    pub recv_ns: u64,
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
    /// Simulator step counter [-].
    pub step: u64,
    /// Servicer base origin relative to the target CoM, Hill frame F_H [m].
    pub r_h: [f64; 3],
    /// Its derivative in the rotating Hill frame F_H [m/s].
    pub v_h: [f64; 3],
    /// Servicer base origin relative to the target CoM, reference frame F_R [m].
    pub r_r: [f64; 3],
    /// Inertial derivative of `r_r`, in F_R [m/s].
    pub v_r: [f64; 3],
    /// q_HR, scalar-first, rotates F_R vectors into F_H [-].
    pub q_hr: [f64; 4],
    /// Angular velocity of F_H w.r.t. inertial, in F_H [rad/s].
    pub omega_h: [f64; 3],
    /// Angular acceleration of F_H w.r.t. inertial, in F_H [rad/s²].
    pub omega_dot_h: [f64; 3],
    /// Mean motion of the target orbit |ω_H| [rad/s].
    pub mean_motion: f64,
    /// Servicer attitude q_RB, scalar-first, rotates F_B vectors into F_R [-].
    pub q_rb: [f64; 4],
    /// Servicer body rate ω_B w.r.t. inertial, in F_B [rad/s].
    pub omega_b: [f64; 3],
    /// Joint angles θ [rad].
    pub theta: [f64; N_JOINTS],
    /// Joint rates θ̇ [rad/s].
    pub theta_dot: [f64; N_JOINTS],
    /// Target attitude q_RT, scalar-first, rotates F_T vectors into F_R [-].
    pub q_rt: [f64; 4],
    /// Target body rate ω_T w.r.t. inertial, in F_T [rad/s].
    pub omega_t: [f64; 3],
    /// Its derivative, in F_T [rad/s²].
    pub omega_dot_t: [f64; 3],
    /// Grasping point relative to the target CoM, F_R [m].
    pub grasp_r: [f64; 3],
    /// Grasping point inertial velocity, F_R [m/s].
    pub grasp_v_r: [f64; 3],
    /// Grasping point inertial acceleration, F_R [m/s²].
    pub grasp_a_r: [f64; 3],
    /// Grasping point relative to the base origin, F_B [m].
    pub grasp_b: [f64; 3],
    /// End-effector position relative to the base origin, F_B [m].
    pub ee_b: [f64; 3],
    /// End-effector position relative to the target CoM, F_R [m].
    pub ee_r: [f64; 3],
    /// End-effector inertial velocity, F_R [m/s].
    pub ee_v_r: [f64; 3],
    /// Servicer system centre of mass relative to the target CoM, Hill frame F_H [m].
    pub com_h: [f64; 3],
    /// Its derivative in the rotating Hill frame F_H [m/s].
    pub com_v_h: [f64; 3],
    /// Servicer system centre of mass relative to the target CoM, F_R [m].
    pub com_r: [f64; 3],
    /// Its inertial velocity, F_R [m/s].
    pub com_v_r: [f64; 3],
    /// Every barrier at this state, from the simulator's own state (the safety monitor),
    /// in telemetry order (units per barrier, docs/ICD.md) [-].
    pub barriers: [f64; N_BARRIERS],
    /// The smallest value of every barrier over the physics steps since the previous
    /// state message (this state included) [-].
    pub barriers_between: [f64; N_BARRIERS],
}

macro_rules! nominal_msg {
    ($(#[$m:meta])* $name:ident, $tn:literal, $field:ident, $n:expr, $doc:literal) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
        #[repr(C)]
        #[type_name($tn)]
        pub struct $name {
            /// Tick index this command answers [-].
            pub tick: u64,
            /// Simulation time of the state used [s].
            pub t: f64,
            /// 1 if the controller ran on valid inputs, 0 otherwise [-].
            pub valid: u32,
            /// Index of the mission phase (0-based, scenario order) [-].
            pub phase: u32,
            /// Stamp at which the state was received, monotonic clock [ns].
            pub recv_ns: u64,
            /// Publish stamp, monotonic clock [ns].
            pub publish_ns: u64,
            #[doc = $doc]
            pub $field: [f64; $n],
        }
    };
}

nominal_msg!(
    /// Nominal translational controller → translational safety filter, recorder.
    NominalTranslational, "safe_capture::v2::NominalTranslational", f_h, 3,
    "Commanded force f_H, Hill frame F_H, unsaturated [N]."
);
nominal_msg!(
    /// Nominal attitude controller → attitude safety filter, recorder.
    NominalAttitude, "safe_capture::v2::NominalAttitude", tau_b, 3,
    "Commanded torque τ_B, base frame F_B, unsaturated [N·m]."
);
nominal_msg!(
    /// Nominal robotic controller → robotic safety filter, recorder.
    NominalRobotic, "safe_capture::v2::NominalRobotic", tau_m, N_JOINTS,
    "Commanded joint torques τ_M, unsaturated [N·m]."
);

macro_rules! safe_msg {
    ($(#[$m:meta])* $name:ident, $tn:literal, $nc:expr, $nu:expr, $udoc:literal, $adoc:literal) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
        #[repr(C)]
        #[type_name($tn)]
        pub struct $name {
            /// Tick index this command answers [-].
            pub tick: u64,
            /// Simulation time of the state used [s].
            pub t: f64,
            /// Stamp at which the last input of this tick arrived, monotonic clock [ns].
            pub recv_ns: u64,
            /// Publish stamp, monotonic clock [ns].
            pub publish_ns: u64,
            /// Bit i set = constraint i active (Φ_i ≈ 0) [-].
            pub active_mask: u64,
            /// Wall time of the filter call [ns].
            pub solve_ns: u64,
            /// `sc_cbf::FilterStatus`: 0 skipped, 1 solved, 2 relaxed, 3 fallback [-].
            pub solver_status: u32,
            /// Interior-point iterations [-].
            pub iterations: u32,
            /// `sc_cbf::faults` bits (UPSTREAM_MISSING = 1<<5 when an input was missing) [-].
            pub fault_flags: u32,
            /// Number of constraints in `h`/`phi` [-].
            pub n_constraints: u32,
            /// Mission phase of the nominal command filtered (0-based) [-].
            pub phase: u32,
            /// CPU time of the filter call on its thread, saturating at u32::MAX [ns].
            pub solve_cpu_ns: u32,
            /// Slack of the relaxed QP (0 otherwise), normalised rows [-].
            pub slack: f64,
            /// Barrier values h_i (NaN when not evaluated) [see docs/ICD.md].
            pub h: [f64; $nc],
            /// CBF conditions Φ_i at the safe command [units of h per s].
            pub phi: [f64; $nc],
            #[doc = $udoc]
            pub u: [f64; $nu],
            #[doc = $adoc]
            pub actuated: [f64; $nu],
        }
    };
}

safe_msg!(
    /// Translational safety filter → attitude and robotic filters, simulator, recorder.
    /// Constraint order: AC, CAZ.
    SafeTranslational, "safe_capture::v2::SafeTranslational", N_CONSTRAINTS_TRANSLATIONAL, 3,
    "Safe force f_H, Hill frame F_H [N].",
    "Safe force f_B = R_BH f_H, base frame F_B (what the thrusters apply) [N]."
);
safe_msg!(
    /// Attitude safety filter → robotic filter, simulator, recorder.
    /// Constraint order: ATT, ω1..3 upper, ω1..3 lower.
    SafeAttitude, "safe_capture::v2::SafeAttitude", N_CONSTRAINTS_ATTITUDE, 3,
    "Safe torque τ_B, base frame F_B [N·m].",
    "Actuated torque τ_B, base frame F_B (equals `u`) [N·m]."
);
safe_msg!(
    /// Robotic safety filter → simulator, recorder.
    /// Constraint order: θ limits 0..7, θ̇ upper 7..14, θ̇ lower 14..21, link-base 21..42.
    SafeRobotic, "safe_capture::v2::SafeRobotic", N_CONSTRAINTS_ROBOTIC, N_JOINTS,
    "Safe joint torques τ_M [N·m].",
    "Actuated joint torques τ_M (equals `u`) [N·m]."
);

/// Simulator → scheduler, recorder: the command applied over the step and how the
/// step ended. Sent once all due safe commands of the tick are in (or their
/// deadline passed and the simulator used the filter's fallback).
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::StepResult")]
pub struct StepResult {
    /// Tick index [-].
    pub tick: u64,
    /// Simulation time at the start of the step [s].
    pub t: f64,
    /// One of [`end`] [-].
    pub end: u32,
    /// Subsystems ([`due`] bits) whose command is the filter fallback computed by the
    /// simulator because the safe command was missing at the deadline [-].
    pub fallback_mask: u32,
    /// Subsystems ([`due`] bits) whose command was held from an earlier tick (slower rate group) [-].
    pub held_mask: u32,
    /// Partition fault flags, bits of [`fault`] [-].
    pub fault_flags: u32,
    /// Stamp at which the robotic safe command (the tick's last) was delivered, monotonic [ns].
    pub safe_recv_ns: u64,
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
    /// Applied base force f_B, F_B [N].
    pub force_b: [f64; 3],
    /// Applied base torque τ_B, F_B [N·m].
    pub torque_b: [f64; 3],
    /// Applied joint torques τ_M [N·m].
    pub tau: [f64; N_JOINTS],
}

/// Recorder → scheduler: the recorder's progress (lock-step flow control); the
/// fields are those of a health report any process could publish.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::Health")]
pub struct Health {
    /// Role id, [`Role::id`] of the role table [-].
    pub role: u32,
    /// Operating-system process id [-].
    pub pid: u32,
    /// State, one of [`health_state`] [-].
    pub state: u32,
    /// Last fault flags, bits of [`fault`] [-].
    pub last_fault_flags: u32,
    /// Ticks handled since start [-].
    pub ticks_handled: u64,
    /// Deadline misses since start [-].
    pub deadline_misses: u64,
    /// Cycle slips (a tick answered late or skipped) since start [-].
    pub cycle_slips: u64,
    /// Last tick index handled [-].
    pub last_tick: u64,
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
}

zeroed!(
    Tick,
    SimState,
    NominalTranslational,
    NominalAttitude,
    NominalRobotic,
    SafeTranslational,
    SafeAttitude,
    SafeRobotic,
    StepResult,
    Health
);

/// The iceoryx2 type name of a message (the `#[type_name]` it was derived with).
pub fn type_name_of<T: ZeroCopySend>() -> &'static str {
    // SAFETY: `type_name` is unsafe only because a wrong override could make two
    // different types look equal; reading it is harmless.
    unsafe { <T as ZeroCopySend>::type_name() }
}

// Size guards: change them only together with scripts/python/sc_partner/icd.py,
// the C header (`c_header`) and docs/ICD.md.
const _: () = assert!(core::mem::size_of::<Tick>() == 40);
const _: () = assert!(core::mem::size_of::<SimState>() == 1568);
const _: () = assert!(core::mem::size_of::<NominalTranslational>() == 64);
const _: () = assert!(core::mem::size_of::<NominalAttitude>() == 64);
const _: () = assert!(core::mem::size_of::<NominalRobotic>() == 96);
const _: () = assert!(core::mem::size_of::<SafeTranslational>() == 160);
const _: () = assert!(core::mem::size_of::<SafeAttitude>() == 240);
const _: () = assert!(core::mem::size_of::<SafeRobotic>() == 864);
const _: () = assert!(core::mem::size_of::<StepResult>() == 152);
const _: () = assert!(core::mem::size_of::<Health>() == 56);
const _: () = assert!(core::mem::align_of::<SimState>() == 8);
const _: () = assert!(core::mem::align_of::<Health>() == 8);
const _: () = assert!(N_CONSTRAINTS_ROBOTIC <= 64);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_names_are_versioned() {
        assert_eq!(type_name_of::<Tick>(), "safe_capture::v2::Tick");
        assert_eq!(
            type_name_of::<SafeRobotic>(),
            "safe_capture::v2::SafeRobotic"
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
}
