"""The safe-capture ICD (docs/ICD.md): messages as ctypes structures, and constants.

GENERATED from the Rust crate sc-icd by sc-icd-gen (libs/icd-gen/src/python.rs); do not
edit. Regenerate: SC_WRITE_ICD=1 cargo test -p sc-icd-gen

Use it through :mod:`sc_partner.icd`, which re-exports every name and adds helpers.
Each field's comment gives its unit in brackets, its frame and its meaning.
"""

import ctypes

# Array lengths of the messages.
N_JOINTS = 7  # Number of manipulator joints.
N_CONSTRAINTS_TRANSLATIONAL = 2  # Number of translational safety constraints: AC (approach corridor), CAZ (collision-avoidance zone).
N_CONSTRAINTS_ATTITUDE = 7  # Number of attitude safety constraints: ATT (pointing), ω1..3 upper, ω1..3 lower.
N_CONSTRAINTS_ROBOTIC = 63  # Number of robotic safety constraints: θ limits 7, θ̇ upper 7, θ̇ lower 7, link-base 21, link-target 21.
N_BARRIERS_MONITORED = 1  # Number of barriers only the safety monitor evaluates: the base's collision zone against the target's body (implied by the collision-avoidance zone).
N_BARRIERS = 73  # Number of barriers of the whole safety layer (translational, attitude, robotic, then the monitored ones).

# Service names (relative: a run's iceoryx2 global.prefix is "sc_<SC_RUN_ID>_").
# Each pub/sub service has an event service of the same name.
SERVICE_TICK = "safe_capture/scheduler/tick"  # Tick, QoS flight
SERVICE_CONTROL = "safe_capture/scheduler/control"  # Tick, QoS flight
SERVICE_MEASUREMENT = "safe_capture/sim/measurement"  # NavState, QoS partner
SERVICE_ESTIMATE = "safe_capture/navigation/estimate"  # NavState, QoS partner
SERVICE_SIM_STATE = "safe_capture/sim/state"  # SimState, QoS flight
SERVICE_PARTNER_STATE = "safe_capture/partner/state"  # SimState, QoS partner
SERVICE_TRUTH = "safe_capture/sim/truth"  # SimState, QoS flight
SERVICE_NAVIGATION_ERROR = "safe_capture/sim/navigation_error"  # NavigationError, QoS flight
SERVICE_NOMINAL_TRANSLATIONAL = "safe_capture/nominal/translational"  # NominalTranslational, QoS partner
SERVICE_NOMINAL_ATTITUDE = "safe_capture/nominal/attitude"  # NominalAttitude, QoS partner
SERVICE_NOMINAL_ROBOTIC = "safe_capture/nominal/robotic"  # NominalRobotic, QoS partner
SERVICE_SAFE_TRANSLATIONAL = "safe_capture/safe/translational"  # SafeTranslational, QoS flight
SERVICE_SAFE_ATTITUDE = "safe_capture/safe/attitude"  # SafeAttitude, QoS flight
SERVICE_SAFE_ROBOTIC = "safe_capture/safe/robotic"  # SafeRobotic, QoS flight
SERVICE_STEP_RESULT = "safe_capture/sim/step_result"  # StepResult, QoS flight
SERVICE_HEALTH = "safe_capture/health"  # Health, QoS flight
SERVICE_STAGE_DEADLINE = "safe_capture/scheduler/deadline"  # event only
SERVICE_PREPARE = "safe_capture/scheduler/prepare"  # event only
SERVICE_HANDSHAKE = "safe_capture/handshake"  # event only
SERVICE_HANDSHAKE_READY = "safe_capture/handshake/ready"
SERVICE_HANDSHAKE_GO = "safe_capture/handshake/go"
# QoS class of each service: "flight" (sc_bus.PARTITION), "partner" (sc_bus.NOMINAL, newest wins),
# "event only".
SERVICE_QOS = {
    SERVICE_TICK: "flight",
    SERVICE_CONTROL: "flight",
    SERVICE_MEASUREMENT: "partner",
    SERVICE_ESTIMATE: "partner",
    SERVICE_SIM_STATE: "flight",
    SERVICE_PARTNER_STATE: "partner",
    SERVICE_TRUTH: "flight",
    SERVICE_NAVIGATION_ERROR: "flight",
    SERVICE_NOMINAL_TRANSLATIONAL: "partner",
    SERVICE_NOMINAL_ATTITUDE: "partner",
    SERVICE_NOMINAL_ROBOTIC: "partner",
    SERVICE_SAFE_TRANSLATIONAL: "flight",
    SERVICE_SAFE_ATTITUDE: "flight",
    SERVICE_SAFE_ROBOTIC: "flight",
    SERVICE_STEP_RESULT: "flight",
    SERVICE_HEALTH: "flight",
    SERVICE_STAGE_DEADLINE: "event only",
    SERVICE_PREPARE: "event only",
    SERVICE_HANDSHAKE: "event only",
}

