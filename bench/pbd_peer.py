#!/usr/bin/env python3
"""Side by side with Jan Bender's PositionBasedDynamics (pypbd): its FEM tetrahedra on the same
three P1 beams as `hox bench` (the paper's Table 1 bending beam: 2 x 0.5 x 0.5 m, clamped at
x = 0, gravity, 50 substeps x 1 iteration per 1/60 s frame), timed, then `hox bench`'s timing of
the same beam right after, so each ratio is measured in one run.

    python3 bench/pbd_peer.py [--frames 15] [--method 3] [--hox PATH]

Prints the machine line and a markdown table (docs/PERFORMANCE.md holds it between generated
markers: `python3 scripts/docs_tables.py` rewrites it, `cargo test -p hox --test doc_tables`
checks its format). `hox` is --hox, else $HOX_BIN, else the release binary under
$CARGO_TARGET_DIR (built if missing; HOX_CARGO="flock /tmp/hox-cargo.lock cargo" where builds
must take turns).

Installs pypbd into bench/.venv (a virtualenv) on first use. The meshes come from hox itself
(`hox bench --beam-json LABEL`), so both solve identical meshes. PBD's solid method 3 is its
XPBD FEM tetrahedron (the constitutive model of Bender et al. 2014 / PBD's `FEMTetConstraint`):
one constraint per tetrahedron, like hox's energy formulation; stiffness is Young's modulus,
3 MPa, Poisson ratio 0.35. Times are medians of ms per frame on one thread (PBD's OpenMP loop is
limited with OMP_NUM_THREADS=1); hox is timed with both of its sweeps: colour (the default: a
register of same-colour tetrahedra at a time, at the widest register this CPU runs, 8 lanes on
AVX-512, else 4) and element order (`Sweep::Element`, the order before issue #22).
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
sys.path.insert(0, str(ROOT / "scripts"))
from hox_binary import hox_binary  # noqa: E402
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


def beam_mesh(hox: str, label: str) -> dict:
    out = subprocess.run([hox, "bench", "--beam-json", label], cwd=ROOT, check=True, capture_output=True, text=True).stdout
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
    parser.add_argument("--hox", help="the hox binary (default: $HOX_BIN, else the release build)")
    parser.add_argument("--inner", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.frames < 1:
        sys.exit("pbd_peer: --frames must be at least 1")
    if args.inner:
        mesh = json.loads(Path(args.inner).read_text())
        print(json.dumps({"ms_per_frame": time_pbd(mesh, args.frames, args.method)}))
        return
    hox = hox_binary(args.hox)
    python = ensure_venv()
    env = dict(os.environ, OMP_NUM_THREADS="1")
    rows = []
    machine = None
    for label in BEAMS:
        mesh = beam_mesh(hox, label)
        path = VENV / f"mesh-{label.replace(' ', '_')}.json"
        path.write_text(json.dumps(mesh))
        out = subprocess.run([str(python), __file__, "--inner", str(path), "--frames", str(args.frames), "--method", str(args.method)],
                             env=env, check=True, capture_output=True, text=True).stdout
        pbd_ms = json.loads(out.strip().splitlines()[-1])["ms_per_frame"]
        bench = [hox, "bench", "--only", label, "--threads", "1", "--sweep", "colour,element", "--frames", str(args.frames)]
        hox_out = subprocess.run(bench, cwd=ROOT, check=True, capture_output=True, text=True).stdout
        lines = hox_out.splitlines()
        machine = lines[0]
        # the configuration's two rows: colour (at the default width) and element order
        hox_ms, lanes = {}, None
        for line in lines:
            if line.startswith("| P1"):
                cells = [c.strip() for c in line.split("|")]
                hox_ms[cells[4]] = float(cells[7])
                if cells[4] == "colour":
                    lanes = cells[5]
        if set(hox_ms) != {"colour", "element"}:
            sys.exit(f"pbd_peer: `{' '.join(bench)}` printed no colour and element rows:\n{hox_out}")
        rows.append((label, len(mesh["tets"]) // 4, pbd_ms, hox_ms["colour"], lanes, hox_ms["element"]))
        print(f"{label}: PBD {pbd_ms:.2f} ms/frame, hox {hox_ms} ms/frame", file=sys.stderr)
    print(machine)
    print()
    print("| P1 beam | tetrahedra | PBD ms/frame, 1 thread | hox ms/frame, colour sweep (the default) | lanes "
          "| hox / PBD | hox ms/frame, element order | hox / PBD |")
    print("|---|---|---|---|---|---|---|---|")
    for label, n, p, colour, lanes, element in rows:
        print(f"| {label} | {n} | {p:.2f} | {colour:.2f} | {lanes} | **{colour / p:.2f}** | {element:.2f} | {element / p:.2f} |")


if __name__ == "__main__":
    main()
