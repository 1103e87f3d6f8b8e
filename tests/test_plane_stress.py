"""Plane-stress elements: patch test, and elastic stiffness of the specimens under mesh refinement."""

import numpy as np
import pytest

import fracid
from fracid.fem.mesh.discretization import plane_stress_discretization
from fracid.fem.mesh.dofs import Conditions
from fracid.fem.material.laws import DamageLaw
from fracid.fem.formulations.problem import GradientDamageProblem
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.dogbone import DogBone
from fracid.specimens.meshing import structured_quad8


def distorted_square():
    """Square [0, 10]^2 mm on a 3 x 3 grid with distorted (curved) interior element edges."""

    def mapping(s, t):
        bump = np.sin(np.pi * s / 10) * np.sin(np.pi * t / 10)  # zero on the boundary
        return s + 0.9 * bump * (t - 5) / 5, t + 0.7 * bump * (s - 4) / 5

    return structured_quad8(np.array([0.0, 3.0, 7.0, 10.0]), np.array([0.0, 4.0, 6.5, 10.0]), mapping=mapping)


def test_patch_test_uniform_tension_on_distorted_mesh():
    mesh = distorted_square()
    params = fracid.DamageParameters(E=25000.0, nu=0.25, kappa_i=1.0)  # stays elastic
    thickness = 2.0
    disc = plane_stress_discretization(mesh.nodes, mesh.cells, mesh.n_vertices, thickness)
    x, y = mesh.nodes.T
    left, right = np.flatnonzero(np.abs(x) < 1e-12), np.flatnonzero(np.abs(x - 10) < 1e-12)
    # consistent nodal forces of a uniform traction on the right edge (Simpson weights per edge)
    load = {}
    for cell in mesh.cells:
        for a, b, m in ((0, 1, 4), (1, 2, 5), (2, 3, 6), (3, 0, 7)):
            if cell[a] in right and cell[b] in right:
                length = abs(y[cell[a]] - y[cell[b]])
                for node, w in ((cell[a], 1 / 6), (cell[b], 1 / 6), (cell[m], 2 / 3)):
                    load[2 * node] = load.get(2 * node, 0.0) + w * length / 10.0  # total 1: lambda = force [N]
    corner = mesh.closest_node((0.0, 0.0))
    top_right = mesh.closest_node((10.0, 10.0))
    problem = GradientDamageProblem(disc, DamageLaw(), params, Conditions(
        load=load, functionals={"u": {2 * top_right: 1.0}}, fixed_dofs=np.concatenate([2 * left, [2 * corner + 1]])))
    result = fracid.follow_path(problem, "u", 1e-3)
    force = result.force[-1]
    sigma = force / (10.0 * thickness)
    q = problem.restrict(result.fields[result.n_steps]["u"])
    strain = np.einsum("eqsi,ei->eqs", disc.strain_operator, problem.gather(q)[:, :16])
    expected = np.array([sigma / params.E, -params.nu * sigma / params.E, 0.0])
    np.testing.assert_allclose(strain.reshape(-1, 3), np.broadcast_to(expected, (strain.size // 3, 3)), atol=1e-10 * sigma / params.E)
    assert result.control[-1] == pytest.approx(1e-3)
    assert force == pytest.approx(params.E * 1e-4 * 10 * thickness, rel=1e-10)  # u = sigma L / E


@pytest.mark.parametrize(
    "specimen, control",
    [(NotchedBeam(), "cmod"), (NotchedBeam(), "deflection"), (DogBone(size=100.0), "elongation")],
    ids=["beam-cmod", "beam-deflection", "dogbone"],
)
def test_elastic_stiffness_converges(specimen, control):
    params = fracid.DamageParameters(E=30000.0, kappa_i=1.0)  # elastic
    stiffness = []
    for s in (specimen, specimen.refined(2.0, everywhere=True)):
        result = fracid.simulate(s, params, control=control, target=1e-3, stop_force_fraction=None)
        stiffness.append(result.force[-1] / result.control[-1])
    assert stiffness[1] == pytest.approx(stiffness[0], rel=0.01)