# Event ids of the partition's event services (`sc_bus::pubsub`, `sc_bus::handshake`; `libs/bus/tests/icd_constants.rs` checks them against sc-bus).
EVENT_SAMPLE = 0  # A publisher notifies this after each send.
EVENT_NOTIFIER_DEAD = 1  # iceoryx2 emits it when dead-node clean-up removes a crashed publisher's notifier.
EVENT_NOTIFIER_DROPPED = 2  # iceoryx2 emits it when a publisher's notifier is dropped (it left).
EVENT_ID_MAX = 7  # Largest event id on a data service.
EVENT_GO = 3  # The coordinator's `go` on `<HANDSHAKE>/go`.
EVENT_HANDSHAKE_ID_OFFSET = 8  # A participant notifies `<HANDSHAKE>/ready` with this + its role id.

# Bits of the `due_mask` fields (Tick, SimState; also `StepResult.fallback_mask` and `held_mask`): which subsystems' rate groups run in a tick (`sc_core::Subsystem::bit`).
DUE_TRANSLATIONAL = 1  # Translational nominal controller and safety filter.
DUE_ATTITUDE = 2  # Attitude nominal controller and safety filter.
DUE_ROBOTIC = 4  # Robotic nominal controller and safety filter.
DUE_ALL = 7  # All three.

# Values of `Tick.command`.
TICK_STEP = 0  # Run one control step.
TICK_STOP = 1  # The run is over: every process finishes its outputs and exits.

# Values of `Tick.clock_mode`.
CLOCK_LOCK_STEP = 0  # Lock-step: the next tick is sent as soon as the previous one completed.
CLOCK_REAL_TIME = 1  # Real time: ticks paced by the wall clock at the rate-group period.
CLOCK_SCALED = 2  # Scaled real time: paced at a configured multiple of real time.

# Values of `StepResult.end`.
END_RUNNING = 0  # The mission goes on.
END_CAPTURED = 1  # Captured: end-effector on the grasping point within tolerance.
END_TIMEOUT = 2  # The configured duration elapsed.
END_SIMULATOR_FAILED = 3  # The simulator failed (non-finite state or command).

# Bits of `StepResult.fault_flags` and `Health.last_fault_flags`.
FAULT_STALE_INPUT = 1  # Input older than one tick (stale state).
FAULT_NON_FINITE_INPUT = 2  # Non-finite number in an input.
FAULT_SOLVER_FAILED = 4  # QP solver failed; output falls back to the backup law.
FAULT_INFEASIBLE = 8  # QP infeasible; constraints relaxed.
FAULT_SATURATED = 16  # Output saturated at actuator limits.
FAULT_NOMINAL_MISSING = 32  # Nominal command missing or invalid; filter used zero nominal input.
FAULT_DEADLINE_MISS = 64  # Deadline missed.
FAULT_PEER_DEAD = 128  # A peer process was detected dead.
FAULT_REJECTED_COMMAND = 256  # The simulator rejected a safe command (not finite or beyond the input bounds, `sc_flight::admission`) and applied the filter's backup instead.
FAULT_NAVIGATION_REJECTED = 512  # The navigation's estimate was missing at the navigation deadline or rejected (not finite, not current, a quaternion off the unit sphere, or farther from the measurement than the declared navigation bounds, `sc_sim::navigation`); the simulator's own navigation (the declared error model) was substituted.
FAULT_COUPLING_MISMATCH = 1024  # A safe command was not applied because it does not fit the chain the filters certified: it was certified against other upstream commands than those acting, or it came after the downstream filters had given up on it and certified against its backup; the backup acts instead (docs/PARTITION.md).

# Values of `Health.state`.
HEALTH_STARTING = 0  # Process started, ports being created.
HEALTH_READY = 1  # Ports exist, handshake announced.
HEALTH_RUNNING = 2  # Handling ticks.
HEALTH_FAULTED = 3  # A fault was detected; see `last_fault_flags`.
HEALTH_STOPPING = 4  # Shutting down.

