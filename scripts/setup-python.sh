#!/usr/bin/env bash
# hox's Python package (issue #60) into a virtual environment: the package built from this
# checkout (python/: the pyo3 extension `hox._hox` by maturin) with numpy, and what its tests and
# notebooks use (pytest, Dask's distributed, meshio, matplotlib, pandas, nbclient and a kernel).
# Idempotent; run it again after changing the Rust.
#
#   bash scripts/setup-python.sh            # python/.venv (or $HOX_PYTHON_VENV), release build
#   python/.venv/bin/python -m pytest python/tests
#
# HOX_PYTHON_PROFILE=dev builds the extension in the workspace's dev profile (hox-sim optimised
# there too): with CARGO_TARGET_DIR shared with `cargo test --workspace`, as .ci/run does, it
# reuses that build's hox-sim and hox-scenes instead of compiling them again in release.
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${HOX_PYTHON_VENV:-python/.venv}"
profile="${HOX_PYTHON_PROFILE:-release}"
case "$profile" in
    release) profile_flag=(--release) ;;
    dev) profile_flag=() ;;
    *) echo "setup-python: HOX_PYTHON_PROFILE must be release or dev, not \"$profile\"" >&2; exit 2 ;;
esac
if ! python3 -c 'import sys; sys.exit(sys.version_info < (3, 10))' 2>/dev/null; then
    echo "setup-python: hox's Python package needs Python 3.10 or newer; python3 is $(python3 --version 2>&1)" >&2
    exit 1
fi
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
start=$(date +%s)
"$venv/bin/python" -m pip install -q --disable-pip-version-check -r python/requirements-dev.txt
echo "setup-python: dependencies installed ($(( $(date +%s) - start )) s)"
start=$(date +%s)
VIRTUAL_ENV="$(cd "$venv" && pwd)" PATH="$venv/bin:$PATH" \
    "$venv/bin/maturin" develop "${profile_flag[@]}" --manifest-path python/Cargo.toml --quiet
echo "setup-python: hox installed into $venv, $profile build ($(( $(date +%s) - start )) s); tests: $venv/bin/python -m pytest python/tests"
