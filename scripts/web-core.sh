#!/usr/bin/env bash
# Builds the simulation core (hox-sim, hox-scenes) for the browser, wasm32-unknown-unknown, with
# the toolchain scripts/setup-web.sh installs (Debian's Rust for the web, the standard library
# built from source, rustup's rust-lld): the code the app in the page runs (issue #59). A native-
# only call in the core (std's `Instant`, a thread, an x86 intrinsic outside its gate) fails here.
#
#   bash scripts/web-core.sh         # target directory: $HOX_WEB_TARGET_DIR or ~/.cache/hox-web-target
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-web.sh
lld=$(find "$(rustc --print sysroot)/lib/rustlib" -name rust-lld -type f | head -n1)
target="${HOX_WEB_TARGET_DIR:-$HOME/.cache/hox-web-target}"
# wasm's 128-bit SIMD: every browser of the last years runs it
RUSTFLAGS="-C target-feature=+simd128" RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1 \
    CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER="$lld" \
    /usr/bin/cargo build --release -p hox-sim -p hox-scenes --target wasm32-unknown-unknown \
    -Zbuild-std=std,panic_abort --target-dir "$target"
echo "web-core: hox-sim and hox-scenes build for wasm32-unknown-unknown"
