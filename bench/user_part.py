#!/usr/bin/env python3
"""A user's own part with no solver flag (issue #61): the L-shaped bracket of
scripts/gmsh_bracket.py made by Gmsh at two sizes (P2, about 5,000 and 12,000 nodes), then, as a
new user runs it, `hox simulate --mesh PART --clamp clamp --settle --json` on one and on two
threads in turn (A B A B …, so each ratio is measured in one run), `hox static` of the same part
(the settled tip against it) and, on the smaller part, `--solver vbd` once.

    python3 bench/user_part.py [--runs 3] [--frames N] [--hox PATH]

Prints the machine line and a markdown table (docs/PERFORMANCE.md holds it between generated
markers: `python3 scripts/docs_tables.py` rewrites it, `cargo test -p hox --test doc_tables`
checks its format): per part and thread count the median over the runs of the median and 95th
percentile ms per frame, the wall-clock seconds to settle, the factorisations, the policy Newton
chose and the settled tip's distance from `hox static`'s; the two-thread row's last column is one
thread's ms per frame over two threads' (the median over the pairs of runs). Installs gmsh into
bench/.venv on first use. `--frames N` runs N frames once instead of settling (the table's
format, checked by `cargo test -p hox --test doc_tables`). `hox` is --hox, else $HOX_BIN, else the release binary under
$CARGO_TARGET_DIR (built if missing).
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
from hox_binary import hox_binary  # noqa: E402

VENV = ROOT / "bench" / ".venv"
PARTS = [("bracket ~5k", 0.014), ("bracket ~12k", 0.0097)]


def gmsh_python() -> str:
    python = VENV / "bin" / "python"
    if not python.exists():
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    if subprocess.run([str(python), "-c", "import gmsh"], capture_output=True).returncode != 0:
        subprocess.run([str(python), "-m", "pip", "install", "--quiet", "gmsh==4.15.2"], check=True)
    return str(python)


def hox_json(hox: str, args: list, threads: int) -> dict:
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    out = subprocess.run([hox, *args, "--json"], cwd=ROOT, env=env, check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def machine() -> str:
    name = "unknown CPU"
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            name = line.split(":", 1)[1].strip()
            break
    return f'Machine: "{name}", {os.cpu_count()} logical cores.'


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--frames", type=int, help="N frames once instead of settling (a format check)")
    parser.add_argument("--hox")
    args = parser.parse_args()
    if args.frames:
        args.runs = 1
    settle = ["--seconds", f"{args.frames / 60}"] if args.frames else ["--settle"]
    hox = hox_binary(args.hox)
    python = gmsh_python()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, size in PARTS:
            mesh = Path(tmp) / f"bracket-{size}.msh"
            subprocess.run([python, str(ROOT / "scripts" / "gmsh_bracket.py"), str(mesh), "--size", str(size)],
                           check=True, capture_output=True)
            part = ["--mesh", str(mesh), "--clamp", "clamp"]
            nodes = hox_json(hox, ["mesh", *part], 1)["nodes"]
            tip = hox_json(hox, ["static", *part], 1)["groups"]["tip"]
            runs = {1: [], 2: []}
            for _ in range(args.runs):
                for threads in (1, 2):
                    runs[threads].append(hox_json(hox, ["simulate", *part, *settle], threads))
            solvers = [("newton (default)", t, runs[t]) for t in (1, 2)]
            if size == PARTS[0][1]:
                solvers.append(("vbd", 1, [hox_json(hox, ["simulate", *part, *settle, "--solver", "vbd"], 1)]))
            for solver, threads, done in solvers:
                med = lambda key: statistics.median(r[key] for r in done)  # noqa: E731
                off = statistics.median(math.dist(r["groups"]["tip"], tip) / math.hypot(*tip) for r in done)
                ratio = "–"
                if solver.startswith("newton") and threads == 2:
                    pairs = [a["ms_per_frame"] / b["ms_per_frame"] for a, b in zip(runs[1], runs[2])]
                    ratio = f"{statistics.median(pairs):.2f}×"
                policy = done[-1]["newton_policy"] or "–"
                settled = args.frames or all(r["settled"] for r in done)
                rows.append(
                    f"| {label} | {nodes} | {solver} | {threads} | {len(done)} | {med('ms_per_frame'):.2f} | "
                    f"{med('ms_per_frame_p95'):.2f} | {med('wall_secs'):.2f}{'' if settled else ' (not settled)'} | "
                    f"{med('frames'):.0f} | {med('factorizations'):.0f} | {policy} | {100 * off:.3f} % | {ratio} |"
                )
    print(machine())
    print()
    print("| part | nodes | solver | threads | runs | ms/frame | p95 ms/frame | seconds to settle | frames | "
          "factorisations | Newton's policy | settled tip off `hox static` | speed-up over 1 thread |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        print(row)


if __name__ == "__main__":
    main()
