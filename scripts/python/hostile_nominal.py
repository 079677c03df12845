#!/usr/bin/env python3
"""A hostile partner: a nominal controller process that attacks the safety layer.

It serves one nominal role of the partition (translational, attitude or robotic) like
``nominal_translational.py`` does — same services, same handshake — but what it sends,
and when, is chosen to break the safety layer. The red team launches it in place of
the Rust nominal (``safe-capture redteam --partition``); by hand::

    [roles.nominal_attitude]
    exec = "../scripts/.venv/bin/python"
    args = ["../scripts/python/hostile_nominal.py", "--role", "attitude",
            "--strategy", "spin:y+burst:40"]

``--strategy`` is ``<values>`` followed by any number of ``+<behaviour>``; a bare
behaviour (``silent``, ``hang:300``) sends zeros.

Values (every command is 1.5 x the input bound unless said otherwise; the bounds are
read from the scenario's ``[limits]``):

- translational ``toward_zone``: the force towards the target's centre (collision-avoidance
  zone, corridor apex); ``off_corridor``: perpendicular to the corridor axis, outwards;
- attitude ``spin:<axis>`` / ``spin:-<axis>`` (e.g. ``spin:-y``): torque about one base
  axis (rate limits; about y or z also the line of sight);
- robotic ``joints:1`` / ``joints:-1``: every joint at once; ``joint:<j>`` / ``joint:-<j>``
  (e.g. ``joint:-7``): one joint (joint angles, joint rates, link-base spheres);
- any role: ``random:<seed>`` every component +-1.5 x the bound at random each step;
  ``nonfinite`` NaN, +inf, -inf and one NaN component in turn; ``huge`` 1e300, 1000 x the
  bound, -1e300 in turn; ``zero``.

Behaviours (how a broken or malicious process acts):

- ``frozen``: the first command, repeated for ever (labelled with each new tick);
- ``stale:<n>``: values computed from the state n ticks old, labelled with the current tick;
- ``old_tick:<n>`` / ``future_tick``: labelled with tick-n / tick+1;
- ``garbage``: ``valid`` alternates 0 and 7, ``phase`` 0xFFFFFFFF, ``t`` NaN;
- ``burst:<n>``: n messages per state, the real one among n-1 with random ticks and values;
- ``late:<ms>[:<every>]``: sleeps ms before answering every ``every``-th state (default 1);
- ``silent``: never publishes (but reads, and follows the stop);
- ``crash:<tick>``: SIGKILLs itself at that tick (no clean-up: its ports are left dead);
- ``hang:<tick>``: from that tick on stops reading and publishing and sleeps until killed;
- ``impersonate``: after the handshake, tries to publish on its filter's safe-command
  service (the one the simulator applies) — with the partition's settings, and by opening
  it with room for more publishers — and, if it ever gets a publisher, sends 1000 x the
  bound there every state. Every attempt is logged (``impersonation refused: ...``).

``--check`` only validates ``--role`` and ``--strategy`` against the scenario and exits
(0 valid, 2 not). Everything it did is counted on stderr when it stops. Like every partner process it
needs the run id (``SC_RUN_ID``) and the partition config (``--config`` or
``SC_PARTITION_CONFIG``), both set by the launcher.
"""

import math
import os
import random
import signal
import sys
import time
from collections import deque

import iceoryx2 as iox2

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sc_partner import bus as sc_bus  # noqa: E402
from sc_partner import icd as sc_icd  # noqa: E402

TIMEOUT_S = 60.0
OVERDRIVE = 1.5  # commands are this times the input bound
HUGE_FACTOR = 1000.0

BEHAVIOURS = {
    "frozen",
    "stale",
    "old_tick",
    "future_tick",
    "garbage",
    "burst",
    "late",
    "silent",
    "crash",
    "hang",
    "impersonate",
}

# the safe-command service of each role's filter, what an impersonator would publish on
SAFE = {
    "translational": (sc_icd.SERVICE_SAFE_TRANSLATIONAL, sc_icd.SafeTranslational, 3),
    "attitude": (sc_icd.SERVICE_SAFE_ATTITUDE, sc_icd.SafeAttitude, 3),
    "robotic": (sc_icd.SERVICE_SAFE_ROBOTIC, sc_icd.SafeRobotic, sc_icd.N_JOINTS),
}


