/* safe_capture_icd.h -- the safe-capture ICD (docs/ICD.md) for C and C++ partners.
 *
 * GENERATED from the Rust crate sc-icd (libs/icd/src/c_header.rs); do not edit.
 * Regenerate: SC_WRITE_C_HEADER=1 cargo test -p sc-icd --test c_header
 *
 * Every message is the #[repr(C)] Rust struct of the same name: fixed size, 8-byte
 * aligned, no implicit padding (explicit _pad* fields are 0). Units and frames of
 * every field: docs/ICD.md and `cargo doc -p sc-icd`. Transport: iceoryx2 0.10.
 */
#ifndef SAFE_CAPTURE_ICD_H
#define SAFE_CAPTURE_ICD_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
#define SC_ICD_STATIC_ASSERT(cond, msg) static_assert(cond, msg)
#define SC_ICD_ALIGNOF(t) alignof(t)
extern "C" {
#else
#define SC_ICD_STATIC_ASSERT(cond, msg) _Static_assert(cond, msg)
#define SC_ICD_ALIGNOF(t) _Alignof(t)
#endif

/* Array lengths */
#define SC_N_JOINTS 7u
#define SC_N_CONSTRAINTS_TRANSLATIONAL 2u
#define SC_N_CONSTRAINTS_ATTITUDE 7u
#define SC_N_CONSTRAINTS_ROBOTIC 42u
#define SC_N_BARRIERS 51u

/* Service names (relative: a run's iceoryx2 global.prefix is "sc_<SC_RUN_ID>_"). Each pub/sub service has an event service of the same name. */
#define SC_SERVICE_TICK "safe_capture/scheduler/tick"
#define SC_SERVICE_CONTROL "safe_capture/scheduler/control"
#define SC_SERVICE_SIM_STATE "safe_capture/sim/state"
#define SC_SERVICE_PARTNER_STATE "safe_capture/partner/state"
#define SC_SERVICE_NOMINAL_TRANSLATIONAL "safe_capture/nominal/translational"
#define SC_SERVICE_NOMINAL_ATTITUDE "safe_capture/nominal/attitude"
#define SC_SERVICE_NOMINAL_ROBOTIC "safe_capture/nominal/robotic"
#define SC_SERVICE_SAFE_TRANSLATIONAL "safe_capture/safe/translational"
#define SC_SERVICE_SAFE_ATTITUDE "safe_capture/safe/attitude"
#define SC_SERVICE_SAFE_ROBOTIC "safe_capture/safe/robotic"
#define SC_SERVICE_STEP_RESULT "safe_capture/sim/step_result"
#define SC_SERVICE_HEALTH "safe_capture/health"
#define SC_SERVICE_STAGE_DEADLINE "safe_capture/scheduler/deadline"
#define SC_SERVICE_PREPARE "safe_capture/scheduler/prepare"
#define SC_SERVICE_HANDSHAKE "safe_capture/handshake"
#define SC_SERVICE_HANDSHAKE_READY "safe_capture/handshake/ready"
#define SC_SERVICE_HANDSHAKE_GO "safe_capture/handshake/go"

/* iceoryx2 type names: give them when opening a service (iceoryx2 matches types by name, size and alignment) */
#define SC_TYPE_NAME_TICK "safe_capture::v2::Tick"
#define SC_TYPE_NAME_SIM_STATE "safe_capture::v3::SimState"
#define SC_TYPE_NAME_NOMINAL_TRANSLATIONAL "safe_capture::v2::NominalTranslational"
#define SC_TYPE_NAME_NOMINAL_ATTITUDE "safe_capture::v2::NominalAttitude"
#define SC_TYPE_NAME_NOMINAL_ROBOTIC "safe_capture::v2::NominalRobotic"
#define SC_TYPE_NAME_SAFE_TRANSLATIONAL "safe_capture::v2::SafeTranslational"
#define SC_TYPE_NAME_SAFE_ATTITUDE "safe_capture::v2::SafeAttitude"
#define SC_TYPE_NAME_SAFE_ROBOTIC "safe_capture::v2::SafeRobotic"
#define SC_TYPE_NAME_STEP_RESULT "safe_capture::v1::StepResult"
#define SC_TYPE_NAME_HEALTH "safe_capture::v1::Health"

/* Event ids */
#define SC_EVENT_SAMPLE 0u
#define SC_EVENT_NOTIFIER_DEAD 1u
#define SC_EVENT_NOTIFIER_DROPPED 2u
#define SC_EVENT_ID_MAX 7u
#define SC_EVENT_GO 3u
#define SC_EVENT_HANDSHAKE_ID_OFFSET 8u

/* due_mask bits (Tick, SimState): the subsystems due in a tick */
#define SC_DUE_TRANSLATIONAL 1u
#define SC_DUE_ATTITUDE 2u
#define SC_DUE_ROBOTIC 4u
#define SC_DUE_ALL 7u

/* Tick.command */
#define SC_TICK_STEP 0u
#define SC_TICK_STOP 1u

/* Tick.clock_mode */
#define SC_CLOCK_LOCK_STEP 0u
#define SC_CLOCK_REAL_TIME 1u
#define SC_CLOCK_SCALED 2u

/* StepResult.end */
#define SC_END_RUNNING 0u
#define SC_END_CAPTURED 1u
#define SC_END_TIMEOUT 2u
#define SC_END_SIMULATOR_FAILED 3u

/* StepResult.fault_flags, Health.last_fault_flags bits */
#define SC_FAULT_STALE_INPUT 1u
#define SC_FAULT_NON_FINITE_INPUT 2u
#define SC_FAULT_SOLVER_FAILED 4u
#define SC_FAULT_INFEASIBLE 8u
#define SC_FAULT_SATURATED 16u
#define SC_FAULT_NOMINAL_MISSING 32u
#define SC_FAULT_DEADLINE_MISS 64u
#define SC_FAULT_PEER_DEAD 128u
#define SC_FAULT_REJECTED_COMMAND 256u

/* Role ids (Health.role; the handshake id is SC_EVENT_HANDSHAKE_ID_OFFSET + role) */
#define SC_ROLE_SCHEDULER 0u
#define SC_ROLE_SIMULATOR 1u
#define SC_ROLE_NOMINAL_TRANSLATIONAL 2u
#define SC_ROLE_NOMINAL_ATTITUDE 3u
#define SC_ROLE_NOMINAL_ROBOTIC 4u
#define SC_ROLE_SAFETY_TRANSLATIONAL 5u
#define SC_ROLE_SAFETY_ATTITUDE 6u
#define SC_ROLE_SAFETY_ROBOTIC 7u
#define SC_ROLE_RECORDER 8u

/* Health.state */
#define SC_HEALTH_STARTING 0u
#define SC_HEALTH_READY 1u
#define SC_HEALTH_RUNNING 2u
#define SC_HEALTH_FAULTED 3u
#define SC_HEALTH_STOPPING 4u

/* Tick -- safe_capture::v2::Tick, 40 B. Scheduler -> simulator, recorder (step); -> every process on the control service (stop). */
typedef struct ScTick {
    uint64_t tick;
    uint32_t due_mask;
    uint32_t clock_mode;
    double t;
    uint64_t send_ns;
    uint32_t command;
    uint32_t _pad0;
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v2::Tick";
#endif
} ScTick;
SC_ICD_STATIC_ASSERT(sizeof(ScTick) == 40, "ScTick: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScTick) == 8, "ScTick: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScTick, tick) == 0, "ScTick.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScTick, due_mask) == 8, "ScTick.due_mask: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScTick, clock_mode) == 12, "ScTick.clock_mode: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScTick, t) == 16, "ScTick.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScTick, send_ns) == 24, "ScTick.send_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScTick, command) == 32, "ScTick.command: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScTick, _pad0) == 36, "ScTick._pad0: offset");

