"""Offline harness: a partner's controller on the states of a recorded run, no partition.

Feeds the states recorded in a run's ``telemetry.csv`` (``safe-capture run --out DIR``
or a partition run, ``safe-capture launch --out DIR``) or a partition run's
``recording.mcap`` to a
:class:`sc_partner.NominalController` exactly as the partition would — ``setup``
once, then ``step`` for every state whose tick the subsystem is due in — and returns
(or writes) its commands, one per due step, with the same validity rules as in the
partition (:meth:`NominalController.command`). So a controller can be unit-tested
without iceoryx2 processes::

    python -m sc_partner.harness my_pkg.my_module:MyController \\
        --telemetry out/run/telemetry.csv --config config/partition.toml --out commands.csv
    python -m sc_partner.harness my_pkg.my_module:MyController \\
        --mcap out/partition/recording.mcap --config config/partition.toml

A navigation (:class:`sc_partner.Navigation`) runs on the measurements a partition run
recorded (``recording.mcap``, channel ``safe_capture/sim/measurement``), one estimate
per measurement, compared with the estimates the run's navigation answered (channel
``safe_capture/navigation/estimate``)::

    python -m sc_partner.harness sc_partner.examples.navigation \\
        --mcap out/partition/recording.mcap --config config/partition.toml --out estimates.csv

or from Python::

    states = states_from_telemetry("out/run/telemetry.csv")
    commands = run_offline(MyController(), states, scenario, period_s=0.1)

What ``telemetry.csv`` holds of a state: time, step, phase, the Hill- and
reference-frame positions and velocities of the base and of the system centre of
mass, the attitudes and rates of both spacecraft, the joints, the end-effector and
grasping point in F_R and every barrier (``barriers``) with its minimum since the
previous row (``barriers_between``). Derived here: ``q_hr`` (from the same two
vectors in F_R and F_H, the base position and the centre of mass; exact to ~1e-14),
``grasp_b`` and ``ee_b`` (rotated into F_B). Not recorded, hence NaN: ``omega_h``,
``omega_dot_h``, ``mean_motion``, ``omega_dot_t``, ``grasp_v_r``, ``grasp_a_r``,
``ee_v_r``; the ``*_ns`` stamps are 0. ``due_mask`` comes from the partition config's
rate groups (``--config``); without one every subsystem is due at every step (the
schedule of ``safe-capture run``).

``recording.mcap`` holds every ``SimState`` the simulator published (channel
``safe_capture/sim/state``, the same states the partners get) with its exact
``due_mask``, ``q_hr``, ``omega_h``, ``mean_motion``, velocities and accelerations;
the recorder leaves out the centre of mass (``com_*``) and the barriers
(``barriers``, ``barriers_between``), which are NaN here (``telemetry.csv`` has them).
The phase comes from the scenario.
"""

import argparse
import csv
import importlib
import importlib.util
import inspect
import math
import os
import sys
from collections import namedtuple

import numpy as np

from . import config as sc_config
from . import icd
from . import mcap
from .controller import NominalController, State
from .navigation import Navigation

#: One command of an offline run: the state's tick, time and phase, whether the
#: command is valid (1/0), its values and, if invalid, why.
OfflineCommand = namedtuple("OfflineCommand", "tick t phase valid values reason")

