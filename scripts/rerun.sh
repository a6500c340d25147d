#!/usr/bin/env bash
# The Rerun viewer and CLI that match hox's recordings: rerun-sdk 0.36.3 from PyPI, installed
# once into a virtualenv under ~/.cache (no system changes). Usage:
#   scripts/rerun.sh recording.rrd          # play a recording (needs a display)
#   scripts/rerun.sh                        # an empty viewer; `hox` can then stream to it
#   scripts/rerun.sh rrd verify FILE.rrd    # any `rerun` CLI command, e.g. verify or stats
set -euo pipefail
version=0.36.3
venv="${HOX_RERUN_VENV:-$HOME/.cache/hox-rerun-$version}"
if [ ! -x "$venv/bin/rerun" ]; then
    echo "rerun.sh: installing rerun-sdk==$version into $venv" >&2
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --disable-pip-version-check "rerun-sdk==$version"
fi
exec "$venv/bin/rerun" "$@"