# Role ids, from the role table (sc_icd::ROLES, start order): Health.role; a participant
# announces EVENT_HANDSHAKE_ID_OFFSET + role in the handshake.
ROLE_SCHEDULER = 0  # rate groups, ticks (lock-step or real time), the end of the run, liveness of the peers
ROLE_SIMULATOR = 1  # the plant: measures the state, admits the navigation's estimate (its own navigation when that is missing or rejected) and publishes the knowledge derived from it, applies the re-validated safe commands (the backup when one is missing or rejected)
ROLE_NOMINAL_TRANSLATIONAL = 2  # the nominal translational controller (MPC), replaceable by a partner's
ROLE_NOMINAL_ATTITUDE = 3  # the nominal attitude controller (MPC), replaceable by a partner's
ROLE_NOMINAL_ROBOTIC = 4  # the nominal robotic controller (joint-space PD), replaceable by a partner's
ROLE_SAFETY_TRANSLATIONAL = 5  # the translational safety filter (approach corridor, collision-avoidance zone)
ROLE_SAFETY_ATTITUDE = 6  # the attitude safety filter (line of sight, body-rate limits), ξ = the translational safe force
ROLE_SAFETY_ROBOTIC = 7  # the robotic safety filter (joint angles and rates, link–base spheres), ξ = the translational and attitude safe commands
ROLE_RECORDER = 8  # telemetry: the same telemetry.csv, timing.csv and summary.json as `safe-capture run`, plus recording.mcap and latency.csv
ROLE_NAVIGATION = 9  # the navigation: the estimate of each tick's state from the measurements (the declared error model), replaceable by a partner's estimator
# The role names (config keys, node names), indexed by role id.
ROLE_NAMES = (
    "scheduler",
    "simulator",
    "nominal_translational",
    "nominal_attitude",
    "nominal_robotic",
    "safety_translational",
    "safety_attitude",
    "safety_robotic",
    "recorder",
    "navigation",
)


class Tick(ctypes.Structure):
    """Scheduler → simulator, every other process (stop), recorder: start one control step."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index, starts at 0, +1 per tick of the fastest rate group [-]
        ("due_mask", ctypes.c_uint32),  # Subsystems due in this tick, bits of `due` (1 translational, 2 attitude, 4 robotic, 7 all) [-]
        ("clock_mode", ctypes.c_uint32),  # Clock mode, one of `clock_mode` (0 lock step, 1 real time, 2 scaled) [-]
        ("t", ctypes.c_double),  # Simulation time at which this step starts [s]
        ("send_ns", ctypes.c_uint64),  # Scheduler send stamp, host CLOCK_MONOTONIC [ns]
        ("command", ctypes.c_uint32),  # Step or stop (the run is over), one of `tick_command` (0 step, 1 stop) [-]
        ("_pad0", ctypes.c_uint32),  # Always 0 [-]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v2::Tick"


class SimState(ctypes.Structure):
    """Simulator → nominal controllers, safety filters, recorder: the observation at the start of the step. Every field of `sc_core::Observation`, copied as f64, so that the stages compute exactly what they compute in one process."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index this state answers (= simulator step count at the base rate) [-]
        ("t", ctypes.c_double),  # Simulation time [s]
        ("due_mask", ctypes.c_uint32),  # Subsystems due in this tick, bits of `due` (1 translational, 2 attitude, 4 robotic, 7 all) [-]
        ("_pad0", ctypes.c_uint32),  # Always 0 [-]
        ("tick_send_ns", ctypes.c_uint64),  # Send stamp of the tick this state answers, host CLOCK_MONOTONIC [ns]
        ("recv_ns", ctypes.c_uint64),  # Stamp at which the simulator received the tick, host CLOCK_MONOTONIC [ns]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
        ("step", ctypes.c_uint64),  # Simulator step counter [-]
        ("r_h", ctypes.c_double * 3),  # Servicer base origin relative to the target CoM, r_H, frame F_H [m]
        ("v_h", ctypes.c_double * 3),  # Derivative of r_H in the rotating Hill frame, frame F_H [m/s]
        ("r_r", ctypes.c_double * 3),  # Servicer base origin relative to the target CoM, r_R, frame F_R [m]
        ("v_r", ctypes.c_double * 3),  # Inertial derivative of r_R, frame F_R [m/s]
        ("q_hr", ctypes.c_double * 4),  # Attitude q_HR of F_R in F_H: rotates F_R vectors into F_H, frame F_R → F_H [-]
        ("omega_h", ctypes.c_double * 3),  # Angular velocity ω_H of F_H w.r.t. inertial, frame F_H [rad/s]
        ("omega_dot_h", ctypes.c_double * 3),  # Angular acceleration of F_H w.r.t. inertial, frame F_H [rad/s²]
        ("mean_motion", ctypes.c_double),  # Mean motion of the target orbit |ω_H| [rad/s]
        ("q_rb", ctypes.c_double * 4),  # Servicer attitude q_RB: rotates F_B vectors into F_R, frame F_B → F_R [-]
        ("omega_b", ctypes.c_double * 3),  # Servicer body rate ω_B w.r.t. inertial, frame F_B [rad/s]
        ("theta", ctypes.c_double * 7),  # Joint angles θ, frame M [rad]
        ("theta_dot", ctypes.c_double * 7),  # Joint rates θ̇, frame M [rad/s]
        ("q_rt", ctypes.c_double * 4),  # Target attitude q_RT: rotates F_T vectors into F_R, frame F_T → F_R [-]
        ("omega_t", ctypes.c_double * 3),  # Target body rate ω_T w.r.t. inertial, frame F_T [rad/s]
        ("omega_dot_t", ctypes.c_double * 3),  # Derivative of ω_T, frame F_T [rad/s²]
        ("grasp_r", ctypes.c_double * 3),  # Grasping point relative to the target CoM, frame F_R [m]
        ("grasp_v_r", ctypes.c_double * 3),  # Grasping point inertial velocity, frame F_R [m/s]
        ("grasp_a_r", ctypes.c_double * 3),  # Grasping point inertial acceleration, frame F_R [m/s²]
        ("grasp_b", ctypes.c_double * 3),  # Grasping point relative to the base origin, frame F_B [m]
        ("ee_b", ctypes.c_double * 3),  # End-effector position relative to the base origin, frame F_B [m]
        ("ee_r", ctypes.c_double * 3),  # End-effector position relative to the target CoM, frame F_R [m]
        ("ee_v_r", ctypes.c_double * 3),  # End-effector inertial velocity, frame F_R [m/s]
        ("com_h", ctypes.c_double * 3),  # Servicer system centre of mass relative to the target CoM, frame F_H [m]
        ("com_v_h", ctypes.c_double * 3),  # Derivative of com_h in the rotating Hill frame, frame F_H [m/s]
        ("com_r", ctypes.c_double * 3),  # Servicer system centre of mass relative to the target CoM, frame F_R [m]
        ("com_v_r", ctypes.c_double * 3),  # Inertial velocity of the servicer system centre of mass, frame F_R [m/s]
        ("barriers", ctypes.c_double * 73),  # Every barrier h at this state, from the simulator's own state (the safety monitor), in telemetry order; NaN (null in the MCAP) = not evaluated. With a declared `[uncertainty]` the state is the estimate and these the barriers on knowledge (the declared model on it) [unit per constraint]
        ("barriers_between", ctypes.c_double * 73),  # The smallest value of every barrier over the physics steps since the previous state message (this state included); with a declared `[uncertainty]` equal to `barriers` (knowledge exists at the ticks only) [unit per constraint]
        ("held_f_b", ctypes.c_double * 3),  # The base force the simulator holds from the previous step: what acts in this tick while the translational group is not due (a downstream filter certifies against it then; docs/PARTITION.md, "Only what was certified acts"), frame F_B [N]
        ("held_tau_b", ctypes.c_double * 3),  # The base torque the simulator holds from the previous step, as `held_f_b`, frame F_B [N·m]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v5::SimState"


