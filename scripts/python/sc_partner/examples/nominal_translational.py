"""Worked example: a third-party nominal translational controller for the partition.

It replaces the Rust role ``nominal_translational`` from the partition config
(docs/PARTNER.md)::

    [roles.nominal_translational]
    exec = "/path/to/venv/bin/sc-partner-nominal-translational"

(installed with ``pip install ./scripts/python``; from a checkout without installing:
``exec = "../scripts/.venv/bin/python"``, ``args =
["../scripts/python/nominal_translational.py"]``). Offline, on a recorded run::

    python -m sc_partner.harness sc_partner.examples.nominal_translational \\
        --telemetry out/run/telemetry.csv --scenario config/scenario.toml

The law is deliberately simple: a PD towards the Go-for-Capture point on the
corridor axis, f_H = m (-kp e - kd v_H) in the Hill frame, switched off in phases
whose ``translational`` mode is "off". It may command something unsafe: the safety
filter keeps the servicer safe. Everything about processes, ports, the handshake,
due ticks and the stop is in :class:`sc_partner.NominalController`.
"""

import sys

import numpy as np

from sc_partner import NominalController
from sc_partner.icd import rotate

OMEGA = 0.06  # closed-loop natural frequency [rad/s]
ZETA = 1.0  # damping ratio
MASS_KG = 269.0  # servicer mass (bus + arm); only scales the gains


class GoForCapturePD(NominalController):
    """PD on the Hill-frame position towards the Go-for-Capture point."""

    subsystem = "translational"
    name = "nominal_translational.py"

    def setup(self, scenario, period_s):
        axis = np.asarray(scenario["safety"]["translational"]["corridor_axis"], dtype=float)
        distance = scenario["nominal"]["translational"]["gfc_distance_m"]
        self.gfc_r = axis / np.linalg.norm(axis) * distance  # F_R [m]
        self.off = [p["translational"] == "off" for p in scenario["mission"]["phases"]]
        self.kp, self.kd = OMEGA * OMEGA, 2.0 * ZETA * OMEGA

    def step(self, state):
        if self.off[state.phase]:
            return np.zeros(3)
        gfc_h = np.asarray(rotate(state.q_hr, self.gfc_r))  # F_R -> F_H
        return MASS_KG * (-self.kp * (state.r_h - gfc_h) - self.kd * state.v_h)  # f_H [N]


def main(argv=None):
    """Runs the example in the partition (``SC_RUN_ID``, ``--config``)."""
    return GoForCapturePD.main(argv)


if __name__ == "__main__":
    sys.exit(main())