_AXES = ("x", "y", "z")
# SimState vector field -> its telemetry.csv columns
_VECTOR_COLUMNS = {
    "r_h": [f"r_h_{a}_m" for a in _AXES],
    "v_h": [f"v_h_{a}_m_s" for a in _AXES],
    "r_r": [f"r_r_{a}_m" for a in _AXES],
    "v_r": [f"v_r_{a}_m_s" for a in _AXES],
    "com_r": [f"com_r_{a}_m" for a in _AXES],
    "com_v_r": [f"com_v_r_{a}_m_s" for a in _AXES],
    "com_h": [f"com_h_{a}_m" for a in _AXES],
    "com_v_h": [f"com_v_h_{a}_m_s" for a in _AXES],
    "q_rb": [f"q{i}_rb" for i in range(4)],
    "omega_b": [f"omega_b_{a}_rad_s" for a in _AXES],
    "theta": [f"theta_{i}_rad" for i in range(1, icd.N_JOINTS + 1)],
    "theta_dot": [f"theta_dot_{i}_rad_s" for i in range(1, icd.N_JOINTS + 1)],
    "q_rt": [f"q{i}_rt" for i in range(4)],
    "omega_t": [f"omega_t_{a}_rad_s" for a in _AXES],
    "ee_r": [f"ee_r_{a}_m" for a in _AXES],
    "grasp_r": [f"grasp_r_{a}_m" for a in _AXES],
}
_NOT_RECORDED = ("omega_h", "omega_dot_h", "mean_motion", "omega_dot_t", "grasp_v_r", "grasp_a_r", "ee_v_r")
# the recorded nominal command of each subsystem (to compare a controller with)
NOMINAL_COLUMNS = {
    "translational": [f"f_h_nom_{a}_n" for a in _AXES],
    "attitude": [f"tau_b_nom_{a}_nm" for a in _AXES],
    "robotic": [f"tau_m_nom_{i}_nm" for i in range(1, icd.N_JOINTS + 1)],
}


def quaternion_from_matrix(m):
    """Scalar-first unit quaternion of the rotation matrix `m` (w >= 0)."""
    m = np.asarray(m, dtype=float)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0.0:
        s = 2.0 * math.sqrt(1.0 + tr)
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    q = np.asarray(q)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0.0 else q


def rotation_between(a_from, b_from, a_to, b_to):
    """The rotation R with R a_from ∥ a_to and R (a_from × b_from) ∥ (a_to × b_to) (TRIAD):
    exact when the two pairs are the same two vectors in two frames."""

    def triad(a, b):
        a = np.asarray(a, dtype=float)
        t1 = a / np.linalg.norm(a)
        t2 = np.cross(a, b)
        t2 /= np.linalg.norm(t2)
        return np.column_stack([t1, t2, np.cross(t1, t2)])

    return triad(a_to, b_to) @ triad(a_from, b_from).T


def _conj(q):
    return [q[0], -q[1], -q[2], -q[3]]


def states_from_telemetry(path, partition=None):
    """The states recorded in `path` (a ``telemetry.csv``), as :class:`State` objects.

    `partition`: a partition config (dict, or a path to one) whose rate groups give
    each state's ``due_mask``; None = every subsystem due at every step.
    """
    if isinstance(partition, (str, os.PathLike)):
        partition = sc_config.read_toml(partition)
    every = {}
    for name in sc_config.SUBSYSTEMS:
        if partition is None:
            every[name] = 1
        else:
            period, base = sc_config.group_periods(partition, name)
            every[name] = max(1, round(period / base))
    bits = {"translational": icd.DUE_TRANSLATIONAL, "attitude": icd.DUE_ATTITUDE, "robotic": icd.DUE_ROBOTIC}
    states = []
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if header is None:
            raise ValueError(f"{path}: empty")
        col = {name: i for i, name in enumerate(header)}
        needed = ["step", "t_s", "phase"] + [c for cols in _VECTOR_COLUMNS.values() for c in cols]
        missing = [c for c in needed if c not in col]
        if missing:
            raise ValueError(f"{path}: not a safe-capture telemetry.csv (no column {missing[0]})")
        h_cols = [i for i, name in enumerate(header) if name.startswith("h_")]
        hmin_cols = [i for i, name in enumerate(header) if name.startswith("hmin_")]
        if len(h_cols) != icd.N_BARRIERS or len(hmin_cols) != icd.N_BARRIERS:
            raise ValueError(f"{path}: {len(h_cols)} h_* and {len(hmin_cols)} hmin_* columns, expected {icd.N_BARRIERS}")
        for n, row in enumerate(reader, start=2):
            if len(row) != len(header):
                raise ValueError(f"{path} line {n}: {len(row)} fields, the header has {len(header)}")
            raw = icd.SimState()
            raw.step = raw.tick = int(row[col["step"]])
            raw.t = float(row[col["t_s"]])
            raw.due_mask = sum(bit for name, bit in bits.items() if raw.tick % every[name] == 0)
            for field, cols in _VECTOR_COLUMNS.items():
                getattr(raw, field)[:] = [float(row[col[c]]) for c in cols]
            raw.barriers[:] = [float(row[i]) for i in h_cols]
            raw.barriers_between[:] = [float(row[i]) for i in hmin_cols]
            for field in _NOT_RECORDED:
                value = getattr(raw, field)
                if isinstance(value, float):
                    setattr(raw, field, math.nan)
                else:
                    value[:] = [math.nan] * len(value)
            rot_hr = rotation_between(raw.r_r, raw.com_r, raw.r_h, raw.com_h)
            raw.q_hr[:] = quaternion_from_matrix(rot_hr).tolist()
            q_br = _conj(list(raw.q_rb))
            raw.grasp_b[:] = icd.rotate(q_br, [g - r for g, r in zip(raw.grasp_r, raw.r_r)])
            raw.ee_b[:] = icd.rotate(q_br, [e - r for e, r in zip(raw.ee_r, raw.r_r)])
            states.append(State(raw, int(row[col["phase"]])))
    return states


