"""The user's own specimen from a Gmsh mesh (fracid.specimens.mesh): physical groups become supports, loads
and controls; linear or quadratic triangles and quadrilaterals run as T6 / Q8; bad meshes give their error."""

import numpy as np
import pytest

import fracid
from fracid.models import DamageModel
from fracid.specimens.mesh import MeshSpecimen
from fracid.specimens.mesh_reading import MeshError, plane_mesh, read_mesh

meshio = pytest.importorskip("meshio")

from hostile_mesh import H, L, grid, strip_config, two_halves, write_msh  # noqa: E402 -- shared with the hostile cases
from _gmsh_beam import beam_msh  # noqa: E402 -- shared with the PF-CZM tests

T, E = 5.0, 30000.0


def strip(path):
    return MeshSpecimen(str(path), thickness=T, supports=(("left", "x"), ("origin", "y")), loads=(("right", "x"),),
                        controls=(("elongation", (("right", "x", 1.0),)),))


@pytest.mark.parametrize("kind, clockwise", [("triangle", False), ("quad", False), ("triangle", True)])
def test_strip_from_a_gmsh_file_is_elastic_then_damages(tmp_path, kind, clockwise):
    points, cells, left, right, corner = grid(6, 2, kind == "triangle")
    path = write_msh(tmp_path / "strip.msh", points, cells, left, right, corner, kind, clockwise)
    specimen = strip(path)
    description = specimen.describe()
    assert description.cells.shape[1] == (6 if kind == "triangle" else 8)
    assert len(description.nodes_of("left")) == 2 * 2 + 1  # 3 corners and 2 mid-edge nodes
    params = fracid.DamageParameters(E=E, nu=0.2, kappa_i=1e-4, beta=300.0, c=4.0)
    result = DamageModel().simulate(specimen, params, target=0.01, stop_force_fraction=None)
    slope = result.force[1] / result.control[1]
    assert slope == pytest.approx(E * H * T / L, rel=1e-9)  # uniform strain, exactly
    assert result.peak_force == pytest.approx(1e-4 * E * H * T, rel=0.02)  # damage onset at kappa_i everywhere


def test_groups_of_quadratic_lines_hold_the_mid_edge_nodes():
    points = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    mesh = plane_mesh(points, [("triangle6", np.array([[0, 1, 2, 3, 4, 5]])), ("line3", np.array([[0, 1, 3]]))],
                      {"bottom": {"line3": np.array([0])}})
    assert mesh.n_vertices == 3 and mesh.cells.shape == (1, 6)
    bottom = mesh.nodes[mesh.node_sets["bottom"]]
    np.testing.assert_allclose(np.sort(bottom[:, 0]), [0.0, 1.0, 2.0])
    np.testing.assert_allclose(bottom[:, 1], 0.0)


def test_a_mesh_read_twice_is_read_once(tmp_path):
    path = write_msh(tmp_path / "a.msh", *grid(2, 1, True), "triangle")
    assert read_mesh(path) is read_mesh(path)


