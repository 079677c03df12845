#!/usr/bin/env bash
# Two "hosts" on this machine, for the partition across hosts (docs/PARTITION.md,
# "Across hosts"): each its own network namespace, joined by a veth pair, and its own
# mount namespace with a private /dev/shm and /tmp/iceoryx2 — so the two iceoryx2
# systems share no memory and reach each other only through the network, as two
# computers would. Needs root (ip, unshare, nsenter, mountpoint, sysctl: iproute2, util-linux, procps).
#
#   scripts/two_hosts.sh up NAME             # hosts NAME-a (127.201.0.1) and NAME-b (127.201.0.2)
#   scripts/two_hosts.sh exec NAME a CMD...  # runs CMD on host a (or b)
#   scripts/two_hosts.sh down NAME           # stops what still runs there, removes both hosts
#
# The addresses are loopback-range (127.201.0.0/30, route_localnet inside the two
# namespaces only): nothing outside this machine can be reached or reach them.
set -euo pipefail

STATE=/run/sc-two-hosts
SUBNET=127.201.0

usage() { sed -n '8,10p' "$0" >&2; exit 2; }
[ $# -ge 2 ] || usage
cmd=$1 name=$2
shift 2
case "$name" in -* | *[!A-Za-z0-9-]* | "") echo "two_hosts: NAME is [A-Za-z0-9][A-Za-z0-9-]*" >&2; exit 2 ;; esac
[ ${#name} -le 8 ] || { echo "two_hosts: NAME is at most 8 characters (interface names)" >&2; exit 2; }

# a private mount point for the namespaces' handles (nsfs bind mounts need one)
state_dir() {
  mkdir -p "$STATE"
  if ! mountpoint -q "$STATE"; then
    mount --bind "$STATE" "$STATE"
    mount --make-private "$STATE"
  fi
}

host_up() { # host side address
  local host=$1 side=$2 addr=$3
  ip netns add "$host"
  ip link set "$name-$side" netns "$host"
  ip netns exec "$host" sysctl -qw net.ipv4.conf.all.route_localnet=1
  ip -n "$host" addr add "$addr/30" dev "$name-$side"
  ip -n "$host" link set "$name-$side" up
  ip -n "$host" link set lo up
  touch "$STATE/$host.mnt"
  unshare --mount="$STATE/$host.mnt" --propagation private sh -c \
    'mount -t tmpfs -o size=2g sc-shm /dev/shm && mkdir -p /tmp/iceoryx2 && mount -t tmpfs sc-iceoryx2 /tmp/iceoryx2'
}

# every step is tried, a failed one is said and makes `down` fail at the end
host_down() {
  local host=$1
  if [ -e "/run/netns/$host" ]; then
    for pid in $(ip netns pids "$host" 2>/dev/null); do kill -TERM "$pid" 2>/dev/null || true; done
    sleep 0.5
    for pid in $(ip netns pids "$host" 2>/dev/null); do kill -KILL "$pid" 2>/dev/null || true; done
    ip netns del "$host" || { echo "two_hosts: cannot remove netns $host" >&2; failed=1; }
  fi
  if [ -e "$STATE/$host.mnt" ]; then
    umount "$STATE/$host.mnt" 2>/dev/null || true
    rm -f "$STATE/$host.mnt" || { echo "two_hosts: cannot remove $STATE/$host.mnt" >&2; failed=1; }
  fi
}

case "$cmd" in
  up)
    state_dir
    ip link add "$name-a" type veth peer name "$name-b"
    host_up "$name-a" a "$SUBNET.1"
    host_up "$name-b" b "$SUBNET.2"
    echo "two_hosts: $name-a ($SUBNET.1) and $name-b ($SUBNET.2) are up"
    ;;
  exec)
    [ $# -ge 2 ] || usage
    side=$1
    shift
    case "$side" in a | b) ;; *) usage ;; esac
    exec nsenter --mount="$STATE/$name-$side.mnt" --net="/run/netns/$name-$side" --wd="$PWD" -- "$@"
    ;;
  down)
    failed=0
    host_down "$name-a"
    host_down "$name-b"
    ip link del "$name-a" 2>/dev/null || true
    [ "$failed" = 0 ] || exit 1
    echo "two_hosts: $name is down"
    ;;
  *) usage ;;
esac