def _json_number(x):
    return math.nan if x is None else float(x)


# SimState fields the recorder leaves out of the MCAP (telemetry.csv has them)
_NOT_IN_MCAP = ("com_h", "com_v_h", "com_r", "com_v_r", "barriers", "barriers_between")


def states_from_mcap(path, scenario):
    """The states the simulator published in a partition run's ``recording.mcap``
    (channel ``safe_capture/sim/state``), as :class:`State` objects with the phase of
    `scenario` (a dict) at their time."""
    states = []
    names = [name for name, _ in icd.SimState._fields_]
    for _, _, m in mcap.messages(path, {icd.SERVICE_SIM_STATE}):
        raw = icd.SimState()
        for name in names:
            if name.startswith("_"):  # padding, not recorded
                continue
            value = m.get(name)
            if value is None and name in _NOT_IN_MCAP:
                value = [None] * len(getattr(raw, name))
            elif name not in m:
                raise ValueError(f"{path}: a {icd.SERVICE_SIM_STATE} message without `{name}`")
            if isinstance(value, list):
                getattr(raw, name)[:] = [_json_number(x) for x in value]
            elif isinstance(getattr(raw, name), float):
                setattr(raw, name, _json_number(value))
            else:
                setattr(raw, name, int(value))
        states.append(State(raw, sc_config.phase_index(scenario, raw.t)))
    return states


def _nav_state(path, service, m):
    """The ``NavState`` of the JSON message `m` of channel `service` in `path`."""
    raw = icd.NavState()
    for name, _ in icd.NavState._fields_:
        if name not in m:
            raise ValueError(f"{path}: a {service} message without `{name}`")
        value = m[name]
        if isinstance(value, list):
            getattr(raw, name)[:] = [_json_number(x) for x in value]
        elif isinstance(getattr(raw, name), float):
            setattr(raw, name, _json_number(value))
        else:
            setattr(raw, name, int(value))
    return raw


def nav_states_from_mcap(path, service=icd.SERVICE_MEASUREMENT):
    """The ``NavState`` messages of channel `service` in a partition run's
    ``recording.mcap``: the measurements the navigation got (default) or, with
    ``icd.SERVICE_ESTIMATE``, the estimates it answered."""
    return [_nav_state(path, service, m) for _, _, m in mcap.messages(path, {service})]


#: One estimate of an offline run: the measurement's tick, time and measurement time,
#: whether there is an estimate (1/0), the estimate (a ``NavState``, or None) and, if
#: there is none, why.
OfflineEstimate = namedtuple("OfflineEstimate", "tick t measured_t valid estimate reason")


def run_offline_navigation(navigation, measurements, scenario, period_s):
    """Runs `navigation` on `measurements` (``NavState``) as the partition would:
    ``setup(scenario, period_s)`` once, then one estimate per measurement."""
    navigation.setup(scenario, period_s)
    out = []
    for m in measurements:
        estimate, reason = navigation.message(m)
        if reason is not None:
            estimate = None  # the partition's answer would be the refusable NaN
        out.append(OfflineEstimate(m.tick, m.t, m.measured_t, int(reason is None), estimate, reason))
    return out


