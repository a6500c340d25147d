#!/usr/bin/env bash
# Prepares a fresh machine for building and testing hox. Idempotent; safe to run again.
# Needs the Rust toolchain (rustc ≥ 1.95); the Debian packages the app's window needs under Xvfb
# (and the Rerun viewer) are installed below when missing.
set -euo pipefail

need_rust="1.95"
if ! command -v cargo >/dev/null 2>&1; then
    echo "setup: cargo not found; install Rust $need_rust or newer (rustup) first" >&2
    exit 1
fi
have=$(rustc --version | awk '{print $2}')
if [ "$(printf '%s\n%s\n' "$need_rust" "$have" | sort -V | head -n1)" != "$need_rust" ]; then
    echo "setup: rustc $have is older than $need_rust" >&2
    exit 1
fi
echo "setup: rustc $have OK"

# Installs the Debian packages named after $2 that are missing (as root), else says how;
# $1 says what they are for.
install_missing() {
    local what="$1"
    shift
    local missing=""
    for p in "$@"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
    done
    if [ -z "$missing" ]; then
        echo "setup: $what: packages present"
    elif [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "setup: installing$missing ($what)"
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing >/dev/null
    else
        echo "setup: $what needs these Debian packages:$missing" >&2
        echo "setup: install them with: sudo apt-get install -y$missing" >&2
    fi
}

# The app's window and its headless screenshots run under Xvfb with Mesa's software OpenGL; the
# stock Rerun viewer needs Vulkan (lavapipe). Building needs none of these: all GUI libraries
# are loaded at run time. Installed once, as root, from Debian's packages.
install_missing "the app's window" xvfb xauth libgl1 libegl1 libgl1-mesa-dri mesa-vulkan-drivers libvulkan1 \
    libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6

# The browser tests (app/tests/web.rs: what `--serve-web` and `hox serve` show, seen in a real
# browser) use Debian's Chromium, headless with software WebGL (SwiftShader, built in), and
# python3 (scripts/browser_shot.py: the standard library only).
install_missing "the browser tests" chromium fonts-liberation python3

# The Python tests make a part hox does not ship with Gmsh (python/tests/test_parts.py, issue
# #61): the gmsh wheel from PyPI loads libGLU and a few X libraries at import.
install_missing "Gmsh's library" libglu1-mesa libxft2 libxinerama1 libgomp1

# The PositionBasedDynamics table of docs/PERFORMANCE.md (bench/pbd_peer.py, checked by
# app/tests/doc_tables.rs) installs pypbd from PyPI into bench/.venv: a virtualenv needs venv.
install_missing "the peer benchmark" python3-venv
