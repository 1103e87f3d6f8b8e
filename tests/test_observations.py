"""Observations as objects: the point-probe operator (fracid.fem.mesh.probes), the field observation kind
and the curve kind behind the ObservationKind protocol of the forward operator."""

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

from fracid.fem.mesh.elements import quad_serendipity, triangle_quadratic
from fracid.fem.mesh.probes import dof_matrix, locate, probe_matrix
from fracid.inverse.core.forward_operator import FieldObservation, ForwardOperator, Observation, ObservationKind
from fracid.inverse.core.probed import ProbedSpecimen, merge_probes
from fracid.inverse.core.runs import run_key
from fracid.models import DamageModel, StepOptions
from fracid.specimens import SPECIMENS
from fracid.specimens.meshing import structured_quad8, structured_tri6

RNG = np.random.default_rng(7)


def _curved(s, t):  # a non-affine map: curved elements, isoparametric geometry
    return s + 0.08 * np.sin(t), t + 0.05 * s**2


def _sheared(s, t):  # an affine map: quadratic fields are reproduced exactly
    return 2.0 * s + 0.6 * t, 0.4 * s + 1.5 * t


MESHES = {
    "quad8": structured_quad8,
    "tri6": structured_tri6,
}
SHAPES = {"quad8": (quad_serendipity, lambda n: RNG.uniform(-1, 1, (n, 2))),
          "tri6": (triangle_quadratic, lambda n: _in_triangle(RNG.uniform(0, 1, (n, 2))))}


def _in_triangle(r):
    return np.where(r.sum(axis=1, keepdims=True) > 1.0, 1.0 - r[:, ::-1], r)


def _mesh(kind, mapping):
    return MESHES[kind](np.linspace(0, 3, 5), np.linspace(0, 2, 4), mapping=mapping)


def _random_points(kind, mesh, n=60):
    """Points at random reference coordinates of random elements, and those elements."""
    functions, draw = SHAPES[kind]
    element = RNG.integers(0, len(mesh.cells), n)
    N, _ = functions(draw(n))
    return np.einsum("pa,pai->pi", N, mesh.nodes[mesh.cells[element]]), element


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_probes_reproduce_a_linear_field_on_curved_elements(kind):
    mesh = _mesh(kind, _curved)
    points, element = _random_points(kind, mesh)
    P = probe_matrix(mesh.nodes, mesh.cells, points)
    assert sp.isspmatrix_csr(P) and P.shape == (len(points), len(mesh.nodes))
    field = 1.5 - 0.7 * mesh.nodes[:, 0] + 2.2 * mesh.nodes[:, 1]
    np.testing.assert_allclose(P @ field, 1.5 - 0.7 * points[:, 0] + 2.2 * points[:, 1], rtol=0, atol=1e-11)
    np.testing.assert_allclose(P.sum(axis=1).A1, 1.0, atol=1e-12)
    found, _ = locate(mesh.nodes, mesh.cells, points)
    np.testing.assert_array_equal(found, element)  # random interior points: one element holds each


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_probes_reproduce_a_quadratic_field_on_affine_elements(kind):
    mesh = _mesh(kind, _sheared)
    points, _ = _random_points(kind, mesh)

    def quadratic(xy):
        x, y = xy[:, 0], xy[:, 1]
        return 0.3 + x - 2 * y + 0.5 * x * x - 0.8 * x * y + 1.2 * y * y

    P = probe_matrix(mesh.nodes, mesh.cells, points)
    np.testing.assert_allclose(P @ quadratic(mesh.nodes), quadratic(points), rtol=0, atol=1e-10)
    # the vector form: component c of node j is dof 2 j + c
    u = np.column_stack([quadratic(mesh.nodes), -2.0 * quadratic(mesh.nodes)]).ravel()
    np.testing.assert_allclose(dof_matrix(P, 1) @ u, -2.0 * quadratic(points), atol=1e-10)
    np.testing.assert_allclose(dof_matrix(P, 0) @ u, quadratic(points), atol=1e-10)


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_probes_at_nodes_and_on_edges(kind):
    mesh = _mesh(kind, _curved)
    P = probe_matrix(mesh.nodes, mesh.cells, mesh.nodes)  # every node, corners and mid-edge nodes alike
    np.testing.assert_allclose(P.toarray(), np.eye(len(mesh.nodes)), atol=1e-10)
    # points on the edges shared by two elements (between a corner and a mid-edge node of the map)
    functions, _ = SHAPES[kind]
    edge = np.array([[0.5, -1.0], [1.0, 0.25]]) if kind == "quad8" else np.array([[0.3, 0.0], [0.6, 0.4]])
    N, _ = functions(edge)
    points = np.einsum("pa,ai->pi", N, mesh.nodes[mesh.cells[5]])
    field = np.sin(mesh.nodes[:, 0]) + mesh.nodes[:, 1] ** 2
    values = probe_matrix(mesh.nodes, mesh.cells, points) @ field
    np.testing.assert_allclose(values, N @ field[mesh.cells[5]], atol=1e-10)  # continuous across the edge