/* SimState -- safe_capture::v3::SimState, 1568 B. Simulator -> nominal controllers (partner/state), safety filters, recorder: the observation at the start of the step. */
typedef struct ScSimState {
    uint64_t tick;
    double t;
    uint32_t due_mask;
    uint32_t _pad0;
    uint64_t tick_send_ns;
    uint64_t recv_ns;
    uint64_t publish_ns;
    uint64_t step;
    double r_h[3];
    double v_h[3];
    double r_r[3];
    double v_r[3];
    double q_hr[4];
    double omega_h[3];
    double omega_dot_h[3];
    double mean_motion;
    double q_rb[4];
    double omega_b[3];
    double theta[7];
    double theta_dot[7];
    double q_rt[4];
    double omega_t[3];
    double omega_dot_t[3];
    double grasp_r[3];
    double grasp_v_r[3];
    double grasp_a_r[3];
    double grasp_b[3];
    double ee_b[3];
    double ee_r[3];
    double ee_v_r[3];
    double com_h[3];
    double com_v_h[3];
    double com_r[3];
    double com_v_r[3];
    double barriers[51];
    double barriers_between[51];
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v3::SimState";
#endif
} ScSimState;
SC_ICD_STATIC_ASSERT(sizeof(ScSimState) == 1568, "ScSimState: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScSimState) == 8, "ScSimState: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, tick) == 0, "ScSimState.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, t) == 8, "ScSimState.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, due_mask) == 16, "ScSimState.due_mask: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, _pad0) == 20, "ScSimState._pad0: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, tick_send_ns) == 24, "ScSimState.tick_send_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, recv_ns) == 32, "ScSimState.recv_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, publish_ns) == 40, "ScSimState.publish_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, step) == 48, "ScSimState.step: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, r_h) == 56, "ScSimState.r_h: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, v_h) == 80, "ScSimState.v_h: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, r_r) == 104, "ScSimState.r_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, v_r) == 128, "ScSimState.v_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, q_hr) == 152, "ScSimState.q_hr: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, omega_h) == 184, "ScSimState.omega_h: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, omega_dot_h) == 208, "ScSimState.omega_dot_h: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, mean_motion) == 232, "ScSimState.mean_motion: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, q_rb) == 240, "ScSimState.q_rb: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, omega_b) == 272, "ScSimState.omega_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, theta) == 296, "ScSimState.theta: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, theta_dot) == 352, "ScSimState.theta_dot: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, q_rt) == 408, "ScSimState.q_rt: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, omega_t) == 440, "ScSimState.omega_t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, omega_dot_t) == 464, "ScSimState.omega_dot_t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, grasp_r) == 488, "ScSimState.grasp_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, grasp_v_r) == 512, "ScSimState.grasp_v_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, grasp_a_r) == 536, "ScSimState.grasp_a_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, grasp_b) == 560, "ScSimState.grasp_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, ee_b) == 584, "ScSimState.ee_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, ee_r) == 608, "ScSimState.ee_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, ee_v_r) == 632, "ScSimState.ee_v_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, com_h) == 656, "ScSimState.com_h: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, com_v_h) == 680, "ScSimState.com_v_h: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, com_r) == 704, "ScSimState.com_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, com_v_r) == 728, "ScSimState.com_v_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, barriers) == 752, "ScSimState.barriers: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, barriers_between) == 1160, "ScSimState.barriers_between: offset");

