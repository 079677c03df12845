#!/usr/bin/env bash
# Every QP of a Monte Carlo campaign and of the in-process red-team campaign, checked by
# `safe-capture verify-qp` (feasibility, and distance to an exact reference built on
# Clarabel's active set — docs/SAFETY.md has the method): each run is re-run with
# `--dump-qp`, its dump verified, then deleted (a mission's dump is 15–30 MB).
#
#   scripts/verify_qp_campaigns.sh [--runs N] [--seed S] [--cases all|none] [--out DIR]
#
# Defaults: --runs 100 --seed 1 --cases all --out out/verify_qp. Prints one line per run
# and a total; exit 0 when every QP was within verify-qp's tolerances, 1 otherwise.
# Takes ~20 min for 100 runs and the 95 red-team cases on 2 cores. Needs the release
# binary: cargo build --release -p safe-capture (or SC_BIN=path).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="${SC_BIN:-$here/target/release/safe-capture}"
runs=100 seed=1 cases=all out=out/verify_qp
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --cases) cases="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "verify_qp_campaigns: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "verify_qp_campaigns: no $bin; build it with cargo build --release -p safe-capture" >&2; exit 2; }
mkdir -p "$out"
out="$(cd "$out" && pwd)"
log="$out/verify_qp.log"
: > "$log"
failed=0 qps=0 exact=0 checked=0
# one mission: run with the dump, verify it, keep verify-qp's lines in the log
verify() {
  local label="$1"; shift
  local dump="$out/qp.jsonl"
  local code=0
  "$bin" run --quiet --no-compare --no-figures --force --out "$out/run" --dump-qp "$dump" "$@" > "$out/run.txt" 2>&1 || code=$?
  # a run that ends unsafe or uncaptured still dumps its QPs (exit 1); other codes fail
  if [ "$code" != 0 ] && [ "$code" != 1 ]; then
    echo "$label: run failed ($code)" | tee -a "$log"; failed=$((failed + 1)); return
  fi
  local v
  code=0
  v="$("$bin" verify-qp "$dump")" || code=$?
  printf '%s\n%s\n' "== $label" "$v" >> "$log"
  local total="${v##*verify-qp: }"
  local n="${total%% solved*}"
  local e; e="$(sed -n 's/.* checked, \([0-9]*\) against an exact.*/\1/p' <<< "$v")"
  qps=$((qps + n)); exact=$((exact + ${e:-0})); checked=$((checked + 1))
  if [ "$code" != 0 ]; then failed=$((failed + 1)); echo "$label: BEYOND TOLERANCE" | tee -a "$log"; fi
  echo "$label: $n QPs, ${e:-0} against an exact reference, verify-qp exit $code"
  rm -f "$dump"
}
if [ "$runs" -gt 0 ]; then
  # its folders are this script's own (--force); a campaign with an unsafe run exits 1 and
  # is still verified, anything else (bad arguments, a refused folder) stops the script
  code=0
  "$bin" montecarlo --runs "$runs" --seed "$seed" --force --out "$out/montecarlo" > "$out/montecarlo.txt" 2>&1 || code=$?
  if [ "$code" -ge 2 ]; then
    echo "verify_qp_campaigns: montecarlo failed (exit $code): $(tail -1 "$out/montecarlo.txt")" >&2
    exit 2
  fi
  for k in $(seq 0 $((runs - 1))); do
    sc="$out/montecarlo/runs/$k/scenario.toml"
    [ -f "$sc" ] || { echo "montecarlo run $k: no $sc" | tee -a "$log"; failed=$((failed + 1)); continue; }
    verify "montecarlo run $k" --scenario "$sc"
  done
fi
if [ "$cases" = all ]; then
  while read -r c; do
    verify "redteam $c" --redteam "$c"
  done < <("$bin" redteam --list)
fi
# the worst distances over everything, from verify-qp's per-filter lines
worst="$(grep -o 'distance to exact [0-9.e+-]*' "$log" | awk '{print $4}' | sort -g | tail -1)"
echo "verify_qp_campaigns: $checked missions, $qps solved QPs, $exact against an exact reference; largest distance to exact ${worst:-n/a} of the input bound; failed: $failed (log: $log)"
[ "$failed" = 0 ]
