#!/usr/bin/env bash
# Prepares a fresh machine for building and testing hox. Idempotent; safe to run again.
# The simulation core needs only the Rust toolchain (rustc ≥ 1.95); later parts (the app's
# window under Xvfb, the Rerun viewer) add their Debian packages here.
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
