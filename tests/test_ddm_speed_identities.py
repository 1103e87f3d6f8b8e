"""The faster forms of the direct differentiation's kernels equal the pointwise formulas they replace.

The pseudo-load and the recoverable energy's derivative are computed from the forces B^T D eps at the
points (the energy's displacement term as the work of the element internal forces on du/dx), the ebar
rows' c column from the element gradient matrix kept by the problem, and PARDISO orders the border of
the bordered tangent last so that no pivot is perturbed: these tests hold each against the direct
formula (no timing here; benchmarks/dic_field.py measures the cost).
"""

import numpy as np
import pytest
import scipy.sparse as sp

import fracid
from fracid.fem.formulations import damage_sensitivity as ds
from fracid.fem.formulations.forms import bt
from fracid.fem.path.linear_backend import block_norm, refine
from fracid.models import DamageModel
from fracid.specimens import SPECIMENS

NAMES = ("E", "nu", "kappa_i", "beta", "c")


@pytest.fixture(scope="module")
def beam_state():
    """A gradient-damage problem on a coarse notched beam, random element states and rates."""
    beam = SPECIMENS["notched-beam"](h_fine=4.0, h_coarse=12.0, fine_width=12.0)
    params = fracid.DamageParameters()
    problem = DamageModel("gradient").build(beam.describe(), params)
    rng = np.random.default_rng(3)
    n_el, n_q = problem.disc.weights.shape
    q = rng.normal(size=problem.n_free) * 1e-3
    omega = rng.uniform(0.0, 0.9, (n_el, n_q))
    omega_rate = rng.normal(size=(n_el, n_q, len(NAMES)))
    dq = rng.normal(size=(problem.n_free, len(NAMES))) * 1e-3
    return problem, params, q, omega, omega_rate, dq


def pointwise_pseudo_load(disc, params, const, ue, omega, omega_rate, names):
    """d f_u / d x as the sum over the points, one parameter at a time (the former kernel)."""
    B, w = disc.strain_operator, disc.weights
    eps = np.einsum("eqsi,ei->eqs", B, ue)
    bt_sigma = bt(np.einsum("eqsj,ej->eqs", const.DB, ue), B)
    intact = (1.0 - omega) * const.E * w
    out = np.empty(ue.shape + (len(names),))
    for k, name in enumerate(names):
        factor = -omega_rate[..., k] * const.E * w + (intact / params.E if name == "E" else 0.0)
        force = np.einsum("eqi,eq->ei", bt_sigma, factor)
        if name == "nu":
            d_sigma = np.einsum("st,eqt->eqs", disc.strain_state.unit_elastic_matrix_derivative(params.nu), eps)
            force += np.einsum("eqi,eq->ei", bt(d_sigma, B), intact)
        out[..., k] = force
    return out


def pointwise_energy_derivative(disc, params, const, ue, due, omega, omega_rate, names):
    """d/dx of 1/2 int (1 - omega) E eps . D eps from the strains' derivatives at the points (the former kernel)."""
    B, w = disc.strain_operator, disc.weights
    eps = np.einsum("eqsi,ei->eqs", B, ue)
    sigma_eff = np.einsum("eqsj,ej->eqs", const.DB, ue)
    density = np.sum(eps * sigma_eff, axis=-1)
    d_eps = np.einsum("eqsi,eip->eqsp", B, due)
    intact = (1.0 - omega) * const.E * w
    out = np.empty(len(names))
    for k, name in enumerate(names):
        value = np.sum(-0.5 * omega_rate[..., k] * const.E * w * density + intact * np.sum(d_eps[..., k] * sigma_eff, -1))
        if name == "E":
            value += 0.5 * np.sum(intact * density) / params.E
        if name == "nu":
            dD = disc.strain_state.unit_elastic_matrix_derivative(params.nu)
            value += 0.5 * np.sum(intact * np.einsum("eqs,st,eqt->eq", eps, dD, eps))
        out[k] = value
    return out


