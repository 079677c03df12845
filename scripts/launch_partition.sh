#!/usr/bin/env bash
# Runs the mission as a process partition: every module its own process over
# iceoryx2 (see docs/PARTITION.md). Builds the binaries, then `safe-capture launch`
# starts every process from the config, waits for all (handshake), runs the mission
# and tears everything down (also on Ctrl-C and on any failure).
#
# usage: scripts/launch_partition.sh [--config FILE] [--out DIR] [--force] [--real-time] [--max-ticks N] [--no-build]
#        (--no-build: run the binaries as they are, without `cargo build` first)
# exit:  0 captured safely, 1 not captured safely, 2 bad usage/config, 3 a process failed
#        or interrupted, 4 samples lost in transport (safe-capture launch --help)
# Paths are relative to the caller's working directory (default config: the checkout's).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
args=()
build=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --config|--out|--max-ticks)
      if [[ $# -lt 2 || "$2" == --* ]]; then
        echo "launch_partition.sh: $1 needs a value (--help)" >&2; exit 2
      fi
      args+=("$1" "$2"); shift 2 ;;
    --real-time|--force) args+=("$1"); shift ;;
    --no-build) build=0; shift ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) echo "launch_partition.sh: unknown argument $1 (--help)" >&2; exit 2 ;;
  esac
done
target="${CARGO_TARGET_DIR:-$root/target}"
if [[ $build == 1 ]]; then
  cargo build --manifest-path "$root/Cargo.toml" --release --quiet -p safe-capture -p sc-partition-apps
fi
# no `cd`: the caller's relative --config and --out stay the caller's; the default
# config is the checkout's (safe-capture finds it next to its executable)
exec "$target/release/safe-capture" launch "${args[@]}"
