"""The hox binary a script of the project runs: --hox, else $HOX_BIN (what `cargo test` and
scripts/docs_tables.py pass), else the release build under $CARGO_TARGET_DIR, built if missing
(HOX_CARGO="flock /tmp/hox-cargo.lock cargo" where builds must take turns)."""
import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def hox_binary(given=None) -> str:
    if given or os.environ.get("HOX_BIN"):
        return given or os.environ["HOX_BIN"]
    target = Path(os.environ.get("CARGO_TARGET_DIR", Path.home() / ".cache/hox-target"))
    hox = target / "release" / "hox"
    if not hox.exists():
        cargo = os.environ.get("HOX_CARGO", "cargo").split()
        subprocess.run(cargo + ["build", "--release", "-p", "hox"], cwd=ROOT, check=True)
    return str(hox)
