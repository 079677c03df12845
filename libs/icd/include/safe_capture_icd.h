/* safe_capture_icd.h -- the safe-capture ICD (docs/ICD.md) for C and C++ partners.
 *
 * GENERATED from the Rust crate sc-icd by sc-icd-gen (libs/icd-gen/src/c_header.rs);
 * do not edit. Regenerate: SC_WRITE_ICD=1 cargo test -p sc-icd-gen
 *
 * Every message is the #[repr(C)] Rust struct of the same name: fixed size, 8-byte
 * aligned, no implicit padding (explicit _pad* fields are 0). Units and frames of
 * every field: the comment after it ([unit], frame, meaning), docs/ICD.md and
 * `cargo doc -p sc-icd`. Transport: iceoryx2 0.10.
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

/* Array lengths of the messages. */
#define SC_N_JOINTS 7u /* Number of manipulator joints. */
#define SC_N_CONSTRAINTS_TRANSLATIONAL 2u /* Number of translational safety constraints: AC (approach corridor), CAZ (collision-avoidance zone). */
#define SC_N_CONSTRAINTS_ATTITUDE 7u /* Number of attitude safety constraints: ATT (pointing), ω1..3 upper, ω1..3 lower. */
#define SC_N_CONSTRAINTS_ROBOTIC 63u /* Number of robotic safety constraints: θ limits 7, θ̇ upper 7, θ̇ lower 7, link-base 21, link-target 21. */
#define SC_N_BARRIERS_MONITORED 1u /* Number of barriers only the safety monitor evaluates: the base's collision zone against the target's body (implied by the collision-avoidance zone). */
#define SC_N_BARRIERS 73u /* Number of barriers of the whole safety layer (translational, attitude, robotic, then the monitored ones). */

/* Service names (relative: a run's iceoryx2 global.prefix is "sc_<SC_RUN_ID>_"). Each pub/sub service has an event service of the same name. */
#define SC_SERVICE_TICK "safe_capture/scheduler/tick" /* Tick, QoS flight */
#define SC_SERVICE_CONTROL "safe_capture/scheduler/control" /* Tick, QoS flight */
#define SC_SERVICE_MEASUREMENT "safe_capture/sim/measurement" /* NavState, QoS partner */
#define SC_SERVICE_ESTIMATE "safe_capture/navigation/estimate" /* NavState, QoS partner */
#define SC_SERVICE_SIM_STATE "safe_capture/sim/state" /* SimState, QoS flight */
#define SC_SERVICE_PARTNER_STATE "safe_capture/partner/state" /* SimState, QoS partner */
#define SC_SERVICE_TRUTH "safe_capture/sim/truth" /* SimState, QoS flight */
#define SC_SERVICE_NAVIGATION_ERROR "safe_capture/sim/navigation_error" /* NavigationError, QoS flight */
#define SC_SERVICE_NOMINAL_TRANSLATIONAL "safe_capture/nominal/translational" /* NominalTranslational, QoS partner */
#define SC_SERVICE_NOMINAL_ATTITUDE "safe_capture/nominal/attitude" /* NominalAttitude, QoS partner */
#define SC_SERVICE_NOMINAL_ROBOTIC "safe_capture/nominal/robotic" /* NominalRobotic, QoS partner */
#define SC_SERVICE_SAFE_TRANSLATIONAL "safe_capture/safe/translational" /* SafeTranslational, QoS flight */
#define SC_SERVICE_SAFE_ATTITUDE "safe_capture/safe/attitude" /* SafeAttitude, QoS flight */
#define SC_SERVICE_SAFE_ROBOTIC "safe_capture/safe/robotic" /* SafeRobotic, QoS flight */
#define SC_SERVICE_STEP_RESULT "safe_capture/sim/step_result" /* StepResult, QoS flight */
#define SC_SERVICE_HEALTH "safe_capture/health" /* Health, QoS flight */
#define SC_SERVICE_STAGE_DEADLINE "safe_capture/scheduler/deadline" /* event only */
#define SC_SERVICE_PREPARE "safe_capture/scheduler/prepare" /* event only */
#define SC_SERVICE_HANDSHAKE "safe_capture/handshake" /* event only */
#define SC_SERVICE_HANDSHAKE_READY "safe_capture/handshake/ready" /* event service `ready` of SC_SERVICE_HANDSHAKE */
#define SC_SERVICE_HANDSHAKE_GO "safe_capture/handshake/go" /* event service `go` of SC_SERVICE_HANDSHAKE */

