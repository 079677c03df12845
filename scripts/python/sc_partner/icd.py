"""The safe-capture ICD in Python (mirror of the Rust crate ``sc-icd``, docs/ICD.md).

Each message class is a ``ctypes.Structure`` with exactly the ``#[repr(C)]`` layout of
the Rust type of the same name, and a static ``type_name()`` that returns the Rust
``#[type_name]`` (the iceoryx2 PyPI package matches types across languages by it).
Beside the messages: service names, event ids, role ids, due-mask bits and the tick
commands, each with the value of the Rust constant of the same meaning.

The Rust test ``libs/icd/tests/python_layout.rs`` runs
``python3 -m sc_partner.icd --layout-json`` and compares size, alignment, every field
offset and every type name with the Rust types.

Only the standard library is needed (the layout check runs with a bare ``python3``);
iceoryx2 is imported by :mod:`sc_partner.bus`, not here.
"""

import ctypes
import json
import sys

c_f64 = ctypes.c_double
c_u64 = ctypes.c_uint64
c_u32 = ctypes.c_uint32
c_i32 = ctypes.c_int32

N_JOINTS = 7
N_CONSTRAINTS_TRANSLATIONAL = 2
N_CONSTRAINTS_ATTITUDE = 7
N_CONSTRAINTS_ROBOTIC = 42
N_BARRIERS = N_CONSTRAINTS_TRANSLATIONAL + N_CONSTRAINTS_ATTITUDE + N_CONSTRAINTS_ROBOTIC


def _vec(n):
    return c_f64 * n


# Service names (same as sc_icd::services). Each pub/sub service has an event
# service of the same name: the publisher notifies it after every send.
SERVICE_TICK = "safe_capture/scheduler/tick"
SERVICE_CONTROL = "safe_capture/scheduler/control"  # Tick messages; the stop
SERVICE_SIM_STATE = "safe_capture/sim/state"  # flight side (filters, recorder)
# the same SimState for nominal controllers (partners): newest wins (sc_bus.NOMINAL)
SERVICE_PARTNER_STATE = "safe_capture/partner/state"
SERVICE_NOMINAL_TRANSLATIONAL = "safe_capture/nominal/translational"
SERVICE_NOMINAL_ATTITUDE = "safe_capture/nominal/attitude"
SERVICE_NOMINAL_ROBOTIC = "safe_capture/nominal/robotic"
SERVICE_SAFE_TRANSLATIONAL = "safe_capture/safe/translational"
SERVICE_SAFE_ATTITUDE = "safe_capture/safe/attitude"
SERVICE_SAFE_ROBOTIC = "safe_capture/safe/robotic"
SERVICE_STEP_RESULT = "safe_capture/sim/step_result"
SERVICE_HEALTH = "safe_capture/health"
SERVICE_HANDSHAKE = "safe_capture/handshake"  # events <base>/ready and <base>/go

# Event ids (sc_bus::pubsub / sc_bus::handshake).
EVENT_SAMPLE = 0
EVENT_NOTIFIER_DEAD = 1
EVENT_NOTIFIER_DROPPED = 2
EVENT_GO = 3
HANDSHAKE_ID_OFFSET = 8

# Role ids (sc_icd::role); a participant announces HANDSHAKE_ID_OFFSET + role.
ROLE_SCHEDULER = 0
ROLE_SIMULATOR = 1
ROLE_NOMINAL_TRANSLATIONAL = 2
ROLE_NOMINAL_ATTITUDE = 3
ROLE_NOMINAL_ROBOTIC = 4
ROLE_SAFETY_TRANSLATIONAL = 5
ROLE_SAFETY_ATTITUDE = 6
ROLE_SAFETY_ROBOTIC = 7
ROLE_RECORDER = 8


def rotate(q, v):
    """Rotates v by the scalar-first unit quaternion q (q_AB: F_B -> F_A), the ICD's convention."""
    w, x, y, z = q
    # v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    ux = (y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0])
    uux = (y * ux[2] - z * ux[1], z * ux[0] - x * ux[2], x * ux[1] - y * ux[0])
    return [v[i] + 2.0 * w * ux[i] + 2.0 * uux[i] for i in range(3)]


def run_prefix(run_id):
    """iceoryx2 global.prefix of a run, as sc_bus::RunScope builds it."""
    clean = "".join(c if (c.isascii() and (c.isalnum() or c in "-.")) else "-" for c in run_id)
    return "sc_" + clean + "_"


