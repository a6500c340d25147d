#!/usr/bin/env bash
# A screenshot of a recording as a user sees it: the stock Rerun viewer 0.36.3 (scripts/rerun.sh)
# opens FILE.rrd with the layout the file carries, in a virtual X display (Xvfb, Mesa's Vulkan
# lavapipe), and writes OUT.png with its own --screenshot-to. The virtual screen is larger than
# the window so the pointer (at the screen's centre) hovers nothing.
#   scripts/rerun-screenshot.sh FILE.rrd OUT.png [WIDTHxHEIGHT]
set -euo pipefail
cd "$(dirname "$0")/.."
file="$1"
out="$2"
size="${3:-1600x900}"
bash scripts/setup.sh >/dev/null
bash scripts/rerun.sh --version >/dev/null
exec xvfb-run -a -s "-screen 0 3840x2400x24 -fakescreenfps 30" \
    bash scripts/rerun.sh "$file" --window-size "$size" --screenshot-to "$out"
