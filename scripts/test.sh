#!/usr/bin/env bash
# The project's test command (README, CI): set-up, fresh Pinocchio reference data, then
# every Rust test of the workspace.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
mkdir -p tests/reference
scripts/.venv/bin/python scripts/pinocchio_reference.py
# the partition's Python partner controller and the interop tests find the venv here
export SC_PYTHON="$PWD/scripts/.venv/bin/python"
cargo test --workspace --no-fail-fast "$@"
