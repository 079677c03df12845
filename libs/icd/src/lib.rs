//! Interface control document (ICD) of the safe-capture partition: the fixed-size
//! messages that the processes exchange over iceoryx2 shared memory.
//!
//! Rules every message follows (checked by compile-time guards here and by
//! `tests/python_layout.rs` against the Python mirror `scripts/python/sc_icd.py`):
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

pub mod services;
pub use services::ServiceName;

/// Number of manipulator joints.
pub const N_JOINTS: usize = 7;
/// Number of translational safety constraints: AC (approach corridor), CAZ (collision-avoidance zone).
pub const N_CONSTRAINTS_TRANSLATIONAL: usize = 2;
/// Number of attitude safety constraints: ATT (pointing), ω1..3 upper, ω1..3 lower.
pub const N_CONSTRAINTS_ATTITUDE: usize = 7;
/// Number of robotic safety constraints: θ limits 7, θ̇ upper 7, θ̇ lower 7, link-base 21.
pub const N_CONSTRAINTS_ROBOTIC: usize = 42;

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

/// Role ids used in [`Health::role`] and as handshake participant ids.
pub mod role {
    /// Scheduler (handshake coordinator).
    pub const SCHEDULER: u32 = 0;
    /// Simulator.
    pub const SIMULATOR: u32 = 1;
    /// Nominal translational controller.
    pub const NOMINAL_TRANSLATIONAL: u32 = 2;
    /// Nominal attitude controller.
    pub const NOMINAL_ATTITUDE: u32 = 3;
    /// Nominal robotic controller.
    pub const NOMINAL_ROBOTIC: u32 = 4;
    /// Translational safety filter.
    pub const SAFETY_TRANSLATIONAL: u32 = 5;
    /// Attitude safety filter.
    pub const SAFETY_ATTITUDE: u32 = 6;
    /// Robotic safety filter.
    pub const SAFETY_ROBOTIC: u32 = 7;
    /// Telemetry recorder.
    pub const RECORDER: u32 = 8;
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
}

/// Scheduler → all: start one control step.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::Tick")]
pub struct Tick {
    /// Tick index, starts at 0, +1 per tick of this rate group [-].
    pub tick: u64,
    /// Rate-group id (0 = the main control rate) [-].
    pub rate_group: u32,
    /// Clock mode, one of [`clock_mode`] [-].
    pub clock_mode: u32,
    /// Simulation time at which this step starts [s].
    pub t: f64,
    /// Scheduler send stamp, monotonic clock [ns].
    pub send_ns: u64,
}

/// Simulator → all: the true state at the start of the step.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::SimState")]
pub struct SimState {
    /// Simulation step counter (equals the tick index it answers) [-].
    pub step: u64,
    /// Simulation time [s].
    pub t: f64,
    /// Mission phase 1..=3, see [`phase`] [-].
    pub phase: u32,
    /// Always 0.
    pub _pad0: u32,
    /// Servicer position relative to the target, Hill frame F_H [m].
    pub r_h: [f64; 3],
    /// Servicer velocity relative to the target, Hill frame F_H [m/s].
    pub v_h: [f64; 3],
    /// Servicer position relative to the target, reference frame F_R [m].
    pub r_r: [f64; 3],
    /// Servicer velocity relative to the target, reference frame F_R [m/s].
    pub v_r: [f64; 3],
    /// Servicer attitude q_RB, scalar-first, rotates F_B vectors into F_R [-].
    pub q_rb: [f64; 4],
    /// Servicer body rate ω_B w.r.t. inertial, in F_B [rad/s].
    pub w_b: [f64; 3],
    /// Joint angles θ [rad].
    pub theta: [f64; N_JOINTS],
    /// Joint rates θ̇ [rad/s].
    pub theta_dot: [f64; N_JOINTS],
    /// Target attitude q_RT, scalar-first, rotates F_T vectors into F_R [-].
    pub q_rt: [f64; 4],
    /// Target body rate ω_T w.r.t. inertial, in F_T [rad/s].
    pub w_t: [f64; 3],
    /// q_HR, scalar-first, rotates F_R vectors into F_H [-].
    pub q_hr: [f64; 4],
    /// Angular velocity of F_H w.r.t. inertial, in F_H [rad/s].
    pub w_h: [f64; 3],
    /// Angular acceleration of F_H w.r.t. inertial, in F_H [rad/s²].
    pub dw_h: [f64; 3],
    /// Mean motion n of the target orbit [rad/s].
    pub n: f64,
    /// Grasping point position relative to the target centre, F_R [m].
    pub p_g_r: [f64; 3],
    /// Grasping point velocity, F_R [m/s].
    pub v_g_r: [f64; 3],
    /// Grasping point acceleration, F_R [m/s²].
    pub a_g_r: [f64; 3],
    /// End-effector position relative to the servicer base, F_B [m].
    pub p_ee_b: [f64; 3],
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
}