def nav_columns():
    """The columns of a ``NavState`` in an estimates CSV (``r_i_0``, ``q_ib_3``, ...)."""
    cols = []
    for name, ctype in icd.NavState._fields_:
        if name in ("tick", "t", "measured_t", "publish_ns"):
            continue
        n = getattr(ctype, "_length_", 0)
        cols += [f"{name}_{i}" for i in range(n)] if n else [name]
    return cols


def _nav_values(raw):
    """The values of `raw` in :func:`nav_columns`' order."""
    values = []
    for name, ctype in icd.NavState._fields_:
        if name in ("tick", "t", "measured_t", "publish_ns"):
            continue
        v = getattr(raw, name)
        values += list(v) if getattr(ctype, "_length_", 0) else [v]
    return values


def write_estimates(path, estimates):
    """Writes `estimates` as CSV: step, t_s, measured_t_s, valid and the estimate's
    fields (empty where there is no estimate)."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        cols = nav_columns()
        w.writerow(["step", "t_s", "measured_t_s", "valid"] + cols)
        for e in estimates:
            values = [repr(float(x)) for x in _nav_values(e.estimate)] if e.estimate is not None else [""] * len(cols)
            w.writerow([e.tick, repr(e.t), repr(e.measured_t), e.valid] + values)


def largest_estimate_difference(estimates, recorded):
    """(difference, tick, column) of the largest absolute difference between
    `estimates` and the `recorded` ones ({tick: NavState}) over the ticks both have,
    or (nan, None, None)."""
    best = (math.nan, None, None)
    labels = ("tick", "t", "measured_t")
    cols = list(labels) + nav_columns()
    for e in estimates:
        if e.estimate is None or e.tick not in recorded:
            continue
        mine = [getattr(e.estimate, k) for k in labels] + _nav_values(e.estimate)
        theirs = [getattr(recorded[e.tick], k) for k in labels] + _nav_values(recorded[e.tick])
        for col, a, b in zip(cols, mine, theirs):
            d = _difference(a, b)
            if not (d <= best[0]):
                best = (d, e.tick, col)
    return best


def _difference(a, b):
    """|a - b|, 0 for two NaNs, infinite for a NaN against a number."""
    if math.isnan(a) or math.isnan(b):
        return 0.0 if math.isnan(a) and math.isnan(b) else math.inf
    return abs(a - b)


def run_offline(controller, states, scenario, period_s):
    """Runs `controller` on `states` as the partition would: ``setup(scenario,
    period_s)`` once, then one command per state whose tick the subsystem is due in.
    Returns the :data:`OfflineCommand` list in state order."""
    controller.setup(scenario, period_s)
    out = []
    for state in states:
        if not controller.due(state):
            continue
        values, reason = controller.command(state)
        out.append(OfflineCommand(state.tick, state.t, state.phase, int(reason is None), values, reason))
    return out


def write_commands(path, controller, commands):
    """Writes `commands` as CSV: step, t_s, phase, valid and the command's columns
    (named as the recorded nominal command in telemetry.csv)."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["step", "t_s", "phase", "valid"] + NOMINAL_COLUMNS[controller.subsystem])
        for c in commands:
            w.writerow([c.tick, repr(c.t), c.phase, c.valid] + [repr(float(v)) for v in c.values])


def recorded_nominal(path, subsystem):
    """{step: the nominal command of `subsystem` recorded in `path`}: a telemetry.csv
    (the command the filter used) or a recording.mcap (the commands published)."""
    if str(path).endswith(".mcap"):
        service, _, field = _SERVICE_FIELD[subsystem]
        return {
            int(m["tick"]): np.array([_json_number(x) for x in m[field]])
            for _, _, m in mcap.messages(path, {service})
        }
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        return {
            int(row["step"]): np.array([float(row[c]) for c in NOMINAL_COLUMNS[subsystem]])
            for row in reader
        }