/* NominalTranslational -- safe_capture::v2::NominalTranslational, 64 B. Nominal translational controller -> translational safety filter: f_h, Hill frame [N]. */
typedef struct ScNominalTranslational {
    uint64_t tick;
    double t;
    uint32_t valid;
    uint32_t phase;
    uint64_t recv_ns;
    uint64_t publish_ns;
    double f_h[3];
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v2::NominalTranslational";
#endif
} ScNominalTranslational;
SC_ICD_STATIC_ASSERT(sizeof(ScNominalTranslational) == 64, "ScNominalTranslational: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScNominalTranslational) == 8, "ScNominalTranslational: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalTranslational, tick) == 0, "ScNominalTranslational.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalTranslational, t) == 8, "ScNominalTranslational.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalTranslational, valid) == 16, "ScNominalTranslational.valid: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalTranslational, phase) == 20, "ScNominalTranslational.phase: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalTranslational, recv_ns) == 24, "ScNominalTranslational.recv_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalTranslational, publish_ns) == 32, "ScNominalTranslational.publish_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalTranslational, f_h) == 40, "ScNominalTranslational.f_h: offset");

/* NominalAttitude -- safe_capture::v2::NominalAttitude, 64 B. Nominal attitude controller -> attitude safety filter: tau_b, base frame [N m]. */
typedef struct ScNominalAttitude {
    uint64_t tick;
    double t;
    uint32_t valid;
    uint32_t phase;
    uint64_t recv_ns;
    uint64_t publish_ns;
    double tau_b[3];
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v2::NominalAttitude";
#endif
} ScNominalAttitude;
SC_ICD_STATIC_ASSERT(sizeof(ScNominalAttitude) == 64, "ScNominalAttitude: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScNominalAttitude) == 8, "ScNominalAttitude: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalAttitude, tick) == 0, "ScNominalAttitude.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalAttitude, t) == 8, "ScNominalAttitude.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalAttitude, valid) == 16, "ScNominalAttitude.valid: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalAttitude, phase) == 20, "ScNominalAttitude.phase: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalAttitude, recv_ns) == 24, "ScNominalAttitude.recv_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalAttitude, publish_ns) == 32, "ScNominalAttitude.publish_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalAttitude, tau_b) == 40, "ScNominalAttitude.tau_b: offset");

