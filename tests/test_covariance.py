"""The covariance objects of fracid.data.covariance_matrix against numpy's dense algebra, their checks, and the
Kalman filter's information form against its gain form."""

import numpy as np
import pytest

from fracid.data.covariance_low_rank import LowRankPlusDiagonal
from fracid.data.covariance_matrix import DENSE_LIMIT, Block, Dense, Diagonal, as_covariance, block_diagonal
from fracid.inverse.methods.assimilation import assimilate, information_update, kalman_update


def _spd(n, seed):
    A = np.random.default_rng(seed).normal(size=(n, n))
    return A @ A.T + n * np.eye(n)


def _kinds():
    rng = np.random.default_rng(7)
    var = rng.uniform(0.5, 2.0, 6)
    U, d = rng.normal(size=(6, 2)), rng.uniform(0.1, 1.0, 6)
    C = _spd(6, 1)
    return {
        "diagonal": (Diagonal(var), np.diag(var)),
        "dense": (Dense(C), C),
        "low-rank": (LowRankPlusDiagonal(U, d), np.diag(d) + U @ U.T),
        "block": (Block([Diagonal(var[:2]), Dense(_spd(3, 2)), LowRankPlusDiagonal(U[:4], d[:4])]), None),
    }


KINDS = _kinds()


def _pair(kind):
    cov, dense = KINDS[kind]
    if dense is None:
        dense = np.asarray(cov)
        blocks = [np.diag(cov.blocks[0].var), cov.blocks[1].C, cov.blocks[2]._dense()]
        np.testing.assert_array_equal(dense, __import__("scipy").linalg.block_diag(*blocks))
    return cov, dense