/* iceoryx2 type names: give them when opening a service (iceoryx2 matches types by name, size and alignment) */
#define SC_TYPE_NAME_TICK "safe_capture::v2::Tick"
#define SC_TYPE_NAME_SIM_STATE "safe_capture::v5::SimState"
#define SC_TYPE_NAME_NOMINAL_TRANSLATIONAL "safe_capture::v2::NominalTranslational"
#define SC_TYPE_NAME_NOMINAL_ATTITUDE "safe_capture::v2::NominalAttitude"
#define SC_TYPE_NAME_NOMINAL_ROBOTIC "safe_capture::v2::NominalRobotic"
#define SC_TYPE_NAME_SAFE_TRANSLATIONAL "safe_capture::v3::SafeTranslational"
#define SC_TYPE_NAME_SAFE_ATTITUDE "safe_capture::v3::SafeAttitude"
#define SC_TYPE_NAME_SAFE_ROBOTIC "safe_capture::v4::SafeRobotic"
#define SC_TYPE_NAME_STEP_RESULT "safe_capture::v1::StepResult"
#define SC_TYPE_NAME_NAVIGATION_ERROR "safe_capture::v1::NavigationError"
#define SC_TYPE_NAME_NAV_STATE "safe_capture::v1::NavState"
#define SC_TYPE_NAME_HEALTH "safe_capture::v1::Health"

/* Event ids of the partition's event services (`sc_bus::pubsub`, `sc_bus::handshake`; `libs/bus/tests/icd_constants.rs` checks them against sc-bus). */
#define SC_EVENT_SAMPLE 0u /* A publisher notifies this after each send. */
#define SC_EVENT_NOTIFIER_DEAD 1u /* iceoryx2 emits it when dead-node clean-up removes a crashed publisher's notifier. */
#define SC_EVENT_NOTIFIER_DROPPED 2u /* iceoryx2 emits it when a publisher's notifier is dropped (it left). */
#define SC_EVENT_ID_MAX 7u /* Largest event id on a data service. */
#define SC_EVENT_GO 3u /* The coordinator's `go` on `<HANDSHAKE>/go`. */
#define SC_EVENT_HANDSHAKE_ID_OFFSET 8u /* A participant notifies `<HANDSHAKE>/ready` with this + its role id. */

/* Bits of the `due_mask` fields (Tick, SimState; also `StepResult.fallback_mask` and `held_mask`): which subsystems' rate groups run in a tick (`sc_core::Subsystem::bit`). */
#define SC_DUE_TRANSLATIONAL 1u /* Translational nominal controller and safety filter. */
#define SC_DUE_ATTITUDE 2u /* Attitude nominal controller and safety filter. */
#define SC_DUE_ROBOTIC 4u /* Robotic nominal controller and safety filter. */
#define SC_DUE_ALL 7u /* All three. */

/* Values of `Tick.command`. */
#define SC_TICK_STEP 0u /* Run one control step. */
#define SC_TICK_STOP 1u /* The run is over: every process finishes its outputs and exits. */

/* Values of `Tick.clock_mode`. */
#define SC_CLOCK_LOCK_STEP 0u /* Lock-step: the next tick is sent as soon as the previous one completed. */
#define SC_CLOCK_REAL_TIME 1u /* Real time: ticks paced by the wall clock at the rate-group period. */
#define SC_CLOCK_SCALED 2u /* Scaled real time: paced at a configured multiple of real time. */

/* Values of `StepResult.end`. */
#define SC_END_RUNNING 0u /* The mission goes on. */
#define SC_END_CAPTURED 1u /* Captured: end-effector on the grasping point within tolerance. */
#define SC_END_TIMEOUT 2u /* The configured duration elapsed. */
#define SC_END_SIMULATOR_FAILED 3u /* The simulator failed (non-finite state or command). */

/* Bits of `StepResult.fault_flags` and `Health.last_fault_flags`. */
#define SC_FAULT_STALE_INPUT 1u /* Input older than one tick (stale state). */
#define SC_FAULT_NON_FINITE_INPUT 2u /* Non-finite number in an input. */
#define SC_FAULT_SOLVER_FAILED 4u /* QP solver failed; output falls back to the backup law. */
#define SC_FAULT_INFEASIBLE 8u /* QP infeasible; constraints relaxed. */
#define SC_FAULT_SATURATED 16u /* Output saturated at actuator limits. */
#define SC_FAULT_NOMINAL_MISSING 32u /* Nominal command missing or invalid; filter used zero nominal input. */
#define SC_FAULT_DEADLINE_MISS 64u /* Deadline missed. */
#define SC_FAULT_PEER_DEAD 128u /* A peer process was detected dead. */
#define SC_FAULT_REJECTED_COMMAND 256u /* The simulator rejected a safe command (not finite or beyond the input bounds, `sc_flight::admission`) and applied the filter's backup instead. */
#define SC_FAULT_NAVIGATION_REJECTED 512u /* The navigation's estimate was missing at the navigation deadline or rejected (not finite, not current, a quaternion off the unit sphere, or farther from the measurement than the declared navigation bounds, `sc_sim::navigation`); the simulator's own navigation (the declared error model) was substituted. */
#define SC_FAULT_COUPLING_MISMATCH 1024u /* A safe command was not applied because it does not fit the chain the filters certified: it was certified against other upstream commands than those acting, or it came after the downstream filters had given up on it and certified against its backup; the backup acts instead (docs/PARTITION.md). */