def test_points_outside_the_mesh_are_named():
    mesh = _mesh("quad8", None)
    inside = np.array([[1.0, 1.0], [3.0, 2.0]])  # an interior point, a corner of the domain
    probe_matrix(mesh.nodes, mesh.cells, inside)
    with pytest.raises(ValueError, match=r"2 of 4 points are outside the mesh: point 1 \(3.5, 1\), 3 \(-0.001, 0.5\)"):
        probe_matrix(mesh.nodes, mesh.cells, [[1.0, 1.0], [3.5, 1.0], [0.5, 0.5], [-1e-3, 0.5]])
    with pytest.raises(ValueError, match="points has shape"):
        probe_matrix(mesh.nodes, mesh.cells, [1.0, 1.0])
    with pytest.raises(ValueError, match="nodes"):
        probe_matrix(mesh.nodes, mesh.cells[:, :5], inside)
    with pytest.raises(ValueError, match="component = 2"):
        dof_matrix(probe_matrix(mesh.nodes, mesh.cells, inside), 2)


def test_a_corner_field_is_probed_with_the_linear_family():
    mesh = _mesh("quad8", _curved)
    corners = mesh.cells[:, :4]
    points, _ = _random_points("quad8", mesh)
    P = probe_matrix(mesh.nodes[: mesh.n_vertices], corners, points)
    assert P.shape == (len(points), mesh.n_vertices)
    np.testing.assert_allclose(P.sum(axis=1).A1, 1.0, atol=1e-12)
    # a field bilinear in the reference coordinates of a straight grid is reproduced
    straight = _mesh("quad8", None)
    xy = straight.nodes[: straight.n_vertices]
    P = probe_matrix(xy, straight.cells[:, :4], points.clip([0, 0], [3, 2]))
    field = 1 + xy[:, 0] - xy[:, 1]
    np.testing.assert_allclose(P @ field, 1 + points.clip([0, 0], [3, 2]) @ [1, -1], atol=1e-11)


# ------------------------------------------------------------------------------------------------
# the field kind on a coarse notched beam (gradient damage), through the forward operator


N_STEPS = 10
NAMES = ("kappa_i", "beta")
POINTS = np.array([[5.0, 30.0], [20.0, 10.0], [2.0, 45.0], [0.5, 25.5]])  # half beam x >= 0, notch 25 deep


@pytest.fixture(scope="module")
def beam_case():
    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0, fine_width=12)
    model = DamageModel("gradient")
    params = model.parameters()
    target = 0.5 * model.default_target(beam, params)
    # one step per checkpoint, the same sequence in every run (no jump to the onset, no growth)
    steps = StepOptions(initial=target / N_STEPS, onset_fraction=1.0, max_factor=1.0, jump_to_onset=False)
    control = np.linspace(0.0, target, N_STEPS + 1)[1:]
    field = FieldObservation(beam, POINTS, control[[2, 5, 9]], name="dic")
    operator = ForwardOperator([Observation(beam, control), field], params, NAMES, model=model, steps=steps,
                               sensitivities=True)
    x = np.array([getattr(params, n) for n in NAMES])
    return beam, model, params, steps, control, field, operator, x, operator(x)


def test_the_field_kind_is_an_observation_kind_with_coordinates(beam_case):
    beam, *_, field, operator, _, record = beam_case
    assert isinstance(field, ObservationKind) and isinstance(operator.observations[0], ObservationKind)
    assert field.size == 3 * 2 * len(POINTS) and operator.n_outputs == N_STEPS + field.size
    c = field.coordinates()
    assert all(len(v) == field.size for v in c.values())
    np.testing.assert_array_equal(c["control"], field.controls)
    np.testing.assert_array_equal(c["x"][:4], POINTS[:, 0])  # frame, then component, then point
    assert c["component"].tolist() == ([0] * 4 + [1] * 4) * 3 and c["frame"].tolist() == [0] * 8 + [1] * 8 + [2] * 8
    assert record.ok and record.S is not None and np.all(np.isfinite(record.S))
    with pytest.raises(ValueError, match=r"outside the mesh: point 1 \(200, 10\)"):
        FieldObservation(beam, [[5.0, 30.0], [200.0, 10.0]], [0.01])
    with pytest.raises(ValueError, match="components"):
        FieldObservation(beam, POINTS, [0.01], components=(2,))


