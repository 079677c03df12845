"""Reading a partition config and its scenario (standard library only).

A partner process is started by the launcher with ``--config <partition.toml>`` (or
``SC_PARTITION_CONFIG``); the partition config names the scenario (its ``scenario``
key, relative to the config file) and the rate groups. The offline harness reads the
same files, or a scenario on its own.
"""

import os
import tomllib

SUBSYSTEMS = ("translational", "attitude", "robotic")


def read_toml(path):
    """The TOML file at `path` as a dict."""
    with open(path, "rb") as f:
        return tomllib.load(f)


def scenario_path(config_path, partition=None):
    """The scenario file a partition config names (absolute, or relative to the config)."""
    partition = partition if partition is not None else read_toml(config_path)
    path = partition["scenario"]
    if not os.path.isabs(path):
        path = os.path.join(os.path.dirname(os.path.abspath(config_path)), path)
    return path


def load_scenario(config_path):
    """The scenario of a partition config (its `scenario` key, relative to the config file)."""
    return read_toml(scenario_path(config_path))


def phase_index(scenario, t):
    """Index of the mission phase at time `t` (scenario order; as sc_scenario's phase_index)."""
    idx = 0
    for i, p in enumerate(scenario["mission"]["phases"]):
        if t + 1e-9 >= p["start_s"]:
            idx = i
    return idx


def base_period(partition):
    """The partition's base period (the fastest rate group's, one tick) in s."""
    groups = partition.get("rate_groups") or []
    if not groups:
        raise ValueError("the partition config has no [[rate_groups]]")
    return min(float(g["period_s"]) for g in groups)


def group_periods(partition, subsystem):
    """(period of `subsystem`'s rate group, base period = fastest group) in s."""
    if subsystem not in SUBSYSTEMS:
        raise ValueError(f"subsystem {subsystem!r}: one of {', '.join(SUBSYSTEMS)}")
    base = base_period(partition)
    for g in partition["rate_groups"]:
        if subsystem in g["members"]:
            return float(g["period_s"]), base
    raise ValueError(f"no rate group has the member {subsystem!r}")