@pytest.mark.parametrize("change, message", [
    ("missing_group", r"no physical group 'top'; the file names \['domain', 'left', 'origin', 'right'\]"),
    ("solid", r"3D elements \(tetra\)"),
    ("mixed", "triangles and quadrilaterals together"),
    ("unused", r"1 node belongs to no triangle or quadrilateral \(node 9 at \[50.0, 50.0\]\)"),
    ("degenerate", r"degenerate elements \(zero area\): \[0\]"),
    ("off_plane", "nodes off the plane z = 0"),
])
def test_bad_meshes_name_the_file_and_the_fault(tmp_path, change, message):
    points, cells, left, right, corner = grid(2, 2, True)
    kind, blocks = "triangle", None
    if change == "solid":
        blocks = [("tetra", np.array([[0, 1, 3, 4]]))]
    if change == "mixed":
        blocks = [("quad", np.array([[0, 3, 4, 1]]))]
    if change == "unused":
        points = np.vstack([points, [[50.0, 50.0, 0.0]]])
    if change == "degenerate":
        cells = cells.copy()
        cells[0] = [0, 1, 2]  # three nodes on the line x = 0
    if change == "off_plane":
        points = points.copy()
        points[4, 2] = 1.0
    path = write_msh(tmp_path / f"{change}.msh", points, cells, left, right, corner, kind)
    if blocks:
        raw = meshio.read(path)
        with pytest.raises(MeshError, match=message):
            plane_mesh(raw.points, [(b.type, b.data) for b in raw.cells] + blocks, {})
        return
    specimen = strip(path)
    if change == "missing_group":
        specimen = MeshSpecimen(str(path), thickness=T, supports=(("top", "y"),), loads=(("right", "x"),),
                                controls=(("elongation", (("right", "x", 1.0),)),))
    with pytest.raises(MeshError, match=message) as err:
        specimen.describe()
    assert str(path) in str(err.value)


def test_missing_and_unreadable_files(tmp_path):
    with pytest.raises(MeshError, match="cannot read the mesh file"):
        read_mesh(tmp_path / "none.msh")
    bad = tmp_path / "bad.msh"
    bad.write_text("$MeshFormat\nnonsense\n")
    with pytest.raises(MeshError, match="not a mesh file fracid can read.*format 2.2 or 4.1"):
        read_mesh(bad)


def test_duplicate_nodes_are_named_with_one_of_them(tmp_path):
    """Two halves meshed apart whose nodes on x = L/2 were never merged: refused when read, not at step 0."""
    path = write_msh(tmp_path / "dup.msh", *two_halves(0.0), "triangle")
    with pytest.raises(MeshError, match=r"dup.msh: 6 nodes lie on another node .* e.g. two at \[15.0, .*Coherence"):
        read_mesh(path)


def test_a_piece_without_support_is_named_and_a_supported_one_is_not(tmp_path):
    path = write_msh(tmp_path / "two.msh", *two_halves(0.5), "triangle")
    with pytest.raises(MeshError, match=r"2 pieces that share no node, and 1 of them holds no support node "
                                        r"\(supports: 'left', 'origin'\).*piece 2 \(12 elements, x in \[15.5, 30.5\], "
                                        r"y in \[0, 6\]\).*Boolean fragments") as err:
        strip(path).describe()
    assert str(path) in str(err.value)
    from dataclasses import replace

    held = replace(strip(path), supports=(("left", "x"), ("origin", "y"), ("right", "y")))
    assert held.describe().nodes.shape[0] == read_mesh(path).nodes.shape[0]  # each piece held: a valid mesh


def test_a_support_sharing_nodes_with_a_rigid_load_is_refused(tmp_path):
    points, cells, left, right, _ = grid(6, 2, True)
    path = write_msh(tmp_path / "tie.msh", points, cells, left, right, right[:1, :1], "triangle")
    specimen = MeshSpecimen(str(path), thickness=T, supports=(("left", "x"), ("origin", "y")),
                            loads=(("right", "y"),), controls=(("deflection", (("right", "y", 1.0),)),))
    with pytest.raises(MeshError, match="tie.msh: the support group 'origin' and the rigid load group 'right' share "
                                        "1 node along y.*rigid = false"):
        specimen.describe()
    from dataclasses import replace

    assert replace(specimen, loads=(("right", "y", False),)).describe() is not None  # spread: no tie, no conflict
    assert replace(specimen, loads=(("right", "x"),)).describe() is not None  # another component


