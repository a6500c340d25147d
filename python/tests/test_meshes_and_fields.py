"""Meshes from numpy and meshio, the state as views, fields, energies and the error (issue #60)."""

import meshio
import numpy as np
import pytest

import hox
from conftest import ROOT

MESHES = ROOT / "assets" / "meshes"


@pytest.mark.parametrize(
    "file", ["beam-tet4.msh", "beam-tet10.msh", "beam-tet20.msh", "beam-hex8.msh", "beam-hex27.msh",
             "beam-prism6.msh", "beam-pyramid.msh", "beam-mixed.msh", "beam-tet10-v22.msh"]
)
def test_a_gmsh_file_through_meshio_is_the_mesh_hox_reads(file):
    read = hox.Simulation(hox.Scene.from_mesh_file(str(MESHES / file), clamp=["clamp"]))
    through = hox.Simulation(hox.from_meshio(meshio.read(MESHES / file), clamp=["clamp"]))
    assert through.num_nodes == read.num_nodes and through.num_elements == read.num_elements
    assert through.volume_m3 == pytest.approx(read.volume_m3, rel=1e-12)
    np.testing.assert_array_equal(through.rest_positions, read.rest_positions)
    for kind, conn in read.elements.items():
        np.testing.assert_array_equal(through.elements[kind], conn, err_msg=f"{file}: {kind} in Gmsh's node order")
    # the same clamp, so the same motion
    read.step(3)
    through.step(3)
    np.testing.assert_allclose(through.positions, read.positions, rtol=0, atol=1e-14)


def test_numpy_arrays_in_give_the_volume_and_node_count_of_the_gmsh_file():
    read = hox.Simulation(hox.Scene.from_mesh_file(str(MESHES / "beam-tet10.msh"), clamp=["clamp"]))
    nodes = np.array(read.rest_positions)
    clamp = np.flatnonzero(nodes[:, 0] < 1e-9)
    scene = hox.Scene.from_arrays(nodes, read.elements, {"clamp": clamp}, clamp=["clamp"])
    sim = hox.Simulation(scene)
    assert (sim.num_nodes, sim.num_elements) == (read.num_nodes, read.num_elements) == (495, 218)
    assert sim.volume_m3 == pytest.approx(read.volume_m3, rel=1e-13)
    assert sim.volume_m3 == pytest.approx(0.5, rel=1e-9), "the 2 × 0.5 × 0.5 m beam"
    assert sim.element_volumes_m3.shape == (218,) and (sim.element_volumes_m3 > 0).all()
    assert scene.groups == {"clamp": len(clamp)}


def test_a_broken_array_mesh_is_a_value_error_naming_the_problem():
    nodes = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    with pytest.raises(ValueError, match="inverted"):
        hox.Scene.from_arrays(nodes, {"p1": np.array([[1, 0, 2, 3]])})
    with pytest.raises(ValueError, match="node 7"):
        hox.Scene.from_arrays(nodes, {"p1": np.array([[0, 1, 2, 7]])})
    with pytest.raises(ValueError, match="p7.*p1, p2"):
        hox.Scene.from_arrays(nodes, {"p7": np.array([[0, 1, 2, 3]])})
    with pytest.raises(ValueError, match="row 0: 3 node indices"):
        hox.Scene.from_arrays(nodes, {"p1": np.array([[0, 1, 2]])})
    with pytest.raises(ValueError, match="nodes: expected an \\(n, 3\\)"):
        hox.Scene.from_arrays(nodes[:, :2].copy(), {"p1": np.array([[0, 1, 2, 3]])})
    with pytest.raises(ValueError, match="non-finite"):
        hox.Scene.from_arrays(np.where(nodes == 1, np.nan, nodes), {"p1": np.array([[0, 1, 2, 3]])})
    with pytest.raises(ValueError, match='"bottom".*clamp'):
        hox.Scene.from_arrays(nodes, {"p1": np.array([[0, 1, 2, 3]])}, {"clamp": [0, 1, 2]}, clamp=["bottom"])
    with pytest.raises(ValueError, match="hexahedron20"):
        hox.from_meshio(meshio.Mesh(np.zeros((20, 3)), [("hexahedron20", np.arange(20)[None, :])]))


def test_a_view_follows_the_simulation_in_place_and_cannot_be_written():
    sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2", grid=(4, 1, 1)))
    view, velocities = sim.positions, sim.velocities
    assert not view.flags.writeable and not view.flags.owndata
    with pytest.raises(ValueError):
        view[0, 0] = 1.0
    kept = view.copy()
    sim.step(5)
    np.testing.assert_array_equal(view, np.array(sim.positions))
    assert np.abs(view - kept).max() > 1e-4, "the view shows the stepped state"
    assert np.abs(velocities).max() > 0
    del sim
    assert np.isfinite(view).all(), "the view keeps the simulation alive"