def impersonate(node, role):
    """Tries to become a publisher of ``role``'s safe-command service; returns the
    publisher, or None (each refusal logged)."""
    name, ctype, _ = SAFE[role]
    for label, qos in (("as the ICD says", sc_bus.PARTITION), ("asking for 8 publishers", dict(sc_bus.PARTITION, max_publishers=8))):
        try:
            svc = sc_bus.open_pubsub(node, name, ctype, qos)
            pub = svc.publisher_builder().create()
        except Exception as e:  # noqa: BLE001 - any refusal is the expected outcome
            print(f"hostile_nominal.py: impersonation refused ({name}, {label}): {e!r}", file=sys.stderr, flush=True)
            continue
        print(f"hostile_nominal.py: impersonation: got a publisher on {name} ({label})", file=sys.stderr, flush=True)
        return pub
    return None


ROLES = {
    # role: (ICD role id, nominal service, message type, payload field, components, due bit, limit key)
    "translational": (
        sc_icd.ROLE_NOMINAL_TRANSLATIONAL,
        sc_icd.SERVICE_NOMINAL_TRANSLATIONAL,
        sc_icd.NominalTranslational,
        "f_h",
        3,
        sc_icd.DUE_TRANSLATIONAL,
        "force_max_n",
    ),
    "attitude": (
        sc_icd.ROLE_NOMINAL_ATTITUDE,
        sc_icd.SERVICE_NOMINAL_ATTITUDE,
        sc_icd.NominalAttitude,
        "tau_b",
        3,
        sc_icd.DUE_ATTITUDE,
        "torque_max_nm",
    ),
    "robotic": (
        sc_icd.ROLE_NOMINAL_ROBOTIC,
        sc_icd.SERVICE_NOMINAL_ROBOTIC,
        sc_icd.NominalRobotic,
        "tau_m",
        sc_icd.N_JOINTS,
        sc_icd.DUE_ROBOTIC,
        "joint_torque_max_nm",
    ),
}


def arg(name, env=None):
    argv = sys.argv[1:]
    if name in argv and argv.index(name) + 1 < len(argv):
        return argv[argv.index(name) + 1]
    return os.environ.get(env) if env else None


def unit(v, fallback):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v] if n > 1e-9 else fallback


