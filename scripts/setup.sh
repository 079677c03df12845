#!/usr/bin/env bash
# One-time (idempotent) set-up of everything the project needs besides the Rust toolchain:
# a Python venv with the independent reference tools (Pinocchio) and the iceoryx2 wheel
# used by the Python partner controller. Safe to run repeatedly.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=scripts/.venv
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV"
fi
stamp="$VENV/.requirements.sha"
want=$(sha256sum scripts/requirements.txt | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null || true)" != "$want" ]; then
  "$VENV/bin/pip" install --quiet --disable-pip-version-check -r scripts/requirements.txt
  echo "$want" > "$stamp"
fi
echo "setup: python venv ready at $VENV ($("$VENV/bin/python" -c 'import pinocchio, iceoryx2; print("pinocchio", pinocchio.__version__)'))"