TICK_STEP = 0  # Tick.command
TICK_STOP = 1
DUE_TRANSLATIONAL = 1  # due_mask bits
DUE_ATTITUDE = 2
DUE_ROBOTIC = 4


class Tick(ctypes.Structure):
    """Scheduler -> simulator (step), every process (stop)."""

    _fields_ = [
        ("tick", c_u64),  # tick index [-]
        ("due_mask", c_u32),  # subsystems due: 1 translational, 2 attitude, 4 robotic
        ("clock_mode", c_u32),  # 0 lock-step, 1 real time, 2 scaled [-]
        ("t", c_f64),  # simulation time [s]
        ("send_ns", c_u64),  # scheduler send stamp, CLOCK_MONOTONIC [ns]
        ("command", c_u32),  # 0 step, 1 stop
        ("_pad0", c_u32),
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v2::Tick"


class SimState(ctypes.Structure):
    """Simulator -> all: the observation at the start of the step (sc_sim::Observation)."""

    _fields_ = [
        ("tick", c_u64),  # [-]
        ("t", c_f64),  # [s]
        ("due_mask", c_u32),  # subsystems due in this tick
        ("_pad0", c_u32),
        ("tick_send_ns", c_u64),  # [ns]
        ("recv_ns", c_u64),  # [ns]
        ("publish_ns", c_u64),  # [ns]
        ("step", c_u64),  # simulator step counter [-]
        ("r_h", _vec(3)),  # F_H [m]
        ("v_h", _vec(3)),  # F_H [m/s]
        ("r_r", _vec(3)),  # F_R [m]
        ("v_r", _vec(3)),  # F_R [m/s]
        ("q_hr", _vec(4)),  # scalar-first, F_R -> F_H
        ("omega_h", _vec(3)),  # F_H [rad/s]
        ("omega_dot_h", _vec(3)),  # F_H [rad/s^2]
        ("mean_motion", c_f64),  # [rad/s]
        ("q_rb", _vec(4)),  # scalar-first, F_B -> F_R
        ("omega_b", _vec(3)),  # F_B [rad/s]
        ("theta", _vec(N_JOINTS)),  # [rad]
        ("theta_dot", _vec(N_JOINTS)),  # [rad/s]
        ("q_rt", _vec(4)),  # scalar-first, F_T -> F_R
        ("omega_t", _vec(3)),  # F_T [rad/s]
        ("omega_dot_t", _vec(3)),  # F_T [rad/s^2]
        ("grasp_r", _vec(3)),  # F_R [m]
        ("grasp_v_r", _vec(3)),  # F_R [m/s]
        ("grasp_a_r", _vec(3)),  # F_R [m/s^2]
        ("grasp_b", _vec(3)),  # F_B [m]
        ("ee_b", _vec(3)),  # F_B [m]
        ("ee_r", _vec(3)),  # F_R [m]
        ("ee_v_r", _vec(3)),  # F_R [m/s]
        ("com_h", _vec(3)),  # servicer CoM, F_H [m]
        ("com_v_h", _vec(3)),  # F_H [m/s]
        ("com_r", _vec(3)),  # servicer CoM, F_R [m]
        ("com_v_r", _vec(3)),  # F_R [m/s]
        ("barriers", _vec(N_BARRIERS)),  # every barrier from the true state
        ("barriers_between", _vec(N_BARRIERS)),  # minima since the previous state
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v3::SimState"


_NOMINAL_HEAD = [
    ("tick", c_u64),  # tick answered [-]
    ("t", c_f64),  # sim time of the state used [s]
    ("valid", c_u32),  # 1 valid, 0 not
    ("phase", c_u32),  # mission phase index, 0-based
    ("recv_ns", c_u64),  # state received [ns]
    ("publish_ns", c_u64),  # [ns]
]


class NominalTranslational(ctypes.Structure):
    """Nominal translational controller -> translational safety filter."""

    _fields_ = _NOMINAL_HEAD + [("f_h", _vec(3))]  # F_H [N]

    @staticmethod
    def type_name():
        return "safe_capture::v2::NominalTranslational"


class NominalAttitude(ctypes.Structure):
    """Nominal attitude controller -> attitude safety filter."""

    _fields_ = _NOMINAL_HEAD + [("tau_b", _vec(3))]  # F_B [N m]

    @staticmethod
    def type_name():
        return "safe_capture::v2::NominalAttitude"


class NominalRobotic(ctypes.Structure):
    """Nominal robotic controller -> robotic safety filter."""

    _fields_ = _NOMINAL_HEAD + [("tau_m", _vec(N_JOINTS))]  # joints [N m]

    @staticmethod
    def type_name():
        return "safe_capture::v2::NominalRobotic"


def _safe(n, m):
    return [
        ("tick", c_u64),
        ("t", c_f64),  # [s]
        ("recv_ns", c_u64),  # [ns]
        ("publish_ns", c_u64),  # [ns]
        ("active_mask", c_u64),  # bit i = constraint i active
        ("solve_ns", c_u64),  # [ns]
        ("solver_status", c_u32),  # 0 skipped, 1 solved, 2 relaxed, 3 fallback
        ("iterations", c_u32),
        ("fault_flags", c_u32),  # sc_cbf::faults bits
        ("n_constraints", c_u32),
        ("phase", c_u32),
        ("solve_cpu_ns", c_u32),  # [ns], saturating
        ("slack", c_f64),
        ("h", _vec(n)),  # barrier values
        ("phi", _vec(n)),  # CBF conditions
        ("u", _vec(m)),  # safe command
        ("actuated", _vec(m)),  # actuated command
    ]


class SafeTranslational(ctypes.Structure):
    """Translational safety filter -> attitude/robotic filters, simulator, recorder."""

    _fields_ = _safe(N_CONSTRAINTS_TRANSLATIONAL, 3)  # u = f_H [N], actuated = f_B [N]

    @staticmethod
    def type_name():
        return "safe_capture::v2::SafeTranslational"


class SafeAttitude(ctypes.Structure):
    """Attitude safety filter -> robotic filter, simulator, recorder."""

    _fields_ = _safe(N_CONSTRAINTS_ATTITUDE, 3)  # tau_B, F_B [N m]

    @staticmethod
    def type_name():
        return "safe_capture::v2::SafeAttitude"


class SafeRobotic(ctypes.Structure):
    """Robotic safety filter -> simulator, recorder."""

    _fields_ = _safe(N_CONSTRAINTS_ROBOTIC, N_JOINTS)  # tau_M [N m]

    @staticmethod
    def type_name():
        return "safe_capture::v2::SafeRobotic"


class StepResult(ctypes.Structure):
    """Simulator -> scheduler, recorder: applied command and end of the step."""

    _fields_ = [
        ("tick", c_u64),
        ("t", c_f64),  # [s]
        ("end", c_u32),  # 0 running, 1 captured, 2 timeout, 3 simulator failed
        ("fallback_mask", c_u32),
        ("held_mask", c_u32),
        ("fault_flags", c_u32),
        ("safe_recv_ns", c_u64),  # [ns]
        ("publish_ns", c_u64),  # [ns]
        ("force_b", _vec(3)),  # F_B [N]
        ("torque_b", _vec(3)),  # F_B [N m]
        ("tau", _vec(N_JOINTS)),  # [N m]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v1::StepResult"


class Health(ctypes.Structure):
    """Every process -> scheduler, recorder."""

    _fields_ = [
        ("role", c_u32),
        ("pid", c_u32),
        ("state", c_u32),  # 0 starting, 1 ready, 2 running, 3 faulted, 4 stopping
        ("last_fault_flags", c_u32),
        ("ticks_handled", c_u64),
        ("deadline_misses", c_u64),
        ("cycle_slips", c_u64),
        ("last_tick", c_u64),
        ("publish_ns", c_u64),  # [ns]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v1::Health"


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
    Health,
]


def layout():
    """Size, alignment, type name and field offsets of every message."""
    out = {}
    for cls in ALL_TYPES:
        out[cls.__name__] = {
            "type_name": cls.type_name(),
            "size": ctypes.sizeof(cls),
            "align": ctypes.alignment(cls),
            "fields": [
                {"name": name, "offset": getattr(cls, name).offset, "size": getattr(cls, name).size}
                for name, _ in cls._fields_
            ],
        }
    return out


if __name__ == "__main__":
    if "--layout-json" in sys.argv[1:]:
        json.dump(layout(), sys.stdout, indent=1)
        sys.stdout.write("\n")
    else:
        for name, info in layout().items():
            print(f"{name:22s} {info['size']:4d} B  {info['type_name']}")