def test_the_sampled_field_is_the_nodal_field_interpolated(beam_case):
    beam, model, params, steps, control, field, operator, _, record = beam_case
    run = model.simulate(beam, params, target=control[-1], steps=steps, checkpoints=control, field_steps="all",
                         stop_force_fraction=None)
    d = beam.describe()
    P = probe_matrix(d.nodes, d.cells, POINTS)
    expected = []
    for frame in field.frames:
        step = int(np.argmin(np.abs(run.control - frame)))
        assert abs(run.control[step] - frame) < 1e-12
        u = run.fields[step]["u"]
        expected += [dof_matrix(P, c) @ u for c in (0, 1)]
    y = record.y[operator.slices()[1]]  # (the operator's run also differentiates: Newton's tolerance apart)
    np.testing.assert_allclose(y, np.concatenate(expected), rtol=0, atol=1e-8 * np.abs(y).max())
    np.testing.assert_allclose(record.y[: N_STEPS], np.interp(control, run.control, run.force), rtol=1e-8)
    assert np.abs(y).max() > 1e-3  # the field is not trivially zero


def test_field_sensitivities_match_central_differences(beam_case):
    *_, operator, x, record = beam_case
    plain = ForwardOperator(operator.observations, operator.base, NAMES, model=operator.model, steps=operator.steps)
    block = operator.slices()[1]
    for j in range(len(NAMES)):
        h = 1e-6 * x[j]
        plus, minus = (plain(x + sign * h * np.eye(len(x))[j]) for sign in (1.0, -1.0))
        difference = (plus.y - minus.y) / (2 * h)
        scale = np.abs(difference[block]).max()
        assert scale > 0
        np.testing.assert_allclose(record.S[block, j], difference[block], rtol=0, atol=1e-4 * scale)
        np.testing.assert_allclose(record.S[: N_STEPS, j], difference[: N_STEPS], rtol=0,
                                   atol=1e-4 * np.abs(difference[: N_STEPS]).max())


def test_needed_outputs_stop_the_run_at_the_frames_asked(beam_case):
    *_, field, operator, x, record = beam_case
    first = ForwardOperator([field, operator.observations[0]], operator.base, NAMES, model=operator.model,
                            steps=operator.steps)
    needed = 2 * len(POINTS) + 1  # the first frame and one value of the second
    partial = first(x, needed=needed)
    assert partial.reached == [pytest.approx(field.frames[1])]  # the run stopped at the second frame
    block = operator.slices()[1]
    np.testing.assert_allclose(partial.y[:needed], record.y[block][:needed], rtol=1e-8)


def test_run_keys_tell_field_observations_apart(beam_case):
    beam, model, params, steps, control, field, operator, x, _ = beam_case
    other = FieldObservation(beam, POINTS[:3], field.frames, name="dic")
    moved = ForwardOperator([operator.observations[0], other], params, NAMES, model=model, steps=steps)
    same = ForwardOperator(operator.observations, params, NAMES, model=model, steps=steps)
    assert run_key(same, x) != run_key(moved, x)
    assert run_key(same, x) == run_key(ForwardOperator(operator.observations, params, NAMES, model=model,
                                                        steps=steps), x)


def test_the_curve_kind_is_unchanged():
    bar = SPECIMENS["bar"]()
    obs = Observation(bar, [0.01, 0.02], quantity="damaged_zone_width", damage_threshold=0.5)
    assert obs.size == 2 and obs.observables == ("damaged_zone_width",) and obs.probes == {}
    assert obs.run_key[1:] == (None, 0.5) and Observation(bar, [0.01]).run_key[2] is None
    assert obs.differentiable_with(DamageModel()) and not obs.differentiable_with(object())
    assert obs.key() == {"specimen": bar, "points": [0.01, 0.02], "quantity": "damaged_zone_width", "control": None,
                         "damage_threshold": 0.5}
    with pytest.raises(TypeError, match="sequence of Observation"):
        ForwardOperator([np.zeros(3)], DamageModel().parameters(), ("c",))


