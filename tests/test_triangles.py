"""Mixed 6-node triangles (quadratic displacement, linear nonlocal strain) beside the 8-node quadrilaterals:
reference element, patch test, and the forward models on a triangulated tension strip."""

from dataclasses import dataclass
from math import factorial

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spl

import fracid
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.fem.mesh.discretization import plane_stress_discretization
from fracid.fem.material.elasticity import plane_stress_matrix
from fracid.fem.mesh.elements import gauss_triangle, triangle_linear, triangle_quadratic
from fracid.fem.path.path_following import StepOptions
from fracid.models import CrackBandModel, DamageModel
from fracid.specimens.description import CrackPath, Description, Load, Measure, Support, ZoneWidth
from fracid.specimens.meshing import structured_quad8, structured_tri6

T6_NODES = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]])
RNG_POINTS = np.random.default_rng(0).dirichlet(np.ones(3), size=20)[:, 1:]  # inside the reference triangle


# reference element


@pytest.mark.parametrize("shape, nodes", [(triangle_quadratic, T6_NODES), (triangle_linear, T6_NODES[:3])],
                         ids=["T6", "T3"])
def test_shape_functions_partition_kronecker_and_derivatives(shape, nodes):
    N, dN = shape(RNG_POINTS)
    assert N.shape == (20, len(nodes)) and dN.shape == (20, len(nodes), 2)
    np.testing.assert_allclose(N.sum(axis=1), 1.0, atol=1e-14)  # partition of unity
    np.testing.assert_allclose(dN.sum(axis=1), 0.0, atol=1e-13)
    np.testing.assert_allclose(shape(nodes)[0], np.eye(len(nodes)), atol=1e-14)  # Kronecker property
    h = 1e-6
    for axis in range(2):
        step = np.zeros(2)
        step[axis] = h
        central = (shape(RNG_POINTS + step)[0] - shape(RNG_POINTS - step)[0]) / (2 * h)
        np.testing.assert_allclose(dN[..., axis], central, atol=1e-8)
    # the shape functions interpolate the linear (T3) or quadratic (T6) polynomials exactly
    x, y = RNG_POINTS.T
    X, Y = nodes.T
    np.testing.assert_allclose(N @ (2 * X - 3 * Y + 1), 2 * x - 3 * y + 1, atol=1e-14)
    if len(nodes) == 6:
        np.testing.assert_allclose(N @ (X * X - X * Y + 2 * Y * Y), x * x - x * y + 2 * y * y, atol=1e-14)


@pytest.mark.parametrize("degree, n_points", [(1, 1), (2, 3), (3, 6), (4, 6), (5, 7), (6, 16), (9, 36)])
def test_gauss_triangle_integrates_monomials_exactly(degree, n_points):
    points, weights = gauss_triangle(degree)
    assert points.shape == (n_points, 2) and weights.shape == (n_points,)
    assert np.all(weights > 0) and weights.sum() == pytest.approx(0.5, abs=1e-15)
    assert np.all(points > 0) and np.all(points.sum(axis=1) < 1)  # inside the triangle
    for a in range(degree + 1):
        for b in range(degree + 1 - a):
            exact = factorial(a) * factorial(b) / factorial(a + b + 2)
            assert np.sum(weights * points[:, 0] ** a * points[:, 1] ** b) == pytest.approx(exact, rel=1e-13, abs=1e-16)
    with pytest.raises(ValueError, match="degree"):
        gauss_triangle(0)


# patch test


def distorted_t6_mesh(n=4, size=8.0, seed=3):
    """n x n squares split into T6, interior vertices moved by up to 20 % of h, mid-edge nodes at edge midpoints."""
    mesh = structured_tri6(np.linspace(0.0, size, n + 1), np.linspace(0.0, size, n + 1))
    nodes, nv, h = mesh.nodes.copy(), mesh.n_vertices, size / n
    x, y = nodes[:nv].T
    inner = np.flatnonzero((x > 0) & (x < size) & (y > 0) & (y < size))
    nodes[inner] += np.random.default_rng(seed).uniform(-0.2 * h, 0.2 * h, (inner.size, 2))
    for corners, mids in (((0, 1), 3), ((1, 2), 4), ((2, 0), 5)):
        nodes[mesh.cells[:, mids]] = 0.5 * (nodes[mesh.cells[:, corners[0]]] + nodes[mesh.cells[:, corners[1]]])
    return nodes, mesh.cells, nv