/// Nominal translational controller → translational safety filter.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::NominalTranslational")]
pub struct NominalTranslational {
    /// Tick index this command answers [-].
    pub tick: u64,
    /// Simulation time of the state used [s].
    pub t: f64,
    /// 1 if the command is valid, 0 otherwise [-].
    pub valid: u32,
    /// Always 0.
    pub _pad0: u32,
    /// Stamp at which the state was received, monotonic clock [ns].
    pub recv_ns: u64,
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
    /// Commanded force f_H, Hill frame F_H [N].
    pub f_h: [f64; 3],
}

/// Nominal attitude controller → attitude safety filter.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::NominalAttitude")]
pub struct NominalAttitude {
    /// Tick index this command answers [-].
    pub tick: u64,
    /// Simulation time of the state used [s].
    pub t: f64,
    /// 1 if the command is valid, 0 otherwise [-].
    pub valid: u32,
    /// Always 0.
    pub _pad0: u32,
    /// Stamp at which the state was received, monotonic clock [ns].
    pub recv_ns: u64,
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
    /// Commanded torque τ_B, base frame F_B [N·m].
    pub tau_b: [f64; 3],
}

/// Nominal robotic controller → robotic safety filter.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::NominalRobotic")]
pub struct NominalRobotic {
    /// Tick index this command answers [-].
    pub tick: u64,
    /// Simulation time of the state used [s].
    pub t: f64,
    /// 1 if the command is valid, 0 otherwise [-].
    pub valid: u32,
    /// Always 0.
    pub _pad0: u32,
    /// Stamp at which the state was received, monotonic clock [ns].
    pub recv_ns: u64,
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
    /// Commanded joint torques τ_M [N·m].
    pub tau_m: [f64; N_JOINTS],
}

/// Translational safety filter → attitude filter, simulator, recorder.
///
/// The filter report (`h`, `phi`, ...) uses the constraint order AC, CAZ.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::SafeTranslational")]
pub struct SafeTranslational {
    /// Tick index this command answers [-].
    pub tick: u64,
    /// Simulation time of the state used [s].
    pub t: f64,
    /// Stamp at which the last input arrived, monotonic clock [ns].
    pub recv_ns: u64,
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
    /// Bit i set = constraint i active (h_i ≈ 0 or QP multiplier > 0) [-].
    pub active_mask: u64,
    /// QP solve wall time [ns].
    pub solve_ns: u64,
    /// Solver status (0 = solved, solver-specific codes otherwise) [-].
    pub solver_status: u32,
    /// Solver iterations [-].
    pub iterations: u32,
    /// Fault flags, bits of [`fault`] [-].
    pub fault_flags: u32,
    /// Number of constraints N in `h`/`phi` (= 2) [-].
    pub n_constraints: u32,
    /// Barrier values h_i, order AC, CAZ [m or m², see CBF design].
    pub h: [f64; N_CONSTRAINTS_TRANSLATIONAL],
    /// CBF condition residuals Φ_i = ḣ_i + α(h_i) at the safe command [units of h per s].
    pub phi: [f64; N_CONSTRAINTS_TRANSLATIONAL],
    /// Safe force f_H, Hill frame F_H [N].
    pub f_h: [f64; 3],
    /// Safe force f_B, base frame F_B [N].
    pub f_b: [f64; 3],
}