def test_reading_positions_of_a_16k_node_mesh_takes_under_a_millisecond():
    sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2", grid=(32, 8, 8)))
    assert sim.num_nodes > 16_000
    import time

    rounds = []
    for _ in range(200):
        t = time.perf_counter()
        sim.positions
        rounds.append(time.perf_counter() - t)
    # the median of many reads: a view, so a fixed cost, not a copy of 16k × 3 numbers
    assert sorted(rounds)[len(rounds) // 2] < 1e-3


def test_fields_per_element_and_on_the_surface_follow_the_deformation():
    sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2"))
    at_rest = sim.element_field("von-mises")
    assert at_rest.shape == (sim.num_elements,) and np.abs(at_rest).max() < 1e-6
    np.testing.assert_allclose(sim.element_field("det-f"), 1.0, atol=1e-12)
    sim.step(20)
    stress = sim.element_field("von-mises")
    assert stress.max() > 1e3, "the sagging beam is stressed"
    assert (sim.element_field("energy-density") >= 0).all() and (sim.element_field("strain") >= 0).all()
    surface = sim.surface(segments=3)
    values = sim.surface_field("displacement", segments=3)
    assert values.shape == (len(surface["points"]),) and surface["triangles"].max() < len(surface["points"])
    np.testing.assert_allclose(values, np.linalg.norm(surface["points"] - surface["rest_points"], axis=1), atol=1e-12)
    assert sim.surface_field("von-mises", segments=3).max() > 1e3
    with pytest.raises(ValueError, match="unknown field.*von-mises"):
        sim.element_field("stress")
    energies = sim.energies
    assert energies["elastic_j"] > 0 and energies["gravity_j"] < 0
    assert energies["total_j"] == pytest.approx(sum(v for k, v in energies.items() if k != "total_j"))


def test_the_error_against_the_reference_falls_as_the_beam_settles():
    sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2"))
    reference = sim.reference()
    assert reference["origin"] == "committed" and "tip" in reference["probes"]
    early = sim.error()["error_pct"]
    sim.settle()
    late = sim.error()
    assert late["error_pct"] < 2.0 < early, (early, late)
    own = hox.Simulation(hox.Scene.from_mesh_file(str(MESHES / "beam-tet10.msh")))
    with pytest.raises(ValueError, match="no probes"):
        own.error()
    probed = hox.Scene.from_mesh_file(str(MESHES / "beam-tet10.msh")).with_probes(tip=(2.0, 0.25, 0.25))
    assert probed.probes == {"tip": [2.0, 0.25, 0.25]}
    probed_sim = hox.Simulation(probed)
    probed_sim.step(2)
    assert probed_sim.error()["reference"].startswith("static solution of this mesh")


def test_a_group_driven_from_python_moves_by_its_translation():
    drive = {"group": "tip", "translation_m": (0.0, 0.0, -0.05), "ramp_secs": 0.1}
    scene = hox.from_meshio(meshio.read(MESHES / "beam-tet10.msh"), clamp=["clamp"], drives=[drive], gravity=False)
    sim = hox.Simulation(scene)
    sim.step(12)  # 0.2 s: the ramp done, then held
    nodes, _, groups = hox.mesh_arrays(meshio.read(MESHES / "beam-tet10.msh"))
    moved = sim.displacements[groups["tip"]]
    np.testing.assert_allclose(moved, [[0.0, 0.0, -0.05]] * len(moved), atol=1e-12)
    assert np.abs(sim.displacements[groups["clamp"]]).max() == 0.0
    with pytest.raises(ValueError, match='unknown key "speed"'):
        hox.Scene.from_mesh_file(str(MESHES / "beam-tet10.msh"), drives=[{"group": "tip", "speed": 1}])
    with pytest.raises(ValueError, match='"nose".*"clamp"'):
        hox.Scene.from_mesh_file(str(MESHES / "beam-tet10.msh"), drives=[{"group": "nose"}])


def test_ctrl_c_stops_a_long_settle_and_the_simulation_is_usable_after():
    import _thread
    import threading

    sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2", grid=(16, 4, 4), substeps=200))
    threading.Timer(0.5, _thread.interrupt_main).start()
    with pytest.raises(KeyboardInterrupt):
        sim.settle(cap_secs=3600)
    t = sim.time_secs
    assert 0 < t < 3600
    sim.step(1)
    assert sim.time_secs == pytest.approx(t + 1 / 60)