/* Values of `Health.state`. */
#define SC_HEALTH_STARTING 0u /* Process started, ports being created. */
#define SC_HEALTH_READY 1u /* Ports exist, handshake announced. */
#define SC_HEALTH_RUNNING 2u /* Handling ticks. */
#define SC_HEALTH_FAULTED 3u /* A fault was detected; see `last_fault_flags`. */
#define SC_HEALTH_STOPPING 4u /* Shutting down. */

/* Role ids, from the role table (sc_icd::ROLES, start order): Health.role; the handshake id is SC_EVENT_HANDSHAKE_ID_OFFSET + role */
#define SC_ROLE_SCHEDULER 0u /* scheduler: rate groups, ticks (lock-step or real time), the end of the run, liveness of the peers */
#define SC_ROLE_SIMULATOR 1u /* simulator: the plant: measures the state, admits the navigation's estimate (its own navigation when that is missing or rejected) and publishes the knowledge derived from it, applies the re-validated safe commands (the backup when one is missing or rejected) */
#define SC_ROLE_NOMINAL_TRANSLATIONAL 2u /* nominal_translational: the nominal translational controller (MPC), replaceable by a partner's */
#define SC_ROLE_NOMINAL_ATTITUDE 3u /* nominal_attitude: the nominal attitude controller (MPC), replaceable by a partner's */
#define SC_ROLE_NOMINAL_ROBOTIC 4u /* nominal_robotic: the nominal robotic controller (joint-space PD), replaceable by a partner's */
#define SC_ROLE_SAFETY_TRANSLATIONAL 5u /* safety_translational: the translational safety filter (approach corridor, collision-avoidance zone) */
#define SC_ROLE_SAFETY_ATTITUDE 6u /* safety_attitude: the attitude safety filter (line of sight, body-rate limits), ξ = the translational safe force */
#define SC_ROLE_SAFETY_ROBOTIC 7u /* safety_robotic: the robotic safety filter (joint angles and rates, link–base spheres), ξ = the translational and attitude safe commands */
#define SC_ROLE_RECORDER 8u /* recorder: telemetry: the same telemetry.csv, timing.csv and summary.json as `safe-capture run`, plus recording.mcap and latency.csv */
#define SC_ROLE_NAVIGATION 9u /* navigation: the navigation: the estimate of each tick's state from the measurements (the declared error model), replaceable by a partner's estimator */

