"""The widened covariances of fracid.data.covariance_update (B + U U^T, B + diag(a)) against numpy's dense algebra,
for every kind of base covariance."""

import numpy as np
import pytest

from fracid.data.covariance_matrix import Block, Dense, Diagonal
from fracid.data.covariance_low_rank import LowRankPlusDiagonal
from fracid.data.covariance_update import LowRankUpdate, low_rank_update, plus_diagonal

N = 7


def _spd(n, seed):
    A = np.random.default_rng(seed).normal(size=(n, n))
    return A @ A.T + n * np.eye(n)


def _bases():
    rng = np.random.default_rng(3)
    var, d, W = rng.uniform(0.5, 2.0, N), rng.uniform(0.2, 1.0, N), rng.normal(size=(N, 2))
    return {"diagonal": Diagonal(var), "dense": Dense(_spd(N, 1)), "low-rank": LowRankPlusDiagonal(W, d),
            "block": Block([Diagonal(var[:2]), Dense(_spd(3, 2)), LowRankPlusDiagonal(W[:2], d[:2])])}


BASES = _bases()
U = np.random.default_rng(5).normal(size=(N, 3)) * np.array([3.0, 0.5, 0.01])


@pytest.mark.parametrize("kind", list(BASES))
def test_low_rank_update_equals_dense_algebra(kind):
    base = BASES[kind]
    C = LowRankUpdate(base, U)
    dense = base.dense() + U @ U.T
    rng = np.random.default_rng(11)
    b, B = rng.normal(size=N), rng.normal(size=(N, 4))
    np.testing.assert_allclose(C.dense(), dense, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(C.solve(b), np.linalg.solve(dense, b), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(C.solve(B), np.linalg.solve(dense, B), rtol=1e-10, atol=1e-12)
    assert C.logdet() == pytest.approx(np.linalg.slogdet(dense)[1], rel=1e-12)
    np.testing.assert_allclose(C.quadratic(b), b @ np.linalg.solve(dense, b), rtol=1e-10)
    # whiten is W with W C W^T = I; color is L with L L^T = C, and whiten undoes color
    Wm, Lm = C.whiten(np.eye(N)), C.color(np.eye(N))
    np.testing.assert_allclose(Wm @ dense @ Wm.T, np.eye(N), atol=1e-10)
    np.testing.assert_allclose(Lm @ Lm.T, dense, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(C.whiten(C.color(B)), B, atol=1e-10)
    np.testing.assert_allclose(C.diag(), np.diag(dense), rtol=1e-12)
    np.testing.assert_allclose(C.noise_diag(), base.noise_diag())


@pytest.mark.parametrize("kind", list(BASES))
def test_take_scaled_and_plus_diagonal_equal_dense_algebra(kind):
    base = BASES[kind]
    C, dense = LowRankUpdate(base, U), base.dense() + U @ U.T
    rows = np.array([0, 2, 3, 6])
    np.testing.assert_allclose(C.take(rows).dense(), dense[np.ix_(rows, rows)], rtol=1e-12)
    np.testing.assert_allclose(C.take(slice(1, 4)).dense(), dense[1:4, 1:4], rtol=1e-12)
    f = np.linspace(0.5, 2.0, N)
    np.testing.assert_allclose(C.scaled(f).dense(), dense * np.outer(f, f), rtol=1e-12)
    add = np.linspace(0.0, 1.5, N)
    np.testing.assert_allclose(plus_diagonal(base, add).dense(), base.dense() + np.diag(add), rtol=1e-12)
    np.testing.assert_allclose(plus_diagonal(C, add).dense(), dense + np.diag(add), rtol=1e-12)
    assert type(plus_diagonal(base, add)) is type(base) or kind == "block"


def test_kinds_are_kept_and_zero_modes_dropped():
    diagonal = BASES["diagonal"]
    assert isinstance(plus_diagonal(diagonal, 1.0), Diagonal)
    assert low_rank_update(diagonal, np.zeros((N, 2))) is diagonal  # nothing to add
    U1 = np.zeros((N, 2))
    U1[:3, 0] = 1.0  # a mode of the first entries only
    C = low_rank_update(low_rank_update(diagonal, U1), U[:, :1])
    assert isinstance(C, LowRankUpdate) and C.U.shape == (N, 2) and C.base is diagonal  # one base, columns joined
    assert C.take(np.arange(3, N)).U.shape == (N - 3, 1)  # the first mode vanishes there
    with pytest.raises(ValueError, match="shape"):
        LowRankUpdate(diagonal, np.ones((N + 1, 1)))
    with pytest.raises(ValueError, match=">= 0"):
        plus_diagonal(diagonal, -1.0)
    with pytest.raises(ValueError, match="right-hand side"):
        C.color(np.ones(N + 2))
