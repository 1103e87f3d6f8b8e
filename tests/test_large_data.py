"""A twin experiment with 100 000 data values and a diagonal covariance: identified back through
``fracid.inverse.methods.strategy.identify`` with no cap on the data size and no n x n matrix (issue 26, item 3)."""

import time
import tracemalloc

import numpy as np
import pytest

from fracid.data import Diagonal, ExperimentalData
from fracid.inverse.core.forward_operator import RunRecord
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.strategy import identify

N = 100_000
SPACE = ParameterSpace(("a", "b"), [1.0, 0.05], [5.0, 1.0])
X_TRUE = np.array([3.0, 0.3])


class Saturation:
    """y(t) = a (1 - exp(-t / b)) at N points t in (0, 1] [N]: a cheap, nonlinear forward operator of N outputs,
    with its exact sensitivities."""

    names = ("a", "b")
    n_outputs = N
    units = {"a": "N", "b": "mm"}
    sensitivities = True

    def __init__(self):
        self.t = np.linspace(1.0 / N, 1.0, N)

    def __call__(self, x, needed=None):
        a, b = np.asarray(x, float)
        e = np.exp(-self.t / b)
        S = np.column_stack([1.0 - e, -a * e * self.t / b**2])
        return RunRecord(np.asarray(x, float), a * (1.0 - e), S=S)

    def valid_bounds(self):
        return np.zeros(2), np.full(2, np.inf)

    def differentiated(self):
        return self  # its runs carry S already


def _twin(seed=4, std=0.3):
    operator = Saturation()
    y = operator(X_TRUE).y + std * np.random.default_rng(seed).standard_normal(N)
    data = ExperimentalData(operator.t, y, Diagonal(np.full(N, std**2)), (("global", 0, N),))
    return operator, data


@pytest.mark.parametrize("groups", ["all", "blocks"])
def test_a_twin_of_100000_values_with_a_diagonal_covariance_is_identified(groups):
    operator, data = _twin()
    assert isinstance(data.covariance, Diagonal) and data.n_y == N
    tracemalloc.start()
    start = time.perf_counter()
    result = identify(operator, data.y, data.covariance, SPACE, n=16, k=4, groups=groups, blocks=list(data.blocks))
    seconds = time.perf_counter() - start
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < 500e6, f"peak memory {peak / 1e6:.0f} MB: an n x n matrix would take {8 * N**2 / 1e9:.0f} GB"
    assert seconds < 30.0
    assert result.converged, result.status
    assert np.all(np.abs(result.x - X_TRUE) < 3.0 * result.std), (result.x, result.std)
    # the std of a least-squares fit of N values: small, and about the linearised (S^T C^-1 S)^-1
    S = operator(result.x).S
    expected = np.sqrt(np.diag(np.linalg.inv(S.T @ S / 0.3**2)))
    np.testing.assert_allclose(result.std, expected, rtol=0.05)
    np.testing.assert_allclose(result.std_exp, 0.3)
    assert result.misfit_std == pytest.approx(1.0, abs=0.02)


def test_the_covariance_of_100000_values_is_not_formed_densely():
    _, data = _twin()
    with pytest.raises(ValueError, match="would take 80 GB"):
        np.asarray(data.covariance)
    weighted = data.weighted({"global": 4.0})
    assert isinstance(weighted.covariance, Diagonal)
    np.testing.assert_allclose(weighted.std, 0.15)