/* NominalRobotic -- safe_capture::v2::NominalRobotic, 96 B. Nominal robotic controller -> robotic safety filter: tau_m, joints [N m]. */
typedef struct ScNominalRobotic {
    uint64_t tick;
    double t;
    uint32_t valid;
    uint32_t phase;
    uint64_t recv_ns;
    uint64_t publish_ns;
    double tau_m[7];
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v2::NominalRobotic";
#endif
} ScNominalRobotic;
SC_ICD_STATIC_ASSERT(sizeof(ScNominalRobotic) == 96, "ScNominalRobotic: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScNominalRobotic) == 8, "ScNominalRobotic: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalRobotic, tick) == 0, "ScNominalRobotic.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalRobotic, t) == 8, "ScNominalRobotic.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalRobotic, valid) == 16, "ScNominalRobotic.valid: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalRobotic, phase) == 20, "ScNominalRobotic.phase: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalRobotic, recv_ns) == 24, "ScNominalRobotic.recv_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalRobotic, publish_ns) == 32, "ScNominalRobotic.publish_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNominalRobotic, tau_m) == 40, "ScNominalRobotic.tau_m: offset");

/* SafeTranslational -- safe_capture::v2::SafeTranslational, 160 B. Translational safety filter -> attitude/robotic filters, simulator, recorder. */
typedef struct ScSafeTranslational {
    uint64_t tick;
    double t;
    uint64_t recv_ns;
    uint64_t publish_ns;
    uint64_t active_mask;
    uint64_t solve_ns;
    uint32_t solver_status;
    uint32_t iterations;
    uint32_t fault_flags;
    uint32_t n_constraints;
    uint32_t phase;
    uint32_t solve_cpu_ns;
    double slack;
    double h[2];
    double phi[2];
    double u[3];
    double actuated[3];
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v2::SafeTranslational";
#endif
} ScSafeTranslational;
SC_ICD_STATIC_ASSERT(sizeof(ScSafeTranslational) == 160, "ScSafeTranslational: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScSafeTranslational) == 8, "ScSafeTranslational: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, tick) == 0, "ScSafeTranslational.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, t) == 8, "ScSafeTranslational.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, recv_ns) == 16, "ScSafeTranslational.recv_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, publish_ns) == 24, "ScSafeTranslational.publish_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, active_mask) == 32, "ScSafeTranslational.active_mask: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, solve_ns) == 40, "ScSafeTranslational.solve_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, solver_status) == 48, "ScSafeTranslational.solver_status: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, iterations) == 52, "ScSafeTranslational.iterations: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, fault_flags) == 56, "ScSafeTranslational.fault_flags: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, n_constraints) == 60, "ScSafeTranslational.n_constraints: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, phase) == 64, "ScSafeTranslational.phase: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, solve_cpu_ns) == 68, "ScSafeTranslational.solve_cpu_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, slack) == 72, "ScSafeTranslational.slack: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, h) == 80, "ScSafeTranslational.h: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, phi) == 96, "ScSafeTranslational.phi: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, u) == 112, "ScSafeTranslational.u: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, actuated) == 136, "ScSafeTranslational.actuated: offset");

