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


@pytest.mark.parametrize("n_side, spacing", [(30, 1.0), (45, 0.7)])
def test_the_factor_estimate_brackets_the_factor_built(n_side, spacing):
    from fracid.data.dic_noise import factor_estimate

    points = _grid(n_side, spacing, seed=4)
    estimate = factor_estimate(points, 6.0)
    C = dic_covariance(points, 1.0, 6.0)
    assert estimate["nonzeros"] == pytest.approx(C.correlation.nnz, rel=0.1)  # sampled neighbours
    kept = 12.0 * C.correlation.nnz + 36.0 * C._factor.L.nnz
    low, high = estimate["bytes"]
    assert 0.9 * low <= kept <= 1.1 * high


def test_a_field_whose_factor_would_not_fit_is_refused_before_it_is_built(monkeypatch):
    import fracid.data.dic.field as dic_field
    from fracid.data.errors import DataError

    points = _grid(10, 1.0)
    sigma = np.ones(2 * len(points))
    dic_field.field_covariance(points, sigma, 1, (0, 1), 6.0)  # the default limit: built
    monkeypatch.setattr(dic_field, "MAX_FACTOR_BYTES", 1e3)
    monkeypatch.setattr(covariance_sparse, "_Factor", lambda K: pytest.fail("built before the refusal"))
    with pytest.raises(DataError, match=r"subset_size = 6 mm: .* GB .*100 points a frame.*point_spacing"):
        dic_field.field_covariance(points, sigma, 1, (0, 1), 6.0)


def test_the_information_of_a_large_correlated_frame_is_exact_at_its_end():
    from fracid.data.covariance_matrix import block_diagonal
    from fracid.data.dic.rigid import with_rigid_motion
    from fracid.inverse.core.sensitivity import PREFIX_SOLVE_LIMIT, cumulative_information

    points = _grid(11, 1.0, seed=6)  # 121 points, u and v: a frame of 242 entries, beyond the per-entry limit
    frame = dic_covariance(points, 1e-3, 4.0)
    C = block_diagonal([with_rigid_motion(block_diagonal([frame, frame]), points, (0, 1)) for _ in range(2)])
    assert C.blocks[0].n > PREFIX_SOLVE_LIMIT
    S = np.random.default_rng(7).standard_normal((C.n, 3))
    info = cumulative_information(S, C)
    dense = C.dense()
    for end in (C.blocks[0].n, C.n):  # each frame's end
        expected = S[:end].T @ np.linalg.solve(dense[:end, :end], S[:end])
        np.testing.assert_allclose(info[end - 1], expected, rtol=1e-6)


def test_the_kalman_groups_end_where_the_covariance_splits():
    from fracid.data.covariance_matrix import Diagonal, block_diagonal, independent_cuts
    from fracid.data.covariance_update import LowRankUpdate
    from fracid.inverse.methods.kalman import independent_groups

    frame = dic_covariance(_grid(4), 1e-3, 4.0)  # 16 correlated entries
    C = block_diagonal([Diagonal(np.ones(5)), frame, frame])  # a curve of 5 values, then two frames
    np.testing.assert_array_equal(independent_cuts(C), [0, 1, 2, 3, 4, 5, 21, 37])
    groups = [np.arange(a, b) for a, b in ((0, 3), (3, 12), (12, 30), (30, 37))]
    aligned = independent_groups(groups, C)
    assert [(g[0], g[-1] + 1) for g in aligned] == [(0, 3), (3, 21), (21, 37)]  # no frame split; one emptied
    assert independent_groups(groups, LowRankUpdate(Diagonal(np.ones(37)), np.ones(37)))[0].size == 37
    same = independent_groups(groups, Diagonal(np.ones(37)))  # independent entries: as given
    assert all(np.array_equal(a, b) for a, b in zip(same, groups)) and len(same) == len(groups)
    scattered = [np.array([0, 2]), np.array([1, 3])]
    assert independent_groups(scattered, C) is scattered
