"""The example notebooks (python/examples/*.ipynb) run from scratch and show what they say.

Each is executed with nbclient in memory (the committed, executed files are never written), in
the repository root, with one more cell appended that prints the notebook's `results` dictionary
as JSON; the test asserts a few facts on those numbers."""

import copy
import json
import time

import nbformat
import pytest
from nbclient import NotebookClient

from conftest import ROOT

EXAMPLES = ROOT / "python" / "examples"
MARKER = "HOX-NOTEBOOK-RESULTS:"


def execute(name):
    """Runs `name` from scratch and returns its `results` (and the executed notebook)."""
    committed = nbformat.read(EXAMPLES / name, as_version=4)
    nb = copy.deepcopy(committed)
    for cell in nb.cells:  # from scratch: none of the committed outputs survive
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None
    nb.cells.append(nbformat.v4.new_code_cell(f"import json as _json\nprint({MARKER!r} + _json.dumps(results))"))
    client = NotebookClient(
        nb, timeout=300, kernel_name="python3", allow_errors=False, resources={"metadata": {"path": str(ROOT)}}
    )
    started = time.perf_counter()
    client.execute()  # raises CellExecutionError on any error
    print(f"{name}: {time.perf_counter() - started:.1f} s")
    for cell in nb.cells:
        for output in cell.get("outputs", []):
            assert output.output_type != "error", f"{name}: {output.ename}: {output.evalue}"
    lines = [
        line
        for output in nb.cells[-1].outputs
        if output.output_type == "stream"
        for line in output.text.splitlines()
        if line.startswith(MARKER)
    ]
    assert len(lines) == 1, f"{name}: no results printed: {nb.cells[-1].outputs}"
    return json.loads(lines[0][len(MARKER) :]), committed


def check_paper_fig3_table1(results):
    meshes = results["meshes"]
    assert {"P1 1,280", "P2 160", "P3 80"} <= set(meshes)
    assert [meshes[m]["elements"] for m in ("P1 1,280", "P2 160", "P3 80")] == [1280, 160, 80]
    p1, p2, p3 = (meshes[m]["error_m"] for m in ("P1 1,280", "P2 160", "P3 80"))
    assert p2 < p1 and p3 < p1, meshes
    assert p2 < 0.1 * p1, "P2 160 is over ten times more accurate than P1 1,280"
    for mesh in meshes.values():
        assert mesh["ms_per_frame"] > 0
        assert -0.6 < mesh["tip_z_m"] < -0.25, "the tip sags between 0.25 and 0.6 m"
    assert results["machine"]


def check_locking_lesson(results):
    missing = results["missing_pct"]
    p1, p2, p3 = (next(v for k, v in missing.items() if k.startswith(e)) for e in ("P1", "P2", "P3"))
    assert p1["0.499"] > p1["0.35"] + 10, "P1 misses over 10 points more of the sag at ν 0.499 than at 0.35"
    for nu in ("0.35", "0.45", "0.49", "0.499"):
        assert p2[nu] < p1[nu] and p3[nu] < p1[nu], nu
    assert p2["0.49"] < 10 and p3["0.49"] < 10, "P2 and P3 lock far less than P1"
    assert p2["0.499"] > p2["0.35"] + 3, "the energy P2 locks too: it misses more of the sag as ν grows"
    mixed = results["mixed_missing_pct"]
    p1_mixed = next(v for k, v in mixed.items() if k.startswith("P1"))
    assert abs(p1_mixed["0.499"]) < 5, f"P1's pressure and strain per node cure its locking within 5 % {p1_mixed}"
    assert p1_mixed["0.35"] < 0, f"but it is soft where nothing locks {p1_mixed}"
    p2_mixed = next(v for k, v in mixed.items() if k.startswith("P2"))
    assert abs(p2_mixed["0.499"]) < 1.5, f"the cure: P2 mixed within 1.5 % at ν 0.499 {p2_mixed}"
    assert all(abs(v) < 2.5 for v in p2_mixed.values()), f"and within 2.5 % at every ν {p2_mixed}"
    tip = results["dynamic_tip_z_m"]
    (p1_name, p1_tip), (p2_name, p2_tip), (p2m_name, p2m_tip) = sorted(tip.items())
    assert p1_name.startswith("P1") and p2_name.startswith("P2") and p2m_name.endswith("mixed")
    assert -p1_tip < 0.9 * -p2_tip, "settled at ν 0.49, P1 sags over 10 % less than P2"
    reference = results["reference_sag_049_m"]
    assert abs(-p2m_tip - reference) < 0.03 * reference, "settled, the mixed P2 sags within 3 % of the reference"
    assert -p2_tip < -p2m_tip, "settled, the energy P2 sags less than the mixed one"
    assert all(results["dynamic_at_rest"].values())


def check_own_gmsh_part(results):
    assert results["settled"]
    assert (results["nodes"], results["elements"]) == (4609, 2493)
    assert results["von_mises_max_pa"] > 0 and results["surface_von_mises_max_pa"] > 0
    ux, uy, uz = results["end_displacement_m"]
    assert uz < 0, "the hook's end sinks under its weight"
    assert 1e-3 < (ux**2 + uy**2 + uz**2) ** 0.5 < 0.2


NOTEBOOKS = {
    "paper_fig3_table1.ipynb": check_paper_fig3_table1,
    "locking_lesson.ipynb": check_locking_lesson,
    "own_gmsh_part.ipynb": check_own_gmsh_part,
}


@pytest.mark.parametrize("name", sorted(NOTEBOOKS))
def test_notebook_runs_and_shows_its_numbers(name, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    before = (EXAMPLES / name).read_bytes()
    results, committed = execute(name)
    NOTEBOOKS[name](results)
    assert (EXAMPLES / name).read_bytes() == before, "the committed notebook is left as it is"
    # the committed notebook is stored executed, with its figures, and without errors
    outputs = [o for c in committed.cells if c.cell_type == "code" for o in c.outputs]
    assert outputs and not any(o.output_type == "error" for o in outputs)
    assert committed.metadata.kernelspec.name == "python3"
    images = sum("image/png" in o.get("data", {}) for o in outputs)
    assert 1 <= images <= 3