/* SafeAttitude -- safe_capture::v2::SafeAttitude, 240 B. Attitude safety filter -> robotic filter, simulator, recorder. */
typedef struct ScSafeAttitude {
    uint64_t tick;
    double t;
    uint64_t recv_ns;
    uint64_t publish_ns;
    uint64_t active_mask;
    uint64_t solve_ns;
    uint32_t solver_status;
    uint32_t iterations;
    uint32_t fault_flags;
    uint32_t n_constraints;
    uint32_t phase;
    uint32_t solve_cpu_ns;
    double slack;
    double h[7];
    double phi[7];
    double u[3];
    double actuated[3];
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v2::SafeAttitude";
#endif
} ScSafeAttitude;
SC_ICD_STATIC_ASSERT(sizeof(ScSafeAttitude) == 240, "ScSafeAttitude: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScSafeAttitude) == 8, "ScSafeAttitude: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, tick) == 0, "ScSafeAttitude.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, t) == 8, "ScSafeAttitude.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, recv_ns) == 16, "ScSafeAttitude.recv_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, publish_ns) == 24, "ScSafeAttitude.publish_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, active_mask) == 32, "ScSafeAttitude.active_mask: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, solve_ns) == 40, "ScSafeAttitude.solve_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, solver_status) == 48, "ScSafeAttitude.solver_status: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, iterations) == 52, "ScSafeAttitude.iterations: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, fault_flags) == 56, "ScSafeAttitude.fault_flags: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, n_constraints) == 60, "ScSafeAttitude.n_constraints: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, phase) == 64, "ScSafeAttitude.phase: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, solve_cpu_ns) == 68, "ScSafeAttitude.solve_cpu_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, slack) == 72, "ScSafeAttitude.slack: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, h) == 80, "ScSafeAttitude.h: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, phi) == 136, "ScSafeAttitude.phi: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, u) == 192, "ScSafeAttitude.u: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, actuated) == 216, "ScSafeAttitude.actuated: offset");