def assembled(element_matrices, dofs, n):
    """The (n, n) sparse matrix of element matrices (n_el, k, k) on their global ``dofs`` (n_el, k)."""
    rows = np.repeat(dofs, dofs.shape[1], axis=1).ravel()
    cols = np.tile(dofs, (1, dofs.shape[1])).ravel()
    return sp.csr_matrix((element_matrices.ravel(), (rows, cols)), shape=(n, n))


def test_patch_test_linear_displacement_on_distorted_t6_mesh():
    nodes, cells, nv = distorted_t6_mesh()
    disc = plane_stress_discretization(nodes, cells, nv, thickness=2.0)
    assert disc.weights.shape == (len(cells), 6) and disc.strain_operator.shape == (len(cells), 6, 3, 12)
    assert disc.weights.sum() == pytest.approx(64.0 * 2.0, rel=1e-13)
    B, D = disc.strain_operator, 25000.0 * plane_stress_matrix(0.25)
    K = assembled(np.einsum("eqsi,st,eqtj,eq->eij", B, D, B, disc.weights), disc.u_dofs, disc.n_u_dofs)
    A, c = np.array([[1e-3, 2e-4], [-5e-4, 3e-3]]), np.array([0.1, -0.2])
    exact = (nodes @ A.T + c).ravel()
    on_side = (np.abs(nodes) < 1e-12) | (np.abs(nodes - 8.0) < 1e-12)
    boundary = np.flatnonzero(on_side.any(axis=1))
    fixed = np.concatenate([2 * boundary, 2 * boundary + 1])
    free = np.setdiff1d(np.arange(disc.n_u_dofs), fixed)
    u = exact.copy()
    u[free] = spl.spsolve(K[free][:, free].tocsc(), -(K[free][:, fixed] @ exact[fixed]))
    assert np.abs(u - exact).max() < 1e-10 * np.abs(exact).max()
    strain = np.einsum("eqsi,ei->eqs", B, u[disc.u_dofs]).reshape(-1, 3)
    np.testing.assert_allclose(strain, np.broadcast_to([A[0, 0], A[1, 1], A[0, 1] + A[1, 0]], strain.shape), atol=1e-13)


def test_ebar_diffusion_matrix_on_distorted_t6_mesh():
    nodes, cells, nv = distorted_t6_mesh()
    disc = plane_stress_discretization(nodes, cells, nv, thickness=1.0)
    linear = disc.space("linear")
    dofs = linear.nodes
    N, G, w = linear.shape, linear.gradient, disc.weights
    M = assembled(np.einsum("qa,qb,eq->eab", N, N, w), dofs, linear.n_nodes)
    L = assembled(np.einsum("eqia,eqib,eq->eab", G, G, w), dofs, linear.n_nodes)
    ones = np.ones(linear.n_nodes)
    assert ones @ M @ ones == pytest.approx(64.0, rel=1e-13)  # the mass matrix sums to the area
    np.testing.assert_allclose(L @ ones, 0.0, atol=1e-12)  # the gradient term annihilates a constant
    # a linear field e = a.x: (L e)_v = int grad N_v . a = int_boundary N_v a.n ds (Green), i.e. a.n times
    # half the adjacent boundary edges at a boundary vertex, zero at the interior ones
    a = np.array([0.3, -0.7])
    e = nodes[:nv] @ a
    expected = np.zeros(nv)
    for axis in range(2):
        for coordinate, sign in ((0.0, -1.0), (8.0, 1.0)):
            side = np.flatnonzero(np.abs(nodes[:nv, axis] - coordinate) < 1e-12)
            side = side[np.argsort(nodes[side, 1 - axis])]
            half_edges = 0.5 * np.diff(nodes[side, 1 - axis])
            np.add.at(expected, side[:-1], sign * a[axis] * half_edges)
            np.add.at(expected, side[1:], sign * a[axis] * half_edges)
    np.testing.assert_allclose(L @ e, expected, atol=1e-12)
    assert ones @ M @ e == pytest.approx(64.0 * a @ [4.0, 4.0], rel=1e-12)  # int e dA: the square's centroid


