#!/usr/bin/env bash
# One-time (idempotent) set-up of everything the project needs besides the Rust toolchain:
# a Python venv with the independent reference tools (Pinocchio) and the iceoryx2 wheel
# used by the Python partner controller, and a system font for PNG/PDF figures (Debian's
# fonts-dejavu-core, only when the machine has none). Safe to run repeatedly.
#
#   scripts/setup.sh                   the lean set-up every test needs
#   scripts/setup.sh --with-basilisk   also Basilisk (bsk, ~600 MB): `safe-capture run
#                                      --basilisk` and scripts/basilisk_reference.py
#                                      (scripts/test.sh installs it: its test needs it)
#   scripts/setup.sh --with-slurm      also Slurm and munge from Debian's packages
#                                      (slurm-wlm, munge; as root): the test against a
#                                      running single-node Slurm (scripts/slurm/local_cluster.sh)
#   scripts/setup.sh --with-netns      also iproute2, util-linux, procps (ip, unshare, nsenter, sysctl; as
#                                      root): two hosts on this machine (scripts/two_hosts.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
WITH_BASILISK=0
WITH_SLURM=0
WITH_NETNS=0
for arg in "$@"; do
  case "$arg" in
    --with-basilisk) WITH_BASILISK=1 ;;
    --with-slurm) WITH_SLURM=1 ;;
    --with-netns) WITH_NETNS=1 ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "setup: unknown option $arg (see --help)" >&2; exit 2 ;;
  esac
done
# A font for the figures' text in PNG and PDF (--figure-format; SVG needs none): Debian's
# DejaVu when the machine has no TrueType/OpenType font at all.
has_font() {
  find /usr/share/fonts /usr/local/share/fonts "$HOME/.local/share/fonts" \
    \( -name '*.ttf' -o -name '*.otf' -o -name '*.ttc' \) -print -quit 2>/dev/null | grep -q .
}
if ! has_font; then
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    echo "setup: no system font for PNG/PDF figures; installing fonts-dejavu-core"
    apt-get install -y -qq fonts-dejavu-core >/dev/null 2>&1 \
      || { apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq fonts-dejavu-core >/dev/null; }
  else
    echo "setup: no system font for PNG/PDF figures (SVG needs none); install one, e.g. sudo apt-get install fonts-dejavu-core" >&2
  fi
fi
if [ "$WITH_SLURM" = 1 ] && ! { command -v slurmctld && command -v slurmd && command -v munged; } >/dev/null; then
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    echo "setup: installing Slurm and munge (Debian's slurm-wlm, munge)"
    apt-get update -qq >/dev/null
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
  else
    echo "setup: --with-slurm needs Debian's slurm-wlm and munge: sudo apt-get install slurm-wlm munge" >&2
    exit 1
  fi
fi
if [ "$WITH_NETNS" = 1 ] && ! { command -v ip && command -v unshare && command -v nsenter \
    && command -v mountpoint && command -v sysctl; } >/dev/null; then
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    echo "setup: installing iproute2, util-linux and procps (two hosts on one machine)"
    apt-get update -qq >/dev/null
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq iproute2 util-linux procps >/dev/null
  else
    echo "setup: --with-netns needs root with Debian's iproute2, util-linux and procps" >&2
    exit 1
  fi
fi
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
if [ "$WITH_BASILISK" = 1 ]; then
  bstamp="$VENV/.requirements-basilisk.sha"
  bwant=$(sha256sum scripts/requirements-basilisk.txt | cut -d' ' -f1)
  if [ "$(cat "$bstamp" 2>/dev/null || true)" != "$bwant" ]; then
    "$VENV/bin/pip" install --quiet --disable-pip-version-check -r scripts/requirements-basilisk.txt
    echo "$bwant" > "$bstamp"
  fi
  echo "setup: Basilisk $("$VENV/bin/python" -c 'import Basilisk; print(Basilisk.__version__)') in $VENV"
fi
echo "setup: python venv ready at $VENV ($("$VENV/bin/python" -c 'import pinocchio, iceoryx2; print("pinocchio", pinocchio.__version__)'))"
