"""The base class of a partner's navigation: the estimate of each tick's state from the
simulator's measurement (docs/PARTNER.md, docs/PARTITION.md "The navigation role").

A subclass implements ``estimate(measurement) -> estimate``; ``MyNavigation.main()``
runs it as the partition's ``navigation`` process (the launcher starts it with
``SC_RUN_ID`` and ``--config``, like a nominal controller): it reads every
``NavState`` the simulator publishes on ``safe_capture/sim/measurement`` and answers
with its estimate on ``safe_capture/navigation/estimate`` (:mod:`sc_partner.process`).

Frames and fields are the ICD's ``NavState`` (docs/ICD.md): inertial positions and
velocities, ``q_it`` and ``q_ib`` scalar-first, body rates in the bodies' frames, the
joints, the grasping point in F_T. ``measured_t`` is the time the measurement was
taken (``t`` minus the sensors' measurement age): an estimate is of the tick's time
``t`` from that measurement.

The simulator admits an estimate only if it is current (the measurement's ``tick``,
``t`` and ``measured_t``), finite, its quaternions unit, the target's orbit
(``target_r``, ``target_v``) the measured one, and every navigated quantity within its
declared bound (the scenario's ``[uncertainty.navigation]``) of the measurement;
otherwise it substitutes its own navigation (the declared error model), flags the tick
``NAVIGATION_REJECTED`` and logs why. With the ``exact`` profile every bound is zero:
the only admissible estimate is the measurement itself.

An ``estimate`` that raises, returns ``None`` or anything but an :class:`Estimate` (or
an ``icd.NavState``) publishes the measurement's labels (``tick``, ``t``,
``measured_t``) with every value NaN: the simulator refuses it at once (not finite) and
substitutes its own navigation for that tick only — no wait for the navigation
deadline, the next tick's estimate used as usual. The first such failure is logged with
its reason, the count at the end.

The same subclass runs offline on a partition run's recorded measurements
(``python -m sc_partner.harness ... --mcap recording.mcap``).
"""

import argparse
import os
import sys
import traceback

import numpy as np

from . import config as sc_config
from . import icd
from .controller import field

HANDSHAKE_TIMEOUT_S = 60.0


class Measurement:
    """One measurement (a copy of the ``NavState`` the simulator sent): every field an
    attribute, scalars as Python numbers, vectors as read-only ``numpy`` float64 arrays;
    ``raw`` is the ``NavState`` itself."""

    __slots__ = ("raw",)

    def __init__(self, raw):
        self.raw = raw

    def __getattr__(self, name):
        return field(self.raw, name)

    def estimate(self):
        """A writable :class:`Estimate` holding the measurement's values (tick, times
        and every field): change what the navigation estimates, return it."""
        return Estimate(icd.NavState.from_buffer_copy(self.raw))

    def __repr__(self):
        return f"Measurement(tick={self.raw.tick}, t={self.raw.t}, measured_t={self.raw.measured_t})"


class Estimate:
    """An estimate: the fields of a ``NavState`` as writable ``numpy`` views (``e.r_i[0]
    += 0.01``, ``e.q_ib[:] = q``) and assignable scalars; ``raw`` is the ``NavState``."""

    __slots__ = ("raw",)

    def __init__(self, raw):
        object.__setattr__(self, "raw", raw)

    def __getattr__(self, name):
        return field(self.raw, name, writeable=True)

    def __setattr__(self, name, value):
        current = field(self.raw, name, writeable=True)
        if isinstance(current, np.ndarray):
            current[:] = value
        else:
            setattr(self.raw, name, value)

    def __repr__(self):
        return f"Estimate(tick={self.raw.tick}, t={self.raw.t})"


class Navigation:
    """Base class of a navigation; subclasses implement ``estimate``.

    ``name``: the prefix of the process's log lines (default: the class name).
    """

    name = None

    def setup(self, scenario, period_s):
        """Called once before the first measurement: `scenario` is the mission's scenario
        (as a dict), `period_s` the base period of the partition (one tick). Optional."""

    def estimate(self, measurement):
        """The estimate for `measurement` (a :class:`Measurement`): an :class:`Estimate`
        (``measurement.estimate()``, changed), or ``None`` for no estimate this tick."""
        raise NotImplementedError(f"{type(self).__name__}.estimate")

    @property
    def label(self):
        """The log prefix."""
        return self.name or type(self).__name__

    def message(self, raw, recv_ns=0):
        """The ``NavState`` answering the measurement `raw`, and the reason there is no
        estimate (None if there is one; then the message is :func:`no_estimate`'s)."""
        del recv_ns  # NavState carries no receive stamp
        try:
            out = self.estimate(Measurement(raw))
        except Exception:
            return no_estimate(raw), "estimate raised:\n" + traceback.format_exc().rstrip()
        if isinstance(out, Estimate):
            out = out.raw
        if isinstance(out, icd.NavState):
            return icd.NavState.from_buffer_copy(out), None
        if out is None:
            return no_estimate(raw), "no estimate (estimate returned None)"
        return no_estimate(raw), f"estimate returned {out!r}, not an Estimate"

    @classmethod
    def main(cls, argv=None):
        """Entry point of a navigation script: ``sys.exit(MyNavigation.main())``."""
        return run_partition(cls(), argv)


def no_estimate(raw):
    """The answer to measurement `raw` when there is no estimate: its labels, every value
    NaN — refused by the simulator at once, for this tick only."""
    msg = icd.NavState(tick=raw.tick, t=raw.t, measured_t=raw.measured_t)
    for name, ctype in icd.NavState._fields_:
        if getattr(ctype, "_length_", 0):
            getattr(msg, name)[:] = [float("nan")] * ctype._length_
    return msg


def run_partition(navigation, argv=None):
    """Runs `navigation` as the partition's navigation process until the stop. Returns
    the process exit code (0 stopped normally, 1 handshake timeout, 2 usage)."""
    from . import bus, process

    label = navigation.label
    parser = argparse.ArgumentParser(prog=label, description="navigation (estimator)")
    parser.add_argument("--config", default=os.environ.get("SC_PARTITION_CONFIG"), help="partition config")
    parser.add_argument("--out", help="the run's output directory (given by the launcher)")
    parser.add_argument("--handshake-timeout-s", type=float, default=HANDSHAKE_TIMEOUT_S)
    args, _ = parser.parse_known_args(argv)
    run_id = os.environ.get("SC_RUN_ID")
    if not run_id or not args.config:
        print(f"{label}: SC_RUN_ID and --config are required", file=sys.stderr)
        return 2
    started_as = os.environ.get("SC_ROLE")
    if started_as and started_as != "navigation":
        print(
            f"{label}: this is a navigation (estimator) but was started as {started_as}: put it under"
            " [roles.navigation] in the partition config",
            file=sys.stderr,
        )
        return 2
    partition = sc_config.read_toml(args.config)
    scenario = sc_config.read_toml(sc_config.scenario_path(args.config, partition))
    navigation.setup(scenario, sc_config.base_period(partition))
    return process.serve(
        label,
        "navigation",
        icd.ROLE_NAVIGATION,
        run_id,
        process.Port(icd.SERVICE_MEASUREMENT, icd.NavState, bus.NOMINAL, "measurements"),
        process.Port(icd.SERVICE_ESTIMATE, icd.NavState, bus.NOMINAL, "estimate"),
        navigation.message,
        args.handshake_timeout_s,
    )
