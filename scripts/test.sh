#!/usr/bin/env bash
# The project's test command (README, CI): set-up (with Basilisk and Slurm), fresh Pinocchio reference
# data, then every Rust test of the workspace.
set -euo pipefail
cd "$(dirname "$0")/.."
# Basilisk too: the closed-loop cross-check (apps/safe-capture/tests/basilisk.rs) must run
# Slurm and munge from Debian's packages: the test against a running single-node Slurm
# (apps/safe-capture/tests/slurm.rs) starts and stops its own cluster
# (as root with apt, as in CI; elsewhere that test says why it is skipped);
# as root, two network namespaces for the partition across hosts (apps/link/tests/across_hosts.rs)
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
  scripts/setup.sh --with-basilisk --with-slurm --with-netns
  export SC_REQUIRE_SLURM=1 SC_REQUIRE_NETNS=1
else
  scripts/setup.sh --with-basilisk
  echo "test.sh: not root with apt: the test against a running Slurm is skipped"
fi
export SC_REQUIRE_BASILISK=1
mkdir -p tests/reference
scripts/.venv/bin/python scripts/pinocchio_reference.py
# the partition's Python partner controller and the interop tests find the venv here
export SC_PYTHON="$PWD/scripts/.venv/bin/python"
# the disk the build writes to: a full one kills the linker (SIGBUS), say how much there was
echo "test.sh: $(df -h --output=avail . | tail -1 | tr -d ' ') free on the disk of $PWD before cargo test"
started=$(date +%s)
status=0
cargo test --workspace --no-fail-fast "$@" || status=$?
elapsed=$(( $(date +%s) - started ))
if [ "$status" = 0 ]; then
  echo "test.sh: every test passed (cargo test: ${elapsed} s)"
else
  echo "test.sh: FAILED, exit $status (cargo test: ${elapsed} s); the failing tests are listed above"
fi
exit "$status"
