"""Shared helpers of the Python package's tests."""

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def hox_binary():
    """The `hox` command line to compare with: $HOX_BIN, else the workspace's release build,
    else its debug build (what .ci/run's tests just made), else `hox` on PATH."""
    if os.environ.get("HOX_BIN"):
        return os.environ["HOX_BIN"]
    target = Path(os.environ.get("CARGO_TARGET_DIR", Path.home() / ".cache/hox-target"))
    for build in ("release", "debug"):
        if (target / build / "hox").exists():
            return str(target / build / "hox")
    return shutil.which("hox") or pytest.skip("no hox binary (cargo build -p hox, or $HOX_BIN)")