class Attack:
    """What to send: parses ``--strategy`` and computes the command of each state."""

    def __init__(self, role, spec, scenario):
        self.role = role
        self.n = ROLES[role][4]
        self.bound = float(scenario["limits"][ROLES[role][6]])
        axis = scenario["safety"]["translational"]["corridor_axis"]
        self.corridor_axis_r = unit(axis, [1.0, 0.0, 0.0])
        merged = spec.split("+")
        if merged[0].partition(":")[0] in BEHAVIOURS:
            merged.insert(0, "zero")  # a bare behaviour (`silent`, `hang:300`) sends zeros
        self.values = merged[0]
        self.behaviours = {}
        for b in merged[1:]:
            name, _, par = b.partition(":")
            self.behaviours[name] = par
        self.rng = random.Random(self._seed())
        self.turn = 0
        self.frozen = None
        self.history = deque(maxlen=1 + int(self.behaviours.get("stale", "0") or 0))
        self.check()

    def _seed(self):
        if self.values.startswith("random:"):
            return int(self.values.split(":", 1)[1])
        return 0

    def check(self):
        for b in self.behaviours:
            if b not in BEHAVIOURS:
                raise ValueError(f"unknown behaviour `{b}` (known: {sorted(BEHAVIOURS)})")
        # computes once on a neutral state: a bad value spec fails here, before the handshake
        self.values_for(None)

    def values_for(self, s):
        """The command for state s (None: a neutral state, used to validate the spec)."""
        v = self.values
        b = OVERDRIVE * self.bound
        n = self.n
        if v == "zero":
            return [0.0] * n
        if v.startswith("random:"):
            return [self.rng.choice((-b, b)) for _ in range(n)]
        if v == "nonfinite":
            self.turn += 1
            pick = self.turn % 4
            if pick == 3:
                return [float("nan")] + [b] * (n - 1)
            return [(float("nan"), float("inf"), float("-inf"))[pick]] * n
        if v == "huge":
            self.turn += 1
            return [(1e300, HUGE_FACTOR * self.bound, -1e300)[self.turn % 3]] * n
        if self.role == "translational" and v in ("toward_zone", "off_corridor"):
            if s is None:
                return [0.0] * n
            if v == "toward_zone":
                return [-b * x for x in unit(list(s.com_h), [1.0, 0.0, 0.0])]
            d = self.corridor_axis_r
            c = list(s.com_r)
            along = sum(c[i] * d[i] for i in range(3))
            perp = unit([c[i] - along * d[i] for i in range(3)], unit([d[1], -d[0], 0.0], [0.0, 0.0, 1.0]))
            return [b * x for x in sc_icd.rotate(list(s.q_hr), perp)]
        sign, what = (-1.0, v.split(":", 1)[1][1:]) if v.count(":-") else (1.0, v.partition(":")[2])
        if self.role == "attitude" and v.startswith("spin:") and what in ("x", "y", "z"):
            u = [0.0] * 3
            u["xyz".index(what)] = sign * b
            return u
        if self.role == "robotic" and v in ("joints:1", "joints:-1"):
            return [sign * b] * n
        if self.role == "robotic" and v.startswith("joint:") and what.isdigit() and 1 <= int(what) <= n:
            u = [0.0] * n
            u[int(what) - 1] = sign * b
            return u
        raise ValueError(f"`{v}` is not a value strategy of the {self.role} role")

    def command(self, s):
        """(tick label, valid, phase, t, values) of the answer to state s."""
        self.history.append(s)
        if "frozen" in self.behaviours:
            if self.frozen is None:
                self.frozen = self.values_for(s)
            u = self.frozen
        elif "stale" in self.behaviours:
            u = self.values_for(self.history[0])
        else:
            u = self.values_for(s)
        tick = s.tick
        if "old_tick" in self.behaviours:
            tick = max(0, tick - int(self.behaviours["old_tick"] or "10"))
        if "future_tick" in self.behaviours:
            tick += 1
        valid, phase, t = 1, 0, s.t
        if "garbage" in self.behaviours:
            valid = 0 if s.tick % 2 == 0 else 7
            phase, t = 0xFFFFFFFF, float("nan")
        return tick, valid, phase, t, u


def parse(role, spec, scenario):
    """The attack and its process behaviour; ValueError on a bad --strategy."""
    attack = Attack(role, spec, scenario)
    beh = attack.behaviours
    try:
        crash_at = int(beh["crash"]) if "crash" in beh else None
        hang_at = int(beh["hang"]) if "hang" in beh else None
        burst = max(1, int(beh.get("burst") or 1))
        late_ms, _, late_every = (beh.get("late") or "0").partition(":")
        late_s, late_every = float(late_ms) / 1000.0, max(1, int(late_every or "1"))
        int(beh.get("stale") or 0)
        int(beh.get("old_tick") or 0)
    except ValueError as e:
        raise ValueError(f"bad behaviour parameter ({e})") from None
    return attack, crash_at, hang_at, burst, late_s, late_every


