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
rm -f "$out"
# the viewer 0.36.3 panics while quitting after the screenshot ("Failed to take store hub"):
# the file it wrote is what counts
xvfb-run -a -s "-screen 0 3840x2400x24 -fakescreenfps 30" \
    bash scripts/rerun.sh "$file" --window-size "$size" --screenshot-to "$out" || true
if [ ! -s "$out" ]; then
    echo "rerun-screenshot: the viewer wrote no screenshot" >&2
    exit 1
fi
# the viewer writes at two pixels per point; the docs keep one (a quarter of the bytes)
venv="${HOX_RERUN_VENV:-$HOME/.cache/hox-rerun-0.36.3}"
"$venv/bin/python" -c "import PIL" 2>/dev/null || "$venv/bin/pip" install --quiet --disable-pip-version-check pillow
"$venv/bin/python" - "$out" "$size" <<'PY'
import sys
from PIL import Image
path, size = sys.argv[1], sys.argv[2]
w, h = (int(v) for v in size.split("x"))
image = Image.open(path)
if image.size != (w, h):
    image.resize((w, h), Image.LANCZOS).save(path, optimize=True)
PY
