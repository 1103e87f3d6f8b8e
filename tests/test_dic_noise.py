"""The DIC noise model: a Gaussian spatial correlation over the subset size, low rank plus diagonal."""

import numpy as np
import pytest

import fracid.data.dic_noise as dic_noise
from fracid.data.covariance_matrix import Block
from fracid.data.covariance_low_rank import LowRankPlusDiagonal
from fracid.data.dic_noise import dic_covariance, dic_frames_covariance, dic_kernel


def _grid(n_side=15, spacing=2.0, seed=1):
    rng = np.random.default_rng(seed)
    g = np.arange(n_side) * spacing
    points = np.array([(x, y) for x in g for y in g], dtype=float)
    return points + rng.uniform(-0.3, 0.3, points.shape) * spacing


def test_kernel_is_gaussian_over_half_the_subset():
    std, subset = 2e-3, 4.0  # l = 2 mm
    K = dic_kernel([[0.0, 0.0]], [[0.0, 0.0], [2.0, 0.0], [4.0, 0.0]], std, subset)
    assert K[0] == pytest.approx(std**2 * np.exp([0.0, -0.5, -2.0]), rel=1e-14)


def test_diagonal_is_std_squared_and_low_rank_approximates_the_kernel():
    points = _grid()
    std, subset = 1e-3, 6.0
    C = dic_covariance(points, std, subset)
    assert isinstance(C, LowRankPlusDiagonal)
    np.testing.assert_allclose(C.diag(), std**2, rtol=1e-12)
    K = dic_kernel(points, points, std, subset)
    low = C.U @ C.U.T
    assert np.linalg.norm(low - K) / np.linalg.norm(K) < 0.1  # the modes alone
    error = np.linalg.norm(C.dense() - K) / np.linalg.norm(K)  # with the rest of the variance on the diagonal
    assert 0.5 * dic_noise.FROBENIUS_TOLERANCE < error <= dic_noise.FROBENIUS_TOLERANCE * (1 + 1e-9)
    assert C.U.shape[1] < len(points) / 2  # a real reduction


def test_given_rank_and_error_decreasing_with_rank():
    points = _grid(10)
    K = dic_kernel(points, points, 1.0, 5.0)
    errors = []
    for k in (5, 20, 60):
        C = dic_covariance(points, 1.0, 5.0, rank=k)
        assert C.U.shape[1] == k
        errors.append(np.linalg.norm(C.U @ C.U.T - K) / np.linalg.norm(K))
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.01  # the rest: the DIAGONAL_FLOOR kept off the modes


def test_nystrom_beyond_the_exact_limit(monkeypatch):
    monkeypatch.setattr(dic_noise, "EXACT_LIMIT", 100)
    monkeypatch.setattr(dic_noise, "NYSTROM_LANDMARKS", 150)
    points = _grid(15, 2.0)
    C = dic_covariance(points, 1.0, 6.0)
    K = dic_kernel(points, points, 1.0, 6.0)
    np.testing.assert_allclose(C.diag(), 1.0, rtol=1e-12)
    assert np.linalg.norm(C.dense() - K) / np.linalg.norm(K) < 0.1  # the tolerance plus Nystrom's own error


def test_draws_have_the_kernel_correlation():
    points = _grid(8, 2.0)
    std, subset = 1e-3, 5.0
    C = dic_covariance(points, std, subset)
    rng = np.random.default_rng(3)
    draws = C.color(rng.standard_normal((len(points), 4000)))
    empirical = np.cov(draws)
    K = dic_kernel(points, points, std, subset)
    np.testing.assert_allclose(np.sqrt(np.diag(empirical)), std, rtol=0.06)
    corr = empirical / np.sqrt(np.outer(np.diag(empirical), np.diag(empirical)))
    assert np.max(np.abs(corr - K / std**2)) < 0.1  # sampling error of 4000 draws: ~ 1/sqrt(4000) x 3


def test_frames_and_components_are_independent_blocks():
    points = _grid(5)
    C = dic_frames_covariance(points, 1e-3, 4.0, n_frames=3)
    assert isinstance(C, Block) and len(C.blocks) == 6 and C.n == 6 * len(points)
    dense = C.dense()
    n = len(points)
    assert np.all(dense[:n, n:] == 0.0)
    np.testing.assert_allclose(np.diag(dense), 1e-6, rtol=1e-12)


@pytest.mark.parametrize("kwargs, match", [
    (dict(points=np.zeros((3, 3)), std=1.0, subset_size=1.0), "points has shape"),
    (dict(points=np.zeros((3, 2)), std=0.0, subset_size=1.0), "std = 0.0"),
    (dict(points=np.zeros((3, 2)), std=1.0, subset_size=-1.0), "subset_size = -1.0"),
    (dict(points=np.zeros((3, 2)), std=1.0, subset_size=1.0, rank=4), "rank = 4"),
    (dict(points=[[0.0, np.nan]], std=1.0, subset_size=1.0), "NaN"),
])
def test_bad_input_is_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        dic_covariance(**kwargs)