/// Attitude safety filter → robotic filter, simulator, recorder.
///
/// Constraint order: ATT, ω1 upper, ω2 upper, ω3 upper, ω1 lower, ω2 lower, ω3 lower.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::SafeAttitude")]
pub struct SafeAttitude {
    /// Tick index this command answers [-].
    pub tick: u64,
    /// Simulation time of the state used [s].
    pub t: f64,
    /// Stamp at which the last input arrived, monotonic clock [ns].
    pub recv_ns: u64,
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
    /// Bit i set = constraint i active [-].
    pub active_mask: u64,
    /// QP solve wall time [ns].
    pub solve_ns: u64,
    /// Solver status (0 = solved) [-].
    pub solver_status: u32,
    /// Solver iterations [-].
    pub iterations: u32,
    /// Fault flags, bits of [`fault`] [-].
    pub fault_flags: u32,
    /// Number of constraints N in `h`/`phi` (= 7) [-].
    pub n_constraints: u32,
    /// Barrier values h_i [rad-based, see CBF design].
    pub h: [f64; N_CONSTRAINTS_ATTITUDE],
    /// CBF condition residuals Φ_i [units of h per s].
    pub phi: [f64; N_CONSTRAINTS_ATTITUDE],
    /// Safe torque τ_B, base frame F_B [N·m].
    pub tau_b: [f64; 3],
}

/// Robotic safety filter → simulator, recorder.
///
/// Constraint order: θ limits 0..7, θ̇ upper 7..14, θ̇ lower 14..21, link-base 21..42.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::SafeRobotic")]
pub struct SafeRobotic {
    /// Tick index this command answers [-].
    pub tick: u64,
    /// Simulation time of the state used [s].
    pub t: f64,
    /// Stamp at which the last input arrived, monotonic clock [ns].
    pub recv_ns: u64,
    /// Publish stamp, monotonic clock [ns].
    pub publish_ns: u64,
    /// Bit i set = constraint i active (42 constraints fit in 64 bits) [-].
    pub active_mask: u64,
    /// QP solve wall time [ns].
    pub solve_ns: u64,
    /// Solver status (0 = solved) [-].
    pub solver_status: u32,
    /// Solver iterations [-].
    pub iterations: u32,
    /// Fault flags, bits of [`fault`] [-].
    pub fault_flags: u32,
    /// Number of constraints N in `h`/`phi` (= 42) [-].
    pub n_constraints: u32,
    /// Barrier values h_i [rad, rad/s or m, see CBF design].
    pub h: [f64; N_CONSTRAINTS_ROBOTIC],
    /// CBF condition residuals Φ_i [units of h per s].
    pub phi: [f64; N_CONSTRAINTS_ROBOTIC],
    /// Safe joint torques τ_M [N·m].
    pub tau_m: [f64; N_JOINTS],
}

/// Every process → scheduler, recorder: health and counters.
#[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
#[repr(C)]
#[type_name("safe_capture::v1::Health")]
pub struct Health {
    /// Role id, one of [`role`] [-].
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
    Health
);

/// The iceoryx2 type name of a message (the `#[type_name]` it was derived with).
pub fn type_name_of<T: ZeroCopySend>() -> &'static str {
    // SAFETY: `type_name` is unsafe only because a wrong override could make two
    // different types look equal; reading it is harmless.
    unsafe { <T as ZeroCopySend>::type_name() }
}

// Size guards: change them only together with scripts/python/sc_icd.py and docs/ICD.md.
const _: () = assert!(core::mem::size_of::<Tick>() == 32);
const _: () = assert!(core::mem::size_of::<SimState>() == 536);
const _: () = assert!(core::mem::size_of::<NominalTranslational>() == 64);
const _: () = assert!(core::mem::size_of::<NominalAttitude>() == 64);
const _: () = assert!(core::mem::size_of::<NominalRobotic>() == 96);
const _: () = assert!(core::mem::size_of::<SafeTranslational>() == 144);
const _: () = assert!(core::mem::size_of::<SafeAttitude>() == 200);
const _: () = assert!(core::mem::size_of::<SafeRobotic>() == 792);
const _: () = assert!(core::mem::size_of::<Health>() == 56);
const _: () = assert!(core::mem::align_of::<SimState>() == 8);
const _: () = assert!(core::mem::align_of::<Health>() == 8);
const _: () = assert!(N_CONSTRAINTS_ROBOTIC <= 64);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_names_are_versioned() {
        assert_eq!(type_name_of::<Tick>(), "safe_capture::v1::Tick");
        assert_eq!(
            type_name_of::<SafeRobotic>(),
            "safe_capture::v1::SafeRobotic"
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
