#!/usr/bin/env bash
# The web build's toolchain (issue #59), installed once; scripts/build-web.sh uses it.
#
# rustup's toolchain here has no wasm32 standard library and cannot fetch one, so the page is
# compiled by Debian's Rust for the web (rustc-web, cargo-web, rust-web-src from
# bookworm-security: /usr/bin/rustc and /usr/bin/cargo beside rustup's, called by path), which
# builds the standard library from source (-Zbuild-std); rust-lld from rustup's toolchain links
# it; wasm-bindgen's command-line tool, at the exact version of the wasm-bindgen crate in
# Cargo.lock, writes the JavaScript glue. The native build stays on rustup's Rust.
#
#   bash scripts/setup-web.sh        # prints the tools' paths when done
set -euo pipefail
cd "$(dirname "$0")/.."

# Debian's Rust for the web: at least the version that builds the workspace's crates.
need=1.96
have=$(/usr/bin/rustc --version 2>/dev/null | awk '{print $2}' || true)
if [ -z "$have" ] || [ "$(printf '%s\n%s\n' "$need" "$have" | sort -V | head -n1)" != "$need" ] \
    || [ ! -d /usr/lib/rustlib/src/rust/library ] || [ ! -x /usr/bin/cargo ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "setup-web: installing rustc-web, cargo-web and rust-web-src (Debian's Rust for the web, >= $need)"
        # the security suite carries the current version; a stale package list offers 1.85 only
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
            rustc-web cargo-web rust-web-src >/dev/null
        have=$(/usr/bin/rustc --version | awk '{print $2}')
    else
        echo "setup-web: the web build needs Debian's rustc-web, cargo-web and rust-web-src >= $need" >&2
        echo "setup-web: install them with: sudo apt-get update && sudo apt-get install -y rustc-web cargo-web rust-web-src" >&2
        exit 1
    fi
fi
if [ "$(printf '%s\n%s\n' "$need" "$have" | sort -V | head -n1)" != "$need" ]; then
    echo "setup-web: /usr/bin/rustc is $have; the web build needs $need or newer (bookworm-security)" >&2
    exit 1
fi
echo "setup-web: /usr/bin/rustc $have OK"

# The linker: rust-lld of rustup's default toolchain.
lld=$(find "$(rustc --print sysroot)/lib/rustlib" -name rust-lld -type f 2>/dev/null | head -n1)
if [ -z "$lld" ]; then
    echo "setup-web: no rust-lld in rustup's toolchain ($(rustc --print sysroot))" >&2
    exit 1
fi
echo "setup-web: linker $lld"

# wasm-bindgen's tool: the exact version of the crate (their formats must match).
version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock)
if [ -z "$version" ]; then
    echo "setup-web: Cargo.lock names no wasm-bindgen" >&2
    exit 1
fi
bindgen="$HOME/.cargo/bin/wasm-bindgen"
if [ "$("$bindgen" --version 2>/dev/null | awk '{print $2}')" != "$version" ]; then
    echo "setup-web: installing wasm-bindgen-cli $version (a few minutes, once)"
    # --locked first; the tool's own lock file may name a dependency the registry mirror lacks
    # (0.2.130's webpki-roots 1.0.11 here), then the newest that fit its requirements
    cargo install --quiet wasm-bindgen-cli --version "=$version" --locked \
        || cargo install --quiet wasm-bindgen-cli --version "=$version"
fi
echo "setup-web: $("$bindgen" --version) OK"
