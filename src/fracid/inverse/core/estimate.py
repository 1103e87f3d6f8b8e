"""A Gaussian estimate: the standard deviations and the correlation of an estimate's covariance.

On the lowest floor of :mod:`fracid.inverse` (numpy only), so that the results of :mod:`fracid.inverse.core`
and of the methods above it share it.
"""

from __future__ import annotations

import numpy as np


class GaussianEstimate:
    """Mixin of the results that hold an estimate's covariance ``C`` (units of the parameters squared): its
    standard deviations and correlation matrix."""

    @property
    def std(self) -> np.ndarray:
        """Standard deviations sqrt(diag C) (units of the parameters)."""
        return np.sqrt(np.diag(self.C))

    @property
    def correlation(self) -> np.ndarray:
        """Correlation matrix C_ij / (std_i std_j) [-]."""
        return self.C / np.outer(self.std, self.std)


__all__ = ["GaussianEstimate"]
