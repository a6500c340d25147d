"""The Python package against the command line and itself (issue #60)."""

import json
import math
import subprocess
from pathlib import Path

import numpy as np
import pytest

import hox


def test_the_registry_s_scenes_and_the_parameter_table_are_listed():
    assert {"bending", "tension", "torsion"} <= set(hox.scenes())
    keys = {p["key"] for p in hox.parameters()}
    assert {"element", "poisson", "youngs", "grid", "solver"} <= keys


@pytest.mark.parametrize(
    "params, named",
    [
        ({"poisson": 0.7}, "poisson"),
        ({"poisson": float("nan")}, "poisson"),
        ({"element": "p9"}, "element"),
        ({"youngs": -3e6}, "youngs"),
        ({"grid": (0, 2, 2)}, "grid"),
        ({"bogus": 1}, "bogus"),
    ],
)
def test_a_bad_parameter_raises_value_error_naming_it(params, named):
    with pytest.raises(ValueError, match=named):
        hox.Scene.builtin("bending").with_params(**params)


def test_every_parameter_of_the_table_refuses_a_bad_value_naming_it():
    table = hox.parameters()
    assert len(table) >= 30
    for p in table:
        key = p["key"]
        with pytest.raises(ValueError, match=key):
            hox.Scene.builtin("bending").with_params(**{key: "bogus-value"})
        if "number" in p["expected"]:
            with pytest.raises(ValueError, match=key):
                hox.Scene.builtin("bending").with_params(**{key: float("nan")})


def test_a_parameter_is_set_by_its_key_with_underscores_for_dashes():
    scene = hox.Scene.builtin("bending").with_params(solver="vbd", vbd_iterations=7, newton_policy="interactive")
    assert scene.params["solver.vbd_iterations"] == 7
    assert scene.params["solver.method"] == "vbd"


def test_an_unknown_scene_raises_value_error_naming_it_and_the_known_ones():
    with pytest.raises(ValueError, match="bendnig.*bending"):
        hox.Scene.builtin("bendnig")


def test_the_state_is_numpy_arrays_and_displacement_is_position_minus_rest():
    sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p1", grid=(8, 2, 2)))
    assert sim.positions.shape == (sim.num_nodes, 3) and sim.positions.dtype == np.float64
    sim.step(10)
    assert sim.time_secs == pytest.approx(10 / 60)
    np.testing.assert_allclose(sim.displacements, sim.positions - sim.rest_positions, atol=1e-15)
    assert sim.probes["tip"][2] < 0, "the beam sags under gravity"
    assert sim.ms_per_frame > 0


def test_a_settled_p2_bending_tip_equals_hox_simulate_settle_json(hox_binary):
    cli = json.loads(
        subprocess.run(
            [hox_binary, "simulate", "--scene", "bending", "--element", "p2", "--settle", "--json"],
            check=True, capture_output=True, text=True,
        ).stdout
    )
    sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2"))
    report = sim.settle()
    assert report["frames"] == cli["frames"]
    for axis in range(3):
        assert abs(sim.probes["tip"][axis] - cli["probes"]["tip"][axis]) <= 1e-12


def test_a_sweep_on_a_dask_local_cluster_equals_the_serial_run():
    distributed = pytest.importorskip("distributed")
    cells = [
        hox.Cell("bending", {"element": e, "poisson": nu, "grid": (4, 1, 1)}, seconds=0.1)
        for e in ("p1", "p2")
        for nu in (0.2, 0.3, 0.4, 0.45)
    ]
    serial = hox.sweep(cells)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            spread = hox.sweep(cells, client.get_executor())
    strip = lambda rows: [{k: v for k, v in r.items() if k != "ms_per_frame"} for r in rows]
    assert len(spread) == 8 and strip(spread) == strip(serial)
    assert all(not math.isnan(r["probe_tip_uz_m"]) for r in spread)


def test_the_type_stubs_name_everything_the_module_has():
    import ast

    stubs = ast.parse((Path(hox.__file__).parent / "_hox.pyi").read_text())
    declared = {n.name for n in stubs.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    members = {
        c.name: {f.name for f in c.body if isinstance(f, ast.FunctionDef)}
        for c in stubs.body
        if isinstance(c, ast.ClassDef)
    }
    module = hox._hox
    public = {n for n in dir(module) if not n.startswith("_")}
    assert public <= declared, f"not in _hox.pyi: {public - declared}"
    for cls in ("Scene", "Simulation"):
        have = {n for n in dir(getattr(module, cls)) if not n.startswith("_")}
        assert have <= members[cls], f"{cls} members not in _hox.pyi: {have - members[cls]}"
    assert (Path(hox.__file__).parent / "py.typed").exists()
    assert hox.Simulation.step.__doc__ and "released" in hox.Simulation.step.__doc__, "help() explains"
