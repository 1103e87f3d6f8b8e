"""Named scalar fields in the dof map and the discretisation, and declared history: counts, numbering,
blocks, the scalar spaces' interpolation, the history allocation and the element arrays' outputs."""

import numpy as np
import pytest

from fracid.fem.mesh.discretization import bar_discretization, plane_stress_discretization
from fracid.fem.mesh.dofs import Conditions, FieldSpec, number_dofs
from fracid.fem.formulations.forms import ElementArrays
from fracid.fem.formulations.protocol import HistoryVariable, allocate_history, initial_history
from fracid.specimens.meshing import structured_quad8, structured_tri6

N_EL = 4  # bar elements: 9 displacement nodes, 5 vertices


def bar_conditions(n_el=N_EL, tied=()):
    end = 2 * n_el
    return Conditions(load={end: 1.0}, functionals={"end": {end: 1.0}}, fixed_dofs=(0,), tied=tied)


def two_field_map(**kwargs):
    disc = bar_discretization(np.linspace(0.0, 40.0, N_EL + 1), 2.0)
    return disc, number_dofs(disc, bar_conditions(**kwargs), [FieldSpec("a", "linear"), FieldSpec("b", "quadratic")])


def test_counts_blocks_and_numbering_of_two_fields_of_different_orders():
    disc, dofs = two_field_map()
    n_u, n_a, n_b = 2 * N_EL + 1, N_EL + 1, 2 * N_EL + 1
    assert dofs.n_dofs == n_u + n_a + n_b and dofs.n_free == n_u - 1 + n_a + n_b
    # unknowns: the free displacements first, then a's nodes, then b's, each in node order
    np.testing.assert_array_equal(dofs.blocks["u"], np.arange(n_u - 1))
    np.testing.assert_array_equal(dofs.blocks["a"], n_u - 1 + np.arange(n_a))
    np.testing.assert_array_equal(dofs.blocks["b"], n_u - 1 + n_a + np.arange(n_b))
    assert list(dofs.blocks) == ["u", "a", "b"] and [f.name for f in dofs.fields] == ["a", "b"]
    # element columns: 3 displacement, 2 linear, 3 quadratic
    assert dofs.columns == {"u": slice(0, 3), "a": slice(3, 5), "b": slice(5, 8)}
    assert dofs.element_dofs.shape == (N_EL, 8)
    np.testing.assert_array_equal(dofs.element_dofs[0], [-1, 0, 1, 8, 9, 13, 14, 15])
    np.testing.assert_array_equal(dofs.element_dofs[-1], [5, 6, 7, 11, 12, 19, 20, 21])
    assert dofs.ranges == {"u": slice(0, n_u), "a": slice(n_u, n_u + n_a), "b": slice(n_u + n_a, n_u + n_a + n_b)}
    # load and functional act on the displacement of the end only
    assert np.flatnonzero(dofs.load_vector).tolist() == [n_u - 2] and dofs.functionals["end"][n_u - 2] == 1.0


def test_split_full_vector_and_restrict_round_trip():
    disc, dofs = two_field_map()
    q = np.arange(1.0, dofs.n_free + 1.0)
    parts = dofs.split(q)
    assert parts["u"][0] == 0.0 and parts["u"].size == disc.n_u_dofs  # the fixed dof
    np.testing.assert_array_equal(parts["a"], q[dofs.blocks["a"]])
    np.testing.assert_array_equal(parts["b"], q[dofs.blocks["b"]])
    full = dofs.full_vector(q)
    np.testing.assert_array_equal(full, np.concatenate([parts["u"], parts["a"], parts["b"]]))
    np.testing.assert_array_equal(dofs.restrict(full), q)
    # gathered element values follow the columns
    qe = dofs.gather(q)
    np.testing.assert_array_equal(qe[:, dofs.columns["b"]], parts["b"][disc.spaces["quadratic"].nodes])
    with pytest.raises(ValueError, match="at most 23 dof values"):
        dofs.restrict(np.zeros(dofs.n_dofs + 1))


def test_tied_groups_share_one_unknown_and_fields_come_after():
    _, dofs = two_field_map(tied=((6, 8),))
    assert dofs.free_index[6] == dofs.free_index[8] and dofs.blocks["u"].size == 2 * N_EL - 1
    assert dofs.blocks["a"][0] == dofs.blocks["u"].max() + 1


