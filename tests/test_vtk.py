"""VTK output: a bar result and a small quad8 mesh written to .vtu and read back with meshio."""

import subprocess
import sys

import numpy as np
import pytest

import fracid
from fracid.models import DamageModel
from fracid.report import write_vtk  # imports meshio only when writing
from fracid.report.vtk import corner_to_nodes

meshio = pytest.importorskip("meshio")


@pytest.fixture(scope="module")
def bar_state():
    bar = fracid.BarWithWeakZone(n_elements=20)
    result = fracid.simulate(bar, fracid.DamageParameters())
    fields = result.fields[result.n_steps]
    assert fields["omega"].max() > 0.5  # a damaged state
    return bar, fields


def test_bar_round_trip(tmp_path, bar_state):
    bar, fields = bar_state
    nodes, cells, cell_type = bar.describe().output_mesh()
    assert nodes.shape == (41, 1) and cells.shape == (20, 3) and cell_type == "line3"
    path = write_vtk(tmp_path / "bar.vtu", nodes, cells, cell_type, fields, n_u_components=1)
    mesh = meshio.read(path)
    assert len(mesh.points) == 41
    assert [(block.type, len(block.data)) for block in mesh.cells] == [("line3", 20)]
    np.testing.assert_array_equal(mesh.cells[0].data, cells)
    np.testing.assert_array_equal(mesh.points[:, 0], nodes[:, 0])
    np.testing.assert_array_equal(mesh.points[:, 1:], 0.0)
    # displacement: u dof j is node j in 1D; padded to 3 components
    displacement = mesh.point_data["displacement"]
    assert displacement.shape == (41, 3)
    np.testing.assert_array_equal(displacement[:, 0], fields["u"])
    np.testing.assert_array_equal(displacement[:, 1:], 0.0)
    # ebar: vertex values as they are, mid-points the mean of the two ends
    ebar = mesh.point_data["ebar"]
    np.testing.assert_array_equal(ebar[0::2], fields["ebar"])
    np.testing.assert_allclose(ebar[1::2], 0.5 * (fields["ebar"][:-1] + fields["ebar"][1:]), rtol=1e-15)
    # cell data
    np.testing.assert_array_equal(mesh.cell_data["damage_max"][0], fields["omega"].max(axis=1))
    np.testing.assert_allclose(mesh.cell_data["damage_mean"][0], fields["omega"].mean(axis=1), rtol=1e-15)
    np.testing.assert_array_equal(mesh.cell_data["kappa_max"][0], fields["kappa"].max(axis=1))


def test_local_model_has_no_ebar(tmp_path):
    bar = fracid.BarWithWeakZone(n_elements=10)
    result = fracid.simulate(bar, fracid.DamageParameters(), model=DamageModel("local"), target=0.005, stop_force_fraction=None)
    fields = result.fields[result.n_steps]
    assert "ebar" not in fields
    mesh = meshio.read(write_vtk(tmp_path / "local.vtu", *bar.describe().output_mesh(), fields))
    assert set(mesh.point_data) == {"displacement"}
    np.testing.assert_array_equal(mesh.point_data["displacement"][:, 0], fields["u"])


def two_quad8():
    """Two 8-node quadrilaterals side by side; corner nodes 0..5 first, then the mid-side nodes."""
    corners = [[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1]]
    # mid-sides: 6 (0-1), 7 (1-4, shared), 8 (4-3), 9 (3-0), 10 (1-2), 11 (2-5), 12 (5-4)
    pairs = [(0, 1), (1, 4), (4, 3), (3, 0), (1, 2), (2, 5), (5, 4)]
    nodes = np.array(corners + [np.mean([corners[a], corners[b]], axis=0).tolist() for a, b in pairs], dtype=float)
    cells = np.array([[0, 1, 4, 3, 6, 7, 8, 9], [1, 2, 5, 4, 10, 11, 12, 7]])
    return nodes, cells, pairs


def test_quad8_round_trip(tmp_path):
    nodes, cells, pairs = two_quad8()
    rng = np.random.default_rng(0)
    fields = {
        "u": rng.standard_normal(2 * 13),
        "ebar": rng.uniform(0, 1e-3, 6),
        "kappa": rng.uniform(0, 1e-3, (2, 9)),
        "omega": rng.uniform(0, 1, (2, 9)),
    }
    extra = {"node_id": np.arange(13.0)}
    path = write_vtk(tmp_path / "quads.vtu", nodes, cells, "quad8", fields, n_u_components=2, point_data_extra=extra)
    mesh = meshio.read(path)
    assert len(mesh.points) == 13
    assert [(block.type, len(block.data)) for block in mesh.cells] == [("quad8", 2)]
    np.testing.assert_array_equal(mesh.points[:, :2], nodes)
    displacement = mesh.point_data["displacement"]
    np.testing.assert_array_equal(displacement[:, :2], fields["u"].reshape(13, 2))
    np.testing.assert_array_equal(displacement[:, 2], 0.0)
    ebar = mesh.point_data["ebar"]
    np.testing.assert_array_equal(ebar[:6], fields["ebar"])
    for node, (a, b) in enumerate(pairs, start=6):  # the shared mid-side node 7 too
        assert ebar[node] == pytest.approx(0.5 * (fields["ebar"][a] + fields["ebar"][b]), rel=1e-15)
    np.testing.assert_array_equal(mesh.point_data["node_id"], extra["node_id"])
    np.testing.assert_array_equal(mesh.cell_data["damage_max"][0], fields["omega"].max(axis=1))
    np.testing.assert_allclose(mesh.cell_data["damage_mean"][0], fields["omega"].mean(axis=1), rtol=1e-15)
    np.testing.assert_array_equal(mesh.cell_data["kappa_max"][0], fields["kappa"].max(axis=1))
    # the component count is inferred when not given
    default = meshio.read(write_vtk(tmp_path / "default.vtu", nodes, cells, "quad8", fields))
    np.testing.assert_array_equal(default.point_data["displacement"], displacement)