@pytest.mark.parametrize("kind", list(KINDS))
def test_solve_logdet_whiten_diag_against_dense(kind):
    cov, C = _pair(kind)
    rng = np.random.default_rng(3)
    b, B = rng.normal(size=cov.n), rng.normal(size=(cov.n, 3))
    np.testing.assert_allclose(cov.solve(b), np.linalg.solve(C, b), rtol=1e-10)
    np.testing.assert_allclose(cov.solve(B), np.linalg.solve(C, B), rtol=1e-10)
    assert cov.logdet() == pytest.approx(np.linalg.slogdet(C)[1], rel=1e-12)
    np.testing.assert_allclose(cov.diag(), np.diag(C), rtol=1e-12)
    np.testing.assert_allclose(cov.dense(), C, rtol=1e-12)
    w = cov.whiten(b)
    assert w @ w == pytest.approx(b @ np.linalg.solve(C, b), rel=1e-10)
    W = cov.whiten(B)
    np.testing.assert_allclose(W.T @ W, B.T @ np.linalg.solve(C, B), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(cov.quadratic(B), np.sum(B * np.linalg.solve(C, B), axis=0), rtol=1e-10)
    # color is the factor whose inverse whiten applies: color(whiten(r)) = r and color color^T = C
    np.testing.assert_allclose(cov.color(w), b, rtol=1e-10, atol=1e-12)
    L = cov.color(np.eye(cov.n))
    np.testing.assert_allclose(L @ L.T, C, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("kind", list(KINDS))
def test_take_is_the_sub_matrix(kind):
    cov, C = _pair(kind)
    for index in ([0, 2, 3, 5], slice(1, 4), np.arange(cov.n) % 3 != 1, [4, 1, 3]):
        rows = np.arange(cov.n)[index]
        sub = cov.take(index)
        np.testing.assert_allclose(sub.dense(), C[np.ix_(rows, rows)], rtol=1e-12)
        np.testing.assert_allclose(np.asarray(cov[index, index]), C[np.ix_(rows, rows)], rtol=1e-12)


@pytest.mark.parametrize("kind", list(KINDS))
def test_scaled_is_D_C_D(kind):
    cov, C = _pair(kind)
    f = np.linspace(0.5, 2.0, cov.n)
    np.testing.assert_allclose(cov.scaled(f).dense(), C * np.outer(f, f), rtol=1e-12)


def test_woodbury_against_dense_for_many_values_and_modes():
    rng = np.random.default_rng(11)
    U, d = rng.normal(size=(300, 5)), rng.uniform(0.01, 0.1, 300)
    cov, C = LowRankPlusDiagonal(U, d), np.diag(d) + U @ U.T
    b = rng.normal(size=300)
    np.testing.assert_allclose(cov.solve(b), np.linalg.solve(C, b), rtol=1e-8)
    assert cov.logdet() == pytest.approx(np.linalg.slogdet(C)[1], rel=1e-10)


def test_as_covariance_keeps_diagonal_and_objects():
    var = np.array([1.0, 2.0, 3.0])
    assert isinstance(as_covariance(var), Diagonal)
    kept = as_covariance(np.diag(var))
    assert isinstance(kept, Diagonal) and np.array_equal(kept.var, var)
    assert isinstance(as_covariance(_spd(3, 0)), Dense)
    cov = Diagonal(var)
    assert as_covariance(cov) is cov
    assert isinstance(block_diagonal([cov, np.diag(var)]), Diagonal)
    assert isinstance(block_diagonal([cov, _spd(2, 0)]), Block)
    assert cov.shape == (3, 3) and np.array_equal(np.diag(cov), var)  # reads as a matrix


@pytest.mark.parametrize("C, words", [
    (np.diag([1.0, 0.0, 2.0]), ["not positive definite", "std > 0"]),
    (np.array([1.0, -1.0]), ["not positive definite"]),
    (np.array([[2.0, 3.0], [3.0, 2.0]]), ["not positive definite"]),
    (np.array([[2.0, 0.5], [0.4, 2.0]]), ["not symmetric"]),
    (np.ones((2, 3)), ["shape (2, 3)", "square"]),
    (np.ones((2, 2, 2)), ["shape (2, 2, 2)"]),
    (np.array([[1.0, np.nan], [np.nan, 1.0]]), ["NaN"]),
    (np.array([1.0, np.nan]), ["NaN"]),
])
def test_bad_covariances_are_refused_with_a_message(C, words):
    with pytest.raises(ValueError) as caught:
        as_covariance(C, name="C_exp")
    assert all(w in str(caught.value) for w in words + ["C_exp"]), str(caught.value)


def test_bad_arguments_of_the_kinds_are_refused():
    with pytest.raises(ValueError, match="covers 3 values, but there are 4"):
        as_covariance(np.ones(3), 4, name="C_exp")
    with pytest.raises(ValueError, match=r"U has shape \(3, 2\); expected \(4, k\)"):
        LowRankPlusDiagonal(np.ones((3, 2)), np.ones(4))
    with pytest.raises(ValueError, match="right-hand side has shape"):
        Diagonal(np.ones(3)).solve(np.ones(4))
    with pytest.raises(ValueError, match="positions must lie in"):
        Diagonal(np.ones(3)).take([0, 3])
    with pytest.raises(TypeError, match="not a covariance object or an array of numbers"):
        as_covariance(["a", "b"])


def test_dense_form_of_a_large_covariance_is_refused():
    big = Diagonal(np.ones(DENSE_LIMIT + 1))
    with pytest.raises(ValueError, match="use its solve / whiten / diag"):
        big.dense()
    assert big.take(slice(0, 10)).dense().shape == (10, 10)


# --- the Kalman filter's update ------------------------------------------------------------------------


@pytest.mark.parametrize("kind", list(KINDS))
def test_information_form_equals_gain_form(kind):
    cov, R = _pair(kind)
    rng = np.random.default_rng(5)
    p = 2
    C = np.array([[2.0, 0.5], [0.5, 1.0]]) * np.array([[1e4, 1e1], [1e1, 1e-2]])  # parameters of unlike scales
    S, innovation, x = rng.normal(size=(cov.n, p)), rng.normal(size=cov.n), np.array([1.0, -2.0])
    x_gain, C_gain, K_gain = kalman_update(x, C, S, innovation, R)
    x_info, C_info, K_info = information_update(x, C, S, innovation, cov)
    np.testing.assert_allclose(x_info, x_gain, rtol=1e-10)
    np.testing.assert_allclose(C_info, C_gain, rtol=1e-9, atol=1e-12 * np.abs(C_gain).max())
    np.testing.assert_allclose(K_info, K_gain, rtol=1e-9, atol=1e-12 * np.abs(K_gain).max())
    # the filter's choice: the gain form for a group of at most p observations, the information form above
    np.testing.assert_array_equal(assimilate(x, C, S[:p], innovation[:p], cov.take(range(p)))[1],
                                  kalman_update(x, C, S[:p], innovation[:p], R[:p, :p])[1])
    np.testing.assert_array_equal(assimilate(x, C, S, innovation, cov)[1], C_info)


# --- consumers: the information along the load history, noise draws, the problem check ---------------


@pytest.mark.parametrize("kind", list(KINDS))
def test_cumulative_information_is_the_leading_block_solve(kind):
    from fracid.inverse.core.sensitivity import cumulative_information

    cov, C = _pair(kind)
    S = np.random.default_rng(8).normal(size=(cov.n, 3))
    expected = [S[: t + 1].T @ np.linalg.solve(C[: t + 1, : t + 1], S[: t + 1]) for t in range(cov.n)]
    np.testing.assert_allclose(cumulative_information(S, cov), expected, rtol=1e-9, atol=1e-12)


def test_noise_draws_through_the_object_are_those_of_the_matrix():
    from fracid.inverse.studies.stability import noisy_replicates

    var = np.linspace(1.0, 4.0, 5)
    np.testing.assert_allclose(noisy_replicates(np.zeros(5), Diagonal(var), 3, seed=2),
                               noisy_replicates(np.zeros(5), np.diag(var), 3, seed=2), rtol=1e-15)
    draws = noisy_replicates(np.zeros(50_000), Diagonal(np.full(50_000, 4.0)), 2, seed=1)  # no 50 000^2 matrix
    assert draws.shape == (2, 50_000) and np.std(draws) == pytest.approx(2.0, rel=0.01)


def test_check_problem_gives_a_covariance_object():
    from fracid.inverse.core.method import check_problem
    from fracid.inverse.core.space import ParameterSpace

    space = ParameterSpace(("a",), [0.0], [1.0])
    y, C = check_problem(lambda x: x, np.ones(3), np.diag([1.0, 2.0, 3.0]), space)
    assert isinstance(C, Diagonal) and np.array_equal(C.var, [1.0, 2.0, 3.0])
    low_rank = LowRankPlusDiagonal(np.ones((3, 1)), np.ones(3))
    assert check_problem(lambda x: x, np.ones(3), low_rank, space)[1] is low_rank
    with pytest.raises(ValueError, match=r"C_exp covers 3 values, but there are 4"):
        check_problem(lambda x: x, np.ones(4), low_rank, space)
