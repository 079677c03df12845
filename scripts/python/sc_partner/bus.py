"""Python counterpart of the Rust crate ``sc-bus``: how a partner process opens the
partition's iceoryx2 services with the same settings as the Rust processes, and
joins the start-up handshake (docs/ICD.md, docs/PARTITION.md).

Needs ``pip install iceoryx2==0.10.0`` (same x.y.z as the Rust crate: the version is
part of the shared-memory names). Whoever creates a service first fixes its settings,
so every process must ask for the same ones.
"""

import os
import time

import iceoryx2 as iox2

from . import icd as sc_icd
from .config import load_scenario  # noqa: F401  (the scripts' entry point to the scenario)

# sc_bus::ServiceSettings::lock_step()
LOCK_STEP = dict(buffer=4, history=0, max_publishers=2, max_subscribers=8, max_nodes=16, safe_overflow=False)
# sc_flight::process::qos(): the partition's data services (never silently lossy; exactly
# one publisher, the owner). The Rust publishers never wait for a full queue (that
# subscriber loses the sample, reported); a Python publisher on them (only the test
# scripts' hostile filters) keeps iceoryx2's own default.
PARTITION = dict(LOCK_STEP, buffer=16, max_publishers=1, safe_overflow=False)
# sc_flight::process::partner_qos(): the services a partner's nominal controller
# publishes on (safe_capture/nominal/*): newest wins, nobody ever waits
NOMINAL = dict(PARTITION, safe_overflow=True)
# sc_flight::process::Qos::across_hosts(): in a run across hosts (the launcher sets
# SC_ACROSS_HOSTS=1, sc_flight::hosts::ACROSS_HOSTS_ENV) every service also carries the
# link's ports on each host: one publisher (LINK_PUBLISHERS), two subscribers
# (LINK_SUBSCRIBERS: the tunnel's and its doorbell's)
LINK_PUBLISHERS = 1
LINK_SUBSCRIBERS = 2
if os.environ.get("SC_ACROSS_HOSTS") == "1":
    PARTITION, NOMINAL = (
        dict(q, max_publishers=q["max_publishers"] + LINK_PUBLISHERS, max_subscribers=q["max_subscribers"] + LINK_SUBSCRIBERS)
        for q in (PARTITION, NOMINAL)
    )
# event ids up to this on data services (sc_bus::pubsub::EVENT_ID_MAX)
EVENT_ID_MAX = 7
# the handshake's event services (sc_bus::handshake)
HANDSHAKE_MAX_PORTS = 32
HANDSHAKE_MAX_NODES = 40
HANDSHAKE_MAX_PARTICIPANTS = 64


# sc_bus::run::SERVICE_CREATION_TIMEOUT: how long opening a service waits for its creator
CREATION_TIMEOUT_S = 10


def run_config(run_id):
    """The iceoryx2 config of run `run_id`, as sc_bus::RunScope builds it."""
    cfg = iox2.config.default()
    cfg.global_cfg.prefix = iox2.FileName.new(sc_icd.run_prefix(run_id))
    cfg.global_cfg.creation_timeout = iox2.Duration.from_secs(CREATION_TIMEOUT_S)
    return cfg


def open_pubsub(node, name, ctype, qos):
    """The pub/sub service `name` carrying `ctype` (a sc_icd class), settings `qos`."""
    return (
        node.service_builder(iox2.ServiceName.new(name))
        .publish_subscribe(ctype)
        .subscriber_max_buffer_size(qos["buffer"])
        .history_size(qos["history"])
        .max_publishers(qos["max_publishers"])
        .max_subscribers(qos["max_subscribers"])
        .max_nodes(qos["max_nodes"])
        .enable_safe_overflow(qos["safe_overflow"])
        .subscriber_max_borrowed_samples(2)
        .open_or_create()
    )


def open_event(node, name, max_ports, max_nodes, id_max):
    return (
        node.service_builder(iox2.ServiceName.new(name))
        .event()
        .max_notifiers(max_ports)
        .max_listeners(max_ports)
        .max_nodes(max_nodes)
        .event_id_max_value(id_max)
        .notifier_dead_event(iox2.EventId.new(sc_icd.EVENT_NOTIFIER_DEAD))
        .notifier_dropped_event(iox2.EventId.new(sc_icd.EVENT_NOTIFIER_DROPPED))
        .open_or_create()
    )


def data_event(node, name, qos):
    """The event service beside the pub/sub service `name` (publish, then notify)."""
    return open_event(node, name, qos["max_publishers"] + qos["max_subscribers"], qos["max_nodes"], EVENT_ID_MAX)


def mark_ready_away_from_home():
    """Across hosts, away from the home host (where the scheduler writes it): the `go`
    came, so this host's launcher may count a role that ends as a finished one, not as a
    failed start — the file `all_ready` in the run's folder (sc_flight::ALL_READY), as
    the Rust roles write it (sc_flight::runner). The launcher sets SC_AWAY_FROM_HOME
    (sc_flight::hosts::AWAY_FROM_HOME_ENV) for the roles away from the home host, and
    SC_OUT_DIR."""
    out = os.environ.get("SC_OUT_DIR")
    if os.environ.get("SC_AWAY_FROM_HOME") == "1" and out:
        os.makedirs(out, exist_ok=True)
        open(os.path.join(out, "all_ready"), "a").close()


def handshake(node, role, timeout_s):
    """Announce `role` until the coordinator says go (sc_bus::handshake); False on timeout."""
    id_max = sc_icd.HANDSHAKE_ID_OFFSET + HANDSHAKE_MAX_PARTICIPANTS
    ready_svc = open_event(node, sc_icd.SERVICE_HANDSHAKE + "/ready", HANDSHAKE_MAX_PORTS, HANDSHAKE_MAX_NODES, id_max)
    go_svc = open_event(node, sc_icd.SERVICE_HANDSHAKE + "/go", HANDSHAKE_MAX_PORTS, HANDSHAKE_MAX_NODES, id_max)
    go = go_svc.listener_builder().create()  # listener first: the go cannot be lost
    ready = ready_svc.notifier_builder().default_event_id(iox2.EventId.new(sc_icd.HANDSHAKE_ID_OFFSET + role)).create()
    deadline = time.monotonic() + timeout_s
    try:
        while time.monotonic() < deadline:
            ready.notify()
            for ev in go.timed_wait(iox2.Duration.from_millis(20)):
                if ev.id.as_value == sc_icd.EVENT_GO:
                    return True
        return False
    finally:
        ready.delete()
        go.delete()
