#!/usr/bin/env python3
"""A refactor proves itself by bytes: run the same jobs with two builds and compare.

    scripts/compare_builds.py OLD NEW [--work DIR] [--old-home H] [--new-home H] [--runs N]

OLD and NEW are folders holding a build's executables (`safe-capture` and the partition's
`sc-*`), e.g. a copy of an earlier `target/release` and this checkout's `target/release`.
Both builds run, from scratch folders under --work (default: a fresh temp folder):

* `run` — the default mission in one process (with its nominal-only comparison and
  figures);
* `launch` — the same mission through the lock-step process partition;
* `montecarlo --runs N --seed 1` (N = 100 by default);
* `redteam` — every in-process red-team case.

Every file the two builds wrote is compared byte for byte, except what holds times,
process ids or host stamps, which no two runs share (`timing.csv`, `latency.csv`,
`runs/K/timing.json`, `recording.mcap`, logs, ...): those are listed as skipped.
`summary.json`, `campaign.json` and `cases.csv` are compared with their timing keys/columns (and the
build's commit) removed.

--old-home/--new-home name each build's installation (SAFE_CAPTURE_HOME: the checkout
whose config/ and scripts/ its defaults come from; default: this checkout for both).
Exit 0 when everything compared is identical, 1 otherwise (the differences listed).
Only the standard library is used.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

# Files that carry wall-clock times, stamps, pids or host load: never identical.
SKIP_NAMES = {
    ".safe-capture",
    "timing.csv",
    "timing.json",
    "latency.csv",
    "launch.json",
    "scheduler.json",
    "recording.mcap",
    "runs_timing.csv",
    "runtime.svg",
    "report.md",
    # names each installation's paths (scenario, executables)
    "partition.effective.toml",
}
SKIP_DIRS = {"logs"}
# Keys of summary.json and campaign.json (at any depth) that are times, host readings or the build's
# own name (two builds differ in their commit by construction).
TIMING_KEYS = {
    "git_commit",
    "solve_time_us",
    "solve_cpu_us",
    "wall_s",
    "wall_time_s",
    "solve_time_max_us",
    "solve_time_geomean_max_us",
    "host_load",
}
# Columns of cases.csv that are times.
TIMING_COLUMNS = {"solve_geomean_us", "solve_max_us"}


def jobs(runs):
    return [
        ("run", ["run", "--out", "run", "--quiet"]),
        ("launch", ["launch", "--out", "launch"]),
        ("montecarlo", ["montecarlo", "--runs", str(runs), "--seed", "1", "--out", "mc"]),
        ("redteam", ["redteam", "--out", "rt"]),
    ]


def run_build(bindir, home, work, runs):
    work.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, SAFE_CAPTURE_HOME=str(home))
    env.pop("SC_PARTITION_BIN_DIR", None)
    exe = str(Path(bindir).resolve() / "safe-capture")
    for name, args in jobs(runs):
        p = subprocess.run([exe, *args], cwd=work, env=env, capture_output=True, text=True)
        last = (p.stdout.strip().splitlines() or [""])[-1]
        print(f"  {name}: exit {p.returncode}: {last}")
        if p.returncode not in (0, 1):
            sys.exit(f"compare_builds: {exe} {' '.join(args)} failed:\n{p.stderr[-2000:]}")


def strip_keys(v):
    if isinstance(v, dict):
        return {k: strip_keys(x) for k, x in v.items() if k not in TIMING_KEYS}
    if isinstance(v, list):
        return [strip_keys(x) for x in v]
    return v


def strip_columns(text):
    lines = text.splitlines()
    if not lines:
        return lines
    head = lines[0].split(",")
    keep = [i for i, c in enumerate(head) if c not in TIMING_COLUMNS]
    return [",".join(r.split(",")[i] for i in keep if i < len(r.split(","))) for r in lines]


def same(a, b):
    name = a.name
    if name in ("summary.json", "campaign.json"):
        return strip_keys(json.loads(a.read_text())) == strip_keys(json.loads(b.read_text()))
    if name == "cases.csv":
        return strip_columns(a.read_text()) == strip_columns(b.read_text())
    return a.read_bytes() == b.read_bytes()


def files(root):
    out = set()
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = [d for d in dirnames if d not in SKIP_DIRS]
        for f in filenames:
            out.add(Path(dirpath, f).relative_to(root))
    return out


def compare(old, new):
    a, b = files(old), files(new)
    diffs, skipped, compared = [], 0, 0
    for rel in sorted(a | b):
        if rel.name in SKIP_NAMES:
            skipped += 1
            continue
        if rel not in a or rel not in b:
            diffs.append(f"{rel}: only in {'old' if rel in a else 'new'}")
            continue
        compared += 1
        if not same(old / rel, new / rel):
            diffs.append(f"{rel}: differs")
    return diffs, compared, skipped


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--work", type=Path)
    here = Path(__file__).resolve().parent.parent
    ap.add_argument("--old-home", type=Path, default=here)
    ap.add_argument("--new-home", type=Path, default=here)
    ap.add_argument("--runs", type=int, default=100)
    a = ap.parse_args()
    work = a.work or Path(tempfile.mkdtemp(prefix="sc-compare-"))
    for tag, bindir, home in (("old", a.old, a.old_home), ("new", a.new, a.new_home)):
        print(f"compare_builds: {tag} = {bindir}")
        run_build(bindir, home, work / tag, a.runs)
    diffs, compared, skipped = compare(work / "old", work / "new")
    for d in diffs:
        print(f"  DIFF {d}")
    verdict = "identical" if not diffs else f"{len(diffs)} differ"
    print(f"compare_builds: {compared} files compared, {verdict}; {skipped} timing files skipped; outputs in {work}")
    return 0 if not diffs else 1


if __name__ == "__main__":
    sys.exit(main())
