#!/usr/bin/env python3
"""A third-party nominal translational controller for the safe-capture partition,
written in Python with the ``iceoryx2`` PyPI package (pin: iceoryx2==0.10.0, the
same 0.10.x as the Rust crate — the version is part of the shared-memory names).

It replaces the Rust role ``nominal_translational`` from config (see
docs/PARTITION.md)::

    [roles.nominal_translational]
    exec = "../scripts/.venv/bin/python"
    args = ["../scripts/python/nominal_translational.py"]

What a partner's controller has to do (every step below is in this file):

1. join the run: iceoryx2 ``global.prefix`` = ``sc_<SC_RUN_ID>_`` (set by the launcher);
2. create its ports: subscriber + listener on ``safe_capture/partner/state`` (SimState,
   newest wins),
   a subscriber without listener on ``safe_capture/scheduler/control`` (Tick
   messages: the stop; read at every wake-up),
   publisher + notifier on ``safe_capture/nominal/translational`` (NominalTranslational);
3. announce itself on the start-up handshake until the scheduler's ``go``;
4. for every SimState whose ``due_mask`` has the translational bit: compute f_H and
   publish it with the same ``tick``, then notify; the safety filter does the rest
   (the command may be unsafe: the filter keeps the servicer safe);
5. exit on a Tick with ``command == 1`` (stop), after notifying once more (the
   filter wakes and sees the stop too), deleting ports before the node.

The law here is deliberately simple: a PD towards the Go-for-Capture point on the
corridor axis, f_H = m (-kp e - kd v_H), in the Hill frame, switched off in phases
whose ``translational`` mode is "off". The scenario (mass, GfC point, phases) is
read from the partition config given by ``--config`` / ``SC_PARTITION_CONFIG``.
"""

import math
import os
import sys
import time

import iceoryx2 as iox2

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sc_bus  # noqa: E402
import sc_icd  # noqa: E402

OMEGA = 0.06  # closed-loop natural frequency [rad/s]
ZETA = 1.0  # damping ratio
MASS_KG = 269.0  # servicer mass (bus + arm); only scales the gains
TIMEOUT_S = 60.0


def arg(name, env):
    argv = sys.argv[1:]
    if name in argv and argv.index(name) + 1 < len(argv):
        return argv[argv.index(name) + 1]
    return os.environ.get(env)


def main():
    run_id = os.environ.get("SC_RUN_ID")
    config = arg("--config", "SC_PARTITION_CONFIG")
    if not run_id or not config:
        print("nominal_translational.py: SC_RUN_ID and --config are required", file=sys.stderr)
        return 2
    sc = sc_bus.load_scenario(config)
    phases = sorted(sc["mission"]["phases"], key=lambda p: p["start_s"])
    axis = sc["safety"]["translational"]["corridor_axis"]
    norm = math.sqrt(sum(a * a for a in axis))
    gfc_r = [a / norm * sc["nominal"]["translational"]["gfc_distance_m"] for a in axis]
    kp, kd = OMEGA * OMEGA, 2.0 * ZETA * OMEGA

    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    cfg = sc_bus.run_config(run_id)
    node = iox2.NodeBuilder.new().name(iox2.NodeName.new("nominal_translational")).config(cfg).create(iox2.ServiceType.Ipc)
    state_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_PARTNER_STATE, sc_icd.SimState, sc_bus.NOMINAL)
    state_ev = sc_bus.data_event(node, sc_icd.SERVICE_PARTNER_STATE, sc_bus.NOMINAL)
    tick_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_CONTROL, sc_icd.Tick, sc_bus.PARTITION)
    cmd_svc = sc_bus.open_pubsub(node, sc_icd.SERVICE_NOMINAL_TRANSLATIONAL, sc_icd.NominalTranslational, sc_bus.NOMINAL)
    cmd_ev = sc_bus.data_event(node, sc_icd.SERVICE_NOMINAL_TRANSLATIONAL, sc_bus.NOMINAL)
    state_sub = state_svc.subscriber_builder().create()
    state_lis = state_ev.listener_builder().create()
    # the scheduler's control service (Tick messages; the stop), no listener: it is
    # read at every wake-up (only the simulator and the recorder get every tick)
    tick_sub = tick_svc.subscriber_builder().create()
    pub = cmd_svc.publisher_builder().create()
    notifier = cmd_ev.notifier_builder().default_event_id(iox2.EventId.new(sc_icd.EVENT_SAMPLE)).create()
    ports = [state_sub, state_lis, tick_sub, pub, notifier]
    handled = 0
    try:
        if not sc_bus.handshake(node, sc_icd.ROLE_NOMINAL_TRANSLATIONAL, TIMEOUT_S):
            print("nominal_translational.py: handshake timed out", file=sys.stderr)
            return 1
        while True:
            # sleep until a state arrives (event wake-up; the simulator also wakes
            # us once when it stops); the timeout only bounds how late the stop is
            # seen if the simulator died
            state_lis.timed_wait(iox2.Duration.from_millis(100))
            while True:
                sample = state_sub.receive()
                if sample is None:
                    break
                s = sample.payload().contents
                tick, t, due = s.tick, s.t, s.due_mask
                r_h, v_h, q_hr = list(s.r_h), list(s.v_h), list(s.q_hr)
                sample.delete()
                if not due & sc_icd.DUE_TRANSLATIONAL:
                    continue
                recv_ns = time.monotonic_ns()
                phase = max(i for i, p in enumerate(phases) if t + 1e-9 >= p["start_s"]) if t >= 0 else 0
                gfc_h = sc_icd.rotate(q_hr, gfc_r)
                f_h = [MASS_KG * (-kp * (r_h[i] - gfc_h[i]) - kd * v_h[i]) for i in range(3)]
                if phases[phase]["translational"] == "off":
                    f_h = [0.0, 0.0, 0.0]
                valid = int(all(math.isfinite(x) for x in f_h))
                cmd = sc_icd.NominalTranslational(tick=tick, t=t, valid=valid, phase=phase, recv_ns=recv_ns)
                for i in range(3):
                    cmd.f_h[i] = f_h[i] if valid else 0.0
                cmd.publish_ns = time.monotonic_ns()
                pub.loan_uninit().write_payload(cmd).send()
                notifier.notify()
                handled += 1
            stop = False
            while True:
                sample = tick_sub.receive()
                if sample is None:
                    break
                stop |= sample.payload().contents.command == sc_icd.TICK_STOP
                sample.delete()
            if stop:
                notifier.notify()  # wake the safety filter once so that it sees the stop too
                print(f"nominal_translational.py: handled {handled} states", file=sys.stderr)
                return 0
    finally:
        for p in ports:
            p.delete()
        del state_svc, state_ev, tick_svc, cmd_svc, cmd_ev
        del node


if __name__ == "__main__":
    sys.exit(main())