def test_pseudo_load_equals_the_pointwise_sum(beam_state):
    problem, params, q, omega, omega_rate, _ = beam_state
    ue = problem.gather(q)[:, problem.dofs.columns["u"]]
    expected = pointwise_pseudo_load(problem.disc, params, problem.const, ue, omega, omega_rate, NAMES)
    stress = ds.unit_stress_forces(problem.disc, problem.const, ue)
    for given in (None, stress):
        got = ds.equilibrium_pseudo_load(problem.disc, params, problem.const, ue, omega, omega_rate, NAMES, given)
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())


def test_energy_derivative_equals_the_pointwise_integral(beam_state):
    problem, params, q, omega, omega_rate, dq = beam_state
    u = problem.dofs.columns["u"]
    ue, due = problem.gather(q)[:, u], problem.gather_columns(dq)[:, u]
    expected = pointwise_energy_derivative(problem.disc, params, problem.const, ue, due, omega, omega_rate, NAMES)
    got = ds.elastic_energy_derivative(problem.disc, params, problem.const, ue, due, omega, omega_rate, NAMES)
    np.testing.assert_allclose(got, expected, rtol=1e-11)


def test_c_column_of_the_ebar_rows_uses_the_gradient_matrix(beam_state):
    problem, params, q, *_ = beam_state
    qe = problem.gather(q)
    space = problem.disc.space("linear")
    G, w, ee = space.gradient, problem.disc.weights, qe[:, problem.dofs.columns["ebar"]]
    expected = np.einsum("eq,eqdi,eqdj,ej->ei", w, G, G, ee)
    n_u = problem.dofs.n_u
    eps = np.einsum("eqsi,ei->eqs", problem.disc.strain_operator, qe[:, :n_u])
    rows = problem._with_field_rows(np.zeros((qe.shape[0], n_u, 1)), qe, eps, ("c",))[:, n_u:, 0]
    np.testing.assert_allclose(rows, expected, rtol=1e-12, atol=1e-14 * np.abs(expected).max())
    # and the diffusion matrix of the constants is the mass matrix plus c times it
    mass = np.einsum("eq,qi,qj->eij", w, space.shape, space.shape)
    np.testing.assert_allclose(problem.const.ebar_matrix, mass + params.c * problem._gradient_matrix(), rtol=1e-13)


def test_refine_reaches_the_tolerance_with_an_approximate_solver():
    rng = np.random.default_rng(0)
    n = 60
    matrix = (sp.random(n, n, density=0.1, random_state=rng) + sp.eye(n) * 5.0).tocsc()
    approximate = np.linalg.inv(matrix.toarray() + 1e-3 * rng.normal(size=(n, n)))
    rhs = rng.normal(size=(n, 3))
    x, residual, scale = refine(lambda r: approximate @ r, matrix, rhs, approximate @ rhs, 1e-12, 10)
    assert residual <= 1e-12 * scale and scale == pytest.approx(np.linalg.norm(rhs))
    assert residual == pytest.approx(block_norm(rhs - matrix @ x))


def test_pardiso_orders_the_border_last_and_perturbs_no_pivot():
    pytest.importorskip("pypardiso")
    from fracid.fem.path.pardiso import PardisoSolver

    rng = np.random.default_rng(5)
    n = 300
    K = sp.random(n, n, density=0.02, random_state=rng, data_rvs=rng.standard_normal)
    K = (K + K.T + sp.diags(4.0 + abs(K).sum(axis=1).A1)).tocsc()
    f, v = np.zeros(n), np.zeros(n)
    f[rng.choice(n, 3, replace=False)] = 1.0
    v[rng.choice(n, 2, replace=False)] = [1.0, -1.0]
    bordered = sp.bmat([[K, -f[:, None]], [v[None, :], None]], format="csc")  # zero at (n, n)
    bordered.sort_indices()
    solver = PardisoSolver()
    solve = solver.factorize(bordered)
    rhs = rng.normal(size=(n + 1, 2))
    x = solve(rhs)
    assert solver.perturbed_pivots == 0
    assert np.linalg.norm(bordered @ x - rhs) <= 1e-12 * np.linalg.norm(rhs)