def test_inverted_triangle_is_reported():
    nodes, cells, nv = distorted_t6_mesh()
    bad = cells.copy()
    bad[5, [1, 2, 3, 5]] = bad[5, [2, 1, 5, 3]]  # clockwise: corners 1 and 2 swapped, mid-edge nodes with them
    with pytest.raises(ValueError, match=r"elements \[5\] are inverted or degenerate \(Jacobian <= 0\)"):
        plane_stress_discretization(nodes, bad, nv, thickness=1.0)
    flat = nodes.copy()
    flat[cells[7, 2]] = 0.5 * (flat[cells[7, 0]] + flat[cells[7, 1]])  # a corner on the opposite edge
    with pytest.raises(ValueError, match="inverted or degenerate"):
        plane_stress_discretization(flat, cells, nv, thickness=1.0)
    with pytest.raises(ValueError, match="corners"):
        plane_stress_discretization(nodes, cells[:, [3, 1, 2, 0, 4, 5]], nv, thickness=1.0)
    with pytest.raises(ValueError, match=r"\(n_el, 6\) triangles"):
        plane_stress_discretization(nodes, cells[:, :5], nv, thickness=1.0)


# the forward models on a tension strip


@dataclass(frozen=True)
class Strip:
    """Plane-stress strip L x H x t, -L/2 < x < L/2, held at x = -L/2 and pulled by a rigid platen at
    x = L/2, meshed with square grid cells of size h (T6: each split in two). The middle ``columns`` of
    cells (around the crack path x = 0, where the FPZ width is measured) are the imperfection:
    weaker (strength_factor, for the crack band) or the only damageable material (for the damage models,
    which read no strength: one column for the local model, which cannot choose between softening
    columns, five, a few internal lengths, for the nonlocal ones). Control: the elongation of the
    middle column."""

    family: str = "tri6"
    imperfection: str = "strength"
    columns: int = 1
    length: float = 33.0
    height: float = 6.0
    thickness: float = 5.0
    n_columns: int = 11

    default_control = "band_opening"

    @property
    def h(self) -> float:
        return self.length / self.n_columns

    def describe(self) -> Description:
        mesher = {"tri6": structured_tri6, "quad8": structured_quad8}[self.family]
        rows = round(self.height / self.h)
        half = 0.5 * self.length
        mesh = mesher(np.linspace(-half, half, self.n_columns + 1), np.linspace(0.0, self.height, rows + 1))
        h = self.h
        sets = {"left": mesh.nodes_near(x=-half), "right": mesh.nodes_near(x=half),
                "corner": np.array([mesh.closest_node((-half, 0.0))]),
                "band_left": mesh.nodes_near(x=-0.5 * h), "band_right": mesh.nodes_near(x=0.5 * h)}
        centre = lambda points, width: np.abs(points[..., 0]) < 0.5 * width  # noqa: E731
        zone = lambda points: centre(points, self.columns * h)  # noqa: E731
        if self.imperfection == "strength":
            field = {"strength_factor": lambda points: np.where(zone(points), 0.97, 1.0)}
        else:
            field = {"damageable": lambda points: np.where(zone(points), 1.0, 0.0)}
        return Description(
            nodes=mesh.nodes, cells=mesh.cells, n_vertices=mesh.n_vertices, section=self.thickness, node_sets=sets,
            supports=(Support("left", 0), Support("corner", 1)), loads=(Load("right", 0, 1.0),),
            functionals={"elongation": (Measure("right", 0),),
                         "band_opening": (Measure("band_right", 0), Measure("band_left", 0, -1.0))},
            crack=CrackPath(None, normal=0, mirrored=False), zone=ZoneWidth("fpz_width", axis=0), **field)

    def default_steps(self, target):
        return StepOptions(maximum=target / 40)


