"""The covariance of independent errors plus a few shared modes, C = diag(d) + U U^T, never formed n x n.

A :class:`~fracid.data.covariance_matrix.Covariance` like the others of
:mod:`fracid.data.covariance_matrix`: a calibration error shared by every value, or the rigid motion of a
DIC frame marginalised out (:mod:`fracid.data.dic.rigid`), gives k << n columns of U. Units: those of y
squared.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from fracid.data.covariance_matrix import Covariance, Diagonal, as_column, checked_index, checked_rows

__all__ = ["LowRankPlusDiagonal"]


class LowRankPlusDiagonal(Covariance):
    """C = diag(d) + U U^T: independent errors plus k shared modes (e.g. a calibration error).

    Solved by the Woodbury identity, C^-1 = D^-1/2 (I - V K^-1 V^T) D^-1/2 with V = D^-1/2 U and
    the capacitance K = I + V^T V (k x k); log det C = sum log d + log det K (matrix determinant
    lemma); whitened by the symmetric square root (I + V V^T)^-1/2 from the thin SVD of V. O(n k^2).

    Parameters
    ----------
    U : array_like, shape (n, k)
        The shared modes [units of y].
    d : array_like, shape (n,)
        Variances of the independent part [units of y squared], > 0.
    nuisance : int
        The last ``nuisance`` columns of U are a vague prior on nuisance motions marginalised out (the rigid
        motion of a DIC frame, :mod:`fracid.data.dic.rigid`), not measurement noise: :meth:`noise_diag` leaves
        them out.
    """

    def __init__(self, U, d, *, name: str = "covariance", nuisance: int = 0):
        self.D = Diagonal(d, name=name)
        U = np.array(U, dtype=float)
        if U.ndim == 1:
            U = U[:, None]
        if U.ndim != 2 or U.shape[0] != self.D.n:
            raise ValueError(f"{name}: U has shape {U.shape}; expected ({self.D.n}, k) like d of {self.D.n} variances")
        if not np.all(np.isfinite(U)):
            raise ValueError(f"{name}: U holds NaN or infinite values")
        U.setflags(write=False)
        self.U, self.n = U, self.D.n
        if not 0 <= int(nuisance) <= U.shape[1]:
            raise ValueError(f"{name}: nuisance = {nuisance!r}; give 0 to {U.shape[1]} (the number of columns of U)")
        self.nuisance = int(nuisance)
        self._root_d = np.sqrt(self.D.var)
        V = U / self._root_d[:, None]
        self._capacitance = np.linalg.cholesky(np.eye(U.shape[1]) + V.T @ V)
        self._Q, sigma, _ = np.linalg.svd(V, full_matrices=False)
        self._s2 = sigma**2

    def _sqrt_apply(self, w, power: float):
        """(I + V V^T)^power w through the thin SVD V = Q diag(sigma) P^T."""
        factor = (1.0 + self._s2) ** power - 1.0
        return w + self._Q @ (as_column(factor, w) * (self._Q.T @ w))

    def solve(self, b):
        b = checked_rows(b, self.n, "solve")
        w = b / as_column(self._root_d, b)
        V = self.U / self._root_d[:, None]
        w = w - V @ scipy.linalg.cho_solve((self._capacitance, True), V.T @ w)
        return w / as_column(self._root_d, b)

    def logdet(self) -> float:
        return self.D.logdet() + float(2.0 * np.sum(np.log(np.diag(self._capacitance))))

    def whiten(self, r):
        r = checked_rows(r, self.n, "whiten")
        return self._sqrt_apply(r / as_column(self._root_d, r), -0.5)

    def color(self, z):
        z = checked_rows(z, self.n, "color")
        return self._sqrt_apply(z, 0.5) * as_column(self._root_d, z)

    def diag(self) -> np.ndarray:
        return self.D.var + np.sum(self.U**2, axis=1)

    def noise_diag(self) -> np.ndarray:
        return self.D.var + np.sum(self.U[:, : self.U.shape[1] - self.nuisance] ** 2, axis=1)

    def _dense(self) -> np.ndarray:
        return np.diag(self.D.var) + self.U @ self.U.T

    def take(self, index) -> "LowRankPlusDiagonal":
        index = checked_index(index, self.n)
        return LowRankPlusDiagonal(self.U[index], self.D.var[index], nuisance=self.nuisance)

    def scaled(self, factors) -> "LowRankPlusDiagonal":
        f = np.asarray(factors, float)
        return LowRankPlusDiagonal(self.U * f[:, None], self.D.var * f**2, nuisance=self.nuisance)