def main():
    run_id = os.environ.get("SC_RUN_ID")
    config = arg("--config", "SC_PARTITION_CONFIG")
    role = arg("--role")
    spec = arg("--strategy")
    check = "--check" in sys.argv[1:]
    if not config or role not in ROLES or not spec or not (run_id or check):
        print(
            "hostile_nominal.py: --config (or SC_PARTITION_CONFIG), --role {translational,attitude,robotic}, --strategy"
            " and SC_RUN_ID (unless --check) are required",
            file=sys.stderr,
        )
        return 2
    try:
        attack, crash_at, hang_at, burst, late_s, late_every = parse(role, spec, sc_bus.load_scenario(config))
    except (ValueError, KeyError, OSError) as e:
        print(f"hostile_nominal.py: {role} --strategy {spec}: {e}", file=sys.stderr)
        return 2
    if check:
        return 0
    beh = attack.behaviours
    role_id, service, ctype, field, n, due_bit, _ = ROLES[role]

    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    cfg = sc_bus.run_config(run_id)
    node = iox2.NodeBuilder.new().name(iox2.NodeName.new(f"nominal_{role}")).config(cfg).create(iox2.ServiceType.Ipc)
    state_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_PARTNER_STATE, sc_icd.SimState, sc_bus.NOMINAL)
    state_ev = sc_bus.data_event(node, sc_icd.SERVICE_PARTNER_STATE, sc_bus.NOMINAL)
    tick_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_CONTROL, sc_icd.Tick, sc_bus.PARTITION)
    cmd_svc = sc_bus.open_pubsub(node, service, ctype, sc_bus.NOMINAL)
    cmd_ev = sc_bus.data_event(node, service, sc_bus.NOMINAL)
    state_sub = state_svc.subscriber_builder().create()
    state_lis = state_ev.listener_builder().create()
    tick_sub = tick_svc.subscriber_builder().create()
    pub = cmd_svc.publisher_builder().create()
    notifier = cmd_ev.notifier_builder().default_event_id(iox2.EventId.new(sc_icd.EVENT_SAMPLE)).create()
    ports = [state_sub, state_lis, tick_sub, pub, notifier]
    counts = {"states": 0, "sent": 0, "bursts": 0}

    def send(tick, valid, phase, t, u):
        msg = ctype(tick=tick, t=t, valid=valid, phase=phase, recv_ns=time.monotonic_ns())
        arr = getattr(msg, field)
        for i in range(n):
            arr[i] = u[i]
        msg.publish_ns = time.monotonic_ns()
        pub.loan_uninit().write_payload(msg).send()
        counts["sent"] += 1

    try:
        if not sc_bus.handshake(node, role_id, TIMEOUT_S):
            print("hostile_nominal.py: handshake timed out", file=sys.stderr)
            return 1
        sc_bus.mark_ready_away_from_home()
        fake = impersonate(node, role) if "impersonate" in beh else None
        if fake is not None:
            ports.insert(0, fake)
        while True:
            state_lis.timed_wait(iox2.Duration.from_millis(100))
            while True:
                sample = state_sub.receive()
                if sample is None:
                    break
                s = sc_icd.SimState.from_buffer_copy(sample.payload().contents)
                sample.delete()
                if not s.due_mask & due_bit:
                    continue
                counts["states"] += 1
                if crash_at is not None and s.tick >= crash_at:
                    print(f"hostile_nominal.py: crashing at tick {s.tick} ({counts})", file=sys.stderr, flush=True)
                    os.kill(os.getpid(), signal.SIGKILL)
                if hang_at is not None and s.tick >= hang_at:
                    print(f"hostile_nominal.py: hanging at tick {s.tick} ({counts})", file=sys.stderr, flush=True)
                    while True:  # reads nothing, answers nothing, until the launcher kills it
                        time.sleep(3600)
                if fake is not None:
                    fctype, fn = SAFE[role][1], SAFE[role][2]
                    m = fctype(tick=s.tick, t=s.t)
                    for i in range(fn):
                        m.u[i] = HUGE_FACTOR * attack.bound
                        m.actuated[i] = HUGE_FACTOR * attack.bound
                    fake.loan_uninit().write_payload(m).send()
                    counts["impersonated"] = counts.get("impersonated", 0) + 1
                if "silent" in beh:
                    continue
                if late_s > 0 and s.tick % late_every == 0:
                    time.sleep(late_s)
                real = attack.command(s)
                if burst > 1:
                    where = attack.rng.randrange(burst)
                    for i in range(burst):
                        if i == where:
                            send(*real)
                        else:
                            junk = [attack.rng.uniform(-1e3, 1e3) * attack.bound for _ in range(n)]
                            send(s.tick + attack.rng.randint(-5, 5), attack.rng.randint(0, 1), 0, s.t, junk)
                    counts["bursts"] += 1
                else:
                    send(*real)
                notifier.notify()
            stop = False
            while True:
                sample = tick_sub.receive()
                if sample is None:
                    break
                stop |= sample.payload().contents.command == sc_icd.TICK_STOP
                sample.delete()
            if stop:
                notifier.notify()
                print(f"hostile_nominal.py: {role} {spec}: {counts}", file=sys.stderr)
                return 0
    finally:
        for p in ports:
            p.delete()
        del state_svc, state_ev, tick_svc, cmd_svc, cmd_ev
        del node


if __name__ == "__main__":
    sys.exit(main())
