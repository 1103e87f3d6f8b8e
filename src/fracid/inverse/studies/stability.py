"""Stability of the estimate (docs/theory.md, section 4.7): identification repeated on data with noise added.

Each replicate adds a draw of N(0, noise covariance) to the data (seeds fixed, so a study is
reproducible) and runs the method's local fit again from the same prior. The scatter of the estimates,
compared with the noise of the data, says how strongly measurement errors are amplified into the
parameters: a stable identification has scatter of the order of the posterior standard deviation.
"""

from __future__ import annotations


from dataclasses import dataclass, field

import numpy as np

from fracid.data.covariance_matrix import as_covariance
from fracid.runtime.executors import concurrently


@dataclass
class Stability:
    """Estimates of the noisy replicates.

    Attributes
    ----------
    estimates : ndarray, shape (N, p)
        One row per replicate (NaN for a replicate whose filter failed).
    errors : list of str
        Failure reason per replicate ("" when it ran).
    noise_level : float
        RMS of std / ``|y|`` over the data (:func:`relative_noise`): the relative noise added.
    seed : int
    """

    estimates: np.ndarray
    errors: list
    noise_level: float
    seed: int
    posterior_std: np.ndarray | None = field(default=None)

    @property
    def ok(self) -> np.ndarray:
        return np.all(np.isfinite(self.estimates), axis=1)

    @property
    def mean(self) -> np.ndarray:
        return self.estimates[self.ok].mean(axis=0)

    @property
    def scatter(self) -> np.ndarray:
        """Sample standard deviation of the estimates per parameter (units of the parameters)."""
        return self.estimates[self.ok].std(axis=0, ddof=1)

    @property
    def relative_scatter(self) -> np.ndarray:
        return self.scatter / np.abs(self.mean)

    @property
    def amplification(self) -> np.ndarray:
        """Relative scatter of each parameter / relative noise of the data."""
        return self.relative_scatter / self.noise_level


def relative_noise(y_exp, C_noise) -> float:
    """RMS of std / ``|y|`` over the values the noise does not swamp (``|y|`` >= 3 std; all if none), the std that of the
    measurement noise alone (a marginalised rigid motion left out: :meth:`Covariance.noise_diag`) [-]."""
    variance = C_noise.noise_diag()
    clear = y_exp**2 >= 9.0 * variance
    ratio = variance / np.maximum(y_exp**2, 1e-300)
    return float(np.sqrt(np.mean(ratio[clear] if clear.any() else ratio)))


def noisy_replicates(y, C_noise, n: int, seed: int = 0) -> np.ndarray:
    """n draws of y + e, e ~ N(0, C_noise), shape (n, len(y)); reproducible from ``seed``.

    ``C_noise`` is an array or a :class:`~fracid.data.covariance_matrix.Covariance` [units of y squared];
    e = L z with C_noise = L L^T (``C_noise.color``), z standard normal: no n x n matrix for a diagonal one.
    """
    rng = np.random.default_rng(seed)
    C_noise = as_covariance(C_noise if np.ndim(C_noise) != 0 else np.atleast_2d(C_noise), name="C_noise")
    return np.asarray(y, float)[None, :] + C_noise.color(rng.standard_normal((n, len(y))).T).T


def stability(evaluate, y_exp, C_exp, x0, C0, *, replicates: int = 10, seed: int = 0, C_noise=None, bounds=None,
              executor=None, progress=None, fit) -> Stability:
    """Identify again from ``replicates`` noisy copies of the data.

    Parameters
    ----------
    evaluate : callable(x, needed)
        The forward operator.
    y_exp, C_exp : ndarray, or ndarray and Covariance
        Data and covariance used by the filter [units of y, and squared].
    x0, C0 : ndarray
        Prior of every replicate (the same for all, so only the noise differs).
    replicates : int
        N >= 2.
    seed : int
        Seed of the noise draws.
    C_noise : ndarray or Covariance, optional
        Covariance of the added noise [units of y squared]; C_exp if None.
    fit : callable
        The local fit of the replicates, ``fit(evaluate, y, C_exp, x0, C0, bounds=, executor=)`` (an
        inverse method's ``fit_from``) giving ``x``, ``std``, ``failed`` and ``status``.
    """
    if int(replicates) != replicates or replicates < 2:
        raise ValueError(f"replicates = {replicates!r}: the scatter needs at least 2 replicates")
    y_exp = np.asarray(y_exp, float)
    C_noise = as_covariance(C_exp if C_noise is None else C_noise, np.size(y_exp), name="C_noise")
    data = noisy_replicates(y_exp, C_noise, int(replicates), seed)
    estimates, errors = np.full((len(data), np.size(x0)), np.nan), []
    stds = []
    def run(y):
        return fit(evaluate, y, C_exp, x0, C0, bounds=bounds, executor=executor)

    for i, result in enumerate(concurrently(run, data, executor, progress)):  # the replicates side by side
        if result.failed:  # a replicate that fails is recorded; the study goes on
            error = result.status
        else:
            estimates[i], error = result.x, ""
            stds.append(result.std)
        errors.append(error)
    noise = relative_noise(y_exp, C_noise)
    posterior = np.mean(stds, axis=0) if stds else None
    return Stability(estimates, errors, noise, seed, posterior)
