"""Worked example: a third-party navigation process for the partition.

It replaces the Rust role ``navigation`` from the partition config (docs/PARTNER.md)::

    [roles.navigation]
    exec = "/path/to/venv/bin/sc-partner-navigation"

(installed with ``pip install ./scripts/python``; from a checkout without installing:
``exec = "../scripts/.venv/bin/python"``, ``args = ["../scripts/python/navigation.py"]``).
Offline, on the measurements a partition run recorded::

    python -m sc_partner.harness sc_partner.examples.navigation \\
        --mcap out/partition/recording.mcap --config config/partition.toml

The estimate is the measurement itself — the navigation of the ``exact`` profile, where
every declared navigation bound is zero; with a declared profile it is admitted too
(its error against the measurement is zero), and the filters' margins still cover the
declared measurement age. A real estimator changes the fields it estimates
(``e = m.estimate(); e.omega_t[:] = ...``) and stays within the declared bounds of the
measurement, or the simulator substitutes its own navigation for that tick, flagged.
Everything about processes, ports, the handshake and the stop is in
:class:`sc_partner.Navigation`.
"""

import sys

import numpy as np

from sc_partner import Navigation


class MeasurementAsEstimate(Navigation):
    """The measurement, unit quaternions checked: what this navigation knows."""

    name = "navigation.py"

    def estimate(self, m):
        for q in (m.q_it, m.q_ib):
            if not abs(np.linalg.norm(q) - 1.0) < 1e-9:
                return None  # no estimate: the simulator's own navigation stands in
        return m.estimate()


def main(argv=None):
    return MeasurementAsEstimate.main(argv)


if __name__ == "__main__":
    sys.exit(main())
