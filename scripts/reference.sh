#!/usr/bin/env bash
# Recomputes the reference solutions in assets/reference/: StVK static equilibria of the three
# paper scenes on Q2 meshes at three levels. "fine" is the reference; "medium" (half the cells
# per direction) estimates the fine level's own discretisation error; "coarse" is re-run by
# every debug test run. About 10 minutes on a 2-core machine.
#
#   bash scripts/reference.sh            # all levels
#   bash scripts/reference.sh coarse     # only the coarse levels
#   bash scripts/reference.sh motion     # only the bending beam's reference motion (≈ 9 minutes)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q
hox="${CARGO_TARGET_DIR:-target}/release/hox"
out=assets/reference
levels="${1:-all}"

run() { # scene level grid
    local scene=$1 level=$2 grid=$3
    echo "reference: $scene $level (q2 $grid)" >&2
    "$hox" static --scene "$scene" --element q2 --grid "$grid" --tolerance 1e-10 --reference none --json \
        | python3 -c "import json,sys; d=json.load(sys.stdin); d.update(scene='$scene', level='$level', element='q2', grid='$grid'); print(json.dumps(d))" \
        > "$out/$scene-$level.json"
}

if [ "$levels" = motion ]; then
    echo "reference: bending motion (q2 16x4x4, Newmark, h = 1/960 s checked against 1/1920 s)" >&2
    cargo run --release -q -p hox-scenes --example reference_motion > "$out/bending-motion.json.new"
    mv "$out/bending-motion.json.new" "$out/bending-motion.json"
    exit 0
fi

run bending coarse 8x2x2
run tension coarse 4x2x2
run torsion coarse 4x2x2
if [ "$levels" = all ]; then
    run bending medium 16x4x4
    run tension medium 12x6x6
    run torsion medium 12x6x6
    run bending fine 32x8x8
    run tension fine 24x12x12
    run torsion fine 24x12x12
fi