/* Tick -- safe_capture::v2::Tick, 40 B. Scheduler → simulator, every other process (stop), recorder: start one control step. */
typedef struct ScTick {
    uint64_t tick; /* Tick index, starts at 0, +1 per tick of the fastest rate group [-] */
    uint32_t due_mask; /* Subsystems due in this tick, bits of `due` (1 translational, 2 attitude, 4 robotic, 7 all) [-] */
    uint32_t clock_mode; /* Clock mode, one of `clock_mode` (0 lock step, 1 real time, 2 scaled) [-] */
    double t; /* Simulation time at which this step starts [s] */
    uint64_t send_ns; /* Scheduler send stamp, host CLOCK_MONOTONIC [ns] */
    uint32_t command; /* Step or stop (the run is over), one of `tick_command` (0 step, 1 stop) [-] */
    uint32_t _pad0; /* Always 0 [-] */
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

/* SimState -- safe_capture::v5::SimState, 1968 B. Simulator → nominal controllers, safety filters, recorder: the observation at the start of the step. Every field of `sc_core::Observation`, copied as f64, so that the stages compute exactly what they compute in one process. */
typedef struct ScSimState {
    uint64_t tick; /* Tick index this state answers (= simulator step count at the base rate) [-] */
    double t; /* Simulation time [s] */
    uint32_t due_mask; /* Subsystems due in this tick, bits of `due` (1 translational, 2 attitude, 4 robotic, 7 all) [-] */
    uint32_t _pad0; /* Always 0 [-] */
    uint64_t tick_send_ns; /* Send stamp of the tick this state answers, host CLOCK_MONOTONIC [ns] */
    uint64_t recv_ns; /* Stamp at which the simulator received the tick, host CLOCK_MONOTONIC [ns] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
    uint64_t step; /* Simulator step counter [-] */
    double r_h[3]; /* Servicer base origin relative to the target CoM, r_H, frame F_H [m] */
    double v_h[3]; /* Derivative of r_H in the rotating Hill frame, frame F_H [m/s] */
    double r_r[3]; /* Servicer base origin relative to the target CoM, r_R, frame F_R [m] */
    double v_r[3]; /* Inertial derivative of r_R, frame F_R [m/s] */
    double q_hr[4]; /* Attitude q_HR of F_R in F_H: rotates F_R vectors into F_H, frame F_R → F_H [-] */
    double omega_h[3]; /* Angular velocity ω_H of F_H w.r.t. inertial, frame F_H [rad/s] */
    double omega_dot_h[3]; /* Angular acceleration of F_H w.r.t. inertial, frame F_H [rad/s²] */
    double mean_motion; /* Mean motion of the target orbit |ω_H| [rad/s] */
    double q_rb[4]; /* Servicer attitude q_RB: rotates F_B vectors into F_R, frame F_B → F_R [-] */
    double omega_b[3]; /* Servicer body rate ω_B w.r.t. inertial, frame F_B [rad/s] */
    double theta[7]; /* Joint angles θ, frame M [rad] */
    double theta_dot[7]; /* Joint rates θ̇, frame M [rad/s] */
    double q_rt[4]; /* Target attitude q_RT: rotates F_T vectors into F_R, frame F_T → F_R [-] */
    double omega_t[3]; /* Target body rate ω_T w.r.t. inertial, frame F_T [rad/s] */
    double omega_dot_t[3]; /* Derivative of ω_T, frame F_T [rad/s²] */
    double grasp_r[3]; /* Grasping point relative to the target CoM, frame F_R [m] */
    double grasp_v_r[3]; /* Grasping point inertial velocity, frame F_R [m/s] */
    double grasp_a_r[3]; /* Grasping point inertial acceleration, frame F_R [m/s²] */
    double grasp_b[3]; /* Grasping point relative to the base origin, frame F_B [m] */
    double ee_b[3]; /* End-effector position relative to the base origin, frame F_B [m] */
    double ee_r[3]; /* End-effector position relative to the target CoM, frame F_R [m] */
    double ee_v_r[3]; /* End-effector inertial velocity, frame F_R [m/s] */
    double com_h[3]; /* Servicer system centre of mass relative to the target CoM, frame F_H [m] */
    double com_v_h[3]; /* Derivative of com_h in the rotating Hill frame, frame F_H [m/s] */
    double com_r[3]; /* Servicer system centre of mass relative to the target CoM, frame F_R [m] */
    double com_v_r[3]; /* Inertial velocity of the servicer system centre of mass, frame F_R [m/s] */
    double barriers[73]; /* Every barrier h at this state, from the simulator's own state (the safety monitor), in telemetry order; NaN (null in the MCAP) = not evaluated. With a declared `[uncertainty]` the state is the estimate and these the barriers on knowledge (the declared model on it) [unit per constraint] */
    double barriers_between[73]; /* The smallest value of every barrier over the physics steps since the previous state message (this state included); with a declared `[uncertainty]` equal to `barriers` (knowledge exists at the ticks only) [unit per constraint] */
    double held_f_b[3]; /* The base force the simulator holds from the previous step: what acts in this tick while the translational group is not due (a downstream filter certifies against it then; docs/PARTITION.md, "Only what was certified acts"), frame F_B [N] */
    double held_tau_b[3]; /* The base torque the simulator holds from the previous step, as `held_f_b`, frame F_B [N·m] */
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v5::SimState";
#endif
} ScSimState;
SC_ICD_STATIC_ASSERT(sizeof(ScSimState) == 1968, "ScSimState: size");
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
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, barriers_between) == 1336, "ScSimState.barriers_between: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, held_f_b) == 1920, "ScSimState.held_f_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSimState, held_tau_b) == 1944, "ScSimState.held_tau_b: offset");