def test_probed_specimen_adds_functionals_and_names_bad_probes():
    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0, fine_width=12)
    d = ProbedSpecimen(beam, {"p": ((3, 1, 0.5), (4, 1, 0.5))}).describe()
    assert d.functionals["p"][0].weight == 0.5 and d.nodes_of(d.functionals["p"][1].nodes).tolist() == [4]
    assert set(d.functionals) - {"p"} == set(beam.describe().functionals)
    assert ProbedSpecimen(beam, {}).default_control == beam.default_control  # the rest is the specimen's
    with pytest.raises(ValueError, match=r"probes \['cmod'\] are functionals of the specimen"):
        ProbedSpecimen(beam, {"cmod": ((3, 0, 1.0),)}).describe()
    with pytest.raises(ValueError, match="outside the mesh"):
        ProbedSpecimen(beam, {"p": ((10**6, 0, 1.0),)}).describe()
    with pytest.raises(ValueError, match="components \\[2\\]"):
        ProbedSpecimen(beam, {"p": ((3, 2, 1.0),)}).describe()
    with pytest.raises(ValueError, match="triples"):
        ProbedSpecimen(beam, {"p": (3, 0, 1.0)})
    one, other = (SimpleNamespace(probes={"dic:ux[0]": ((node, 0, 1.0),)}) for node in (3, 4))
    with pytest.raises(ValueError, match="define the probe 'dic:ux\\[0\\]' differently"):
        merge_probes([one, other])


# ------------------------------------------------------------------------------------------------
# missing values: the keep mask of a field observation


def _fake_run(values, derivatives):
    return SimpleNamespace(probed_at=lambda frames: (values, derivatives))


def test_keep_restricts_size_controls_coordinates_and_sample(beam_case):
    beam, *_ = beam_case
    frames = [0.01, 0.02, 0.03]
    full = FieldObservation(beam, POINTS, frames, name="dic")
    keep = np.ones((3, 2, len(POINTS)), dtype=bool)
    keep[0, :, 1] = False  # a hole at point 1 in frame 0 (both components)
    keep[2, 1, 3] = False  # v of point 3 in frame 2
    kept = FieldObservation(beam, POINTS, frames, name="dic", keep=keep)
    flat = keep.ravel()
    assert kept.size == full.size - 3 == int(flat.sum())
    np.testing.assert_array_equal(kept.controls, full.controls[flat])
    assert np.all(np.diff(kept.controls) >= 0)
    for name, values in full.coordinates().items():
        np.testing.assert_array_equal(kept.coordinates()[name], values[flat])
    dropped = kept.coordinates()
    assert (0, 1) not in set(zip(dropped["frame"][dropped["component"] == 0].tolist(),
                                 dropped["point"][dropped["component"] == 0].tolist()))
    values = np.arange(full.size, dtype=float).reshape(3, -1)  # (frames, components x points)
    derivatives = np.stack([values, -2 * values], axis=-1)
    y, S = kept.sample(_fake_run(values, derivatives))
    np.testing.assert_array_equal(y, np.flatnonzero(flat))  # the entry numbers of the kept entries
    np.testing.assert_array_equal(S, np.column_stack([y, -2 * y]))
    y, S = kept.sample(_fake_run(values, None))
    assert S is None and y.size == kept.size
    assert kept.key() != full.key() and full.keep is None


def test_keep_is_checked(beam_case):
    beam, *_ = beam_case
    with pytest.raises(ValueError, match=r"keep has dtype int64 and shape \(3,\); give booleans of shape \(1, 2, 4\)"):
        FieldObservation(beam, POINTS, [0.01], keep=np.ones(3, dtype=int))
    with pytest.raises(ValueError, match="keep holds no True value"):
        FieldObservation(beam, POINTS, [0.01], keep=np.zeros(8, dtype=bool))


def test_a_kept_field_through_the_operator_is_the_full_field_restricted(beam_case):
    beam, model, params, steps, control, field, operator, x, record = beam_case
    keep = np.ones(field.size, dtype=bool)
    keep[[1, 5, 9, 20]] = False
    kept = FieldObservation(beam, POINTS, field.frames, name="dic", keep=keep)
    partial = ForwardOperator([operator.observations[0], kept], params, NAMES, model=model, steps=steps,
                              sensitivities=True)(x)
    full_block, kept_block = operator.slices()[1], slice(N_STEPS, N_STEPS + kept.size)
    np.testing.assert_allclose(partial.y[kept_block], record.y[full_block][keep], rtol=0,
                               atol=1e-8 * np.abs(record.y[full_block]).max())
    np.testing.assert_allclose(partial.S[kept_block], record.S[full_block][keep], rtol=1e-6,
                               atol=1e-8 * np.abs(record.S[full_block]).max())