@pytest.mark.parametrize("content, words", [
    ("$NOD\n1\n1 0 0 0\n$ENDNOD\n$ELM\n0\n$ENDELM\n", "a Gmsh 1.0 file"),
    ("x,y\n0,0\n", "not a mesh file fracid can read"),
    (b"\x89PNG\r\n\x1a\n\xff\xfe" * 8, "not a mesh file fracid can read"),
])
def test_files_meshio_cannot_read_say_which_formats_to_export(tmp_path, capsys, content, words):
    """meshio's own exits and exceptions (SystemExit, ReadError, UnicodeDecodeError) become MeshError."""
    path = tmp_path / "old.msh"
    path.write_bytes(content) if isinstance(content, bytes) else path.write_text(content)
    with pytest.raises(MeshError, match="format 2.2 or 4.1") as err:
        read_mesh(path)
    assert words in str(err.value) and str(path) in str(err.value)
    assert capsys.readouterr().err == ""  # meshio's own "Error: ..." is not printed


def test_mesh_unknowns_and_the_size_limit(tmp_path, monkeypatch):
    """The count from the corners and elements is exact for one piece without holes; beyond
    MAX_UNKNOWNS the configuration refuses the mesh before it is built."""
    from fracid.specimens import protocol
    from fracid.specimens.mesh_reading import mesh_size, mesh_unknowns
    from fracid.specimens.mesh_section import check_mesh_size

    for triangles in (True, False):
        points, cells = grid(5, 3, triangles)[:2]
        mesh = plane_mesh(points, [("triangle" if triangles else "quad", cells)], {})
        assert mesh_unknowns(mesh.n_vertices, len(mesh.cells)) == 2 * len(mesh.nodes) + mesh.n_vertices
    monkeypatch.setattr(protocol, "MAX_UNKNOWNS", 100)
    path = write_msh(tmp_path / "big.msh", *grid(6, 2, True), "triangle")
    assert mesh_size(path) == (21, 24)
    with pytest.raises(MeshError, match=r"big.msh: 24 elements and 21 corner nodes make about 151 unknowns .*"
                                        r"at most 100 unknowns are allowed: use a coarser mesh"):
        check_mesh_size(str(path))
    assert read_mesh(path).n_vertices == 21  # the limit is the configuration's, not the reader's


def units_error(tmp_path, size, c=4.0, scale=1.0, bounds=None, model="gradient-damage", parameters=None):
    """The ConfigError of the mesh's unit check (:func:`fracid.config.sections.check_specimen_section`) on the strip
    drawn ``size`` times its size in mm (None if none)."""
    from types import SimpleNamespace

    from fracid.config import ConfigError
    from fracid.config.checker import Checker
    from fracid.config.schema import ModelConfig, SpecimenConfig
    from fracid.config.sections import check_specimen_section

    path = write_msh(tmp_path / "units.msh", *grid(6, 2, True, L * size, H * size), "triangle")
    options = dict(path=str(path), thickness=T, scale=scale, supports=(("left", "x"), ("origin", "y")),
                   loads=(("right", "x", True, 1.0),), controls=(("elongation", (("right", "x", 1.0),)),))
    identify = bounds and SimpleNamespace(parameters=("beta", "c"), lower=(100.0, bounds[0]), upper=(900.0, bounds[1]))
    try:
        check_specimen_section(Checker(tmp_path / "cfg.toml"), ModelConfig(model, (("c", c),) if parameters is None else parameters),
                               SpecimenConfig("mesh", "elongation", tuple(options.items())), identify)
    except ConfigError as err:
        return str(err)
    return None


