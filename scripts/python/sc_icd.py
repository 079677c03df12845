#!/usr/bin/env python3
"""Python mirror of the safe-capture ICD (Rust crate ``sc-icd``, see docs/ICD.md).

Each class is a ``ctypes.Structure`` with exactly the ``#[repr(C)]`` layout of the
Rust type of the same name, and a static ``type_name()`` that returns the Rust
``#[type_name]`` (the iceoryx2 PyPI package matches types across languages by it).

The Rust test ``libs/icd/tests/python_layout.rs`` runs
``python3 scripts/python/sc_icd.py --layout-json`` and compares size, alignment,
every field offset and every type name with the Rust types.

Only the standard library is needed; iceoryx2 itself is imported by the users
of these types (e.g. ``interop_check.py``), not here.
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


def _vec(n):
    return c_f64 * n


# Service names (same as sc_icd::services). Each pub/sub service has an event
# service of the same name: the publisher notifies it after every send.
SERVICE_TICK = "safe_capture/scheduler/tick"
SERVICE_SIM_STATE = "safe_capture/sim/state"
SERVICE_NOMINAL_TRANSLATIONAL = "safe_capture/nominal/translational"
SERVICE_NOMINAL_ATTITUDE = "safe_capture/nominal/attitude"
SERVICE_NOMINAL_ROBOTIC = "safe_capture/nominal/robotic"
SERVICE_SAFE_TRANSLATIONAL = "safe_capture/safe/translational"
SERVICE_SAFE_ATTITUDE = "safe_capture/safe/attitude"
SERVICE_SAFE_ROBOTIC = "safe_capture/safe/robotic"
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


def run_prefix(run_id):
    """iceoryx2 global.prefix of a run, as sc_bus::RunScope builds it."""
    clean = "".join(c if (c.isascii() and (c.isalnum() or c in "-.")) else "-" for c in run_id)
    return "sc_" + clean + "_"


class Tick(ctypes.Structure):
    """Scheduler -> all: start one control step."""

    _fields_ = [
        ("tick", c_u64),  # tick index [-]
        ("rate_group", c_u32),  # rate-group id [-]
        ("clock_mode", c_u32),  # 0 lock-step, 1 real time, 2 scaled [-]
        ("t", c_f64),  # simulation time [s]
        ("send_ns", c_u64),  # scheduler send stamp, CLOCK_MONOTONIC [ns]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v1::Tick"


class SimState(ctypes.Structure):
    """Simulator -> all: true state at the start of the step."""

    _fields_ = [
        ("step", c_u64),  # [-]
        ("t", c_f64),  # [s]
        ("phase", c_u32),  # 1 approach, 2 synchronisation, 3 capture
        ("_pad0", c_u32),
        ("r_h", _vec(3)),  # F_H [m]
        ("v_h", _vec(3)),  # F_H [m/s]
        ("r_r", _vec(3)),  # F_R [m]
        ("v_r", _vec(3)),  # F_R [m/s]
        ("q_rb", _vec(4)),  # scalar-first, F_B -> F_R
        ("w_b", _vec(3)),  # F_B [rad/s]
        ("theta", _vec(N_JOINTS)),  # [rad]
        ("theta_dot", _vec(N_JOINTS)),  # [rad/s]
        ("q_rt", _vec(4)),  # scalar-first, F_T -> F_R
        ("w_t", _vec(3)),  # F_T [rad/s]
        ("q_hr", _vec(4)),  # scalar-first, F_R -> F_H
        ("w_h", _vec(3)),  # F_H [rad/s]
        ("dw_h", _vec(3)),  # F_H [rad/s^2]
        ("n", c_f64),  # mean motion [rad/s]
        ("p_g_r", _vec(3)),  # grasping point, F_R [m]
        ("v_g_r", _vec(3)),  # F_R [m/s]
        ("a_g_r", _vec(3)),  # F_R [m/s^2]
        ("p_ee_b", _vec(3)),  # end effector, F_B [m]
        ("publish_ns", c_u64),  # [ns]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v1::SimState"


_NOMINAL_HEAD = [
    ("tick", c_u64),  # tick answered [-]
    ("t", c_f64),  # sim time of the state used [s]
    ("valid", c_u32),  # 1 valid, 0 not
    ("_pad0", c_u32),
    ("recv_ns", c_u64),  # state received [ns]
    ("publish_ns", c_u64),  # [ns]
]


class NominalTranslational(ctypes.Structure):
    """Nominal translational controller -> translational safety filter."""

    _fields_ = _NOMINAL_HEAD + [("f_h", _vec(3))]  # F_H [N]

    @staticmethod
    def type_name():
        return "safe_capture::v1::NominalTranslational"


class NominalAttitude(ctypes.Structure):
    """Nominal attitude controller -> attitude safety filter."""

    _fields_ = _NOMINAL_HEAD + [("tau_b", _vec(3))]  # F_B [N m]

    @staticmethod
    def type_name():
        return "safe_capture::v1::NominalAttitude"


class NominalRobotic(ctypes.Structure):
    """Nominal robotic controller -> robotic safety filter."""

    _fields_ = _NOMINAL_HEAD + [("tau_m", _vec(N_JOINTS))]  # joints [N m]

    @staticmethod
    def type_name():
        return "safe_capture::v1::NominalRobotic"


def _safe_head(n):
    return [
        ("tick", c_u64),
        ("t", c_f64),  # [s]
        ("recv_ns", c_u64),  # [ns]
        ("publish_ns", c_u64),  # [ns]
        ("active_mask", c_u64),  # bit i = constraint i active
        ("solve_ns", c_u64),  # [ns]
        ("solver_status", c_u32),  # 0 solved
        ("iterations", c_u32),
        ("fault_flags", c_u32),  # sc_icd::fault bits
        ("n_constraints", c_u32),
        ("h", _vec(n)),  # barrier values
        ("phi", _vec(n)),  # CBF residuals
    ]


class SafeTranslational(ctypes.Structure):
    """Translational safety filter output; constraints AC, CAZ."""

    _fields_ = _safe_head(N_CONSTRAINTS_TRANSLATIONAL) + [
        ("f_h", _vec(3)),  # F_H [N]
        ("f_b", _vec(3)),  # F_B [N]
    ]

    @staticmethod
    def type_name():
        return "safe_capture::v1::SafeTranslational"


class SafeAttitude(ctypes.Structure):
    """Attitude safety filter output; constraints ATT, w1..3 upper, w1..3 lower."""

    _fields_ = _safe_head(N_CONSTRAINTS_ATTITUDE) + [("tau_b", _vec(3))]  # F_B [N m]

    @staticmethod
    def type_name():
        return "safe_capture::v1::SafeAttitude"


class SafeRobotic(ctypes.Structure):
    """Robotic safety filter output; 42 constraints (theta 7, dtheta up 7, dtheta low 7, link-base 21)."""

    _fields_ = _safe_head(N_CONSTRAINTS_ROBOTIC) + [("tau_m", _vec(N_JOINTS))]  # [N m]

    @staticmethod
    def type_name():
        return "safe_capture::v1::SafeRobotic"


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
