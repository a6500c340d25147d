#!/usr/bin/env bash
# Builds hox for the browser (issue #59): the app compiled to WebAssembly with the toolchain
# scripts/setup-web.sh installs, its JavaScript glue (wasm-bindgen) and the page (app/web/
# index.html), into one folder any static web server serves, with the references every lesson
# and the app's readouts show (references/, written by the native `hox lesson --references-to`,
# so a lesson's errors show at once; any other physics the page computes in a Web Worker).
# `hox serve-app` serves it to a classroom; the sizes printed are the ones docs/WEB.md quotes.
#
#   bash scripts/build-web.sh [SITE_DIR]     # default: site/ in the repository
#   bash scripts/build-web.sh --open         # and serve it here (`hox serve-app`; a browser opened
#                                            # on its address where xdg-open finds one)
#   bash scripts/build-web.sh --no-references  # without references/ (the page computes them)
set -euo pipefail
cd "$(dirname "$0")/.."
open=0
references=1
site=site
for a in "$@"; do
    case "$a" in
        --open) open=1 ;;
        --no-references) references=0 ;;
        -h|--help) sed -n 2,11p "$0"; exit 0 ;;
        *) site="$a" ;;
    esac
done
bash scripts/setup-web.sh >/dev/null
lld=$(find "$(rustc --print sysroot)/lib/rustlib" -name rust-lld -type f | head -n1)
target="${HOX_WEB_TARGET_DIR:-$HOME/.cache/hox-web-target}"
start=$(date +%s)
# wasm's 128-bit SIMD (every browser of the last years runs it); no debug information in the page
RUSTFLAGS="-C target-feature=+simd128" RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1 \
    CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER="$lld" \
    CARGO_PROFILE_RELEASE_DEBUG=false CARGO_PROFILE_RELEASE_STRIP=debuginfo \
    /usr/bin/cargo build --release -p hox --bin hox --target wasm32-unknown-unknown \
    -Zbuild-std=std,panic_abort --target-dir "$target"
mkdir -p "$site"
"$HOME/.cargo/bin/wasm-bindgen" --target web --no-typescript --out-dir "$site" --out-name hox \
    "$target/wasm32-unknown-unknown/release/hox.wasm"
cp app/web/index.html app/web/worker.js "$site/"
wasm="$site/hox_bg.wasm"
bytes=$(stat -c %s "$wasm")
# the gzipped copy `hox serve-app` sends to browsers that accept it
gzip -9 -k -f "$wasm"
gz=$(stat -c %s "$wasm.gz")
# every lesson's computed references, by the native binary as `hox lesson` computes them (each
# once per machine: the user's cache, ~/.cache/hox, keeps them): $HOX_BIN (the tests' build),
# else the release build
if [ "$references" = 1 ]; then
    if [ -n "${HOX_BIN:-}" ]; then
        hox="$HOX_BIN"
    else
        cargo build --release -p hox --bin hox
        hox="${CARGO_TARGET_DIR:-$PWD/target}/release/hox"
    fi
    refs_start=$(date +%s)
    for lesson in $("$hox" lessons --json | python3 -c 'import json, sys; print(" ".join(l["name"] for l in json.load(sys.stdin)))'); do
        "$hox" lesson "$lesson" --json --references-to "$site/references" >/dev/null
    done
    echo "build-web: $site/references: $(find "$site/references" -name '*.json' | wc -l) references of the lessons, $(( $(date +%s) - refs_start )) s"
fi
echo "build-web: $site: hox_bg.wasm $(( bytes / 1024 )) KiB ($(( gz / 1024 )) KiB gzipped), built in $(( $(date +%s) - start )) s"
if [ "$open" = 1 ]; then
    echo "build-web: serving $site (Ctrl-C stops)"
    if command -v xdg-open >/dev/null 2>&1 && [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
        (sleep 3 && xdg-open "http://127.0.0.1:9090/" >/dev/null 2>&1) &
    fi
    exec cargo run --release -p hox -- serve-app --site "$site"
fi
