#!/usr/bin/env python3
"""What calling hox from Python costs (issue #60): the P2 160 bending beam stepped from Python one
frame per call (`Simulation.step(1)`, the interpreter released and taken back each frame) against
the same frames stepped in one loop in Rust (`Simulation.step_in_rust`), side by side: two
simulations of the same scene from rest, each round one of them steps 60 frames one way and the
other the same 60 frames the other way, the two ways taking turns first; the figure is the median
round of each. Then reading the positions of a 16k-node mesh (P2 32×8×8 bending: a view, no copy)
and copying them.

    python3 python/bench/overhead.py [--frames 60] [--rounds 15]

Prints a Markdown table with the machine line (docs/PYTHON.md; scripts/docs_tables.py runs it).
Runs in the Python package's virtual environment (python/.venv, or $HOX_PYTHON_VENV: made by
scripts/setup-python.sh), re-starting itself there when started by another Python.
"""

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def in_venv() -> None:
    """Re-runs this script in the package's virtual environment unless `hox` imports here."""
    try:
        import hox  # noqa: F401
    except ImportError:
        venv = Path(os.environ.get("HOX_PYTHON_VENV", ROOT / "python" / ".venv"))
        python = venv / "bin" / "python"
        if not python.exists() or os.environ.get("HOX_OVERHEAD_REEXEC"):
            sys.exit(f"overhead.py: the hox package is not installed (run: bash scripts/setup-python.sh)")
        env = dict(os.environ, HOX_OVERHEAD_REEXEC="1")
        sys.exit(subprocess.run([str(python), __file__, *sys.argv[1:]], env=env).returncode)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=60, help="frames per round (default 60)")
    parser.add_argument("--rounds", type=int, default=15, help="rounds of each way (default 15)")
    args = parser.parse_args()
    if args.frames < 1 or args.rounds < 1:
        sys.exit("overhead.py: --frames and --rounds must be at least 1")
    in_venv()
    import hox

    scene = hox.Scene.builtin("bending").with_params(element="p2")
    one_call, in_rust = hox.Simulation(scene), hox.Simulation(scene)
    python_ms, rust_ms = [], []
    for r in range(args.rounds):
        def from_python():
            t = time.perf_counter()
            for _ in range(args.frames):
                one_call.step(1)
            python_ms.append((time.perf_counter() - t) * 1e3 / args.frames)

        def from_rust():
            t = time.perf_counter()
            in_rust.step_in_rust(args.frames)
            rust_ms.append((time.perf_counter() - t) * 1e3 / args.frames)

        for way in ((from_python, from_rust) if r % 2 == 0 else (from_rust, from_python)):
            way()
    assert one_call.probes == in_rust.probes, "the two ways step the same frames"
    p, q = statistics.median(python_ms), statistics.median(rust_ms)

    big = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2", grid=(32, 8, 8)))
    big.step(1)

    def median_us(read, times=200):
        rounds = []
        for _ in range(times):
            t = time.perf_counter()
            read()
            rounds.append((time.perf_counter() - t) * 1e6)
        return statistics.median(rounds)

    view = median_us(lambda: big.positions)
    copy = median_us(lambda: big.positions.copy())
    print(f"Machine: {hox.machine()}.")
    print()
    print("| P2 160 bending, one frame | ms per frame | against Rust |")
    print("|---|---|---|")
    print(f"| stepped in one Rust loop (`step_in_rust({args.frames})`) | {q:.3f} | 1.000 |")
    print(f"| from Python, one call per frame (`step(1)`) | {p:.3f} | {p / q:.3f} |")
    print()
    print(f"| reading the positions of P2 32x8x8 ({big.num_nodes} nodes) | µs |")
    print("|---|---|")
    print(f"| `sim.positions` (a read-only view) | {view:.1f} |")
    print(f"| `sim.positions.copy()` | {copy:.1f} |")


if __name__ == "__main__":
    main()
