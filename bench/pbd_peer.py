#!/usr/bin/env python3
"""Side by side with Jan Bender's PositionBasedDynamics (pypbd): its FEM tetrahedra on the same
three P1 beams as `hox bench` (the paper's Table 1 bending beam: 2 x 0.5 x 0.5 m, clamped at
x = 0, gravity, 50 substeps x 1 iteration per 1/60 s frame), timed, then `hox`'s own timing of
the same beams run right after, so the ratio is measured in one run.

    python3 bench/pbd_peer.py [--frames 20] [--method 3]

(set HOX_CARGO="flock /tmp/hox-cargo.lock cargo" where builds must take turns).

Installs pypbd into bench/.venv (a virtualenv) on first use. The meshes come from hox itself
(`cargo run --release -p hox-scenes --example beam_mesh -- LABEL`), so both solve identical meshes.
PBD's solid method 3 is its XPBD FEM tetrahedron (the constitutive model of Bender et al.
2014 / PBD's `FEMTetConstraint`): one constraint per tetrahedron, like hox's energy
formulation; stiffness is Young's modulus, 3 MPa, Poisson ratio 0.35. Times are medians of ms
per frame on one thread (PBD's OpenMP loop is limited with OMP_NUM_THREADS=1); hox is timed
with both of its sweeps: colour (the default: a register of same-colour tetrahedra at a time,
`Sweep::Colour`) at each register width the CPU runs (8 lanes on AVX-512, the default there; 4
on AVX2) and element order (`Sweep::Element`, the order before issue #22).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VENV = ROOT / "bench" / ".venv"
BEAMS = ["P1 16x4x4", "P1 16x4x4 r1", "P1 16x4x4 r2"]


def ensure_venv() -> Path:
    python = VENV / "bin" / "python"
    if not python.exists():
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    probe = subprocess.run([str(python), "-c", "import pypbd, numpy"], capture_output=True)
    if probe.returncode != 0:
        subprocess.run([str(python), "-m", "pip", "install", "--quiet", "pypbd", "numpy"], check=True)
    return python


def cargo() -> list:
    """The cargo command (HOX_CARGO, e.g. "flock /tmp/hox-cargo.lock cargo" on a shared machine)."""
    return os.environ.get("HOX_CARGO", "cargo").split()


def beam_mesh(label: str) -> dict:
    out = subprocess.run(
        cargo() + ["run", "--quiet", "--release", "-p", "hox-scenes", "--example", "beam_mesh", "--", label],
        cwd=ROOT, check=True, capture_output=True, text=True,
    ).stdout
    return json.loads(out)


def time_pbd(mesh: dict, frames: int, method: int) -> float:
    """Runs inside the virtualenv: ms per frame (median) of PBD's solid method on the mesh."""
    import pypbd as pbd

    sim = pbd.Simulation.getCurrent()
    sim.initDefault()
    model = sim.getModel()
    tet_model = model.addTetModel(mesh["positions_m"], mesh["tets"], testMesh=False)
    particles = model.getParticles()
    rho = 1000.0
    # lumped masses: a quarter of each tetrahedron's mass to each of its nodes
    pos = mesh["positions_m"]
    tets = mesh["tets"]
    masses = [0.0] * len(pos)
    for t in range(0, len(tets), 4):
        a, b, c, d = (pos[i] for i in tets[t:t + 4])
        u = [b[k] - a[k] for k in range(3)]
        v = [c[k] - a[k] for k in range(3)]
        w = [d[k] - a[k] for k in range(3)]
        vol = abs(u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0])) / 6.0
        for i in tets[t:t + 4]:
            masses[i] += rho * vol / 4.0
    for i, m in enumerate(masses):
        particles.setMass(i, m)
    for i in mesh["clamped"]:
        particles.setMass(int(i), 0.0)
    model.addSolidConstraints(tet_model, method, 3.0e6, 0.35, 3.0e6, False, False)
    ts = sim.getTimeStep()
    ts.setValueUInt(pbd.TimeStepController.NUM_SUB_STEPS, 50)
    ts.setValueUInt(pbd.TimeStepController.MAX_ITERATIONS, 1)
    ts.setValueUInt(pbd.TimeStepController.MAX_ITERATIONS_V, 0)
    pbd.TimeManager.getCurrent().setTimeStepSize(1.0 / 60.0)
    for _ in range(5):
        ts.step(model)
    times_ms = []
    for _ in range(frames):
        start = time.perf_counter()
        ts.step(model)
        times_ms.append((time.perf_counter() - start) * 1e3)
    return statistics.median(times_ms)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--method", type=int, default=3, help="PBD solid method (3: XPBD FEM tetrahedra)")
    parser.add_argument("--hox", default="run --quiet --release -p hox-scenes --example bench_table --",
                        help="cargo arguments that print the hox bench table for FRAMES THREADS FILTER")
    parser.add_argument("--inner", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.inner:
        mesh = json.loads(Path(args.inner).read_text())
        print(json.dumps({"ms_per_frame": time_pbd(mesh, args.frames, args.method)}))
        return
    python = ensure_venv()
    env = dict(os.environ, OMP_NUM_THREADS="1")
    rows = []
    for label in BEAMS:
        mesh = beam_mesh(label)
        path = VENV / f"mesh-{label.replace(' ', '_')}.json"
        path.write_text(json.dumps(mesh))
        out = subprocess.run([str(python), __file__, "--inner", str(path), "--frames", str(args.frames), "--method", str(args.method)],
                             env=env, check=True, capture_output=True, text=True).stdout
        pbd_ms = json.loads(out.strip().splitlines()[-1])["ms_per_frame"]
        hox_out = subprocess.run(cargo() + args.hox.split() + [str(args.frames), "1", label], cwd=ROOT, check=True, capture_output=True, text=True,
                                 env=dict(os.environ, HOX_BENCH_ELEMENT_ORDER="1", HOX_BENCH_LANES=lanes_here())).stdout
        # one row per sweep and width: colour ×8 / ×4 (a register of tetrahedra) and element (mesh order)
        hox = {}
        for line in hox_out.splitlines():
            if line.startswith("| P1"):
                cells = [c.strip() for c in line.split("|")]
                key = cells[4] if cells[5] in ("", "–") else f"{cells[4]} x{cells[5]}"
                hox[key] = float(cells[7])
        nan = float("nan")
        rows.append((label, len(mesh["tets"]) // 4, pbd_ms, hox.get("colour x8", nan), hox.get("colour x4", nan), hox.get("element", nan)))
        print(f"{label}: PBD {pbd_ms:.2f} ms/frame, hox {hox} ms/frame", file=sys.stderr)
    print("| beam | tetrahedra | PBD ms/frame (1 thread) | hox colour ×8 (AVX-512, the default there) | hox / PBD | hox colour ×4 (AVX2) | hox / PBD | hox element order | hox / PBD |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, n, p, h8, h4, e in rows:
        print(f"| {label} | {n} | {p:.2f} | {h8:.2f} | {h8 / p:.2f} | {h4:.2f} | {h4 / p:.2f} | {e:.2f} | {e / p:.2f} |")


def lanes_here() -> str:
    """The register widths this CPU runs: 4,8 with AVX-512 F, else 4."""
    try:
        flags = Path("/proc/cpuinfo").read_text()
    except OSError:
        return "4"
    return "4,8" if " avx512f" in flags else "4"


if __name__ == "__main__":
    main()