def test_a_mesh_in_metres_or_micrometres_is_a_unit_error(tmp_path):
    """l = sqrt(2 c) larger than the whole mesh (drawn in metres) or 100 times smaller than its smallest
    element (micrometres, or a scale too large): errors naming the extent, l and specimen.scale."""
    metres = units_error(tmp_path, 1e-3)
    assert "units.msh" in metres and "the mesh spans 0.03 x 0.006 units of its own" in metres
    assert "l = sqrt(2 c) = 2.83 mm (with c = 4 mm^2)" in metres and "scale = 1000" in metres
    assert "lower bound c = 0.5 mm^2" in units_error(tmp_path, 1e-3, bounds=(0.5, 50.0))  # the smallest l
    assert units_error(tmp_path, 1e-3, scale=1000.0) is None
    micrometres = units_error(tmp_path, 1e3)
    assert "smallest element side, 3000 mm, is more than 100 times" in micrometres and "scale = 0.001" in micrometres
    assert "upper bound c = 50 mm^2" in units_error(tmp_path, 1e3, bounds=(1.0, 50.0))  # the largest l
    assert units_error(tmp_path, 1e3, bounds=(1.0, 2e5)) is None  # the largest l = 632 mm: plausible
    assert "leave scale out" in units_error(tmp_path, 1.0, scale=1000.0)  # a mesh in mm with scale = 1000
    assert units_error(tmp_path, 1e-3, model="local-damage") is None  # no internal length
    assert units_error(tmp_path, 1.0) is None


def test_the_unit_check_reads_the_models_mesh_length(tmp_path):
    """The check is the model's MeshLength's, not the damage models' c alone: a PF-CZM (h <= l / 5) on a mesh
    drawn in metres or micrometres is refused too, naming l and its unit."""
    metres = units_error(tmp_path, 1e-3, model="pf-czm", parameters=())
    assert "units.msh" in metres and "smaller than l / 5 (a fifth of the length scale) = 0.5 mm" in metres
    assert "(with l = 2.5 mm (default))" in metres and "scale = 1000" in metres
    micrometres = units_error(tmp_path, 1e3, model="pf-czm", parameters=(("l", 4.0),))
    assert "more than 100 times l / 5 (a fifth of the length scale) = 0.8 mm (with l = 4 mm)" in micrometres
    assert "that l is in mm" in micrometres
    assert units_error(tmp_path, 1.0, model="pf-czm", parameters=()) is None
    assert units_error(tmp_path, 1e-3, model="cohesive-crack", parameters=()) is None  # no length to resolve


def test_bad_specimen_fields():
    with pytest.raises(ValueError, match="thickness"):
        MeshSpecimen("x.msh", thickness=0.0, supports=(), loads=(("a", "x"),), controls=(("c", ()),))
    with pytest.raises(ValueError, match="component 'z'; use 'x' or 'y'"):
        from fracid.specimens.mesh import _component
        _component("z", "supports")


PEER = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=1.1e-4, alpha=0.99, beta=500.0, c=4.0, eta=10.0)


def test_the_notched_beam_rebuilt_from_a_gmsh_file_traces_the_built_in_curve(tmp_path):
    """The half beam's mesh written as a linear quadrilateral Gmsh mesh, its node sets as line and point groups:
    fracid rebuilds the Q8 mesh (renumbered) and the same force-CMOD curve."""
    from fracid.specimens.beam import NotchedBeam

    beam = NotchedBeam(h_fine=4.0, h_coarse=12.0)
    d = beam.describe()
    rebuilt = beam_msh(beam, tmp_path / "beam.msh")
    assert all(np.array_equal(np.sort(rebuilt.describe().nodes[rebuilt.describe().nodes_of(name)], axis=0),
                              np.sort(d.nodes[d.nodes_of(name)], axis=0)) for name in d.node_sets)
    runs = [DamageModel().simulate(s, PEER, target=0.05, stop_force_fraction=None, control="cmod")
            for s in (beam, rebuilt)]
    assert runs[1].n_steps == runs[0].n_steps and runs[0].force[-1] < 0.97 * runs[0].peak_force  # past the peak
    np.testing.assert_allclose(runs[1].control, runs[0].control, rtol=1e-9)
    np.testing.assert_allclose(runs[1].force, runs[0].force, rtol=0, atol=1e-6 * runs[0].peak_force)
    widths = [run.observables["fpz_width"] for run in runs]
    assert widths[0][-1] > 0
    np.testing.assert_allclose(widths[1], widths[0], rtol=0, atol=1e-6 * widths[0].max())
    # the discrete cohesive crack opens along the same line; the built-in beam then rests on a roller at the
    # support's centre and spreads the load over the plate (rigid plates would clamp the cracked halves)
    from dataclasses import replace

    from fracid.fem.material.cohesive import CohesiveParameters
    from fracid.models import CohesiveCrackModel

    open_crack = replace(rebuilt, supports=(("support_point", "y"),), loads=(("loading_plate", "y", False, -0.5),))
    hordijk = CohesiveParameters(E=37000.0, nu=0.2, ft=3.0, Gf=0.1)
    cracks = [CohesiveCrackModel().simulate(s, hordijk, target=0.05, stop_force_fraction=None, control="cmod",
                                            steps=beam.default_steps(0.05)) for s in (beam, open_crack)]
    assert cracks[1].n_steps == cracks[0].n_steps
    np.testing.assert_allclose(cracks[1].force, cracks[0].force, rtol=0, atol=1e-6 * cracks[0].peak_force)


