"""The covariance of errors correlated over a short distance, C = diag(s) K diag(s) with K sparse, never dense.

A :class:`~fracid.data.covariance_matrix.Covariance` like the others of :mod:`fracid.data.covariance_matrix`,
for many values whose errors are correlated with their neighbours only: the displacements of a DIC field at
camera resolution (thousands of points a frame, each correlated with the few hundred within a subset or two:
:mod:`fracid.data.dic_noise`). K is a sparse symmetric positive definite correlation matrix (unit diagonal), s
the standard deviations [units of y].

K is factorised once by SuperLU (:func:`scipy.sparse.linalg.splu`) in symmetric mode: a fill-reducing ordering
P (minimum degree on K + K^T), diagonal pivots only, so that P K P^T = L U with U = diag(u) L^T (L unit lower
triangular): K = P^T L diag(u) L^T P, the Cholesky factor in LU form. Then

* solve: C^-1 b = s^-1 K^-1 (s^-1 b) (the LU solve);
* logdet: log det C = sum log u + 2 sum log s;
* whiten: diag(u)^-1/2 L^-1 P (r / s), so that ``|whiten(r)|^2 = r^T C^-1 r`` (the elimination order P, not the
  entries' order: a row of the whitened vector mixes entries, exact as a whole);
* color: s P^T L diag(u)^1/2 z, a draw of N(0, C) from a standard normal z.

The factor is shared: :meth:`SparseCovariance.scaled` (other standard deviations, e.g. another frame or
component at the same points) reuses it, and :meth:`SparseCovariance.take` (the points present at a frame, the
holes of failed subsets left out) factorises the sub-matrix once per distinct set of entries, so that frames
with the same holes share one factor. Cost: O(nnz(L)) memory and per solve; the factorisation of 8 000 points
on a 1 mm grid correlated over 10 mm (370 neighbours a point) takes about 0.5 s (benchmarks/dic_camera.py).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse
import scipy.sparse.linalg

from fracid.data.covariance_matrix import Covariance, as_column, checked_index, checked_rows

__all__ = ["SparseCovariance"]

#: SuperLU's ordering: minimum degree on K + K^T (for 8 000 DIC points, 0.5 s against 17 s in the natural order)
ORDERING = "MMD_AT_PLUS_A"


class _Factor:
    """The symmetric factorisation K = P^T L diag(u) L^T P of one sparse correlation matrix, and those of its
    principal sub-matrices already asked for (keyed by their entries)."""

    def __init__(self, K):
        self.K = scipy.sparse.csc_matrix(K)
        try:
            self.lu = scipy.sparse.linalg.splu(self.K, permc_spec=ORDERING, diag_pivot_thresh=0.0,
                                               options={"SymmetricMode": True})
        except RuntimeError as error:  # "Factor is exactly singular"
            raise ValueError(f"the sparse correlation matrix is singular ({error}); it must be positive definite")
        u = self.lu.U.diagonal()
        if not (np.array_equal(self.lu.perm_r, self.lu.perm_c) and np.all(u > 0)):
            raise ValueError("the sparse correlation matrix is not positive definite (a pivot <= 0 or off the "
                             "diagonal in its symmetric factorisation)")
        self.root_u = np.sqrt(u)
        self.L = self.lu.L.tocsr()
        self.order = self.lu.perm_r  # row i of K goes to row order[i] of P K P^T
        self.logdet = float(np.sum(np.log(u)))
        self._parts: dict = {}

    def part(self, index: np.ndarray) -> "_Factor":
        """The factor of K[index, index] (``index`` increasing positions), computed once."""
        key = index.tobytes()
        if key not in self._parts:
            self._parts[key] = _Factor(self.K[index][:, index])
        return self._parts[key]

    def whiten(self, b: np.ndarray) -> np.ndarray:
        """diag(u)^-1/2 L^-1 P b."""
        permuted = np.empty_like(b)
        permuted[self.order] = b
        solved = scipy.sparse.linalg.spsolve_triangular(self.L, permuted, lower=True, unit_diagonal=True)
        return solved / as_column(self.root_u, b)

    def color(self, z: np.ndarray) -> np.ndarray:
        """P^T L diag(u)^1/2 z."""
        return (self.L @ (z * as_column(self.root_u, z)))[self.order]


class SparseCovariance(Covariance):
    """C = diag(s) K diag(s): errors of standard deviation s correlated by a sparse correlation matrix K.

    Parameters
    ----------
    K : sparse matrix, shape (n, n)
        The correlation matrix: symmetric positive definite, unit diagonal (any scipy.sparse format).
    std : array_like, shape (n,), optional
        Standard deviations s [units of y] (default 1).
    name : str
        For messages.

    Notes
    -----
    See the module docstring for the factorisation and what each method costs. Two objects made by
    :meth:`scaled` share the factor; :meth:`take` factorises a sub-matrix once per set of entries.
    """

    def __init__(self, K, std=None, *, name: str = "covariance", _factor: _Factor | None = None):
        self._factor = _factor if _factor is not None else _Factor(_checked_correlation(K, name))
        self.n = self._factor.K.shape[0]
        s = np.ones(self.n) if std is None else np.asarray(std, dtype=float)
        if s.shape != (self.n,) or not np.all(np.isfinite(s) & (s > 0)):
            raise ValueError(f"{name}: std must be {self.n} finite values > 0, got shape {s.shape}")
        s.setflags(write=False)
        self.s = s

    @property
    def correlation(self):
        """K, the sparse correlation matrix (CSC)."""
        return self._factor.K

    def solve(self, b):
        b = checked_rows(b, self.n, "solve")
        s = as_column(self.s, b)
        return self._factor.lu.solve(np.ascontiguousarray(b / s)) / s

    def logdet(self) -> float:
        return self._factor.logdet + float(2.0 * np.sum(np.log(self.s)))

    def whiten(self, r):
        r = checked_rows(r, self.n, "whiten")
        return self._factor.whiten(r / as_column(self.s, r))

    def color(self, z):
        z = checked_rows(z, self.n, "color")
        return self._factor.color(z) * as_column(self.s, z)

    def diag(self) -> np.ndarray:
        return self.s**2 * self._factor.K.diagonal()

    def _dense(self) -> np.ndarray:
        return self._factor.K.toarray() * np.outer(self.s, self.s)

    def take(self, index) -> "SparseCovariance":
        """The entries ``index`` (positions, a slice or a mask): kept in increasing order by the caller
        (:class:`~fracid.data.covariance_matrix.Block` sorts); the sub-matrix's factor is computed once."""
        index = checked_index(index, self.n)
        if index.size == self.n and np.array_equal(index, np.arange(self.n)):
            return self
        if np.any(np.diff(index) <= 0):
            order = np.argsort(index, kind="stable")
            part = self.take(index[order])
            back = np.empty_like(order)
            back[order] = np.arange(order.size)
            return SparseCovariance(part.correlation[back][:, back], part.s[back])
        return SparseCovariance(None, self.s[index], _factor=self._factor.part(index))

    def scaled(self, factors) -> "SparseCovariance":
        f = np.asarray(factors, float)
        return SparseCovariance(None, self.s * np.abs(f), _factor=self._factor)

    def plus_diagonal(self, add) -> "SparseCovariance":
        """C + diag(add) [units of y squared, >= 0]: the same kind, K and s of the sum (a new factor)."""
        add = np.broadcast_to(np.asarray(add, float), (self.n,))
        s_new = np.sqrt(self.s**2 + add)
        ratio = self.s / s_new
        K = scipy.sparse.diags(ratio) @ self._factor.K @ scipy.sparse.diags(ratio)
        K = K + scipy.sparse.diags(1.0 - K.diagonal())
        return SparseCovariance(K, s_new)


def _checked_correlation(K, name: str):
    """K as CSC, checked square, finite, symmetric, with a unit diagonal."""
    if K is None or not scipy.sparse.issparse(K):
        raise ValueError(f"{name}: K must be a scipy.sparse matrix, got {type(K).__name__}")
    K = scipy.sparse.csc_matrix(K, dtype=float)
    if K.shape[0] != K.shape[1] or K.shape[0] == 0:
        raise ValueError(f"{name}: K has shape {K.shape}; expected (n, n), n >= 1")
    if not np.all(np.isfinite(K.data)):
        raise ValueError(f"{name}: K holds NaN or infinite values")
    if not np.allclose(K.diagonal(), 1.0, rtol=0, atol=1e-12):
        raise ValueError(f"{name}: K must have a unit diagonal (a correlation matrix)")
    asymmetry = abs(K - K.T)
    if asymmetry.nnz and asymmetry.max() > 1e-12:
        raise ValueError(f"{name}: K is not symmetric (largest |K - K^T| {asymmetry.max():.3g})")
    return K
