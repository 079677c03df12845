"""The base class of a partner's nominal controller.

A subclass says which subsystem it commands and implements ``step(state) ->
command``; :func:`run_partition` (or ``MyController.main()``) does everything else
that the partition expects of a nominal controller process (docs/PARTITION.md,
docs/ICD.md):

1. join the run: iceoryx2 ``global.prefix`` = ``sc_<SC_RUN_ID>_`` (the launcher sets
   ``SC_RUN_ID``), the scenario and rate groups from ``--config`` /
   ``SC_PARTITION_CONFIG``;
2. create its ports before announcing itself: subscriber + listener on
   ``safe_capture/partner/state`` (newest wins), a subscriber without listener on
   ``safe_capture/scheduler/control`` (the stop), publisher + notifier on
   ``safe_capture/nominal/<subsystem>``;
3. announce the role on the start-up handshake until the scheduler's ``go``;
4. for every state whose ``due_mask`` has the subsystem's bit: call ``step`` and
   publish its command with the state's ``tick``, ``t`` and mission phase, then
   notify (the safety filter wakes on it);
5. on the stop: notify once more (the filter wakes and sees the stop too), log how
   many states it handled, delete its ports.

A step that raises, returns ``None``, a vector of the wrong length or a non-finite
value publishes ``valid = 0``: the safety filter then filters the subsystem's
substitute nominal (its braking law) for that tick. The first such failure is
logged with its reason, the count at the end.

The same subclass runs offline on recorded states (:mod:`sc_partner.harness`).
"""

import argparse
import ctypes
import os
import sys
import traceback

import numpy as np

from . import config as sc_config
from . import icd

# per subsystem: role id, service, message class, command field, due bit, command length
_SUBSYSTEM = {
    "translational": (
        icd.ROLE_NOMINAL_TRANSLATIONAL,
        icd.SERVICE_NOMINAL_TRANSLATIONAL,
        icd.NominalTranslational,
        "f_h",
        icd.DUE_TRANSLATIONAL,
        3,
    ),
    "attitude": (
        icd.ROLE_NOMINAL_ATTITUDE,
        icd.SERVICE_NOMINAL_ATTITUDE,
        icd.NominalAttitude,
        "tau_b",
        icd.DUE_ATTITUDE,
        3,
    ),
    "robotic": (
        icd.ROLE_NOMINAL_ROBOTIC,
        icd.SERVICE_NOMINAL_ROBOTIC,
        icd.NominalRobotic,
        "tau_m",
        icd.DUE_ROBOTIC,
        icd.N_JOINTS,
    ),
}

HANDSHAKE_TIMEOUT_S = 60.0


def field(raw, name, writeable=False):
    """Field `name` of the ctypes message `raw`: a scalar as a Python number, an array as
    a ``numpy`` float64 view of the message's memory (read-only unless `writeable`)."""
    if name.startswith("_"):
        raise AttributeError(name)
    value = getattr(raw, name)
    if isinstance(value, ctypes.Array):
        array = np.ctypeslib.as_array(value)
        array.flags.writeable = writeable
        return array
    return value


class State:
    """One state of the mission as a controller sees it (a copy of ``SimState``).

    Every ``SimState`` field is an attribute (docs/ICD.md, ``sc_partner.icd``): the
    scalars as Python numbers (``tick``, ``t``, ``due_mask``, ``mean_motion``, ...),
    the vectors as read-only ``numpy`` float64 arrays (``r_h``, ``v_h``, ``q_hr``,
    ``theta``, ``barriers``, ...). ``phase`` is the index of the mission phase at
    ``t`` (scenario order), ``raw`` the ``SimState`` itself.
    """

    __slots__ = ("raw", "phase")

    def __init__(self, raw, phase):
        self.raw = raw
        self.phase = phase

    def __getattr__(self, name):
        return field(self.raw, name)

    def __repr__(self):
        return f"State(tick={self.raw.tick}, t={self.raw.t}, phase={self.phase})"


