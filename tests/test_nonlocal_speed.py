"""The integral damage model's costs kept where they must be (issue 39): the averaging matrix built once
per process and mesh and internal length, the nonlocal tangent built only when an iteration factorizes,
and the coupling equal to its definition - G (A - diag A) H."""

import numpy as np
import pytest
import scipy.sparse as sp
from test_tangent import post_peak_state

import fracid
from fracid.fem.formulations import forms, nonlocal_average
from fracid.fem.material.damage import update_history
from fracid.fem.material.laws import DAMAGE_LAWS
from fracid.fem.formulations.nonlocal_average import (averaging_length_derivative, averaging_matrix,
                                                      cached_averaging_matrix)
from fracid.models import DamageModel
from fracid.specimens.dogbone import DogBone


@pytest.fixture
def empty_cache():
    nonlocal_average._CACHE.clear()
    yield
    nonlocal_average._CACHE.clear()


def points(n=40, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.0, 10.0, (n, 2)), rng.uniform(0.5, 1.5, n)


def test_cache_hits_only_the_same_mesh_length_cutoff_and_planes(empty_cache):
    x, w = points()
    first = cached_averaging_matrix(x, w, 1.5, mirror=[(0, 0.0)])
    assert cached_averaging_matrix(x.copy(), w.copy(), 1.5, mirror=[(0, 0.0)]) is first  # same values: a hit
    # the cached matrix is the uncached one, to the last bit
    assert abs(first - averaging_matrix(x, w, 1.5, mirror=[(0, 0.0)])).max() == 0.0
    moved = x.copy()
    moved[3, 1] += 1e-9
    others = [cached_averaging_matrix(moved, w, 1.5, mirror=[(0, 0.0)]),  # another mesh
              cached_averaging_matrix(x, w * 1.01, 1.5, mirror=[(0, 0.0)]),  # other weights
              cached_averaging_matrix(x, w, 1.6, mirror=[(0, 0.0)]),  # another internal length
              cached_averaging_matrix(x, w, 1.5, cutoff=3.0, mirror=[(0, 0.0)]),
              cached_averaging_matrix(x, w, 1.5)]  # no plane
    assert all(other is not first for other in others)
    assert len(nonlocal_average._CACHE) == nonlocal_average.CACHE_SIZE  # bounded: old entries dropped


def test_problems_of_the_same_mesh_and_c_share_one_matrix(empty_cache):
    specimen = DogBone(size=50.0, h_fine=5.0)
    build = DamageModel("integral").build
    a = build(specimen, fracid.DamageParameters(c=4.0, beta=300.0))
    b = build(specimen, fracid.DamageParameters(c=4.0, beta=900.0))  # other parameters, same l
    c = build(specimen, fracid.DamageParameters(c=5.0))
    assert b.averaging.matrix is a.averaging.matrix and c.averaging.matrix is not a.averaging.matrix
    np.testing.assert_array_equal(a.averaging.self_weight.ravel(), a.averaging.matrix.diagonal())


def test_row_scaling_in_place_gives_the_normalised_matrix_and_its_derivative():
    x, w = points(60, seed=1)
    A = averaging_matrix(x, w, 2.0, mirror=[(1, 0.0)])
    np.testing.assert_allclose(A @ np.ones(60), 1.0, rtol=1e-14)
    # dA/dl against central differences of A (the truncation moves with l: its weights are below 3.4e-4)
    step = 1e-6
    numeric = (averaging_matrix(x, w, 2.0 + step, mirror=[(1, 0.0)]) - averaging_matrix(x, w, 2.0 - step, mirror=[(1, 0.0)]))
    numeric = numeric.toarray() / (2 * step)
    exact = averaging_length_derivative(x, w, 2.0, mirror=[(1, 0.0)]).toarray()
    assert np.abs(exact - numeric).max() <= 1e-6 * np.abs(numeric).max()
    np.testing.assert_allclose(exact.sum(axis=1), 0.0, atol=1e-14 * np.abs(exact).max())  # rows of A sum to 1 for every l


@pytest.fixture(scope="module")
def damaged_state():
    params = fracid.DamageParameters(E=30000.0, nu=0.2, alpha=0.99, beta=300.0, c=4.0, eta=10.0)
    return post_peak_state("integral", params, DogBone(size=50.0, h_fine=5.0), control="elongation", target=0.02)


def test_the_tangent_parts_are_built_at_the_first_access_only(damaged_state, monkeypatch):
    problem, q, kappa_old = damaged_state
    calls = []
    original = forms.softening_coupling
    monkeypatch.setattr(forms, "softening_coupling", lambda *args: calls.append(1) or original(*args))
    _, arrays, _ = problem.evaluate(q, kappa_old)
    assert calls == []  # a residual alone (modified Newton's iterations) builds no coupling
    coupling = arrays.coupling
    assert calls == [1] and arrays.coupling is coupling  # built once, then kept
    copy = arrays._replace(tangent=np.array(arrays.tangent))  # the derivatives' thread's copy shares it
    assert copy.coupling is coupling and calls == [1]
    assert coupling.nnz > 0 and np.abs(coupling).max() > 0.0


