#!/usr/bin/env bash
# Regenerates the Gmsh test meshes in assets/meshes/ and the curved parts in assets/parts/ with
# the gmsh wheel from PyPI (in a venv at $HOX_VENV, default ~/.cache/hox-venv). The meshes are committed: tests and CI do not run this.
# The wheel's libgmsh needs libGLU and a few X libraries, present on the project's machine
# image; on a machine without them (and as root) they are installed with apt.
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${HOX_VENV:-$HOME/.cache/hox-venv}"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install -q "gmsh==4.15.2"
if ! ldconfig -p | grep -q 'libGLU.so.1'; then
    if [ "$(id -u)" = 0 ]; then
        apt-get update -q && apt-get install -y -q libglu1-mesa libxcursor1 libxft2 libxinerama1 libgomp1
    else
        echo "gmsh_meshes: libGLU.so.1 is missing; install libglu1-mesa libxcursor1 libxft2 libxinerama1 (as root)" >&2
        exit 1
    fi
fi
"$venv/bin/python" scripts/gmsh_meshes.py assets/meshes
"$venv/bin/python" scripts/gmsh_parts.py assets/parts
