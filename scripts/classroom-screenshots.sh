#!/usr/bin/env bash
# The screenshots of docs/APP.md's "A classroom session" (issue #35): the states the UI test
# `a_classroom_session_at_projector_and_full_hd_sizes` checks, shown by the release app under Xvfb
# with software OpenGL, at a projector's 1280×720 and at 1920×1080, from a fresh home and an
# empty reference cache. Usage: scripts/classroom-screenshots.sh [OUT_DIR] (default docs/images).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-docs/images}"
mkdir -p "$out"
hox="${CARGO_TARGET_DIR:-$HOME/.cache/hox-target}/release/hox"
[ -x "$hox" ] || cargo build --release
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT
shot() { # NAME SCREEN SECONDS ARGS...
    local name=$1 screen=$2 secs=$3
    shift 3
    local w=${screen%x*} h=${screen#*x}
    rm -rf "$home/cache"
    HOME="$home" HOX_CACHE_DIR="$home/cache" xvfb-run -a -s "-screen 0 ${screen}x24" \
        "$hox" app --fresh --size "$((w - 16))x$((h - 40))" --screenshot "$out/$name.png" --after-secs "$secs" "$@"
}
# ν = 0.49 typed on the default comparison: a provisional reference within seconds
shot classroom-1280-nu-049 1280x720 6 --compare element=p1,refine=1 --compare element=p2 --poisson 0.49
# a lesson step ended at its simulated time, with the numbers `hox lesson` prints
shot classroom-1280-lesson 1280x720 5 --lesson why-high-order
# presenter mode: the caption below the view, short labels, the lesson's parameters
shot classroom-1280-presenter 1280x720 4 --lesson locking --presenter
# Full HD: Newton against XPBD, the solver's effect on the motion said under it
shot classroom-1920-newton 1920x1080 5 --compare element=p1,refine=1,solver=newton,integrator=euler --compare element=p2 --play
# The second round (issue #57), the states `the_second_round_classroom_session_replays_at_both_sizes`
# replays: a lesson's labels showing the step's measurement as its panel does, at both sizes;
# presenter mode with the step's explanation; a static step solved at its own values.
shot classroom2-1280-lesson-labels 1280x720 6 --lesson accuracy-cost
shot classroom2-1280-presenter 1280x720 5 --lesson locking --lesson-step 2 --presenter
shot classroom2-1920-static 1920x1080 5 --lesson locking --lesson-step 2
shot classroom2-1920-presenter 1920x1080 6 --lesson why-high-order --lesson-step 3 --presenter
