"""Covariances widened by error terms: any data covariance plus a low-rank term, or plus variances.

The error terms of :mod:`fracid.inverse.likelihood` (the mesh's discretisation error, the model's own error) are
added to the measurement covariance C_exp without forming an n x n matrix:

* :class:`LowRankUpdate` ``B + U U^T`` for any covariance object B (a :class:`~fracid.data.covariance_matrix.
  Covariance`) and k columns U: errors correlated along a curve (a smooth kernel of low numerical rank);
* :func:`plus_diagonal` ``B + diag(a)``: independent extra variances (kept in B's own kind).

Units: those of y squared (N^2 for forces, mm^2 for lengths); U in units of y.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from fracid.data.covariance_matrix import Block, Covariance, Dense, Diagonal, as_covariance, block_diagonal
from fracid.data.covariance_low_rank import LowRankPlusDiagonal


def _vectors(b, n: int, what: str) -> np.ndarray:
    """``b`` as a float array of n rows (a vector or columns), or a ValueError naming ``what``."""
    b = np.asarray(b, dtype=float)
    if b.ndim not in (1, 2) or b.shape[0] != n:
        raise ValueError(f"{what}: the right-hand side has shape {b.shape}; expected ({n},) or ({n}, k)")
    return b


class LowRankUpdate(Covariance):
    """C = B + U U^T: a covariance B (any :class:`~fracid.data.covariance_matrix.Covariance`) plus k shared modes.

    With B = L L^T and the whitened modes V = L^-1 U (``B.whiten(U)``), C = L (I + V V^T) L^T, so

    * solve: the Woodbury identity C^-1 = B^-1 - B^-1 U K^-1 U^T B^-1, K = I + V^T V (k x k);
    * logdet: log det B + log det K (matrix determinant lemma);
    * whiten: (I + V V^T)^-1/2 L^-1 r, the symmetric root from the thin SVD V = Q diag(s) P^T:
      (I + V V^T)^-1/2 = I + Q (diag(1 / sqrt(1 + s^2)) - 1) Q^T, applied after ``B.whiten``;
    * color: L (I + V V^T)^1/2 z.

    O(n k^2) besides B's own cost; B's kind (diagonal, block, low rank) is kept.

    Parameters
    ----------
    base : Covariance or array_like
        B [units of y squared] (through :func:`~fracid.data.covariance_matrix.as_covariance`).
    U : array_like, shape (n,) or (n, k)
        The modes [units of y].
    """

    def __init__(self, base, U, *, name: str = "covariance"):
        self.base = as_covariance(base, name=name)
        U = np.array(U, dtype=float)
        U = U[:, None] if U.ndim == 1 else U
        if U.ndim != 2 or U.shape[0] != self.base.n:
            raise ValueError(f"{name}: U has shape {U.shape}; expected ({self.base.n}, k) like the base covariance")
        if not np.all(np.isfinite(U)):
            raise ValueError(f"{name}: U holds NaN or infinite values")
        U.setflags(write=False)
        self.U, self.n = U, self.base.n
        V = self.base.whiten(U)
        self._capacitance = np.linalg.cholesky(np.eye(U.shape[1]) + V.T @ V)
        self._base_solved = self.base.solve(U)  # B^-1 U
        self._Q, sigma, _ = np.linalg.svd(V, full_matrices=False)
        self._s2 = sigma**2

    def _root_apply(self, w, power: float):
        """(I + V V^T)^power w through the thin SVD of V."""
        factor = (1.0 + self._s2) ** power - 1.0
        return w + self._Q @ ((factor if w.ndim == 1 else factor[:, None]) * (self._Q.T @ w))

    def solve(self, b):
        solved = self.base.solve(_vectors(b, self.n, "solve"))
        correction = scipy.linalg.cho_solve((self._capacitance, True), self.U.T @ solved)
        return solved - self._base_solved @ correction

    def logdet(self) -> float:
        return self.base.logdet() + float(2.0 * np.sum(np.log(np.diag(self._capacitance))))

    def whiten(self, r):
        return self._root_apply(self.base.whiten(_vectors(r, self.n, "whiten")), -0.5)

    def color(self, z):
        return self.base.color(self._root_apply(_vectors(z, self.n, "color"), 0.5))

    def diag(self) -> np.ndarray:
        return self.base.diag() + np.sum(self.U**2, axis=1)

    def noise_diag(self) -> np.ndarray:
        """The measurement noise's variances: the base's (the modes are error terms, not noise)."""
        return self.base.noise_diag()

    def _dense(self) -> np.ndarray:
        return self.base.dense() + self.U @ self.U.T

    def take(self, index) -> Covariance:
        """The entries ``index``: the base's and the modes' rows (modes that vanish there dropped)."""
        index = np.arange(self.n)[index]  # a slice, positions or a boolean mask
        return low_rank_update(self.base.take(index), self.U[index])

    def scaled(self, factors) -> "LowRankUpdate":
        f = np.asarray(factors, float)
        return LowRankUpdate(self.base.scaled(f), self.U * f[:, None])


def low_rank_update(base, U) -> Covariance:
    """``base + U U^T`` (:class:`LowRankUpdate`), without the columns of U that are zero (``base`` itself when
    none is left); an update of an update keeps one base and joins the columns."""
    base = as_covariance(base)
    U = np.asarray(U, float)
    U = U[:, None] if U.ndim == 1 else U
    U = U[:, np.any(U != 0.0, axis=0)]
    if U.shape[1] == 0:
        return base
    if isinstance(base, LowRankUpdate):
        return LowRankUpdate(base.base, np.hstack([base.U, U]))
    return LowRankUpdate(base, U)


def plus_diagonal(C, add) -> Covariance:
    """``C + diag(add)``: independent extra variances ``add`` [units of y squared, >= 0] on the entries of C,
    in C's own kind (a diagonal stays diagonal, a block diagonal block diagonal).

    Raises
    ------
    TypeError
        For a covariance kind it does not know (not a sum it can keep sparse).
    """
    C = as_covariance(C)
    add = np.broadcast_to(np.asarray(add, float), (C.n,))
    if np.any(add < 0) or not np.all(np.isfinite(add)):
        raise ValueError("plus_diagonal: the added variances must be finite and >= 0")
    if isinstance(C, Diagonal):
        return Diagonal(C.var + add)
    if isinstance(C, Dense):
        return Dense(C.C + np.diag(add))
    if isinstance(C, LowRankPlusDiagonal):
        return LowRankPlusDiagonal(C.U, C.D.var + add, nuisance=C.nuisance)
    if isinstance(C, Block):
        return block_diagonal([plus_diagonal(block, add[start:stop])
                               for block, start, stop in zip(C.blocks, C.offsets[:-1], C.offsets[1:])])
    if isinstance(C, LowRankUpdate):
        return LowRankUpdate(plus_diagonal(C.base, add), C.U)
    if hasattr(C, "plus_diagonal"):  # a kind that keeps its own form (SparseCovariance)
        return C.plus_diagonal(add)
    raise TypeError(f"plus_diagonal: a {type(C).__name__} covariance has no diagonal to add to; give a Diagonal, "
                    "Dense, LowRankPlusDiagonal, SparseCovariance, Block or LowRankUpdate")


__all__ = ["LowRankUpdate", "low_rank_update", "plus_diagonal"]
