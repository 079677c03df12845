#!/usr/bin/env python3
"""A hostile navigation: a navigation process whose estimates the simulator must refuse.

It serves the partition's ``navigation`` role like ``navigation.py`` (the SDK's
:class:`sc_partner.Navigation`), answering every measurement with the measurement
itself until tick ``--from-tick``, and from then on with what ``--strategy`` says:

- ``nan``: the servicer's relative position has a NaN component (not finite);
- ``jump:<m>``: the relative position moved ``m`` metres along x (farther from the
  measurement than the declared bound);
- ``stale:<n>``: the navigated values of the measurement ``n`` ticks old, labelled
  with the current tick, times and orbit (an estimator that stopped updating);
- ``old_tick``: the current values labelled with the previous tick (not current);
- ``nonunit``: the servicer's attitude quaternion scaled by 1.01;
- ``silent``: no estimate at all (the simulator's navigation deadline passes).

The simulator refuses each of them (``sc_sim::navigation::NavigationGate``) — ``jump``
and ``stale`` when they leave the declared bounds, which under ``exact`` (all zero) they
always do — substitutes its own navigation and flags the tick ``NAVIGATION_REJECTED``.
Until ``stale:<n>`` has ``n`` measurements of history it answers with the measurement.
By hand::

    [roles.navigation]
    exec = "../scripts/.venv/bin/python"
    args = ["../scripts/python/hostile_navigation.py", "--strategy", "jump:1", "--from-tick", "20"]

Like every partner process it needs ``SC_RUN_ID`` and ``--config`` (set by the launcher).
"""

import argparse
import math
import os
import sys
from collections import deque

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sc_partner import Navigation, icd  # noqa: E402
from sc_partner.navigation import run_partition  # noqa: E402

STRATEGIES = ("nan", "jump:<m>", "stale:<n>", "old_tick", "nonunit", "silent")


def parse_strategy(text):
    """(name, number) of a ``--strategy`` value; ValueError if it is not one."""
    name, _, arg = text.partition(":")
    if name in ("nan", "old_tick", "nonunit", "silent") and not arg:
        return name, None
    if name == "jump" and arg:
        return name, float(arg)
    if name == "stale" and arg and int(arg) > 0:
        return name, int(arg)
    raise ValueError(f"--strategy {text!r}: one of {', '.join(STRATEGIES)}")


class HostileNavigation(Navigation):
    name = "hostile_navigation.py"

    def __init__(self, strategy, from_tick):
        self.strategy, self.arg = strategy
        self.from_tick = from_tick
        # the measurements of the last ticks (for stale:n)
        self.history = deque(maxlen=(self.arg or 0) + 1 if self.strategy == "stale" else 1)
        self.attacks = 0

    def estimate(self, m):
        self.history.append(m.raw)
        e = m.estimate()
        attack_possible = not (self.strategy == "old_tick" and m.tick == 0)
        if m.tick < self.from_tick or len(self.history) < self.history.maxlen or not attack_possible:
            return e
        self.attacks += 1
        if self.strategy == "nan":
            e.r_i[1] = math.nan
        elif self.strategy == "jump":
            e.r_i[0] += self.arg
        elif self.strategy == "stale":
            old = icd.NavState.from_buffer_copy(self.history[0])
            old.tick, old.t, old.measured_t = m.tick, m.t, m.measured_t
            old.target_r[:], old.target_v[:] = m.target_r, m.target_v
            return old
        elif self.strategy == "old_tick":
            e.tick = max(m.tick, 1) - 1
        elif self.strategy == "nonunit":
            e.q_ib[:] = 1.01 * m.q_ib
        return e

    def message(self, raw, recv_ns=0):
        # silent: nothing published at all (the SDK would answer a None with NaN)
        if self.strategy == "silent" and raw.tick >= self.from_tick:
            self.attacks += 1
            return None, "silent"
        return super().message(raw, recv_ns)


def main(argv=None):
    p = argparse.ArgumentParser(prog="hostile_navigation.py", description=__doc__.split("\n")[0])
    p.add_argument("--strategy", required=True, help=", ".join(STRATEGIES))
    p.add_argument("--from-tick", type=int, default=0, help="the first tick attacked")
    args, rest = p.parse_known_args(argv)
    try:
        strategy = parse_strategy(args.strategy)
    except ValueError as e:
        print(f"hostile_navigation.py: {e}", file=sys.stderr)
        return 2
    nav = HostileNavigation(strategy, args.from_tick)
    code = run_partition(nav, rest)
    print(f"hostile_navigation.py: {args.strategy} on {nav.attacks} measurements", file=sys.stderr)
    return code


if __name__ == "__main__":
    sys.exit(main())
