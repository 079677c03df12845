#!/usr/bin/env bash
# Runs a command with one CPU shielded: every task that may move (other processes,
# unbound kernel threads such as DAMON's kdamond) and the unbound workqueues are
# moved off CPU, and everything is put back afterwards (also on Ctrl-C).
# An experiment of docs/PARTITION.md ("What was tried"), not part of a normal run;
# needs root. Usage:
#   scripts/shield_cpu.sh CPU COMMAND [ARGS...]
# e.g. with a partition config that pins every role but the recorder to CPU 1:
#   scripts/shield_cpu.sh 1 target/release/safe-capture bench latency --config my.toml
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: $0 CPU COMMAND [ARGS...]" >&2
    exit 2
fi
cpu=$1
shift
bit=$((1 << cpu))
wq=/sys/devices/virtual/workqueue/cpumask
saved=$(mktemp)
old_wq=$(cat "$wq")
restore() {
    while read -r tid mask; do taskset -p "$mask" "$tid" >/dev/null 2>&1 || true; done <"$saved"
    echo "$old_wq" >"$wq"
    rm -f "$saved"
}
trap restore EXIT
all=$(printf '%x' $(( (1 << $(nproc --all)) - 1 )))
rest=$(printf '%x' $(( 0x$all & ~bit )))
for t in /proc/[0-9]*/task/[0-9]*; do
    tid=${t##*/}
    [ "$tid" = "$$" ] && continue # this script: COMMAND inherits its affinity
    mask=$(taskset -p "$tid" 2>/dev/null | awk '{print $NF}') || continue
    [ -n "$mask" ] || continue
    # tasks that may run on the shielded CPU and elsewhere; bound ones refuse (skipped)
    if (( (0x$mask & bit) != 0 && (0x$mask & ~bit) != 0 )); then
        taskset -p "$(printf '%x' $(( 0x$mask & ~bit )))" "$tid" >/dev/null 2>&1 &&
            echo "$tid $mask" >>"$saved" || true
    fi
done
echo "$rest" >"$wq"
echo "shield_cpu: moved $(wc -l <"$saved") tasks off CPU $cpu" >&2
"$@"
