"""The misfit of computed observations to the data: the objective every method and check ranks points by.

Numpy and the data's covariance objects only; on the lowest floor of :mod:`fracid.inverse`.
"""

from __future__ import annotations

import numpy as np

from fracid.data.covariance_matrix import as_covariance


def objective(y_exp, C_exp, Y) -> np.ndarray:
    """f_i = (y_exp - y_i)^T C_exp^-1 (y_exp - y_i) for every row of Y; inf for failed (NaN) rows.

    ``C_exp`` is an (n, n) array or a :class:`~fracid.data.covariance_matrix.Covariance` (used through
    its whitening: no n x n matrix for a diagonal one) [units of y squared]; f is dimensionless.
    """
    C_exp = as_covariance(C_exp, name="C_exp")
    Y = np.atleast_2d(np.asarray(Y, float))
    computed = np.all(np.isfinite(Y), axis=1)
    residual = np.where(computed[:, None], np.asarray(y_exp, float) - Y, 0.0)
    return np.where(computed, C_exp.quadratic(residual.T), np.inf)


__all__ = ["objective"]