class NominalTranslational(ctypes.Structure):
    """Nominal translational controller → translational safety filter, recorder."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index this command answers [-]
        ("t", ctypes.c_double),  # Simulation time of the state used [s]
        ("valid", ctypes.c_uint32),  # 1 if the controller ran on valid inputs, 0 otherwise [-]
        ("phase", ctypes.c_uint32),  # Index of the mission phase (0-based, scenario order) [-]
        ("recv_ns", ctypes.c_uint64),  # Stamp at which the state was received, host CLOCK_MONOTONIC [ns]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
        ("f_h", ctypes.c_double * 3),  # Commanded force f_H, unsaturated, frame F_H [N]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v2::NominalTranslational"


class NominalAttitude(ctypes.Structure):
    """Nominal attitude controller → attitude safety filter, recorder."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index this command answers [-]
        ("t", ctypes.c_double),  # Simulation time of the state used [s]
        ("valid", ctypes.c_uint32),  # 1 if the controller ran on valid inputs, 0 otherwise [-]
        ("phase", ctypes.c_uint32),  # Index of the mission phase (0-based, scenario order) [-]
        ("recv_ns", ctypes.c_uint64),  # Stamp at which the state was received, host CLOCK_MONOTONIC [ns]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
        ("tau_b", ctypes.c_double * 3),  # Commanded torque τ_B, unsaturated, frame F_B [N·m]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v2::NominalAttitude"