def test_plane_stress_specimen(tmp_path):
    """A 2D run: u is numbered node by node (2 j, 2 j + 1), ebar on the vertices, numbered first."""
    from fracid.specimens.dogbone import DogBone

    specimen = DogBone(h_fine=4.0)
    mesh = specimen.mesh()
    result = fracid.simulate(specimen, fracid.DamageParameters(), max_steps=5)
    fields = result.fields[result.n_steps]
    data = meshio.read(write_vtk(tmp_path / "dogbone.vtu", mesh.nodes, mesh.cells, "quad8", fields))
    assert [(block.type, len(block.data)) for block in data.cells] == [("quad8", len(mesh.cells))]
    np.testing.assert_array_equal(data.point_data["displacement"][:, :2], fields["u"].reshape(-1, 2))
    np.testing.assert_array_equal(data.point_data["ebar"][: mesh.n_vertices], fields["ebar"])
    np.testing.assert_array_equal(data.cell_data["damage_max"][0], fields["omega"].max(axis=1))


def test_corner_values_with_explicit_nodes_and_nodal_values():
    _, cells, _ = two_quad8()
    values = np.arange(6.0)
    permuted = corner_to_nodes(values[::-1], cells, "quad8", 13, corner_nodes=np.arange(6)[::-1])
    np.testing.assert_array_equal(permuted, corner_to_nodes(values, cells, "quad8", 13))
    nodal = np.arange(13.0)
    np.testing.assert_array_equal(corner_to_nodes(nodal, cells, "quad8", 13), nodal)


def test_invalid_input(tmp_path):
    nodes, cells, _ = two_quad8()
    fields = {"u": np.zeros(26), "kappa": np.zeros((2, 4)), "omega": np.zeros((2, 4))}
    with pytest.raises(ValueError, match="cell_type"):
        write_vtk(tmp_path / "x.vtu", nodes, cells, "hexahedron27", fields)
    with pytest.raises(ValueError, match="shape"):
        write_vtk(tmp_path / "x.vtu", nodes, cells[:, :4], "quad8", fields)
    with pytest.raises(ValueError, match="n_el"):
        write_vtk(tmp_path / "x.vtu", nodes, cells, "quad8", {**fields, "omega": np.zeros((3, 4))})
    with pytest.raises(ValueError, match="displacement dofs"):
        write_vtk(tmp_path / "x.vtu", nodes, cells, "quad8", {**fields, "u": np.zeros(25)})
    with pytest.raises(ValueError, match="corner"):
        write_vtk(tmp_path / "x.vtu", nodes, cells, "quad8", {**fields, "ebar": np.zeros(5)})


def test_missing_meshio_gives_a_clear_error(tmp_path, monkeypatch, bar_state):
    bar, fields = bar_state
    monkeypatch.setitem(sys.modules, "meshio", None)
    with pytest.raises(ImportError, match=r"needs meshio, a dependency of fracid: pip install meshio"):
        write_vtk(tmp_path / "bar.vtu", *bar.describe().output_mesh(), fields)


def test_importing_the_report_package_does_not_import_meshio():
    code = "import sys, fracid, fracid.report; assert 'meshio' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.parametrize("which", ["bar", "beam"])
@pytest.mark.slow
def test_write_result_vtk_writes_requested_steps(tmp_path, which):
    meshio = pytest.importorskip("meshio")
    import fracid
    from fracid.report import write_result_vtk
    from fracid.specimens.beam import NotchedBeam

    if which == "bar":
        specimen, params, target = fracid.BarWithWeakZone(n_elements=30), fracid.DamageParameters(), 0.02
    else:
        specimen = NotchedBeam(h_fine=4.0, h_coarse=8.0, fine_width=12.0)
        params, target = fracid.DamageParameters(E=37000.0, kappa_i=8e-5, c=25.0), 0.03
    result = fracid.simulate(specimen, params, target=target, stop_force_fraction=None, field_steps=[2, 5])
    files = write_result_vtk(tmp_path / "out", specimen, result)
    assert [f.name for f in files] == ["step_0002.vtu", "step_0005.vtu", f"step_{result.n_steps:04d}.vtu"]
    last = meshio.read(files[-1])
    nodes, cells, _ = specimen.describe().output_mesh()
    assert last.points.shape[0] == len(nodes)
    assert last.cell_data["damage_max"][0].max() > 0.0  # past the peak: damaged cells
