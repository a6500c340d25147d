"""The mixed formulation against a code that shares nothing with hox (issue #62): the bending
beam in linear elasticity (E = 3 GPa, a third of a millimetre of sag) at ν = 0.499 and 0.4999,
solved by scikit-fem with Taylor–Hood tetrahedra (P2 displacement, continuous P1 pressure,
scripts/taylor_hood.py) on three meshes and extrapolated, against `hox static` with
`--formulation mixed` (P2, one pressure per element) — and the same beam without the cure,
which locks."""

import json
import subprocess
import sys

import pytest

from conftest import ROOT

pytest.importorskip("skfem")


def taylor_hood(nu):
    out = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "taylor_hood.py"), "--cells", "8,16,24", "--poisson", str(nu), "--json"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def hox_tip_z(hox_binary, nu, formulation, grid="24x6x6"):
    args = ["static", "--scene", "bending", "--element", "p2", "--grid", grid, "--poisson", str(nu)]
    args += ["--youngs", "3e9", "--formulation", formulation, "--reference", "none", "--json"]
    done = subprocess.run([hox_binary, *args], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)["probes"]["tip"][2]


@pytest.mark.parametrize("nu", [0.499, 0.4999])
def test_the_mixed_p2_beam_agrees_with_taylor_hood_and_the_plain_one_locks(hox_binary, nu):
    th = taylor_hood(nu)
    limit = th["limit"]["tip_z_m"]
    finest = th["levels"][-1]["tip_z_m"]
    # the Taylor–Hood levels converge towards their limit (within a per cent of the finest)
    assert abs(finest / limit - 1) < 0.01, th
    mixed = hox_tip_z(hox_binary, nu, "mixed")
    assert abs(mixed / limit - 1) < 0.01, f"hox mixed {mixed} m against Taylor-Hood's {limit} m"
    # successive hox levels agree within 0.2 % (the reference's levels, issue #62)
    coarser = hox_tip_z(hox_binary, nu, "mixed", grid="16x4x4")
    assert abs(coarser / mixed - 1) < 0.002, f"16x4x4 {coarser} m, 24x6x6 {mixed} m"
    plain = hox_tip_z(hox_binary, nu, "energy")
    assert plain / limit < 0.995, f"the plain P2 beam ({plain} m) should lock against {limit} m"