_SERVICE_FIELD = {
    "translational": (icd.SERVICE_NOMINAL_TRANSLATIONAL, icd.NominalTranslational, "f_h"),
    "attitude": (icd.SERVICE_NOMINAL_ATTITUDE, icd.NominalAttitude, "tau_b"),
    "robotic": (icd.SERVICE_NOMINAL_ROBOTIC, icd.NominalRobotic, "tau_m"),
}


def load_controller(spec):
    """The controller or navigation class named by `spec`: ``package.module:Class`` or
    ``path/to/file.py:Class``; without ``:Class`` the module's one subclass of
    :class:`NominalController` or :class:`Navigation`."""
    target, _, cls_name = spec.partition(":")
    module = _load_module(target)
    if cls_name:
        return getattr(module, cls_name)
    return _only_class(module, spec)


def _only_class(module, spec):
    """The one NominalController or Navigation subclass `module` defines."""
    found = [
        c
        for c in vars(module).values()
        if inspect.isclass(c)
        and issubclass(c, (NominalController, Navigation))
        and c not in (NominalController, Navigation)
        and c.__module__ == module.__name__
    ]
    if len(found) != 1:
        names = ", ".join(c.__name__ for c in found) or "none"
        raise ValueError(
            f"{spec}: name the class (module:Class); NominalController and Navigation subclasses found: {names}"
        )
    return found[0]


def _is_file(target):
    return target.endswith(".py") or os.sep in target


def _load_module(target):
    """The module `target` names: a file path or a dotted module name."""
    if _is_file(target):
        name = os.path.splitext(os.path.basename(target))[0]
        loader_spec = importlib.util.spec_from_file_location(name, target)
        if loader_spec is None:
            raise ValueError(f"{target}: cannot load")
        module = importlib.util.module_from_spec(loader_spec)
        loader_spec.loader.exec_module(module)
        return module
    return importlib.import_module(target)


def main(argv=None):
    """Command line: see the module's documentation (``--help``)."""
    p = argparse.ArgumentParser(
        prog="python -m sc_partner.harness",
        description="Run a nominal controller offline on the states of a recorded telemetry.csv or recording.mcap,"
        " or a navigation on the measurements of a recording.mcap.",
    )
    p.add_argument("controller", help="package.module:Class or path/to/file.py:Class")
    rec = p.add_mutually_exclusive_group(required=True)
    rec.add_argument("--telemetry", help="telemetry.csv of a recorded run")
    rec.add_argument("--mcap", help="recording.mcap of a partition run")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--config", help="partition config (scenario and rate groups)")
    src.add_argument("--scenario", help="scenario.toml (every subsystem due at every control step)")
    p.add_argument("--out", help="write the commands to this CSV")
    p.add_argument("--strict", action="store_true", help="exit 1 if any due step has no valid command")
    args = p.parse_args(argv)
    try:
        # the inputs only: the partner's own code (its module, class, setup and step)
        # runs outside, so that its errors keep their traceback
        cls = _controller_class(args.controller)
    except InputError as e:
        print(f"harness: {e}", file=sys.stderr)
        return 2
    controller = cls()
    try:
        if isinstance(controller, Navigation):
            inputs = _navigation_inputs(p, args)
        else:
            inputs = _controller_inputs(args, controller.subsystem)
    except InputError as e:
        print(f"harness: {e}", file=sys.stderr)
        return 2
    if isinstance(controller, Navigation):
        return _main_navigation(args, controller, *inputs)
    partition, scenario, period_s, states, recorded = inputs
    commands = run_offline(controller, states, scenario, period_s)
    if args.out:
        write_commands(args.out, controller, commands)
    invalid = [c for c in commands if not c.valid]
    print(
        f"harness: {type(controller).__name__} ({controller.subsystem}) on {len(states)} states: "
        f"{len(commands)} commands, {len(invalid)} without a valid one"
        + (f" -> {args.out}" if args.out else "")
        + "; "
        + _largest_difference(commands, recorded, controller.subsystem)
    )
    for c in invalid[:1]:
        print(f"harness: first invalid, tick {c.tick}: {c.reason}", file=sys.stderr)
    return 1 if args.strict and invalid else 0


