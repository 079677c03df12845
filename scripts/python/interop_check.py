#!/usr/bin/env python3
"""Python <-> Rust interop check, and a template for a Python nominal controller.

Plays the nominal translational controller of the partition:
1. joins run ``SC_RUN_ID`` (iceoryx2 global.prefix ``sc_<run id>_``);
2. creates its ports: subscriber + listener on ``safe_capture/sim/state``,
   publisher + notifier on ``safe_capture/nominal/translational``;
3. announces itself on the handshake (event ``safe_capture/handshake/ready``,
   id 8 + role) until the coordinator's ``go`` (event ``.../go``, id 3);
4. for every SimState: f_H = -k * r_H  published as NominalTranslational, then
   notify; stops after a SimState with ``due_mask == 0`` (sent by the Rust test).

Usage: ``SC_RUN_ID=<id> scripts/.venv/bin/python scripts/python/interop_check.py``
Exit code 0 on success. Needs ``pip install iceoryx2==0.10.0`` (same x.y.z as the
Rust crate: the version is part of the shared-memory names).
"""

import os
import sys
import time

import iceoryx2 as iox2

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sc_partner import bus as sc_bus  # noqa: E402
from sc_partner import icd as sc_icd  # noqa: E402

GAIN = 0.5
TIMEOUT_S = 20.0


def main():
    run_id = os.environ.get("SC_RUN_ID")
    if not run_id:
        print("interop_check: SC_RUN_ID not set", file=sys.stderr)
        return 2
    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    cfg = sc_bus.run_config(run_id)
    node = iox2.NodeBuilder.new().name(iox2.NodeName.new("py_nominal_t")).config(cfg).create(iox2.ServiceType.Ipc)

    state_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_SIM_STATE, sc_icd.SimState, sc_bus.LOCK_STEP)
    state_ev = sc_bus.data_event(node, sc_icd.SERVICE_SIM_STATE, sc_bus.LOCK_STEP)
    cmd_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_NOMINAL_TRANSLATIONAL, sc_icd.NominalTranslational, sc_bus.LOCK_STEP)
    cmd_ev = sc_bus.data_event(node, sc_icd.SERVICE_NOMINAL_TRANSLATIONAL, sc_bus.LOCK_STEP)
    sub = state_svc.subscriber_builder().create()
    listener = state_ev.listener_builder().create()
    pub = cmd_svc.publisher_builder().create()
    notifier = cmd_ev.notifier_builder().default_event_id(iox2.EventId.new(sc_icd.EVENT_SAMPLE)).create()
    ports = [sub, listener, pub, notifier]

    rc = 1
    try:
        if not sc_bus.handshake(node, sc_icd.ROLE_NOMINAL_TRANSLATIONAL, TIMEOUT_S):
            print("interop_check: handshake timed out", file=sys.stderr)
            return 1
        handled = 0
        deadline = time.monotonic() + TIMEOUT_S
        while time.monotonic() < deadline:
            listener.timed_wait(iox2.Duration.from_millis(100))  # sleep on the event
            while True:
                sample = sub.receive()
                if sample is None:
                    break
                s = sample.payload().contents
                step, due, r_h, t = s.tick, s.due_mask, list(s.r_h), s.t
                sample.delete()
                if due == 0:
                    print(f"interop_check: handled {handled} states")
                    rc = 0
                    return rc
                recv_ns = time.monotonic_ns()
                cmd = sc_icd.NominalTranslational(
                    tick=step, t=t, valid=1, recv_ns=recv_ns, publish_ns=time.monotonic_ns()
                )
                for i in range(3):
                    cmd.f_h[i] = -GAIN * r_h[i]
                pub.loan_uninit().write_payload(cmd).send()
                if os.environ.get("SC_DEBUG"):
                    print(f"interop_check: answered step {step}", file=sys.stderr)
                notifier.notify()
                handled += 1
        print("interop_check: timed out waiting for states", file=sys.stderr)
        return 1
    finally:
        # Delete ports, then the node: otherwise a dead node is left behind.
        for p in ports:
            p.delete()
        del state_svc, state_ev, cmd_svc, cmd_ev
        del node


if __name__ == "__main__":
    sys.exit(main())
