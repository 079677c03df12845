#!/usr/bin/env python3
"""A late attitude safety filter, for the partition's "applied only what was certified" test.

It takes the attitude safety filter's role and answers every attitude-due state with an
admissible command (zero torque, certified against the tick's translational command)
``--delay-ms`` (default 85) after the simulator received the tick: after the robotic
filter's stage deadline (80 ms, so the robotic filter certifies against the attitude
backup) and before the simulator's (90 ms, so the command does reach the simulator).
The simulator must then apply the attitude backup the robotic command was certified
against, never this command (``sc_flight::roles::simulator``); the test is
``apps/partition/tests/certified_chain.rs``. Needs a real-time run: the deadlines are
counted on CLOCK_MONOTONIC from the tick. Not a partner example: partners replace
nominal controllers, never filters.

Needs ``SC_RUN_ID`` and ``--config`` (or ``SC_PARTITION_CONFIG``), set by the launcher.
"""

import os
import sys
import time

import iceoryx2 as iox2

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sc_partner import bus as sc_bus  # noqa: E402
from sc_partner import icd as sc_icd  # noqa: E402

TIMEOUT_S = 60.0
DEFAULT_DELAY_MS = 85.0  # between the default robotic (80 ms) and simulator (90 ms) deadlines


def drain(sub, cls):
    """Every sample queued on `sub`, as `cls`."""
    out = []
    while True:
        sample = sub.receive()
        if sample is None:
            return out
        out.append(cls.from_buffer_copy(sample.payload().contents))
        sample.delete()


def main():
    run_id = os.environ.get("SC_RUN_ID")
    argv = sys.argv[1:]
    config = argv[argv.index("--config") + 1] if "--config" in argv else os.environ.get("SC_PARTITION_CONFIG")
    delay_ms = float(argv[argv.index("--delay-ms") + 1]) if "--delay-ms" in argv else DEFAULT_DELAY_MS
    if not run_id or not config:
        print("late_attitude_filter.py: SC_RUN_ID and --config are required", file=sys.stderr)
        return 2

    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    node = (
        iox2.NodeBuilder.new()
        .name(iox2.NodeName.new("safety_attitude"))
        .config(sc_bus.run_config(run_id))
        .create(iox2.ServiceType.Ipc)
    )
    q = sc_bus.PARTITION
    state_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_SIM_STATE, sc_icd.SimState, q)
    state_ev = sc_bus.data_event(node, sc_icd.SERVICE_SIM_STATE, q)
    up_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_SAFE_TRANSLATIONAL, sc_icd.SafeTranslational, q)
    tick_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_CONTROL, sc_icd.Tick, q)
    safe_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_SAFE_ATTITUDE, sc_icd.SafeAttitude, q)
    safe_ev = sc_bus.data_event(node, sc_icd.SERVICE_SAFE_ATTITUDE, q)
    state_sub = state_svc.subscriber_builder().create()
    state_lis = state_ev.listener_builder().create()
    up_sub = up_svc.subscriber_builder().create()
    tick_sub = tick_svc.subscriber_builder().create()
    pub = safe_svc.publisher_builder().create()
    notifier = safe_ev.notifier_builder().default_event_id(iox2.EventId.new(sc_icd.EVENT_SAMPLE)).create()
    ports = [state_sub, state_lis, up_sub, tick_sub, pub, notifier]
    forces = {}
    sent = 0
    try:
        if not sc_bus.handshake(node, sc_icd.ROLE_SAFETY_ATTITUDE, TIMEOUT_S):
            print("late_attitude_filter.py: handshake timed out", file=sys.stderr)
            return 1
        while True:
            state_lis.timed_wait(iox2.Duration.from_millis(100))
            for s in drain(state_sub, sc_icd.SimState):
                if not s.due_mask & sc_icd.DUE_ATTITUDE:
                    continue
                wait_ns = s.recv_ns + int(delay_ms * 1e6) - time.monotonic_ns()
                if wait_ns > 0:
                    time.sleep(wait_ns / 1e9)
                for t in drain(up_sub, sc_icd.SafeTranslational):
                    forces[t.tick] = list(t.actuated)
                m = sc_icd.SafeAttitude(tick=s.tick, t=s.t, n_constraints=sc_icd.N_CONSTRAINTS_ATTITUDE, solver_status=1)
                for i, f in enumerate(forces.pop(s.tick, list(s.held_f_b))):
                    m.xi_f_b[i] = f
                forces = {k: v for k, v in forces.items() if k > s.tick}
                m.publish_ns = time.monotonic_ns()
                pub.loan_uninit().write_payload(m).send()
                notifier.notify()
                sent += 1
            stop = any(t.command == sc_icd.TICK_STOP for t in drain(tick_sub, sc_icd.Tick))
            if stop:
                notifier.notify()
                print(f"late_attitude_filter.py: sent {sent} late commands", file=sys.stderr)
                return 0
    finally:
        for p in ports:
            p.delete()
        del state_svc, state_ev, up_svc, tick_svc, safe_svc, safe_ev
        del node


if __name__ == "__main__":
    sys.exit(main())
