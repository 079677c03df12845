#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, everything in one scratch folder: munge
# and Slurm's controller and node daemons started by this script (no systemd), for the
# test against a running Slurm (apps/safe-capture/tests/slurm.rs) and to try the batch
# scripts by hand. Needs root and Debian's slurm-wlm and munge (scripts/setup.sh
# --with-slurm). Debian 12's Slurm 22.05 runs so as root without systemd.
#
#   scripts/slurm/local_cluster.sh start DIR   start it; prints `export SLURM_CONF=...`
#   scripts/slurm/local_cluster.sh stop DIR    cancel every job, stop the daemons by the
#                                              pids they wrote, remove DIR
#
# Clients (sbatch, squeue, scontrol, scripts/slurm/submit.sh) find the cluster through
# SLURM_CONF=DIR/slurm.conf. Ports: SC_SLURM_PORT (controller, default 6817) and the
# next one (node).
set -euo pipefail
cmd=${1:-} dir=${2:-}
[ -n "$cmd" ] && [ -n "$dir" ] || { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
# how long the daemons get to stop, and jobs to end, before they are killed [s]
GRACE_S=5
# the share of the machine's memory the node offers to jobs
MEMORY_SHARE_PERCENT=90
# how long the node may take to come up [s]
START_TIMEOUT_S=30

# Stops the cluster in $dir: only a folder this script made (it holds run/ and the
# cluster's marker) is touched.
stop() {
  [ -d "$dir" ] || return 0
  if [ ! -f "$dir/run/local_cluster" ]; then
    echo "local_cluster: $dir is not a cluster this script started; left alone" >&2
    return 1
  fi
  if [ -f "$dir/slurm.conf" ] && command -v scancel >/dev/null; then
    export SLURM_CONF="$dir/slurm.conf"
    timeout "$GRACE_S" scancel --user="$(id -un)" 2>/dev/null || true
    # the jobs' steps end before their node daemon does
    local until=$((SECONDS + GRACE_S))
    while [ "$SECONDS" -lt "$until" ]; do
      [ -z "$(timeout "$GRACE_S" squeue -h 2>/dev/null)" ] && break
      sleep 0.1
    done
  fi
  for f in "$dir/run/slurmd.pid" "$dir/run/slurmctld.pid" "$dir/munge/munged.pid"; do
    [ -f "$f" ] || continue
    pid=$(cat "$f")
    kill "$pid" 2>/dev/null || true
    for _ in $(seq $((GRACE_S * 10))); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  rm -rf "$dir"
}

start() {
  for p in munged mungekey slurmctld slurmd sbatch; do
    command -v "$p" >/dev/null || { echo "local_cluster: $p not found: scripts/setup.sh --with-slurm" >&2; exit 1; }
  done
  [ "$(id -u)" = 0 ] || { echo "local_cluster: needs root (the daemons run as root and munge)" >&2; exit 1; }
  [ ! -e "$dir" ] || { echo "local_cluster: $dir exists; stop that cluster first or choose another folder" >&2; exit 1; }
  mkdir -p "$dir"/{run,log,state,spool,munge/key}
  dir=$(cd "$dir" && pwd)
  touch "$dir/run/local_cluster"
  # whatever fails from here on, nothing is left running
  trap 'status=$?; [ "$status" = 0 ] || stop; exit "$status"' EXIT
  local host port cpus mem
  host=$(hostname -s)
  port=${SC_SLURM_PORT:-6817}
  cpus=$(nproc)
  mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * MEMORY_SHARE_PERCENT / 100 ))
  # munge: a key and a daemon of this cluster's own, as the munge user (the socket's
  # folder open to every user, the key's to munge only)
  chown -R munge:munge "$dir/munge"
  chmod 755 "$dir" "$dir/run" "$dir/munge"
  chmod 700 "$dir/munge/key"
  su -s /bin/sh munge -c "mungekey -c -k '$dir/munge/key/munge.key'"
  su -s /bin/sh munge -c "munged --key-file='$dir/munge/key/munge.key' --socket='$dir/munge/munge.socket' \
    --pid-file='$dir/munge/munged.pid' --log-file='$dir/munge/munged.log' --seed-file='$dir/munge/munged.seed'"
  munge -n --socket="$dir/munge/munge.socket" | unmunge --socket="$dir/munge/munge.socket" >/dev/null
  cat > "$dir/slurm.conf" <<CONF
ClusterName=safecapture
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
JobRequeue=1
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  slurmctld -f "$dir/slurm.conf"
  slurmd -f "$dir/slurm.conf"
  export SLURM_CONF="$dir/slurm.conf"
  for _ in $(seq $((START_TIMEOUT_S * 5))); do
    state=$(sinfo -h -o %t 2>/dev/null || true)
    case "$state" in idle*|mix*|alloc*) echo "export SLURM_CONF=$SLURM_CONF"; trap - EXIT; return 0 ;; esac
    sleep 0.2
  done
  echo "local_cluster: the node did not come up within $START_TIMEOUT_S s (state '${state:-none}'); logs in $dir/log" >&2
  tail -n 20 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" >&2 || true
  exit 1
}

case "$cmd" in
  start) start ;;
  stop) stop ;;
  *) echo "local_cluster: start or stop, not '$cmd'" >&2; exit 2 ;;
esac