/* SafeRobotic -- safe_capture::v2::SafeRobotic, 864 B. Robotic safety filter -> simulator, recorder. */
typedef struct ScSafeRobotic {
    uint64_t tick;
    double t;
    uint64_t recv_ns;
    uint64_t publish_ns;
    uint64_t active_mask;
    uint64_t solve_ns;
    uint32_t solver_status;
    uint32_t iterations;
    uint32_t fault_flags;
    uint32_t n_constraints;
    uint32_t phase;
    uint32_t solve_cpu_ns;
    double slack;
    double h[42];
    double phi[42];
    double u[7];
    double actuated[7];
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v2::SafeRobotic";
#endif
} ScSafeRobotic;
SC_ICD_STATIC_ASSERT(sizeof(ScSafeRobotic) == 864, "ScSafeRobotic: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScSafeRobotic) == 8, "ScSafeRobotic: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, tick) == 0, "ScSafeRobotic.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, t) == 8, "ScSafeRobotic.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, recv_ns) == 16, "ScSafeRobotic.recv_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, publish_ns) == 24, "ScSafeRobotic.publish_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, active_mask) == 32, "ScSafeRobotic.active_mask: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, solve_ns) == 40, "ScSafeRobotic.solve_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, solver_status) == 48, "ScSafeRobotic.solver_status: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, iterations) == 52, "ScSafeRobotic.iterations: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, fault_flags) == 56, "ScSafeRobotic.fault_flags: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, n_constraints) == 60, "ScSafeRobotic.n_constraints: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, phase) == 64, "ScSafeRobotic.phase: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, solve_cpu_ns) == 68, "ScSafeRobotic.solve_cpu_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, slack) == 72, "ScSafeRobotic.slack: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, h) == 80, "ScSafeRobotic.h: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, phi) == 416, "ScSafeRobotic.phi: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, u) == 752, "ScSafeRobotic.u: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, actuated) == 808, "ScSafeRobotic.actuated: offset");

/* StepResult -- safe_capture::v1::StepResult, 152 B. Simulator -> scheduler, recorder: the applied command and how the step ended. */
typedef struct ScStepResult {
    uint64_t tick;
    double t;
    uint32_t end;
    uint32_t fallback_mask;
    uint32_t held_mask;
    uint32_t fault_flags;
    uint64_t safe_recv_ns;
    uint64_t publish_ns;
    double force_b[3];
    double torque_b[3];
    double tau[7];
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v1::StepResult";
#endif
} ScStepResult;
SC_ICD_STATIC_ASSERT(sizeof(ScStepResult) == 152, "ScStepResult: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScStepResult) == 8, "ScStepResult: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, tick) == 0, "ScStepResult.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, t) == 8, "ScStepResult.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, end) == 16, "ScStepResult.end: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, fallback_mask) == 20, "ScStepResult.fallback_mask: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, held_mask) == 24, "ScStepResult.held_mask: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, fault_flags) == 28, "ScStepResult.fault_flags: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, safe_recv_ns) == 32, "ScStepResult.safe_recv_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, publish_ns) == 40, "ScStepResult.publish_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, force_b) == 48, "ScStepResult.force_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, torque_b) == 72, "ScStepResult.torque_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScStepResult, tau) == 96, "ScStepResult.tau: offset");

/* Health -- safe_capture::v1::Health, 56 B. Recorder -> scheduler: progress (lock-step flow control). */
typedef struct ScHealth {
    uint32_t role;
    uint32_t pid;
    uint32_t state;
    uint32_t last_fault_flags;
    uint64_t ticks_handled;
    uint64_t deadline_misses;
    uint64_t cycle_slips;
    uint64_t last_tick;
    uint64_t publish_ns;
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v1::Health";
#endif
} ScHealth;
SC_ICD_STATIC_ASSERT(sizeof(ScHealth) == 56, "ScHealth: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScHealth) == 8, "ScHealth: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScHealth, role) == 0, "ScHealth.role: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScHealth, pid) == 4, "ScHealth.pid: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScHealth, state) == 8, "ScHealth.state: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScHealth, last_fault_flags) == 12, "ScHealth.last_fault_flags: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScHealth, ticks_handled) == 16, "ScHealth.ticks_handled: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScHealth, deadline_misses) == 24, "ScHealth.deadline_misses: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScHealth, cycle_slips) == 32, "ScHealth.cycle_slips: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScHealth, last_tick) == 40, "ScHealth.last_tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScHealth, publish_ns) == 48, "ScHealth.publish_ns: offset");

#ifdef __cplusplus
}
#endif

#endif /* SAFE_CAPTURE_ICD_H */
