#!/usr/bin/env bash
# Submits a campaign to Slurm as a job array of shards and a merge that runs after it
# (docs/MONTECARLO.md, "On a cluster"):
#
#   scripts/slurm/submit.sh montecarlo --shards 4 --out /shared/mc -- --runs 10000 --seed 3
#   scripts/slurm/submit.sh redteam --shards 8 --out /shared/rt -- --partition --seeds 5
#
# Everything after `--` is the campaign's own options (as for `safe-capture montecarlo`
# or `safe-capture redteam`, without --out, --shard, --jobs). Options before it:
#   --shards N        tasks of the array (shard i of N each)               [required]
#   --out DIR         the campaign's folder on a filesystem every node sees  [required]
#   --cpus C          CPUs per task (the task's --jobs)                       [1]
#   --time T          time limit per task (sbatch --time)                     [none]
#   --partition P     Slurm partition                                        [default]
#   --bin PATH        the safe-capture executable          [target/release/safe-capture]
#   --sbatch-arg ARG  one more option for both sbatch calls (repeatable)
#
# Prints the array's and the merge's job ids and where the result will be:
# DIR/shards/<i> per task, DIR/merged the campaign, DIR/logs the tasks' output.
# Campaigns through the process partition (montecarlo --mode partition, redteam
# --partition) need /dev/shm on the nodes; every task's processes use iceoryx2 names of
# their own (the launcher's run tag), so tasks sharing a node do not meet.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
usage() { sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
[ $# -ge 1 ] || usage
kind=$1; shift
case "$kind" in montecarlo|redteam) ;; -h|--help) usage ;; *) echo "submit.sh: first argument montecarlo or redteam, not '$kind'" >&2; exit 2 ;; esac
shards="" out="" cpus=1 time="" part="" bin="$here/../../target/release/safe-capture"
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --shards) shards=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --cpus) cpus=$2; shift 2 ;;
    --time) time=$2; shift 2 ;;
    --partition) part=$2; shift 2 ;;
    --bin) bin=$2; shift 2 ;;
    --sbatch-arg) extra+=("$2"); shift 2 ;;
    --) shift; break ;;
    -h|--help) usage ;;
    *) echo "submit.sh: unknown option '$1' (the campaign's options go after --)" >&2; exit 2 ;;
  esac
done
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: --shards N (N >= 1) is required" >&2; exit 2; }
[ -n "$out" ] || { echo "submit.sh: --out DIR is required" >&2; exit 2; }
[ -x "$bin" ] || { echo "submit.sh: $bin is not an executable (build it: cargo build --release, or pass --bin)" >&2; exit 2; }
for a in "$@"; do
  case "$a" in --out|--out=*|--shard|--shard=*|--jobs|--jobs=*|-j*|--resume|-q|--quiet|--force|-[a-z]*q*)
    echo "submit.sh: '$a' is set per task; leave it out of the campaign's options" >&2; exit 2 ;;
  esac
done
command -v sbatch >/dev/null || { echo "submit.sh: sbatch not found (is this a Slurm login node?)" >&2; exit 2; }
if [ -n "$(ls -A "$out/shards" 2>/dev/null)" ]; then
  echo "submit.sh: $out/shards holds a campaign already: choose another --out (a shard of it is completed with \`safe-capture $kind --resume --out $out/shards/<i>\`)" >&2
  exit 2
fi
mkdir -p "$out/logs" "$out/shards"
out="$(cd "$out" && pwd)"
bin="$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")"
# the campaign's options, checked before anything is queued (a task would fail on them)
if [ $# -gt 0 ]; then printf '%s\n' "$@"; fi > "$out/campaign.args"
if [ "$kind" = redteam ]; then
  "$bin" redteam "$@" --list >/dev/null || { echo "submit.sh: the red team's options are refused (above)" >&2; exit 2; }
fi
common=(--parsable --export="ALL,SC_BIN=$bin,SC_KIND=$kind,SC_OUT=$out,SC_SHARDS=$shards"
        "${extra[@]}")
[ -n "$part" ] && common+=(--partition="$part")
task=("${common[@]}" --array="0-$((shards - 1))" --cpus-per-task="$cpus"
      --job-name="sc-$kind" --output="$out/logs/task-%a.log")
[ -n "$time" ] && task+=(--time="$time")
array=$(sbatch "${task[@]}" "$here/campaign_task.sbatch")
array=${array%%;*}
merge=$(sbatch "${common[@]}" --dependency="afterany:$array" --job-name="sc-$kind-merge" \
  --output="$out/logs/merge.log" "$here/merge.sbatch")
merge=${merge%%;*}
echo "submitted $kind: array job $array ($shards tasks, $cpus CPU each), merge job $merge after it"
echo "result: $out/merged (summary.json, report.md); shards in $out/shards; logs in $out/logs"
echo "follow: squeue -j $array,$merge    cancel: scancel $array $merge"
