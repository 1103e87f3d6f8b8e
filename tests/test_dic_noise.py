"""The DIC noise model: a compactly supported correlation over the subset size, a sparse covariance."""

import numpy as np
import pytest
import scipy.sparse

import fracid.data.covariance_sparse as covariance_sparse
from fracid.data.covariance_matrix import Block, Dense
from fracid.data.covariance_sparse import SparseCovariance
from fracid.data.covariance_update import plus_diagonal
from fracid.data.dic_noise import (NUGGET, dic_correlation, dic_covariance, dic_frames_covariance, dic_kernel,
                                   support_radius)


def _grid(n_side=15, spacing=2.0, seed=1):
    rng = np.random.default_rng(seed)
    g = np.arange(n_side) * spacing
    points = np.array([(x, y) for x in g for y in g], dtype=float)
    return points + rng.uniform(-0.3, 0.3, points.shape) * spacing


def test_kernel_follows_the_gaussian_over_half_the_subset_and_vanishes_beyond_its_support():
    subset = 4.0  # l = 2 mm
    d = np.linspace(0.0, 12.0, 241)
    K = dic_kernel([[0.0, 0.0]], np.column_stack([d, 0 * d]), 1.0, subset)[0] / (1 - NUGGET)
    gaussian = np.exp(-d**2 / (2 * 2.0**2))
    assert np.max(np.abs(K - gaussian)) < 0.02  # the module docstring's bound
    assert K[0] == 1.0 and np.all(K[d >= support_radius(subset)] == 0.0)
    assert support_radius(subset) == pytest.approx(np.sqrt(14) * 2.0)
    # the same integral over the plane as the Gaussian: 2 pi l^2
    integral = 2 * np.pi * np.trapezoid(K * d, d)
    assert integral == pytest.approx(2 * np.pi * 2.0**2, rel=1e-3)


def test_covariance_is_the_kernel_plus_the_nugget_exactly_and_sparse():
    points = _grid()
    std, subset = 1e-3, 6.0
    C = dic_covariance(points, std, subset)
    assert isinstance(C, SparseCovariance)
    expected = dic_kernel(points, points, std, subset) + NUGGET * std**2 * np.eye(len(points))
    np.testing.assert_allclose(C.dense(), expected, rtol=1e-12, atol=1e-20)
    np.testing.assert_allclose(C.diag(), std**2, rtol=1e-12)
    assert C.correlation.nnz < 0.5 * len(points) ** 2  # sparse beyond the support
    assert np.linalg.eigvalsh(expected).min() > 0.5 * NUGGET * std**2  # the nugget bounds it away from singular


def _sparse_and_dense(n_side=12, seed=2):
    points = _grid(n_side, 1.5, seed)
    s = np.random.default_rng(seed).uniform(0.5, 2.0, len(points))
    C = dic_covariance(points, 1.0, 5.0).scaled(s)
    return C, Dense(C.dense())


def test_solve_logdet_whiten_color_agree_with_the_dense_matrix():
    C, D = _sparse_and_dense()
    rng = np.random.default_rng(0)
    b = rng.standard_normal((C.n, 3))
    np.testing.assert_allclose(C.solve(b), D.solve(b), rtol=1e-8)
    np.testing.assert_allclose(C.solve(b[:, 0]), D.solve(b[:, 0]), rtol=1e-8)
    assert C.logdet() == pytest.approx(D.logdet(), rel=1e-10)
    np.testing.assert_allclose(C.quadratic(b), D.quadratic(b), rtol=1e-8)
    W = C.whiten(np.eye(C.n))  # W^T W = C^-1
    np.testing.assert_allclose(W.T @ W, np.linalg.inv(D.dense()), rtol=1e-6, atol=1e-8)
    L = C.color(np.eye(C.n))  # L L^T = C
    np.testing.assert_allclose(L @ L.T, D.dense(), rtol=1e-10, atol=1e-12)


