#!/usr/bin/env python3
"""A lying translational safety filter, for the simulator's re-validation test.

The partition's filters are ours, but the simulator must not trust the bytes on a
safe-command service either (issue #12): this process takes the translational safety
filter's role and, for every state, publishes a command for the right tick that is
1000 x the force bound, NaN, or +inf, in turn. The simulator must reject every one,
apply the filter's backup instead and flag it (``sc_partition::admission``); the test
is ``apps/partition/tests/hostile_filter.rs``. Not a partner example: partners replace
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


def main():
    run_id = os.environ.get("SC_RUN_ID")
    argv = sys.argv[1:]
    config = argv[argv.index("--config") + 1] if "--config" in argv else os.environ.get("SC_PARTITION_CONFIG")
    if not run_id or not config:
        print("hostile_filter.py: SC_RUN_ID and --config are required", file=sys.stderr)
        return 2
    bound = float(sc_bus.load_scenario(config)["limits"]["force_max_n"])
    lies = [1000.0 * bound, float("nan"), float("inf")]

    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    node = (
        iox2.NodeBuilder.new()
        .name(iox2.NodeName.new("safety_translational"))
        .config(sc_bus.run_config(run_id))
        .create(iox2.ServiceType.Ipc)
    )
    state_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_SIM_STATE, sc_icd.SimState, sc_bus.PARTITION)
    state_ev = sc_bus.data_event(node, sc_icd.SERVICE_SIM_STATE, sc_bus.PARTITION)
    tick_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_CONTROL, sc_icd.Tick, sc_bus.PARTITION)
    safe_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_SAFE_TRANSLATIONAL, sc_icd.SafeTranslational, sc_bus.PARTITION)
    safe_ev = sc_bus.data_event(node, sc_icd.SERVICE_SAFE_TRANSLATIONAL, sc_bus.PARTITION)
    state_sub = state_svc.subscriber_builder().create()
    state_lis = state_ev.listener_builder().create()
    tick_sub = tick_svc.subscriber_builder().create()
    pub = safe_svc.publisher_builder().create()
    notifier = safe_ev.notifier_builder().default_event_id(iox2.EventId.new(sc_icd.EVENT_SAMPLE)).create()
    ports = [state_sub, state_lis, tick_sub, pub, notifier]
    sent = 0
    try:
        if not sc_bus.handshake(node, sc_icd.ROLE_SAFETY_TRANSLATIONAL, TIMEOUT_S):
            print("hostile_filter.py: handshake timed out", file=sys.stderr)
            return 1
        while True:
            state_lis.timed_wait(iox2.Duration.from_millis(100))
            while True:
                sample = state_sub.receive()
                if sample is None:
                    break
                s = sc_icd.SimState.from_buffer_copy(sample.payload().contents)
                sample.delete()
                if not s.due_mask & sc_icd.DUE_TRANSLATIONAL:
                    continue
                lie = lies[sent % len(lies)]
                m = sc_icd.SafeTranslational(tick=s.tick, t=s.t, n_constraints=sc_icd.N_CONSTRAINTS_TRANSLATIONAL)
                for i in range(3):
                    m.u[i] = lie
                    m.actuated[i] = lie
                m.publish_ns = time.monotonic_ns()
                pub.loan_uninit().write_payload(m).send()
                notifier.notify()
                sent += 1
            stop = False
            while True:
                sample = tick_sub.receive()
                if sample is None:
                    break
                stop |= sample.payload().contents.command == sc_icd.TICK_STOP
                sample.delete()
            if stop:
                notifier.notify()
                print(f"hostile_filter.py: sent {sent} lying commands", file=sys.stderr)
                return 0
    finally:
        for p in ports:
            p.delete()
        del state_svc, state_ev, tick_svc, safe_svc, safe_ev
        del node


if __name__ == "__main__":
    sys.exit(main())