class NominalController:
    """Base class of a nominal controller; subclasses set ``subsystem`` and implement ``step``.

    ``subsystem``: ``"translational"`` (command f_H, Hill frame [N], 3 values),
    ``"attitude"`` (τ_B, base frame [N m], 3) or ``"robotic"`` (τ_M, joints [N m], 7).
    ``name``: the prefix of the process's log lines (default: the class name).
    """

    subsystem = None
    name = None

    def setup(self, scenario, period_s):
        """Called once before the first state: `scenario` is the mission's scenario
        (config/scenario.toml as a dict), `period_s` the period of the subsystem's rate
        group (the controller's step). Optional."""

    def step(self, state):
        """The command for `state` (a :class:`State`): a sequence of floats of the
        subsystem's length, or ``None`` for no command (``valid = 0``)."""
        raise NotImplementedError(f"{type(self).__name__}.step")

    # ----------------------------------------------------------------- helpers

    @property
    def label(self):
        """The log prefix."""
        return self.name or type(self).__name__

    def spec(self):
        """(role id, service, message class, command field, due bit, length) of the subsystem."""
        if self.subsystem not in _SUBSYSTEM:
            raise ValueError(
                f"{type(self).__name__}.subsystem = {self.subsystem!r}: one of {', '.join(_SUBSYSTEM)}"
            )
        return _SUBSYSTEM[self.subsystem]

    def due(self, state):
        """Whether the subsystem is due in `state`'s tick (its bit of ``due_mask``)."""
        return bool(state.due_mask & self.spec()[4])

    def command(self, state):
        """Runs ``step`` on `state`; returns (values as a float64 array of the
        subsystem's length, None) or (zeros, the reason it is not a valid command)."""
        n = self.spec()[5]
        zeros = np.zeros(n)
        try:
            out = self.step(state)
        except Exception as e:
            # the first line is the reason (the launcher's verdict quotes it), then the traceback
            return zeros, f"step raised {type(e).__name__}: {e}\n" + traceback.format_exc().rstrip()
        if out is None:
            return zeros, "step returned None"
        try:
            values = np.asarray(out, dtype=np.float64)
        except (TypeError, ValueError) as e:
            return zeros, f"step returned {out!r}, not numbers ({e})"
        if values.shape != (n,):
            return zeros, (
                f"step returned shape {values.shape}, the {self.subsystem} command is {n} values (shape ({n},))"
            )
        if not np.all(np.isfinite(values)):
            return zeros, f"step returned a non-finite command {values.tolist()}"
        return values, None

    def message(self, state, recv_ns=0):
        """The ICD message answering `state`, and the reason it is invalid (None if valid)."""
        _, _, msg_cls, field, _, _ = self.spec()
        values, reason = self.command(state)
        msg = msg_cls(tick=state.tick, t=state.t, valid=int(reason is None), phase=state.phase, recv_ns=recv_ns)
        getattr(msg, field)[:] = values.tolist()
        return msg, reason

    @classmethod
    def main(cls, argv=None):
        """Entry point of a controller script: ``sys.exit(MyController.main())``."""
        return run_partition(cls(), argv)


def run_partition(controller, argv=None):
    """Runs `controller` as the partition's nominal controller of its subsystem until
    the stop. Returns the process exit code (0 stopped normally, 1 handshake timeout,
    2 usage)."""
    from . import bus, process

    label = controller.label
    parser = argparse.ArgumentParser(prog=label, description=f"nominal {controller.subsystem} controller")
    parser.add_argument("--config", default=os.environ.get("SC_PARTITION_CONFIG"), help="partition config")
    parser.add_argument("--out", help="the run's output directory (given by the launcher)")
    parser.add_argument("--handshake-timeout-s", type=float, default=HANDSHAKE_TIMEOUT_S)
    # the launcher may pass more options to every role; a controller needs none of them
    args, _ = parser.parse_known_args(argv)
    run_id = os.environ.get("SC_RUN_ID")
    if not run_id or not args.config:
        print(f"{label}: SC_RUN_ID and --config are required", file=sys.stderr)
        return 2
    role, service, msg_cls, _, due_bit, _ = controller.spec()
    # the launcher says which role slot this process fills (SC_ROLE); a controller of
    # another subsystem there would publish on another role's service
    started_as = os.environ.get("SC_ROLE")
    implements = f"nominal_{controller.subsystem}"
    if started_as and started_as != implements:
        print(
            f"{label}: this controller commands the {controller.subsystem} subsystem ({type(controller).__name__}.subsystem"
            f" = {controller.subsystem!r}) but was started as {started_as}: put it under [roles.{implements}] in"
            " the partition config",
            file=sys.stderr,
        )
        return 2
    partition = sc_config.read_toml(args.config)
    scenario = sc_config.read_toml(sc_config.scenario_path(args.config, partition))
    period_s, _ = sc_config.group_periods(partition, controller.subsystem)
    controller.setup(scenario, period_s)

    def answer(raw, recv_ns):
        if not raw.due_mask & due_bit:
            return None, None
        return controller.message(State(raw, sc_config.phase_index(scenario, raw.t)), recv_ns)

    return process.serve(
        label,
        f"nominal_{controller.subsystem}",
        role,
        run_id,
        process.Port(icd.SERVICE_PARTNER_STATE, icd.SimState, bus.NOMINAL, "states"),
        process.Port(service, msg_cls, bus.NOMINAL, "command"),
        answer,
        args.handshake_timeout_s,
    )