class NominalRobotic(ctypes.Structure):
    """Nominal robotic controller → robotic safety filter, recorder."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index this command answers [-]
        ("t", ctypes.c_double),  # Simulation time of the state used [s]
        ("valid", ctypes.c_uint32),  # 1 if the controller ran on valid inputs, 0 otherwise [-]
        ("phase", ctypes.c_uint32),  # Index of the mission phase (0-based, scenario order) [-]
        ("recv_ns", ctypes.c_uint64),  # Stamp at which the state was received, host CLOCK_MONOTONIC [ns]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
        ("tau_m", ctypes.c_double * 7),  # Commanded joint torques τ_M, unsaturated, frame M [N·m]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v2::NominalRobotic"


class SafeTranslational(ctypes.Structure):
    """Translational safety filter → attitude and robotic filters, simulator, recorder. Constraint order: AC, CAZ."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index this command answers [-]
        ("t", ctypes.c_double),  # Simulation time of the state used [s]
        ("recv_ns", ctypes.c_uint64),  # Stamp at which the last input of this tick arrived, host CLOCK_MONOTONIC [ns]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
        ("active_mask", ctypes.c_uint64),  # Bit i set = constraint i active (Φ_i ≈ 0) [-]
        ("solve_ns", ctypes.c_uint64),  # Wall time of the filter call [ns]
        ("solver_status", ctypes.c_uint32),  # `sc_cbf::FilterStatus`: 0 skipped, 1 solved, 2 relaxed, 3 fallback [-]
        ("iterations", ctypes.c_uint32),  # QP solver iterations [-]
        ("fault_flags", ctypes.c_uint32),  # `sc_cbf::faults` bits (5 upstream_missing, 7 nominal_missing, 9 margins_degraded, 10 safe_mode: docs/ICD.md) [-]
        ("n_constraints", ctypes.c_uint32),  # Number of constraints in `h` and `phi` [-]
        ("phase", ctypes.c_uint32),  # Mission phase of the nominal command filtered (0-based) [-]
        ("solve_cpu_ns", ctypes.c_uint32),  # CPU time of the filter call on its thread, saturating at u32::MAX [ns]
        ("slack", ctypes.c_double),  # Slack of the relaxed QP (0 otherwise), normalised rows; for a translational step degraded under a declared uncertainty, the share of the declared margins given up (docs/SAFETY.md) [-]
        ("h", ctypes.c_double * 2),  # Barrier values h_i the filter evaluated; NaN (null in the MCAP) = not evaluated [unit per constraint]
        ("phi", ctypes.c_double * 2),  # CBF conditions Φ_i at the safe command [unit per constraint / s]
        ("u", ctypes.c_double * 3),  # Safe force f_H, frame F_H [N]
        ("actuated", ctypes.c_double * 3),  # Safe force f_B = R_BH f_H (what the thrusters apply), frame F_B [N]
        ("xi_f_b", ctypes.c_double * 3),  # Coupling ξ this command was certified against: the base force f_B acting upstream (the translational command or its backup; 0 for the translational filter, which has no upstream). The simulator applies the command only with exactly this force acting (docs/PARTITION.md), frame F_B [N]
        ("xi_tau_b", ctypes.c_double * 3),  # Coupling ξ this command was certified against: the base torque τ_B acting upstream (the attitude command or its backup; 0 for the translational and attitude filters), frame F_B [N·m]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v3::SafeTranslational"