def test_coupling_is_minus_g_times_the_off_diagonal_average_times_h(damaged_state):
    problem, q, kappa_old = damaged_state
    disc, law, params, const = problem.disc, problem.law, problem.params, problem.const
    ue = problem.gather(q)
    eps = forms.strain_of(disc.strain_operator, ue)
    eq, d_eq = law.equivalent_strain(disc.strain_state, eps, params)
    kappa, loading = update_history(kappa_old, (problem.averaging.matrix @ eq.ravel()).reshape(eq.shape))
    _, d_omega = forms.masked_damage(law, params, const, kappa)
    active = loading & (d_omega > 0.0)
    g = forms.bt(forms.strain_of(const.DB, ue), disc.strain_operator) * (disc.weights * const.E * d_omega * loading)[..., None]
    h = forms.bt(d_eq, disc.strain_operator)
    # dense reference: every point's element vectors on the free dofs
    av, n = problem.averaging, problem.n_free
    G, H = np.zeros((n, av.point_dofs.shape[0])), np.zeros((av.point_dofs.shape[0], n))
    for k, dofs in enumerate(av.point_dofs):
        keep = dofs >= 0
        np.add.at(G[:, k], dofs[keep], g.reshape(-1, g.shape[-1])[k][keep] * np.ravel(active)[k])
        np.add.at(H[k], dofs[keep], h.reshape(-1, h.shape[-1])[k][keep])
    off = av.matrix.toarray() - np.diag(av.matrix.diagonal())
    expected = -G @ off @ H
    coupling = nonlocal_average.softening_coupling(av, g, h, active)
    assert sp.isspmatrix_csc(coupling) and active.sum() > 10
    np.testing.assert_allclose(coupling.toarray(), expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    # the shared matrix keeps its diagonal (the coupling zeroed it in its own copy of the rows)
    np.testing.assert_array_equal(av.matrix.diagonal(), av.self_weight.ravel())


def test_bounded_average_gives_every_row_that_reaches_the_floor_to_the_last_bit(empty_cache):
    specimen = DogBone(size=50.0, h_fine=4.0)
    problem = DamageModel("integral").build(specimen, fracid.DamageParameters(c=4.0))
    av, rng = problem.averaging, np.random.default_rng(5)
    n = av.matrix.shape[0]
    x = np.exp(-np.sum(problem.disc.points.reshape(n, -1) ** 2, axis=1) / 50.0) + 0.01 * rng.uniform(size=n)
    full = av.matrix @ x
    upper = av.bound.weights @ np.maximum.reduceat(x[av.bound.order], av.bound.starts)
    assert np.all(upper >= full * (1 - 1e-12))  # a bound
    for level in (0.3, 0.6, 0.9):
        floor = np.full(n, level * full.max())
        floor[rng.choice(n, 20)] = np.inf  # points that cannot damage are never needed
        rows, values = nonlocal_average.bounded_average(av, x, floor)
        reached = np.flatnonzero(full >= floor)
        assert 0 < reached.size and np.isin(reached, rows).all() and rows.size < n
        np.testing.assert_array_equal(values, full[rows])  # the same sums in the same order
    sliced = av.rows["matrix"]
    nonlocal_average.bounded_average(av, x, floor * 1.01)  # needs fewer rows: the slice is kept
    assert av.rows["matrix"] is sliced


def test_integral_history_is_the_average_at_every_point(damaged_state):
    problem, q, kappa_old = damaged_state
    _, arrays, _ = problem.evaluate(q, kappa_old)
    eps = forms.strain_of(problem.disc.strain_operator, problem.gather(q))
    eq, _ = problem.law.equivalent_strain(problem.disc.strain_state, eps, problem.params)
    expected, _ = update_history(kappa_old, (problem.averaging.matrix @ eq.ravel()).reshape(eq.shape))
    np.testing.assert_array_equal(arrays.history, expected)
    # also below the onset, where the residual did not need the average
    below = expected < problem.params.kappa_i
    assert below.any() and np.any(expected[below] > kappa_old[below])


@pytest.mark.parametrize("name", sorted(DAMAGE_LAWS))
def test_damage_laws_do_not_damage_below_their_onset(name):
    """What the bounded average relies on: below onset(params) omega and d omega / d kappa are zero."""
    law, params = DAMAGE_LAWS[name](), fracid.DamageParameters()
    onset = law.softening.onset(params)
    omega, d_omega = law.softening.damage(np.array([0.0, 0.5 * onset, onset * (1 - 1e-12)]), params)
    assert np.all(omega == 0.0) and np.all(d_omega == 0.0)
    omega, d_omega = law.softening.damage(np.array([onset * 1.01]), params)
    assert omega[0] > 0.0 and d_omega[0] > 0.0