DAMAGE = fracid.DamageParameters(E=30000.0, nu=0.2, kappa_i=1e-4, alpha=0.99, beta=500.0, c=4.5)
BAND = CohesiveParameters(E=30000.0, nu=0.2, ft=3.0, Gf=0.1)
MODELS = {  # model, parameters, strip, target band opening [mm]
    "gradient": (DamageModel("gradient"), DAMAGE, dict(imperfection="damageable", columns=5), 0.02),
    "local": (DamageModel("local"), DAMAGE, dict(imperfection="damageable", columns=1), 0.02),
    "integral": (DamageModel("integral"), DAMAGE, dict(imperfection="damageable", columns=5), 0.02),
    "crack-band": (CrackBandModel(), BAND, dict(imperfection="strength", columns=1), 0.1),
}


@pytest.fixture(scope="module", params=sorted(MODELS))
def strip_runs(request):
    model, params, strip, target = MODELS[request.param]
    runs = {family: model.simulate(Strip(family, **strip), params, target=target, stop_force_fraction=0.3)
            for family in ("quad8", "tri6")}
    return request.param, params, runs


def test_strip_t6_elastic_peak_and_softening_match_q8(strip_runs):
    name, params, runs = strip_runs
    strip = Strip()
    for family, result in runs.items():
        slope = result.force[1] / result.observables["elongation"][1]  # the first step is elastic
        assert slope == pytest.approx(params.E * strip.height * strip.thickness / strip.length, rel=1e-8), family
        peak = int(np.argmax(result.force))
        assert 1 < peak < result.n_steps, family
        assert result.status.startswith("force below"), (family, result.status)  # softening past the peak
        assert np.all(np.diff(result.force[peak:]) < 0), family
    q8, t6 = runs["quad8"], runs["tri6"]
    assert t6.peak_force == pytest.approx(q8.peak_force, rel=0.02), name
    if name != "local":  # the local model depends on the mesh (its band is one element wide)
        x = np.linspace(q8.control[np.argmax(q8.force)], min(q8.control[-1], t6.control[-1]), 12)
        np.testing.assert_allclose(np.interp(x, t6.control, t6.force), np.interp(x, q8.control, q8.force),
                                   atol=0.02 * q8.peak_force)
    if "fpz_width" in q8.observables:  # the damage models: the across-path sampler on triangles
        assert t6.observables["fpz_width"][-1] == pytest.approx(q8.observables["fpz_width"][-1], rel=0.05)
        assert t6.observables["fpz_width"][1] == 0.0


def test_t6_strip_vtk_output(tmp_path):
    meshio = pytest.importorskip("meshio")
    from fracid.report import write_result_vtk

    strip = Strip("tri6", imperfection="damageable", columns=5)
    nodes, cells, cell_type = strip.describe().output_mesh()
    assert cell_type == "triangle6" and cells.shape[1] == 6
    assert Strip("quad8").describe().output_mesh()[2] == "quad8"
    result = DamageModel("gradient").simulate(strip, DAMAGE, target=0.01, stop_force_fraction=None)
    (path,) = write_result_vtk(tmp_path, strip, result)
    mesh = meshio.read(path)
    assert mesh.cells[0].type == "triangle6" and len(mesh.cells[0].data) == len(cells)
    assert mesh.points.shape[0] == len(nodes)
    ebar = mesh.point_data["ebar"]
    assert np.all(np.isfinite(ebar)) and ebar.max() > DAMAGE.kappa_i
    assert mesh.cell_data["damage_max"][0].max() > 0.0