class SafeAttitude(ctypes.Structure):
    """Attitude safety filter → robotic filter, simulator, recorder. Constraint order: ATT, ω1..3 upper, ω1..3 lower."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index this command answers [-]
        ("t", ctypes.c_double),  # Simulation time of the state used [s]
        ("recv_ns", ctypes.c_uint64),  # Stamp at which the last input of this tick arrived, host CLOCK_MONOTONIC [ns]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
        ("active_mask", ctypes.c_uint64),  # Bit i set = constraint i active (Φ_i ≈ 0) [-]
        ("solve_ns", ctypes.c_uint64),  # Wall time of the filter call [ns]
        ("solver_status", ctypes.c_uint32),  # `sc_cbf::FilterStatus`: 0 skipped, 1 solved, 2 relaxed, 3 fallback [-]
        ("iterations", ctypes.c_uint32),  # QP solver iterations [-]
        ("fault_flags", ctypes.c_uint32),  # `sc_cbf::faults` bits (5 upstream_missing, 7 nominal_missing, 9 margins_degraded, 10 safe_mode: docs/ICD.md) [-]
        ("n_constraints", ctypes.c_uint32),  # Number of constraints in `h` and `phi` [-]
        ("phase", ctypes.c_uint32),  # Mission phase of the nominal command filtered (0-based) [-]
        ("solve_cpu_ns", ctypes.c_uint32),  # CPU time of the filter call on its thread, saturating at u32::MAX [ns]
        ("slack", ctypes.c_double),  # Slack of the relaxed QP (0 otherwise), normalised rows; for a translational step degraded under a declared uncertainty, the share of the declared margins given up (docs/SAFETY.md) [-]
        ("h", ctypes.c_double * 7),  # Barrier values h_i the filter evaluated; NaN (null in the MCAP) = not evaluated [unit per constraint]
        ("phi", ctypes.c_double * 7),  # CBF conditions Φ_i at the safe command [unit per constraint / s]
        ("u", ctypes.c_double * 3),  # Safe torque τ_B, frame F_B [N·m]
        ("actuated", ctypes.c_double * 3),  # Actuated torque τ_B (equals `u`), frame F_B [N·m]
        ("xi_f_b", ctypes.c_double * 3),  # Coupling ξ this command was certified against: the base force f_B acting upstream (the translational command or its backup; 0 for the translational filter, which has no upstream). The simulator applies the command only with exactly this force acting (docs/PARTITION.md), frame F_B [N]
        ("xi_tau_b", ctypes.c_double * 3),  # Coupling ξ this command was certified against: the base torque τ_B acting upstream (the attitude command or its backup; 0 for the translational and attitude filters), frame F_B [N·m]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v3::SafeAttitude"


class SafeRobotic(ctypes.Structure):
    """Robotic safety filter → simulator, recorder. Constraint order: θ limits 0..7, θ̇ upper 7..14, θ̇ lower 14..21, link-base 21..42, link-target 42..63."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index this command answers [-]
        ("t", ctypes.c_double),  # Simulation time of the state used [s]
        ("recv_ns", ctypes.c_uint64),  # Stamp at which the last input of this tick arrived, host CLOCK_MONOTONIC [ns]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
        ("active_mask", ctypes.c_uint64),  # Bit i set = constraint i active (Φ_i ≈ 0) [-]
        ("solve_ns", ctypes.c_uint64),  # Wall time of the filter call [ns]
        ("solver_status", ctypes.c_uint32),  # `sc_cbf::FilterStatus`: 0 skipped, 1 solved, 2 relaxed, 3 fallback [-]
        ("iterations", ctypes.c_uint32),  # QP solver iterations [-]
        ("fault_flags", ctypes.c_uint32),  # `sc_cbf::faults` bits (5 upstream_missing, 7 nominal_missing, 9 margins_degraded, 10 safe_mode: docs/ICD.md) [-]
        ("n_constraints", ctypes.c_uint32),  # Number of constraints in `h` and `phi` [-]
        ("phase", ctypes.c_uint32),  # Mission phase of the nominal command filtered (0-based) [-]
        ("solve_cpu_ns", ctypes.c_uint32),  # CPU time of the filter call on its thread, saturating at u32::MAX [ns]
        ("slack", ctypes.c_double),  # Slack of the relaxed QP (0 otherwise), normalised rows; for a translational step degraded under a declared uncertainty, the share of the declared margins given up (docs/SAFETY.md) [-]
        ("h", ctypes.c_double * 63),  # Barrier values h_i the filter evaluated; NaN (null in the MCAP) = not evaluated [unit per constraint]
        ("phi", ctypes.c_double * 63),  # CBF conditions Φ_i at the safe command [unit per constraint / s]
        ("u", ctypes.c_double * 7),  # Safe joint torques τ_M, frame M [N·m]
        ("actuated", ctypes.c_double * 7),  # Actuated joint torques τ_M (equals `u`), frame M [N·m]
        ("xi_f_b", ctypes.c_double * 3),  # Coupling ξ this command was certified against: the base force f_B acting upstream (the translational command or its backup; 0 for the translational filter, which has no upstream). The simulator applies the command only with exactly this force acting (docs/PARTITION.md), frame F_B [N]
        ("xi_tau_b", ctypes.c_double * 3),  # Coupling ξ this command was certified against: the base torque τ_B acting upstream (the attitude command or its backup; 0 for the translational and attitude filters), frame F_B [N·m]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v4::SafeRobotic"