/* NominalTranslational -- safe_capture::v2::NominalTranslational, 64 B. Nominal translational controller → translational safety filter, recorder. */
typedef struct ScNominalTranslational {
    uint64_t tick; /* Tick index this command answers [-] */
    double t; /* Simulation time of the state used [s] */
    uint32_t valid; /* 1 if the controller ran on valid inputs, 0 otherwise [-] */
    uint32_t phase; /* Index of the mission phase (0-based, scenario order) [-] */
    uint64_t recv_ns; /* Stamp at which the state was received, host CLOCK_MONOTONIC [ns] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
    double f_h[3]; /* Commanded force f_H, unsaturated, frame F_H [N] */
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

/* NominalAttitude -- safe_capture::v2::NominalAttitude, 64 B. Nominal attitude controller → attitude safety filter, recorder. */
typedef struct ScNominalAttitude {
    uint64_t tick; /* Tick index this command answers [-] */
    double t; /* Simulation time of the state used [s] */
    uint32_t valid; /* 1 if the controller ran on valid inputs, 0 otherwise [-] */
    uint32_t phase; /* Index of the mission phase (0-based, scenario order) [-] */
    uint64_t recv_ns; /* Stamp at which the state was received, host CLOCK_MONOTONIC [ns] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
    double tau_b[3]; /* Commanded torque τ_B, unsaturated, frame F_B [N·m] */
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

/* NominalRobotic -- safe_capture::v2::NominalRobotic, 96 B. Nominal robotic controller → robotic safety filter, recorder. */
typedef struct ScNominalRobotic {
    uint64_t tick; /* Tick index this command answers [-] */
    double t; /* Simulation time of the state used [s] */
    uint32_t valid; /* 1 if the controller ran on valid inputs, 0 otherwise [-] */
    uint32_t phase; /* Index of the mission phase (0-based, scenario order) [-] */
    uint64_t recv_ns; /* Stamp at which the state was received, host CLOCK_MONOTONIC [ns] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
    double tau_m[7]; /* Commanded joint torques τ_M, unsaturated, frame M [N·m] */
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

/* SafeTranslational -- safe_capture::v3::SafeTranslational, 208 B. Translational safety filter → attitude and robotic filters, simulator, recorder. Constraint order: AC, CAZ. */
typedef struct ScSafeTranslational {
    uint64_t tick; /* Tick index this command answers [-] */
    double t; /* Simulation time of the state used [s] */
    uint64_t recv_ns; /* Stamp at which the last input of this tick arrived, host CLOCK_MONOTONIC [ns] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
    uint64_t active_mask; /* Bit i set = constraint i active (Φ_i ≈ 0) [-] */
    uint64_t solve_ns; /* Wall time of the filter call [ns] */
    uint32_t solver_status; /* `sc_cbf::FilterStatus`: 0 skipped, 1 solved, 2 relaxed, 3 fallback [-] */
    uint32_t iterations; /* QP solver iterations [-] */
    uint32_t fault_flags; /* `sc_cbf::faults` bits (5 upstream_missing, 7 nominal_missing, 9 margins_degraded, 10 safe_mode: docs/ICD.md) [-] */
    uint32_t n_constraints; /* Number of constraints in `h` and `phi` [-] */
    uint32_t phase; /* Mission phase of the nominal command filtered (0-based) [-] */
    uint32_t solve_cpu_ns; /* CPU time of the filter call on its thread, saturating at u32::MAX [ns] */
    double slack; /* Slack of the relaxed QP (0 otherwise), normalised rows; for a translational step degraded under a declared uncertainty, the share of the declared margins given up (docs/SAFETY.md) [-] */
    double h[2]; /* Barrier values h_i the filter evaluated; NaN (null in the MCAP) = not evaluated [unit per constraint] */
    double phi[2]; /* CBF conditions Φ_i at the safe command [unit per constraint / s] */
    double u[3]; /* Safe force f_H, frame F_H [N] */
    double actuated[3]; /* Safe force f_B = R_BH f_H (what the thrusters apply), frame F_B [N] */
    double xi_f_b[3]; /* Coupling ξ this command was certified against: the base force f_B acting upstream (the translational command or its backup; 0 for the translational filter, which has no upstream). The simulator applies the command only with exactly this force acting (docs/PARTITION.md), frame F_B [N] */
    double xi_tau_b[3]; /* Coupling ξ this command was certified against: the base torque τ_B acting upstream (the attitude command or its backup; 0 for the translational and attitude filters), frame F_B [N·m] */
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v3::SafeTranslational";
#endif
} ScSafeTranslational;
SC_ICD_STATIC_ASSERT(sizeof(ScSafeTranslational) == 208, "ScSafeTranslational: size");
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
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, xi_f_b) == 160, "ScSafeTranslational.xi_f_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeTranslational, xi_tau_b) == 184, "ScSafeTranslational.xi_tau_b: offset");

/* SafeAttitude -- safe_capture::v3::SafeAttitude, 288 B. Attitude safety filter → robotic filter, simulator, recorder. Constraint order: ATT, ω1..3 upper, ω1..3 lower. */
typedef struct ScSafeAttitude {
    uint64_t tick; /* Tick index this command answers [-] */
    double t; /* Simulation time of the state used [s] */
    uint64_t recv_ns; /* Stamp at which the last input of this tick arrived, host CLOCK_MONOTONIC [ns] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
    uint64_t active_mask; /* Bit i set = constraint i active (Φ_i ≈ 0) [-] */
    uint64_t solve_ns; /* Wall time of the filter call [ns] */
    uint32_t solver_status; /* `sc_cbf::FilterStatus`: 0 skipped, 1 solved, 2 relaxed, 3 fallback [-] */
    uint32_t iterations; /* QP solver iterations [-] */
    uint32_t fault_flags; /* `sc_cbf::faults` bits (5 upstream_missing, 7 nominal_missing, 9 margins_degraded, 10 safe_mode: docs/ICD.md) [-] */
    uint32_t n_constraints; /* Number of constraints in `h` and `phi` [-] */
    uint32_t phase; /* Mission phase of the nominal command filtered (0-based) [-] */
    uint32_t solve_cpu_ns; /* CPU time of the filter call on its thread, saturating at u32::MAX [ns] */
    double slack; /* Slack of the relaxed QP (0 otherwise), normalised rows; for a translational step degraded under a declared uncertainty, the share of the declared margins given up (docs/SAFETY.md) [-] */
    double h[7]; /* Barrier values h_i the filter evaluated; NaN (null in the MCAP) = not evaluated [unit per constraint] */
    double phi[7]; /* CBF conditions Φ_i at the safe command [unit per constraint / s] */
    double u[3]; /* Safe torque τ_B, frame F_B [N·m] */
    double actuated[3]; /* Actuated torque τ_B (equals `u`), frame F_B [N·m] */
    double xi_f_b[3]; /* Coupling ξ this command was certified against: the base force f_B acting upstream (the translational command or its backup; 0 for the translational filter, which has no upstream). The simulator applies the command only with exactly this force acting (docs/PARTITION.md), frame F_B [N] */
    double xi_tau_b[3]; /* Coupling ξ this command was certified against: the base torque τ_B acting upstream (the attitude command or its backup; 0 for the translational and attitude filters), frame F_B [N·m] */
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v3::SafeAttitude";
#endif
} ScSafeAttitude;
SC_ICD_STATIC_ASSERT(sizeof(ScSafeAttitude) == 288, "ScSafeAttitude: size");
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
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, xi_f_b) == 240, "ScSafeAttitude.xi_f_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeAttitude, xi_tau_b) == 264, "ScSafeAttitude.xi_tau_b: offset");

/* SafeRobotic -- safe_capture::v4::SafeRobotic, 1248 B. Robotic safety filter → simulator, recorder. Constraint order: θ limits 0..7, θ̇ upper 7..14, θ̇ lower 14..21, link-base 21..42, link-target 42..63. */
typedef struct ScSafeRobotic {
    uint64_t tick; /* Tick index this command answers [-] */
    double t; /* Simulation time of the state used [s] */
    uint64_t recv_ns; /* Stamp at which the last input of this tick arrived, host CLOCK_MONOTONIC [ns] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
    uint64_t active_mask; /* Bit i set = constraint i active (Φ_i ≈ 0) [-] */
    uint64_t solve_ns; /* Wall time of the filter call [ns] */
    uint32_t solver_status; /* `sc_cbf::FilterStatus`: 0 skipped, 1 solved, 2 relaxed, 3 fallback [-] */
    uint32_t iterations; /* QP solver iterations [-] */
    uint32_t fault_flags; /* `sc_cbf::faults` bits (5 upstream_missing, 7 nominal_missing, 9 margins_degraded, 10 safe_mode: docs/ICD.md) [-] */
    uint32_t n_constraints; /* Number of constraints in `h` and `phi` [-] */
    uint32_t phase; /* Mission phase of the nominal command filtered (0-based) [-] */
    uint32_t solve_cpu_ns; /* CPU time of the filter call on its thread, saturating at u32::MAX [ns] */
    double slack; /* Slack of the relaxed QP (0 otherwise), normalised rows; for a translational step degraded under a declared uncertainty, the share of the declared margins given up (docs/SAFETY.md) [-] */
    double h[63]; /* Barrier values h_i the filter evaluated; NaN (null in the MCAP) = not evaluated [unit per constraint] */
    double phi[63]; /* CBF conditions Φ_i at the safe command [unit per constraint / s] */
    double u[7]; /* Safe joint torques τ_M, frame M [N·m] */
    double actuated[7]; /* Actuated joint torques τ_M (equals `u`), frame M [N·m] */
    double xi_f_b[3]; /* Coupling ξ this command was certified against: the base force f_B acting upstream (the translational command or its backup; 0 for the translational filter, which has no upstream). The simulator applies the command only with exactly this force acting (docs/PARTITION.md), frame F_B [N] */
    double xi_tau_b[3]; /* Coupling ξ this command was certified against: the base torque τ_B acting upstream (the attitude command or its backup; 0 for the translational and attitude filters), frame F_B [N·m] */
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v4::SafeRobotic";
#endif
} ScSafeRobotic;
SC_ICD_STATIC_ASSERT(sizeof(ScSafeRobotic) == 1248, "ScSafeRobotic: size");
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
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, phi) == 584, "ScSafeRobotic.phi: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, u) == 1088, "ScSafeRobotic.u: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, actuated) == 1144, "ScSafeRobotic.actuated: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, xi_f_b) == 1200, "ScSafeRobotic.xi_f_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScSafeRobotic, xi_tau_b) == 1224, "ScSafeRobotic.xi_tau_b: offset");

