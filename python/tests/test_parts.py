"""A part hox does not ship (issue #61): an L-shaped bracket with a filleted corner and a bolt
hole, made by Gmsh here from scripts/gmsh_bracket.py (P2, about 5,000 nodes), run as a new user
runs it — `hox simulate --mesh … --clamp clamp --settle` with no solver flag — against
`hox static` of the same part. Times are not checked here (the machine's speed is not the
test's); docs/PERFORMANCE.md measures them."""

import json
import math
import subprocess
import sys

import pytest

from conftest import ROOT


@pytest.fixture(scope="module")
def bracket(tmp_path_factory):
    out = tmp_path_factory.mktemp("parts") / "bracket.msh"
    script = ROOT / "scripts" / "gmsh_bracket.py"
    subprocess.run([sys.executable, str(script), str(out), "--size", "0.014"], check=True)
    return out


def hox_json(hox_binary, *args):
    done = subprocess.run([hox_binary, *args, "--json"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout), done.stderr


def test_gmsh_makes_a_p2_part_of_about_five_thousand_nodes(hox_binary, bracket):
    mesh, _ = hox_json(hox_binary, "mesh", "--mesh", str(bracket))
    assert mesh["element"] == "p2"
    assert 4500 <= mesh["nodes"] <= 5500, mesh["nodes"]
    assert mesh["groups"]["clamp"]["nodes"] > 0 and mesh["groups"]["tip"]["nodes"] > 0


def test_with_no_solver_flag_the_part_settles_on_the_static_solution_by_the_interactive_newton(
    hox_binary, bracket
):
    run, _ = hox_json(hox_binary, "simulate", "--mesh", str(bracket), "--clamp", "clamp", "--settle")
    static, _ = hox_json(hox_binary, "static", "--mesh", str(bracket), "--clamp", "clamp")
    assert run["solver"] == "newton" and run["settled"], run
    # the policy chosen by the part's size, and said why
    assert run["newton_policy"] == "interactive", run["newton_policy_why"]
    assert run["newton_policy_why"].startswith("auto: a factorisation of the 13"), run["newton_policy_why"]
    assert run["rejected_steps"] == 0 and run["solver_advice"] is None
    # the factor kept: a few factorisations over the whole settle, not one per frame
    assert run["factorizations"] < run["frames"] / 2, (run["factorizations"], run["frames"])
    tip, reference = run["groups"]["tip"], static["groups"]["tip"]
    error = math.dist(tip, reference) / math.hypot(*reference)
    assert error < 1e-3, f"the settled tip is {100 * error:.3f} % off hox static's"


def test_vbd_on_the_part_says_it_is_not_the_solver_and_names_newton(hox_binary, bracket):
    run, stderr = hox_json(
        hox_binary, "simulate", "--mesh", str(bracket), "--clamp", "clamp", "--solver", "vbd", "--seconds", "0.05"
    )
    advice = run["solver_advice"]
    assert advice.startswith("vbd is not the solver for this part") and "newton" in advice, advice
    assert "note: vbd is not the solver for this part" in stderr
    # a box beam, which VBD's coarse grid fills, is not advised against
    beam, stderr = hox_json(hox_binary, "simulate", "--scene", "bending", "--solver", "vbd", "--seconds", "0.05")
    assert beam["solver_advice"] is None and "not the solver" not in stderr


def test_python_says_the_policy_and_the_advice_as_the_command_line(bracket):
    import hox

    scene = hox.Scene.from_mesh_file(str(bracket), clamp=["clamp"])
    sim = hox.Simulation(scene)
    assert sim.newton_policy is None, "before a step"
    sim.step(1)
    policy, why = sim.newton_policy
    assert policy == "interactive" and why.startswith("auto: a factorisation of the"), why
    assert sim.solver_advice is None
    vbd = hox.Simulation(scene.with_params(solver="vbd"))
    vbd.step(1)
    assert vbd.newton_policy is None
    assert vbd.solver_advice.startswith("vbd is not the solver for this part"), vbd.solver_advice