@pytest.mark.parametrize("mesh", [structured_quad8, structured_tri6])
def test_two_fields_on_a_plane_mesh(mesh):
    m = mesh(np.array([0.0, 2.0, 5.0]), np.array([0.0, 3.0]))
    disc = plane_stress_discretization(m.nodes, m.cells, m.n_vertices, 1.0)
    conditions = Conditions(load={1: 1.0}, functionals={"v": {1: 1.0}}, fixed_dofs=(0,))
    dofs = number_dofs(disc, conditions, {"p": "quadratic", "s": "linear"})
    n_nodes = len(m.nodes)
    assert dofs.n_free == 2 * n_nodes - 1 + n_nodes + m.n_vertices
    assert [dofs.blocks[f].size for f in ("u", "p", "s")] == [2 * n_nodes - 1, n_nodes, m.n_vertices]
    width = m.cells.shape[1]
    assert dofs.columns == {"u": slice(0, 2 * width), "p": slice(2 * width, 3 * width),
                            "s": slice(3 * width, 3 * width + width // 2 + width % 2)}
    # p's element dofs are the cell's nodes, s's its corners, each after all of u
    np.testing.assert_array_equal(dofs.element_dofs[:, dofs.columns["p"]], 2 * n_nodes - 1 + m.cells)
    n_corners = dofs.columns["s"].stop - dofs.columns["s"].start
    np.testing.assert_array_equal(dofs.element_dofs[:, dofs.columns["s"]], 3 * n_nodes - 1 + m.cells[:, :n_corners])


@pytest.mark.parametrize("mesh", [structured_quad8, structured_tri6])
def test_scalar_spaces_interpolate_linear_fields_exactly(mesh):
    """Both spaces reproduce f = 2 + 3 x - y: its value at the points and its gradient (3, -1)."""
    m = mesh(np.array([0.0, 2.0, 5.0]), np.array([0.0, 1.5, 3.0]),
             mapping=lambda s, t: (s + 0.1 * t * t, t + 0.05 * s * t))
    disc = plane_stress_discretization(m.nodes, m.cells, m.n_vertices, 1.0)
    f = lambda xy: 2.0 + 3.0 * xy[..., 0] - xy[..., 1]  # noqa: E731
    for name, nodes in (("linear", m.nodes[: m.n_vertices]), ("quadratic", m.nodes)):
        space = disc.space(name)
        values = f(nodes)[space.nodes]
        if name == "quadratic":  # the curved map is isoparametric with the quadratic space only
            np.testing.assert_allclose(values @ space.shape.T, f(disc.points), rtol=1e-12)
            np.testing.assert_allclose(np.einsum("eqdi,ei->eqd", space.gradient, values),
                                       np.broadcast_to([3.0, -1.0], disc.points.shape), atol=1e-12)
        np.testing.assert_allclose(space.shape.sum(axis=1), 1.0, rtol=1e-14)
        np.testing.assert_allclose(space.gradient.sum(axis=-1), 0.0, atol=1e-12)
    with pytest.raises(ValueError, match=r"unknown scalar space 'cubic'.*\['linear', 'quadratic'\]"):
        disc.space("cubic")


def test_bar_spaces():
    x = np.array([0.0, 1.0, 3.0, 6.0])
    disc = bar_discretization(x, 1.0)
    nodes = {"linear": x, "quadratic": np.insert(x, np.arange(1, 4), 0.5 * (x[:-1] + x[1:]))}
    for name, coordinates in nodes.items():
        space = disc.space(name)
        assert space.n_nodes == coordinates.size
        values = (coordinates**2 if name == "quadratic" else coordinates)[space.nodes]
        exact = disc.points[..., 0] ** 2 if name == "quadratic" else disc.points[..., 0]
        np.testing.assert_allclose(values @ space.shape.T, exact, rtol=1e-13)
    assert not hasattr(disc, "ebar_dofs")  # "ebar" is the gradient model's own name, not the discretisation's


def test_bad_field_declarations_are_named():
    disc = bar_discretization(np.linspace(0.0, 4.0, 3), 1.0)
    with pytest.raises(ValueError, match="unknown scalar space 'cubic'"):
        number_dofs(disc, bar_conditions(2), {"phi": "cubic"})
    with pytest.raises(ValueError, match="each named field must appear once"):
        number_dofs(disc, bar_conditions(2), [FieldSpec("phi"), FieldSpec("phi", "quadratic")])
    with pytest.raises(ValueError, match="other than 'u'"):
        FieldSpec("u")
    with pytest.raises(ValueError, match="other than 'u'"):
        FieldSpec("not a name")


def test_history_is_allocated_from_its_declaration():
    disc = bar_discretization(np.linspace(0.0, 4.0, 3), 1.0)  # 2 elements x 3 points
    single = allocate_history({"kappa": ()}, disc)
    assert isinstance(single, np.ndarray) and single.shape == (2, 3) and not single.any()
    several = allocate_history({"eps_max": (), "back_stress": (2,), "w_max": HistoryVariable(points=(5, 2), initial=1.5)},
                               disc)
    assert {k: v.shape for k, v in several.items()} == {"eps_max": (2, 3), "back_stress": (2, 3, 2), "w_max": (5, 2)}
    assert np.all(several["w_max"] == 1.5)
    with pytest.raises(ValueError, match="history_spec"):
        allocate_history({}, disc)
    with pytest.raises(ValueError, match="HistoryVariable shape"):
        HistoryVariable(shape=(-1,))

    class Declared:  # a problem that declares its history and writes no initial_history()
        history_spec = {"kappa": (), "d": ()}

    Declared.disc = disc
    assert set(initial_history(Declared())) == {"kappa", "d"}


def test_element_arrays_carry_history_and_named_outputs():
    history, omega, stress = np.ones((2, 3)), np.full((2, 3), 0.5), np.full((2, 3), 7.0)
    arrays = ElementArrays(np.zeros((2, 4)), np.zeros((2, 4, 4)), {}, history, outputs={"stress": stress})
    assert arrays.history is history and arrays.outputs == {"stress": stress}
    assert not hasattr(ElementArrays, "kappa")  # the history has no formulation's name
    with pytest.raises(AttributeError, match="no point output 'omega'"):
        arrays.omega
    damaged = ElementArrays(np.zeros((2, 4)), np.zeros((2, 4, 4)), {}, history, outputs={"omega": omega})
    assert damaged.omega is omega and damaged.outputs == {"omega": omega}
    replaced = damaged._replace(history=2 * history)
    assert np.all(replaced.history == 2.0) and replaced.omega is omega
