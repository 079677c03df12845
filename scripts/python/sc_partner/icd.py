"""The safe-capture ICD in Python (docs/ICD.md): the messages, the constants and helpers.

The messages and constants are those of the generated module :mod:`sc_partner._icd`
(written from the Rust crate ``sc-icd`` by ``sc-icd-gen``; never edit it by hand), all
re-exported here. Each message class is a ``ctypes.Structure`` with exactly the
``#[repr(C)]`` layout of the Rust type of the same name, and a static ``type_name()``
that returns the Rust ``#[type_name]`` (the iceoryx2 PyPI package matches types across
languages by it). Beside the messages: array lengths (``N_JOINTS``), service names
(``SERVICE_SIM_STATE``), event ids (``EVENT_SAMPLE``), role ids from the role table
(``ROLE_NOMINAL_TRANSLATIONAL``, ``ROLE_NAMES``), due-mask bits (``DUE_ROBOTIC``), tick
commands (``TICK_STOP``), clock modes, end codes, fault bits and health states.

The Rust test ``libs/icd/tests/python_layout.rs`` runs
``python3 -m sc_partner.icd --layout-json`` and ``--constants-json`` and compares size,
alignment, every field offset, every type name and every constant with Rust.

Only the standard library is needed (the layout check runs with a bare ``python3``);
iceoryx2 is imported by :mod:`sc_partner.bus`, not here.
"""

import ctypes
import json
import sys

from . import _icd
from ._icd import *  # noqa: F401,F403 -- the generated messages and constants

c_f64 = ctypes.c_double
c_u64 = ctypes.c_uint64
c_u32 = ctypes.c_uint32
c_i32 = ctypes.c_int32

# The SDK's name of the handshake offset (the generated one is EVENT_HANDSHAKE_ID_OFFSET).
HANDSHAKE_ID_OFFSET = _icd.EVENT_HANDSHAKE_ID_OFFSET


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


def layout():
    """Size, alignment, type name and field offsets of every message."""
    out = {}
    for cls in _icd.ALL_TYPES:
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


def constants():
    """Every constant of the generated module (int, str, tuple of names) by name."""
    return {
        name: getattr(_icd, name)
        for name in _icd.__all__
        if isinstance(getattr(_icd, name), (int, str, tuple))
    }


if __name__ == "__main__":
    if "--layout-json" in sys.argv[1:]:
        json.dump(layout(), sys.stdout, indent=1)
        sys.stdout.write("\n")
    elif "--constants-json" in sys.argv[1:]:
        json.dump(constants(), sys.stdout, indent=1, ensure_ascii=False)
        sys.stdout.write("\n")
    else:
        for name, info in layout().items():
            print(f"{name:22s} {info['size']:4d} B  {info['type_name']}")