class StepResult(ctypes.Structure):
    """Simulator → scheduler, recorder: the command applied over the step and how the step ended. Sent once all due safe commands of the tick are in (or their deadline passed and the simulator used the filter's fallback)."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index [-]
        ("t", ctypes.c_double),  # Simulation time at the start of the step [s]
        ("end", ctypes.c_uint32),  # How the step ended, one of `end` (0 running, 1 captured, 2 timeout, 3 simulator failed) [-]
        ("fallback_mask", ctypes.c_uint32),  # Subsystems (bits of `due`) whose command is the filter fallback computed by the simulator: the safe command was missing at the deadline, refused, or did not fit what acts upstream (`fault::COUPLING_MISMATCH`) (1 translational, 2 attitude, 4 robotic, 7 all) [-]
        ("held_mask", ctypes.c_uint32),  # Subsystems (bits of `due`) whose command was held from an earlier tick (slower rate group) (1 translational, 2 attitude, 4 robotic, 7 all) [-]
        ("fault_flags", ctypes.c_uint32),  # Partition fault flags, bits of `fault` (1 stale input, 2 non finite input, 4 solver failed, 8 infeasible, 16 saturated, 32 nominal missing, 64 deadline miss, 128 peer dead, 256 rejected command, 512 navigation rejected, 1024 coupling mismatch) [-]
        ("safe_recv_ns", ctypes.c_uint64),  # Stamp at which the robotic safe command (the tick's last) was delivered, host CLOCK_MONOTONIC [ns]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
        ("force_b", ctypes.c_double * 3),  # Applied base force f_B, frame F_B [N]
        ("torque_b", ctypes.c_double * 3),  # Applied base torque τ_B, frame F_B [N·m]
        ("tau", ctypes.c_double * 7),  # Applied joint torques τ_M, frame M [N·m]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v1::StepResult"


class NavigationError(ctypes.Structure):
    """Simulator → recorder, with a declared `[uncertainty]` only: the realised navigation errors of the tick's estimate (the state on `SIM_STATE`) against the truth measured `measurement_age_s` before it (with an age of 0 the truth on `TRUTH`), each as in `navigation.csv` (vectors: Euclidean norm; joints: the largest of the seven)."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index [-]
        ("t", ctypes.c_double),  # Simulation time of the estimate [s]
        ("relative_position_m", ctypes.c_double),  # Relative position error of the servicer base to the target CoM [m]
        ("relative_velocity_m_s", ctypes.c_double),  # Relative velocity error [m/s]
        ("servicer_attitude_rad", ctypes.c_double),  # Servicer attitude error (rotation angle) [rad]
        ("servicer_rate_rad_s", ctypes.c_double),  # Servicer body rate error [rad/s]
        ("target_attitude_rad", ctypes.c_double),  # Target attitude error (rotation angle) [rad]
        ("target_rate_rad_s", ctypes.c_double),  # Target body rate error [rad/s]
        ("grasp_point_m", ctypes.c_double),  # Grasping point error in the target frame [m]
        ("joint_angle_rad", ctypes.c_double),  # Largest joint angle error [rad]
        ("joint_rate_rad_s", ctypes.c_double),  # Largest joint rate error [rad/s]
        ("measurement_age_s", ctypes.c_double),  # Age of the measurement the estimate rests on [s]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v1::NavigationError"