def test_take_is_the_sub_matrix_and_frames_with_the_same_holes_share_one_factor(monkeypatch):
    C, D = _sparse_and_dense()
    built = []
    factor = covariance_sparse._Factor
    monkeypatch.setattr(covariance_sparse, "_Factor", lambda K: built.append(K.shape) or factor(K))
    holes = np.ones(C.n, bool)
    holes[[3, 40, 41, 100]] = False
    index = np.flatnonzero(holes)
    part = C.take(index)
    np.testing.assert_allclose(part.dense(), D.dense()[np.ix_(index, index)], rtol=1e-12)
    b = np.random.default_rng(1).standard_normal(index.size)
    np.testing.assert_allclose(part.solve(b), np.linalg.solve(D.dense()[np.ix_(index, index)], b), rtol=1e-8)
    other = C.scaled(np.full(C.n, 3.0)).take(holes)  # another frame (other stds), the same holes
    assert other._factor is part._factor and len(built) == 1
    assert other.logdet() == pytest.approx(part.logdet() + 2 * index.size * np.log(3.0), rel=1e-12)
    shuffled = index[::-1]  # an order not increasing: the sub-matrix in that order
    np.testing.assert_allclose(C.take(shuffled).dense(), D.dense()[np.ix_(shuffled, shuffled)], rtol=1e-12)


def test_plus_diagonal_keeps_the_sparse_kind():
    C, D = _sparse_and_dense()
    add = np.linspace(0.0, 0.5, C.n)
    wider = plus_diagonal(C, add)
    assert isinstance(wider, SparseCovariance)
    np.testing.assert_allclose(wider.dense(), D.dense() + np.diag(add), rtol=1e-12, atol=1e-14)


def test_draws_have_the_kernel_correlation():
    points = _grid(8, 2.0)
    std, subset = 1e-3, 5.0
    C = dic_covariance(points, std, subset)
    draws = C.color(np.random.default_rng(3).standard_normal((len(points), 4000)))
    empirical = np.cov(draws)
    np.testing.assert_allclose(np.sqrt(np.diag(empirical)), std, rtol=0.06)
    corr = empirical / np.sqrt(np.outer(np.diag(empirical), np.diag(empirical)))
    assert np.max(np.abs(corr - C.dense() / std**2)) < 0.1  # sampling error of 4000 draws: ~ 1/sqrt(4000) x 3


def test_frames_and_components_are_independent_blocks_on_one_factor():
    points = _grid(5)
    C = dic_frames_covariance(points, 1e-3, 4.0, n_frames=3)
    assert isinstance(C, Block) and len(C.blocks) == 6 and C.n == 6 * len(points)
    assert len({id(block._factor) for block in C.blocks}) == 1
    dense = C.dense()
    n = len(points)
    assert np.all(dense[:n, n:] == 0.0)
    np.testing.assert_allclose(np.diag(dense), 1e-6, rtol=1e-12)


def test_a_matrix_that_is_not_a_correlation_is_refused():
    with pytest.raises(ValueError, match="unit diagonal"):
        SparseCovariance(scipy.sparse.identity(3) * 2.0)
    with pytest.raises(ValueError, match="not symmetric"):
        SparseCovariance(scipy.sparse.csc_matrix(np.array([[1.0, 0.5], [0.2, 1.0]])))
    with pytest.raises(ValueError, match="positive definite|singular"):
        SparseCovariance(scipy.sparse.csc_matrix(np.array([[1.0, 2.0], [2.0, 1.0]])))
    with pytest.raises(ValueError, match="std must be"):
        SparseCovariance(scipy.sparse.identity(2), [1.0, -1.0])


def test_the_correlation_is_symmetric_with_a_unit_diagonal():
    K = dic_correlation(_grid(6), 4.0)
    assert abs(K - K.T).max() == 0.0 and np.all(K.diagonal() == 1.0)


@pytest.mark.parametrize("kwargs, match", [
    (dict(points=np.zeros((3, 3)), std=1.0, subset_size=1.0), "points has shape"),
    (dict(points=np.zeros((3, 2)), std=0.0, subset_size=1.0), "std = 0.0"),
    (dict(points=np.zeros((3, 2)), std=1.0, subset_size=-1.0), "subset_size = -1.0"),
    (dict(points=[[0.0, np.nan]], std=1.0, subset_size=1.0), "NaN"),
])
def test_bad_input_is_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        dic_covariance(**kwargs)