/* StepResult -- safe_capture::v1::StepResult, 152 B. Simulator → scheduler, recorder: the command applied over the step and how the step ended. Sent once all due safe commands of the tick are in (or their deadline passed and the simulator used the filter's fallback). */
typedef struct ScStepResult {
    uint64_t tick; /* Tick index [-] */
    double t; /* Simulation time at the start of the step [s] */
    uint32_t end; /* How the step ended, one of `end` (0 running, 1 captured, 2 timeout, 3 simulator failed) [-] */
    uint32_t fallback_mask; /* Subsystems (bits of `due`) whose command is the filter fallback computed by the simulator: the safe command was missing at the deadline, refused, or did not fit what acts upstream (`fault::COUPLING_MISMATCH`) (1 translational, 2 attitude, 4 robotic, 7 all) [-] */
    uint32_t held_mask; /* Subsystems (bits of `due`) whose command was held from an earlier tick (slower rate group) (1 translational, 2 attitude, 4 robotic, 7 all) [-] */
    uint32_t fault_flags; /* Partition fault flags, bits of `fault` (1 stale input, 2 non finite input, 4 solver failed, 8 infeasible, 16 saturated, 32 nominal missing, 64 deadline miss, 128 peer dead, 256 rejected command, 512 navigation rejected, 1024 coupling mismatch) [-] */
    uint64_t safe_recv_ns; /* Stamp at which the robotic safe command (the tick's last) was delivered, host CLOCK_MONOTONIC [ns] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
    double force_b[3]; /* Applied base force f_B, frame F_B [N] */
    double torque_b[3]; /* Applied base torque τ_B, frame F_B [N·m] */
    double tau[7]; /* Applied joint torques τ_M, frame M [N·m] */
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

/* NavigationError -- safe_capture::v1::NavigationError, 96 B. Simulator → recorder, with a declared `[uncertainty]` only: the realised navigation errors of the tick's estimate (the state on `SIM_STATE`) against the truth measured `measurement_age_s` before it (with an age of 0 the truth on `TRUTH`), each as in `navigation.csv` (vectors: Euclidean norm; joints: the largest of the seven). */
typedef struct ScNavigationError {
    uint64_t tick; /* Tick index [-] */
    double t; /* Simulation time of the estimate [s] */
    double relative_position_m; /* Relative position error of the servicer base to the target CoM [m] */
    double relative_velocity_m_s; /* Relative velocity error [m/s] */
    double servicer_attitude_rad; /* Servicer attitude error (rotation angle) [rad] */
    double servicer_rate_rad_s; /* Servicer body rate error [rad/s] */
    double target_attitude_rad; /* Target attitude error (rotation angle) [rad] */
    double target_rate_rad_s; /* Target body rate error [rad/s] */
    double grasp_point_m; /* Grasping point error in the target frame [m] */
    double joint_angle_rad; /* Largest joint angle error [rad] */
    double joint_rate_rad_s; /* Largest joint rate error [rad/s] */
    double measurement_age_s; /* Age of the measurement the estimate rests on [s] */
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v1::NavigationError";
#endif
} ScNavigationError;
SC_ICD_STATIC_ASSERT(sizeof(ScNavigationError) == 96, "ScNavigationError: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScNavigationError) == 8, "ScNavigationError: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, tick) == 0, "ScNavigationError.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, t) == 8, "ScNavigationError.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, relative_position_m) == 16, "ScNavigationError.relative_position_m: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, relative_velocity_m_s) == 24, "ScNavigationError.relative_velocity_m_s: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, servicer_attitude_rad) == 32, "ScNavigationError.servicer_attitude_rad: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, servicer_rate_rad_s) == 40, "ScNavigationError.servicer_rate_rad_s: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, target_attitude_rad) == 48, "ScNavigationError.target_attitude_rad: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, target_rate_rad_s) == 56, "ScNavigationError.target_rate_rad_s: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, grasp_point_m) == 64, "ScNavigationError.grasp_point_m: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, joint_angle_rad) == 72, "ScNavigationError.joint_angle_rad: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, joint_rate_rad_s) == 80, "ScNavigationError.joint_rate_rad_s: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavigationError, measurement_age_s) == 88, "ScNavigationError.measurement_age_s: offset");

