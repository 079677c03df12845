#!/usr/bin/env bash
# The certified envelope's sweep (docs/SAFETY.md, "The certified envelope"): for every
# tumbling rate and grasping-point offset from the spin axis, a scenario that differs from
# config/scenario.toml in those two values only (and in [world] with the options below); `safe-capture check` decides whether it is
# inside the envelope, and every scenario it accepts runs the whole red team
# (`safe-capture redteam --scenario`, in process; with --partition also through the
# partition). One line per scenario in OUT/sweep.csv:
#   spin_rad_s,offset_m,verdict,cases,unsafe,detail
# verdict: refused (check refused it, its line in detail), safe (every case safe on the
# true state), announced (unsafe cases, each only after the layer had said, entering the
# safe mode, that the line of sight was at risk; exit 1), unsafe (a case unsafe without
# that: the envelope is wrong; exit 1), disturbed (every case safe, but an attack reached
# a subsystem it does not attack; exit 1), failed (the red team could not run; exit 1).
#
# With --spin-up-at T the tumble starts as in config/scenario.toml and the world spins the
# target up to the swept rate at T s ([world.target_spin_change], undeclared to the
# filters): the sweep of leaving the envelope during a run (docs/SAFETY.md, "Safe mode").
# With --fixture-at Y the scenario declares the fixture at each swept offset, but the world
# puts it at [-0.55, Y, 0.0] ([world] grasp_point_m, undeclared to the filters): a target
# that is not the one catalogued.
#
# Usage: scripts/envelope_sweep.sh [--out DIR] [--spins "0.05 0.08 …"]
#                                  [--offsets "0.1 0.35 0.6"] [--cases LIST] [--partition]
#                                  [--spin-up-at T] [--fixture-at Y]
# Defaults: the acceptance grid, spins 0.05–0.30 rad/s, offsets 0.1–0.6 m (measured on two
# cores: ≈ 4 min in process, ≈ 7 min and ≈ 1.5 GB of telemetry per accepted cell with
# --partition; --cases narrows the red team).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="out/envelope_sweep"
spins="0.05 0.08 0.10 0.12 0.15 0.17 0.20 0.25 0.30"
offsets="0.1 0.35 0.6"
cases=""
partition=
spin_up=
fixture=
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="${2:?--out needs a directory}"; shift 2 ;;
    --spins) spins="${2:?--spins needs a list}"; shift 2 ;;
    --offsets) offsets="${2:?--offsets needs a list}"; shift 2 ;;
    --cases) cases="${2:?--cases needs a list}"; shift 2 ;;
    --partition) partition="--partition"; shift ;;
    --spin-up-at) spin_up="${2:?--spin-up-at needs a time in s}"; shift 2 ;;
    --fixture-at) fixture="${2:?--fixture-at needs an offset in m}"; shift 2 ;;
    -h|--help) sed -n '2,28p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "envelope_sweep.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
sc="${SC_BIN:-$here/target/release/safe-capture}"
if [[ ! -x "$sc" ]]; then
  cargo build --release --manifest-path "$here/Cargo.toml" -p safe-capture >&2
fi
mkdir -p "$out"
csv="$out/sweep.csv"
echo "spin_rad_s,offset_m,verdict,cases,unsafe,detail" > "$csv"
status=0
for w in $spins; do
  for o in $offsets; do
    dir="$out/spin${w}_offset${o}"
    mkdir -p "$dir"
    initial="[-$w, 0.0, 0.0]"
    [[ -n "$spin_up" ]] && initial="$(sed -n '/^\[target\]/,/^\[/ s|^initial_omega_rad_s = \(\[[^]]*\]\).*|\1|p' "$here/config/scenario.toml")"
    sed -e "s|^urdf = \"servicer.urdf\"|urdf = \"$here/config/servicer.urdf\"|" \
        -e "/^\[target\]/,/^\[/ s|^initial_omega_rad_s = .*|initial_omega_rad_s = $initial|" \
        -e "s|^grasp_point_m = .*|grasp_point_m = [-0.55, $o, 0.0]|" \
        "$here/config/scenario.toml" > "$dir/scenario.toml"
    if [[ -n "$spin_up" ]]; then
      printf '\n[world.target_spin_change]\nt_s = %s\nomega_rad_s = [-%s, 0.0, 0.0]\n' \
        "$spin_up" "$w" >> "$dir/scenario.toml"
    fi
    if [[ -n "$fixture" ]]; then
      printf '\n[world]\ngrasp_point_m = [-0.55, %s, 0.0]\n' "$fixture" >> "$dir/scenario.toml"
    fi
    if ! line="$("$sc" check "$dir/scenario.toml" 2>&1)"; then
      echo "$w,$o,refused,0,0,\"${line//\"/\'}\"" >> "$csv"
      echo "envelope_sweep: spin $w rad/s, offset $o m: refused by check" >&2
      continue
    fi
    args=(redteam --scenario "$dir/scenario.toml" --out "$dir/redteam" --force ${partition:+"$partition"})
    [[ -n "$cases" ]] && args+=(--cases "$cases")
    rc=0
    "$sc" "${args[@]}" > "$dir/redteam.log" 2>&1 || rc=$?
    last="$(tail -1 "$dir/redteam.log")"
    n="$(sed -n 's/.*: \([0-9]*\) of \([0-9]*\) cases safe.*/\2/p' <<< "$last")"
    ok="$(sed -n 's/.*: \([0-9]*\) of \([0-9]*\) cases safe.*/\1/p' <<< "$last")"
    announced="$(sed -n 's/.*(\([0-9]*\) of the unsafe announced.*/\1/p' <<< "$last")"
    unsafe=$(( ${n:-0} - ${ok:-0} ))
    case $rc in
      0) verdict=safe ;;
      1) if grep -q 'could not run' <<< "$last"; then verdict=failed
         elif [[ $unsafe -eq 0 ]]; then verdict=disturbed # only bystanders disturbed
         elif [[ "${announced:-0}" -eq $unsafe ]]; then verdict=announced
         else verdict=unsafe; fi
         status=1 ;;
      *) verdict=failed; status=1 ;; # the red team could not run (its log says why)
    esac
    echo "$w,$o,$verdict,${n:-0},$(( ${n:-0} - ${ok:-0} )),\"${last//\"/\'}\"" >> "$csv"
    echo "envelope_sweep: spin $w rad/s, offset $o m: $verdict (${ok:-?} of ${n:-?} safe)" >&2
  done
done
count() { grep -c "^[^,]*,[^,]*,$1," "$csv" || true; }
echo "envelope_sweep: $(count safe) safe, $(count refused) refused, $(count announced) announced, $(count unsafe) unsafe, $(count disturbed) disturbed, $(count failed) failed -> $csv" >&2
exit $status
