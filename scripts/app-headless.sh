#!/usr/bin/env bash
# Runs the app in a virtual X display (Xvfb, Mesa's software OpenGL): no monitor, no GPU.
# Used for the README's screenshot and the frame-rate figure in docs/APP.md:
#   scripts/app-headless.sh --screenshot docs/app.png --after-secs 4 --play
#   scripts/app-headless.sh --measure-secs 10
# Any `hox app` option may be given; --fresh (ignore saved settings) is always added.
# The virtual screen is 1920x1200 unless HOX_XVFB_SCREEN (e.g. 2560x1440x24) says otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
cargo build --release -q -p hox
target="${CARGO_TARGET_DIR:-target}"
exec xvfb-run -a -s "-screen 0 ${HOX_XVFB_SCREEN:-1920x1200x24}" "$target/release/hox" app --fresh "$@"