/* NavState -- safe_capture::v1::NavState, 376 B. A navigation state in the inertial frame the simulator propagates in: on `MEASUREMENT` what the simulator's sensors measured (simulator → navigation), on `ESTIMATE` what the navigation estimates (navigation → simulator). The simulator admits an estimate (`sc_sim::navigation`), then derives every quantity of the `SIM_STATE` the controllers and filters get from it with the declared model. */
typedef struct ScNavState {
    uint64_t tick; /* Tick index this state answers [-] */
    double t; /* Simulation time of the tick: the time an estimate is of [s] */
    double measured_t; /* Simulation time of the measurement the values rest on (≤ `t`: the sensors' age); an estimate carries its measurement's [s] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
    double target_r[3]; /* Target CoM position from the Earth's centre, frame F_I [m] */
    double target_v[3]; /* Target CoM inertial velocity, frame F_I [m/s] */
    double q_it[4]; /* Target attitude q_IT: rotates F_T vectors into F_I, frame F_T → F_I [-] */
    double omega_t[3]; /* Target body rate ω_T w.r.t. inertial, frame F_T [rad/s] */
    double r_i[3]; /* Servicer base origin relative to the target CoM, frame F_I [m] */
    double v_i[3]; /* Inertial derivative of `r_i`, frame F_I [m/s] */
    double q_ib[4]; /* Servicer attitude q_IB: rotates F_B vectors into F_I, frame F_B → F_I [-] */
    double omega_b[3]; /* Servicer body rate ω_B w.r.t. inertial, frame F_B [rad/s] */
    double theta[7]; /* Joint angles θ, frame M [rad] */
    double theta_dot[7]; /* Joint rates θ̇, frame M [rad/s] */
    double grasp_t[3]; /* Grasping point relative to the target CoM, frame F_T [m] */
#if defined(__cplusplus) && __cplusplus >= 201703L
    /* the name iceoryx2's C++ API matches the payload type by */
    static constexpr const char* IOX2_TYPE_NAME = "safe_capture::v1::NavState";
#endif
} ScNavState;
SC_ICD_STATIC_ASSERT(sizeof(ScNavState) == 376, "ScNavState: size");
SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF(ScNavState) == 8, "ScNavState: alignment");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, tick) == 0, "ScNavState.tick: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, t) == 8, "ScNavState.t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, measured_t) == 16, "ScNavState.measured_t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, publish_ns) == 24, "ScNavState.publish_ns: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, target_r) == 32, "ScNavState.target_r: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, target_v) == 56, "ScNavState.target_v: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, q_it) == 80, "ScNavState.q_it: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, omega_t) == 112, "ScNavState.omega_t: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, r_i) == 136, "ScNavState.r_i: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, v_i) == 160, "ScNavState.v_i: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, q_ib) == 184, "ScNavState.q_ib: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, omega_b) == 216, "ScNavState.omega_b: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, theta) == 240, "ScNavState.theta: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, theta_dot) == 296, "ScNavState.theta_dot: offset");
SC_ICD_STATIC_ASSERT(offsetof(ScNavState, grasp_t) == 352, "ScNavState.grasp_t: offset");

/* Health -- safe_capture::v1::Health, 56 B. Recorder → scheduler: the recorder's progress (lock-step flow control); the fields are those of a health report any process could publish. */
typedef struct ScHealth {
    uint32_t role; /* Role id: the role's position in the role table `ROLES` [-] */
    uint32_t pid; /* Operating-system process id [-] */
    uint32_t state; /* State, one of `health_state` (0 starting, 1 ready, 2 running, 3 faulted, 4 stopping) [-] */
    uint32_t last_fault_flags; /* Last fault flags, bits of `fault` (1 stale input, 2 non finite input, 4 solver failed, 8 infeasible, 16 saturated, 32 nominal missing, 64 deadline miss, 128 peer dead, 256 rejected command, 512 navigation rejected, 1024 coupling mismatch) [-] */
    uint64_t ticks_handled; /* Ticks handled since start [-] */
    uint64_t deadline_misses; /* Deadline misses since start [-] */
    uint64_t cycle_slips; /* Cycle slips (a tick answered late or skipped) since start [-] */
    uint64_t last_tick; /* Last tick index handled [-] */
    uint64_t publish_ns; /* Publish stamp, host CLOCK_MONOTONIC [ns] */
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