class NavState(ctypes.Structure):
    """A navigation state in the inertial frame the simulator propagates in: on `MEASUREMENT` what the simulator's sensors measured (simulator → navigation), on `ESTIMATE` what the navigation estimates (navigation → simulator). The simulator admits an estimate (`sc_sim::navigation`), then derives every quantity of the `SIM_STATE` the controllers and filters get from it with the declared model."""

    _fields_ = [
        ("tick", ctypes.c_uint64),  # Tick index this state answers [-]
        ("t", ctypes.c_double),  # Simulation time of the tick: the time an estimate is of [s]
        ("measured_t", ctypes.c_double),  # Simulation time of the measurement the values rest on (≤ `t`: the sensors' age); an estimate carries its measurement's [s]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
        ("target_r", ctypes.c_double * 3),  # Target CoM position from the Earth's centre, frame F_I [m]
        ("target_v", ctypes.c_double * 3),  # Target CoM inertial velocity, frame F_I [m/s]
        ("q_it", ctypes.c_double * 4),  # Target attitude q_IT: rotates F_T vectors into F_I, frame F_T → F_I [-]
        ("omega_t", ctypes.c_double * 3),  # Target body rate ω_T w.r.t. inertial, frame F_T [rad/s]
        ("r_i", ctypes.c_double * 3),  # Servicer base origin relative to the target CoM, frame F_I [m]
        ("v_i", ctypes.c_double * 3),  # Inertial derivative of `r_i`, frame F_I [m/s]
        ("q_ib", ctypes.c_double * 4),  # Servicer attitude q_IB: rotates F_B vectors into F_I, frame F_B → F_I [-]
        ("omega_b", ctypes.c_double * 3),  # Servicer body rate ω_B w.r.t. inertial, frame F_B [rad/s]
        ("theta", ctypes.c_double * 7),  # Joint angles θ, frame M [rad]
        ("theta_dot", ctypes.c_double * 7),  # Joint rates θ̇, frame M [rad/s]
        ("grasp_t", ctypes.c_double * 3),  # Grasping point relative to the target CoM, frame F_T [m]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v1::NavState"


class Health(ctypes.Structure):
    """Recorder → scheduler: the recorder's progress (lock-step flow control); the fields are those of a health report any process could publish."""

    _fields_ = [
        ("role", ctypes.c_uint32),  # Role id: the role's position in the role table `ROLES` [-]
        ("pid", ctypes.c_uint32),  # Operating-system process id [-]
        ("state", ctypes.c_uint32),  # State, one of `health_state` (0 starting, 1 ready, 2 running, 3 faulted, 4 stopping) [-]
        ("last_fault_flags", ctypes.c_uint32),  # Last fault flags, bits of `fault` (1 stale input, 2 non finite input, 4 solver failed, 8 infeasible, 16 saturated, 32 nominal missing, 64 deadline miss, 128 peer dead, 256 rejected command, 512 navigation rejected, 1024 coupling mismatch) [-]
        ("ticks_handled", ctypes.c_uint64),  # Ticks handled since start [-]
        ("deadline_misses", ctypes.c_uint64),  # Deadline misses since start [-]
        ("cycle_slips", ctypes.c_uint64),  # Cycle slips (a tick answered late or skipped) since start [-]
        ("last_tick", ctypes.c_uint64),  # Last tick index handled [-]
        ("publish_ns", ctypes.c_uint64),  # Publish stamp, host CLOCK_MONOTONIC [ns]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v1::Health"


# Every message type, in the order of docs/ICD.md.
ALL_TYPES = [
    Tick,
    SimState,
    NominalTranslational,
    NominalAttitude,
    NominalRobotic,
    SafeTranslational,
    SafeAttitude,
    SafeRobotic,
    StepResult,
    NavigationError,
    NavState,
    Health,
]

__all__ = [
    "N_JOINTS",
    "N_CONSTRAINTS_TRANSLATIONAL",
    "N_CONSTRAINTS_ATTITUDE",
    "N_CONSTRAINTS_ROBOTIC",
    "N_BARRIERS_MONITORED",
    "N_BARRIERS",
    "SERVICE_TICK",
    "SERVICE_CONTROL",
    "SERVICE_MEASUREMENT",
    "SERVICE_ESTIMATE",
    "SERVICE_SIM_STATE",
    "SERVICE_PARTNER_STATE",
    "SERVICE_TRUTH",
    "SERVICE_NAVIGATION_ERROR",
    "SERVICE_NOMINAL_TRANSLATIONAL",
    "SERVICE_NOMINAL_ATTITUDE",
    "SERVICE_NOMINAL_ROBOTIC",
    "SERVICE_SAFE_TRANSLATIONAL",
    "SERVICE_SAFE_ATTITUDE",
    "SERVICE_SAFE_ROBOTIC",
    "SERVICE_STEP_RESULT",
    "SERVICE_HEALTH",
    "SERVICE_STAGE_DEADLINE",
    "SERVICE_PREPARE",
    "SERVICE_HANDSHAKE",
    "SERVICE_HANDSHAKE_READY",
    "SERVICE_HANDSHAKE_GO",
    "SERVICE_QOS",
    "EVENT_SAMPLE",
    "EVENT_NOTIFIER_DEAD",
    "EVENT_NOTIFIER_DROPPED",
    "EVENT_ID_MAX",
    "EVENT_GO",
    "EVENT_HANDSHAKE_ID_OFFSET",
    "DUE_TRANSLATIONAL",
    "DUE_ATTITUDE",
    "DUE_ROBOTIC",
    "DUE_ALL",
    "TICK_STEP",
    "TICK_STOP",
    "CLOCK_LOCK_STEP",
    "CLOCK_REAL_TIME",
    "CLOCK_SCALED",
    "END_RUNNING",
    "END_CAPTURED",
    "END_TIMEOUT",
    "END_SIMULATOR_FAILED",
    "FAULT_STALE_INPUT",
    "FAULT_NON_FINITE_INPUT",
    "FAULT_SOLVER_FAILED",
    "FAULT_INFEASIBLE",
    "FAULT_SATURATED",
    "FAULT_NOMINAL_MISSING",
    "FAULT_DEADLINE_MISS",
    "FAULT_PEER_DEAD",
    "FAULT_REJECTED_COMMAND",
    "FAULT_NAVIGATION_REJECTED",
    "FAULT_COUPLING_MISMATCH",
    "HEALTH_STARTING",
    "HEALTH_READY",
    "HEALTH_RUNNING",
    "HEALTH_FAULTED",
    "HEALTH_STOPPING",
    "ROLE_SCHEDULER",
    "ROLE_SIMULATOR",
    "ROLE_NOMINAL_TRANSLATIONAL",
    "ROLE_NOMINAL_ATTITUDE",
    "ROLE_NOMINAL_ROBOTIC",
    "ROLE_SAFETY_TRANSLATIONAL",
    "ROLE_SAFETY_ATTITUDE",
    "ROLE_SAFETY_ROBOTIC",
    "ROLE_RECORDER",
    "ROLE_NAVIGATION",
    "ROLE_NAMES",
    "Tick",
    "SimState",
    "NominalTranslational",
    "NominalAttitude",
    "NominalRobotic",
    "SafeTranslational",
    "SafeAttitude",
    "SafeRobotic",
    "StepResult",
    "NavigationError",
    "NavState",
    "Health",
    "ALL_TYPES",
]