CONFIG = strip_config() + "stop_force_fraction = 0.5\n\n[output]\nvtk_steps = [3]\n"


def test_a_mesh_specimen_runs_from_the_command_line(tmp_path):
    from fracid import cli

    write_msh(tmp_path / "strip.msh", *grid(6, 2, True), "triangle")
    (tmp_path / "strip.toml").write_text(CONFIG)
    assert cli.main(["simulate", str(tmp_path / "strip.toml"), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert (tmp_path / "out" / "curve.csv").exists() and any((tmp_path / "out").rglob("*.vtu"))


@pytest.mark.parametrize("replace, words", [
    ('file = "strip.msh"', ["specimen.file", "file not found"]),
    ('{group = "left", component = "x"}', ["specimen.supports[0].component", "must be one of 'x', 'y'"]),
    ('loads = [{group = "right",', ["specimen.file", "no physical group 'top'"]),
    ('elongation = [{group = "right", component = "x"}]', ["specimen.controls.elongation[0].weight", "non-zero"]),
    ('thickness = 5.0', ["specimen.thickness", "must be a number > 0"]),
])
def test_bad_mesh_configs_name_the_key(tmp_path, replace, words):
    from fracid.config import ConfigError, load_config

    write_msh(tmp_path / "strip.msh", *grid(2, 1, True), "triangle")
    broken = {'file = "strip.msh"': 'file = "none.msh"',
              '{group = "left", component = "x"}': '{group = "left", component = "z"}',
              'loads = [{group = "right",': 'loads = [{group = "top",',
              'elongation = [{group = "right", component = "x"}]': 'elongation = [{group = "right", component = "x", weight = 0}]',
              'thickness = 5.0': 'thickness = -5.0'}[replace]
    (tmp_path / "bad.toml").write_text(CONFIG.replace(replace, broken))
    with pytest.raises(ConfigError) as err:
        load_config(tmp_path / "bad.toml", purpose="simulate")
    for word in words:
        assert word in str(err.value)


@pytest.mark.slow
def test_the_triangle_meshed_beam_matches_the_built_in_q8_beam(tmp_path):
    """The beam meshed with triangles (the built-in's quadrilaterals split in two, run as T6) at h_fine 1:
    peak within 0.5 % of the built-in Q8 beam's (measured 0.36 %), force-CMOD within 1.5 % of the peak
    (measured 1.37 %; 0.36 % / 0.39 % with c = 16 mm^2, where h = 1 mm resolves l better)."""
    from fracid.specimens.beam import NotchedBeam

    points = np.linspace(0.01, 0.06, 11)

    def run(specimen):
        return DamageModel().simulate(specimen, PEER, target=0.06, stop_force_fraction=None, control="cmod",
                                      checkpoints=points)

    beam = NotchedBeam(h_fine=1.0, h_coarse=10.0)
    built_in, triangles = run(beam), run(beam_msh(beam, tmp_path / "fine.msh", triangles=True))
    assert triangles.stats.failed_increments == 0 and triangles.force[-1] < 0.95 * triangles.peak_force
    assert abs(triangles.peak_force / built_in.peak_force - 1.0) < 5e-3
    difference = np.interp(points, triangles.control, triangles.force) - np.interp(points, built_in.control, built_in.force)
    assert np.max(np.abs(difference)) < 1.5e-2 * built_in.peak_force


@pytest.mark.slow
def test_twin_identification_of_c_and_beta_on_a_triangle_meshed_beam(tmp_path):
    """Noise-free CMOD data of the gradient model on the beam meshed with triangles at (c, beta) = (4, 500):
    Gauss-Newton with the exact sensitivities from (6, 400) finds them back within 1 %."""
    from fracid.inverse.core.forward_operator import ForwardOperator, Observation
    from fracid.inverse.methods.gauss_newton import gauss_newton
    from fracid.specimens.beam import NotchedBeam

    specimen = beam_msh(NotchedBeam(h_fine=4.0, h_coarse=12.0), tmp_path / "beam.msh", triangles=True)
    operator = ForwardOperator([Observation(specimen, np.linspace(0.01, 0.08, 10), control="cmod")], PEER,
                               ("c", "beta"))
    truth = np.array([4.0, 500.0])
    y = operator(truth).y
    std = 0.01 * np.abs(y).max()
    result = gauss_newton(operator.differentiated(), y, np.eye(y.size) * std**2, np.array([6.0, 400.0]),
                          np.diag([3.0, 200.0]) ** 2, bounds=(np.array([1.0, 100.0]), np.array([20.0, 2000.0])),
                          tol=1e-3)
    np.testing.assert_allclose(result.x, truth, rtol=1e-2)


def test_an_edited_mesh_file_is_another_specimen(tmp_path):
    from fracid.store.runs import key_for

    path = write_msh(tmp_path / "strip.msh", *grid(2, 1, True), "triangle")
    first = strip(path)
    assert first == strip(path) and key_for(s=first) == key_for(s=strip(path))
    write_msh(path, *grid(3, 1, True), "triangle")
    assert key_for(s=strip(path)) != key_for(s=first)  # the run store keys differ


def test_regions_of_their_own_stiffness_stay_elastic():
    """The left half of the strip is a stiff elastic block (5 E, no damage): springs in series, and the damage
    only in the right half."""
    points, cells, left, right, corner = grid(6, 2, False)
    centres = points[cells, 0].mean(axis=1)
    blocks = [("quad", cells), ("line", left), ("line", right), ("vertex", corner)]
    groups = {"steel": {"quad": np.flatnonzero(centres < L / 2)}, "left": {"line": np.arange(len(left))},
              "right": {"line": np.arange(len(left), len(left) + len(right))}, "origin": {"vertex": np.array([0])}}
    blocks = [blocks[0], ("line", np.vstack([left, right])), blocks[3]]
    specimen = MeshSpecimen("strip", thickness=T, supports=(("left", "x"), ("origin", "y")), loads=(("right", "x"),),
                            controls=(("elongation", (("right", "x", 1.0),)),), regions=(("steel", 5.0, False),))
    description = specimen.describe_mesh(plane_mesh(points, blocks, groups))
    params = fracid.DamageParameters(E=E, nu=0.0, kappa_i=1e-4, beta=300.0, c=4.0)  # nu 0: no lateral mismatch
    result = DamageModel().simulate(description, params, target=0.006, stop_force_fraction=None,
                                    control="elongation", steps=specimen.default_steps(0.006))
    slope = result.force[1] / result.control[1]
    assert slope == pytest.approx(H * T / (0.5 * L / (5 * E) + 0.5 * L / E), rel=1e-9)
    kappa = result.fields[result.n_steps]["kappa"]
    steel = np.flatnonzero(centres < L / 2)
    assert np.all(kappa[steel] <= 1e-4 * 1.0001) and np.max(kappa) > 2e-4  # only the concrete half damaged
    with pytest.raises(MeshError, match="region 'left' is no physical surface"):
        MeshSpecimen("strip", thickness=T, supports=(), loads=(("right", "x"),), controls=(("e", (("right", "x", 1.0),)),),
                     regions=(("left", 5.0, False),)).describe_mesh(plane_mesh(points, blocks, groups))


IDENTIFY = """
[model]
type = "gradient-damage"
[model.parameters]
E = 30000.0
kappa_i = 1e-4
c = 4.0

[specimen]
type = "mesh"
file = "strip.msh"
thickness = 5.0
supports = [{group = "left", component = "x"}, {group = "origin", component = "y"}]
loads = [{group = "right", component = "x"}]
[specimen.controls]
elongation = [{group = "right", component = "x"}]

[[experiments]]
file = "curve.csv"
control_column = "elongation"
control_unit = "mm"
force_unit = "N"
kind = "single"
force_columns = ["force"]
std = 0.5
n_points = 8

[identify]
parameters = ["beta"]
[identify.bounds]
beta = [100.0, 1000.0]
[identify.knn]
n = 6
k = 2
[identify.kalman]
max_iterations = 3

[output]
directory = "results"
"""


def write_strip_twin(directory, config: str) -> None:
    """strip.msh (triangles), curve.csv (its elongation-force curve at beta = 300) and strip.toml (``config``)."""
    path = write_msh(directory / "strip.msh", *grid(6, 2, True), "triangle")
    truth = DamageModel().simulate(strip(path), fracid.DamageParameters(E=E, kappa_i=1e-4, c=4.0, beta=300.0),
                                   target=0.012, stop_force_fraction=None, checkpoints=np.linspace(0.002, 0.012, 8))
    (directory / "curve.csv").write_text("elongation,force\n" + "".join(
        f"{x:.9g},{f:.9g}\n" for x, f in zip(truth.control[1:], truth.force[1:])))
    (directory / "strip.toml").write_text(config)


def test_identify_with_a_mesh_specimen_writes_result_report_and_vtk(tmp_path):
    """fracid identify on a mesh specimen as on a built-in one: a twin of beta = 300 found back."""
    from fracid import cli

    write_strip_twin(tmp_path, IDENTIFY)
    assert cli.main(["identify", str(tmp_path / "strip.toml"), "--quiet", "--workers", "1"]) == 0
    import json

    out = tmp_path / "results"
    result = json.loads((out / "result.json").read_text())
    assert result["names"] == ["beta"] and abs(result["x"][0] / 300.0 - 1.0) < 0.05
    assert any(out.rglob("*.html"))


@pytest.mark.slow
def test_study_on_a_mesh_specimen_gives_its_verdict(tmp_path):
    """fracid study on a mesh specimen as on a built-in one: multi-start, noisy replicates and a verdict."""
    from fracid import cli
    import json

    write_strip_twin(tmp_path, IDENTIFY + "\n[study]\nstarts = 2\nreplicates = 2\n")
    assert cli.main(["study", str(tmp_path / "strip.toml"), "--quiet", "--workers", "2"]) == 0
    study = json.loads((tmp_path / "results" / "study.json").read_text())
    [verdict] = study["verdict"]["parameters"]
    assert verdict["name"] == "beta" and verdict["status"] == "identified"
    assert len(study["multi_start"]["ends"]) == 2 and len(study["stability"]["estimates"]) == 2
    assert (tmp_path / "results" / "report.html").exists() and not (tmp_path / "results" / "size_effect.csv").exists()
    assert cli.main(["size-effect", str(tmp_path / "strip.toml"), "--quiet"]) == 2  # no size to scale: a message
