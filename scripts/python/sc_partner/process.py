"""The process loop every partner process of the partition runs (docs/PARTITION.md,
docs/ICD.md); :mod:`sc_partner.controller` and :mod:`sc_partner.navigation` give it
their inbound and outbound services and how they answer one inbound message.

1. join the run: iceoryx2 ``global.prefix`` = ``sc_<SC_RUN_ID>_`` (the launcher sets
   ``SC_RUN_ID``);
2. create the ports before announcing the role: subscriber + listener on the inbound
   service (newest wins), a subscriber without listener on
   ``safe_capture/scheduler/control`` (the stop), publisher + notifier on the outbound
   service;
3. announce the role on the start-up handshake until the scheduler's ``go``;
4. answer every inbound message: publish the answer, then notify (whoever waits for it
   wakes on the notification); an answer of ``None`` publishes nothing;
5. on the stop: notify once more (the consumer wakes and sees the stop too), log what
   was handled, delete the ports.
"""

import sys
import time
from collections import namedtuple

import iceoryx2 as iox2

from . import bus
from . import icd

# the longest sleep between two looks at the stop (only matters if the simulator died)
WAIT_MS = 100

#: A service of the loop: its name, message class and settings (``bus.NOMINAL``...),
#: and what one message is called in the log (``"states"``, ``"command"``).
Port = namedtuple("Port", "service msg_cls qos noun")


class Counts:
    """What the loop handled: inbound messages, and how many had no valid answer."""

    def __init__(self):
        self.handled = 0
        self.invalid = 0


def serve(label, node_name, role, run_id, inbound, outbound, answer, handshake_timeout_s):
    """Runs the loop until the stop. `answer(raw, recv_ns)` gets each inbound message
    (a copy) and returns (the message to publish or None, the reason the answer is not
    valid or None). Returns the exit code: 0 stopped normally, 1 handshake timeout."""
    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    node = iox2.NodeBuilder.new().name(iox2.NodeName.new(node_name)).config(bus.run_config(run_id)).create(
        iox2.ServiceType.Ipc
    )
    in_svc = bus.open_pubsub(node, inbound.service, inbound.msg_cls, inbound.qos)
    in_ev = bus.data_event(node, inbound.service, inbound.qos)
    control_svc = bus.open_pubsub(node, icd.SERVICE_CONTROL, icd.Tick, bus.PARTITION)
    out_svc = bus.open_pubsub(node, outbound.service, outbound.msg_cls, outbound.qos)
    out_ev = bus.data_event(node, outbound.service, outbound.qos)
    subscriber = in_svc.subscriber_builder().create()
    listener = in_ev.listener_builder().create()
    # the stop comes on the control service; no listener: it is read at every wake-up
    # (the simulator notifies the inbound service once more when it stops)
    control_sub = control_svc.subscriber_builder().create()
    publisher = out_svc.publisher_builder().create()
    notifier = out_ev.notifier_builder().default_event_id(iox2.EventId.new(icd.EVENT_SAMPLE)).create()
    ports = [subscriber, listener, control_sub, publisher, notifier]
    counts = Counts()
    try:
        if not bus.handshake(node, role, handshake_timeout_s):
            print(f"{label}: handshake timed out", file=sys.stderr)
            return 1
        bus.mark_ready_away_from_home()
        while True:
            listener.timed_wait(iox2.Duration.from_millis(WAIT_MS))
            _answer_all(label, subscriber, inbound.msg_cls, answer, publisher, notifier, counts, outbound.noun)
            if _stopped(control_sub):
                notifier.notify()  # wake the consumer once so that it sees the stop too
                print(
                    f"{label}: handled {counts.handled} {inbound.noun} ({counts.invalid} without a valid {outbound.noun})",
                    file=sys.stderr,
                )
                return 0
    finally:
        for p in ports:
            p.delete()
        del in_svc, in_ev, control_svc, out_svc, out_ev
        del node


def _answer_all(label, subscriber, msg_cls, answer, publisher, notifier, counts, noun):
    """Answers every message waiting on `subscriber`."""
    while True:
        sample = subscriber.receive()
        if sample is None:
            return
        raw = msg_cls.from_buffer_copy(sample.payload().contents)
        sample.delete()
        msg, reason = answer(raw, time.monotonic_ns())
        if msg is None and reason is None:
            continue  # not this process's turn (e.g. a subsystem not due)
        counts.handled += 1
        if reason is not None:
            counts.invalid += 1
            if counts.invalid == 1:
                print(
                    f"{label}: tick {raw.tick} (t = {raw.t:.1f} s): no valid {noun}: {reason}", file=sys.stderr, flush=True
                )
        if msg is not None:
            msg.publish_ns = time.monotonic_ns()
            publisher.loan_uninit().write_payload(msg).send()
            notifier.notify()


def _stopped(control_sub):
    """Whether the control service carried the stop since the last look."""
    stop = False
    while True:
        sample = control_sub.receive()
        if sample is None:
            return stop
        stop |= sample.payload().contents.command == icd.TICK_STOP
        sample.delete()
