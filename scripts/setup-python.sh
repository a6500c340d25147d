#!/usr/bin/env bash
# hox's Python package (issue #60) into a virtual environment: the package built from this
# checkout (python/: the pyo3 extension `hox._hox` by maturin, in release) with numpy, and what
# its tests use (pytest, Dask's distributed). Idempotent; run it again after changing the Rust.
#
#   bash scripts/setup-python.sh            # python/.venv (or $HOX_PYTHON_VENV)
#   python/.venv/bin/python -m pytest python/tests
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${HOX_PYTHON_VENV:-python/.venv}"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check "maturin>=1.9,<2" "numpy>=1.24" "pytest>=8" "distributed>=2024.1"
start=$(date +%s)
VIRTUAL_ENV="$(cd "$venv" && pwd)" PATH="$venv/bin:$PATH" \
    "$venv/bin/maturin" develop --release --manifest-path python/Cargo.toml --quiet
echo "setup-python: hox installed into $venv ($(( $(date +%s) - start )) s); tests: $venv/bin/python -m pytest python/tests"