class InputError(Exception):
    """An input the harness cannot use, said in one line naming the file and the fix."""


def _one_line(e):
    return " ".join(str(e).split()) or type(e).__name__


# the unit of each subsystem's nominal command
_UNIT = {"translational": "N", "attitude": "N m", "robotic": "N m"}

# the first bytes of an MCAP file
_MCAP_MAGIC = b"\x89MCAP"


def _largest_difference(commands, recorded, subsystem):
    """"largest difference to the recorded nominal command: 161.8 N (tick 42, f_h_nom_y_n)",
    over the valid commands with a recorded counterpart."""
    best = None
    for c in commands:
        if not c.valid or c.tick not in recorded:
            continue
        d = np.abs(c.values - recorded[c.tick])
        if not np.all(np.isfinite(d)):
            continue
        k = int(np.argmax(d))
        if best is None or d[k] > best[0]:
            best = (float(d[k]), c.tick, k)
    if best is None:
        return "no valid command to compare with the recorded nominal command"
    diff, tick, axis = best
    column = NOMINAL_COLUMNS[subsystem][axis]
    return f"largest difference to the recorded nominal command: {diff:.6g} {_UNIT[subsystem]} (tick {tick}, {column})"


def _controller_class(spec):
    """The class `spec` names, or an InputError when the spec names no file, module or
    class; an error inside the partner's module propagates with its traceback."""
    target, _, cls_name = spec.partition(":")
    if _is_file(target):
        if not os.path.isfile(target):
            raise InputError(f"{spec}: no such file ({target})")
        if not target.endswith(".py"):
            raise InputError(f"{spec}: not a Python file ({target}; give path/to/file.py:Class)")
    else:
        try:
            found = importlib.util.find_spec(target)
        except ModuleNotFoundError as e:
            # the spec's own package missing; a module the partner's package imports
            # that is missing is the partner's error (its traceback follows)
            if not (e.name == target or target.startswith(f"{e.name}.")):
                raise
            found = None
        if found is None:
            raise InputError(f"{spec}: no module {target!r} (give package.module:Class or path/to/file.py:Class)")
    module = _load_module(target)
    if cls_name:
        if not hasattr(module, cls_name):
            raise InputError(
                f"{spec}: module {module.__name__!r} has no attribute {cls_name!r} (give the class's name after the colon)"
            )
        cls = getattr(module, cls_name)
    else:
        try:
            cls = _only_class(module, spec)
        except ValueError as e:
            raise InputError(_one_line(e)) from None
    if not (inspect.isclass(cls) and issubclass(cls, (NominalController, Navigation))):
        raise InputError(f"{spec}: not a NominalController or Navigation subclass")
    return cls


def _read_recording(recording, read):
    """`read()` of a recording, its errors as one InputError naming the file."""
    try:
        return read()
    except KeyError as e:
        raise InputError(f"{recording}: not a recording of safe-capture (no {e})") from None
    except (OSError, ValueError) as e:
        msg = _one_line(e)
        if not msg.startswith(str(recording)):
            msg = f"{recording}: not a recording of safe-capture ({msg})"
        raise InputError(msg) from None


def _controller_inputs(args, subsystem):
    """(partition, scenario, period, the recorded states, the recorded nominal commands)."""
    partition, scenario, period_s = _sources(args, subsystem)
    recording = args.mcap or args.telemetry
    if args.mcap:
        states = _read_recording(recording, lambda: states_from_mcap(args.mcap, scenario))
    else:
        _check_text(args.telemetry)
        states = _read_recording(recording, lambda: states_from_telemetry(args.telemetry, partition))
    recorded = _read_recording(recording, lambda: recorded_nominal(recording, subsystem))
    return partition, scenario, period_s, states, recorded


