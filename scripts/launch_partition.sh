#!/usr/bin/env bash
# Runs the mission as a process partition: every module its own process over
# iceoryx2 (see docs/PARTITION.md). Builds the binaries, then `safe-capture launch`
# starts every process from the config, waits for all (handshake), runs the mission
# and tears everything down (also on Ctrl-C and on any failure).
#
# usage: scripts/launch_partition.sh [--config FILE] [--out DIR] [--real-time] [--max-ticks N]
# exit:  0 captured safely, 1 not captured safely, 3 a process failed, 2 bad usage/config
set -euo pipefail
cd "$(dirname "$0")/.."
config=config/partition.toml
out=out/partition
extra=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --config) config="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --real-time) extra+=(--real-time); shift ;;
    --max-ticks) extra+=(--max-ticks "$2"); shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "launch_partition.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
target="${CARGO_TARGET_DIR:-target}"
cargo build --release --quiet -p safe-capture -p sc-partition-apps
exec "$target/release/safe-capture" launch --config "$config" --out "$out" "${extra[@]}"