def _check_text(path):
    """A telemetry.csv given with --telemetry: readable text, not an MCAP recording."""
    try:
        with open(path, "rb") as f:
            head = f.read(len(_MCAP_MAGIC))
    except FileNotFoundError:
        raise InputError(f"{path}: no such file (--telemetry)") from None
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror or e}; --telemetry)") from None
    if head == _MCAP_MAGIC:
        raise InputError(f"{path} is an MCAP recording: give it with --mcap, not --telemetry")


def _read_toml(path, flag):
    try:
        return sc_config.read_toml(path)
    except FileNotFoundError:
        raise InputError(f"{path}: no such file ({flag})") from None
    except Exception as e:  # tomllib's own error, or bytes that are no text
        raise InputError(f"{path}: not a TOML file ({flag}: {_one_line(e)})") from None


def _sources(args, subsystem):
    """(partition config or None, scenario, period [s]) of `--config` or `--scenario`:
    the period of `subsystem`'s rate group, or (None) the base period; a scenario alone
    runs every subsystem at its control period."""
    if not args.config:
        scenario = _read_toml(args.scenario, "--scenario")
        if "mission" not in scenario:
            if "roles" in scenario or "rate_groups" in scenario:
                raise InputError(f"{args.scenario} is a partition config, not a scenario: give it with --config")
            raise InputError(f"{args.scenario}: not a scenario (no [mission]; --scenario)")
        try:
            return None, scenario, float(scenario["mission"]["control_period_s"])
        except (KeyError, TypeError, ValueError) as e:
            raise InputError(f"{args.scenario}: no valid mission.control_period_s ({_one_line(e)}; --scenario)") from None
    partition = _read_toml(args.config, "--config")
    if "rate_groups" not in partition:
        if "mission" in partition:
            raise InputError(f"{args.config} is a scenario, not a partition config: give it with --scenario")
        raise InputError(f"{args.config}: not a partition config (no rate_groups; --config)")
    try:
        scenario_path = sc_config.scenario_path(args.config, partition)
    except (KeyError, TypeError) as e:
        raise InputError(f"{args.config}: names no scenario ({_one_line(e)}; --config)") from None
    scenario = _read_toml(scenario_path, "the config's scenario")
    try:
        if subsystem is None:
            return partition, scenario, sc_config.base_period(partition)
        return partition, scenario, sc_config.group_periods(partition, subsystem)[0]
    except (KeyError, TypeError, ValueError) as e:
        raise InputError(f"{args.config}: {_one_line(e)} (--config)") from None


def _navigation_inputs(parser, args):
    """(scenario, period, the recorded measurements, the recorded estimates by tick)."""
    if not args.mcap:
        parser.error("a navigation runs on the measurements of a partition run: give its --mcap recording.mcap")
    _, scenario, period_s = _sources(args, None)
    measurements = _read_recording(args.mcap, lambda: nav_states_from_mcap(args.mcap))
    recorded = _read_recording(
        args.mcap, lambda: {e.tick: e for e in nav_states_from_mcap(args.mcap, icd.SERVICE_ESTIMATE)}
    )
    return scenario, period_s, measurements, recorded


def _main_navigation(args, navigation, scenario, period_s, measurements, recorded):
    """`main` for a navigation: its estimates of a partition run's recorded measurements."""
    estimates = run_offline_navigation(navigation, measurements, scenario, period_s)
    if args.out:
        write_estimates(args.out, estimates)
    diff, tick, col = largest_estimate_difference(estimates, recorded)
    where = f" (tick {tick}, {col}; units of the ICD's NavState)" if diff > 0 else ""
    invalid = [e for e in estimates if not e.valid]
    print(
        f"harness: {type(navigation).__name__} (navigation) on {len(measurements)} measurements: "
        f"{len(estimates) - len(invalid)} estimates, {len(invalid)} without one"
        + (f" -> {args.out}" if args.out else "")
        + f"; largest difference to the recorded estimate: {diff:.6g}{where}"
    )
    for e in invalid[:1]:
        print(f"harness: first without an estimate, tick {e.tick}: {e.reason}", file=sys.stderr)
    return 1 if args.strict and invalid else 0


if __name__ == "__main__":
    sys.exit(main())
