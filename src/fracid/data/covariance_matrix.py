"""Covariance matrices of the data, C_exp, that never form an n x n array unless they are one.

Every inverse method and the posterior use C_exp only through ``solve`` (C^-1 b), ``logdet``
(log det C), ``whiten`` (L^-1 r with C = L L^T, so that ``|whiten(r)|^2 = r^T C^-1 r``), ``color``
(L z: a draw of N(0, C) from a standard normal z), ``diag`` (the variances) and ``take`` (the
covariance of a subset of the entries). Five kinds implement them:

* :class:`Diagonal` ``diag(var)``: independent errors (what standard deviations give), O(n);
* :class:`Dense` ``C``: any symmetric positive definite matrix (small n), Cholesky factor;
* :class:`~fracid.data.covariance_low_rank.LowRankPlusDiagonal` ``diag(d) + U U^T``: independent errors
  plus k shared modes (Woodbury identity and the matrix determinant lemma), O(n k^2), in its own module;
* :class:`~fracid.data.covariance_sparse.SparseCovariance` ``diag(s) K diag(s)``, K sparse: errors correlated
  with near neighbours only (a DIC field), a sparse symmetric factorisation, in its own module;
* :class:`Block` the block diagonal of any of these (stacked datasets).

:func:`as_covariance` turns what the user gives (a covariance object, a 1-D array of variances, a
2-D array, kept :class:`Diagonal` when its off-diagonal entries are zero) into one of them.
Units: those of y squared (N^2 for forces, mm^2 for lengths).

For backward compatibility a covariance also reads as a numpy array (``np.asarray(C)``,
``C.shape``, ``C[s, s]``) as long as its dense form is small (:data:`DENSE_LIMIT`).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

#: largest n whose n x n dense form a covariance gives (``dense()``, ``np.asarray``): 20 000 values take 3.2 GB
DENSE_LIMIT = 20_000


def checked_rows(b, n: int, what: str) -> np.ndarray:
    """``b`` as a float array of n rows (a vector or a matrix of columns), checked."""
    b = np.asarray(b, dtype=float)
    if b.ndim not in (1, 2) or b.shape[0] != n:
        raise ValueError(f"{what}: the right-hand side has shape {b.shape}; expected ({n},) or ({n}, k)")
    return b


def as_column(v: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``v`` (n,) shaped to broadcast against ``b``, a vector (n,) or a matrix of columns (n, k)."""
    return v if b.ndim == 1 else v[:, None]


def checked_index(index, n: int) -> np.ndarray:
    """``index`` (slice, integers or booleans) as integer positions in range(n)."""
    if isinstance(index, slice):
        return np.arange(n)[index]
    index = np.asarray(index)
    if index.dtype == bool:
        if index.shape != (n,):
            raise ValueError(f"take: a boolean mask must have shape ({n},), got {index.shape}")
        return np.flatnonzero(index)
    index = np.atleast_1d(index)
    if index.ndim != 1 or not np.issubdtype(index.dtype, np.integer):
        raise ValueError(f"take: give a slice, a boolean mask or a 1-D array of integer positions, got {index!r}")
    if index.size and (index.min() < -n or index.max() >= n):
        raise ValueError(f"take: positions must lie in [0, {n}), got min {index.min()} and max {index.max()}")
    return np.where(index < 0, index + n, index)


class Covariance:
    """A symmetric positive definite n x n covariance [units of y squared]; see the module docstring.

    Subclasses implement ``n``, ``solve``, ``logdet``, ``whiten``, ``color``, ``diag``, ``_dense``,
    ``take`` and ``scaled``.
    """

    n: int
    ndim = 2  # it reads as a matrix (np.ndim)

    @property
    def shape(self) -> tuple[int, int]:
        """(n, n), as a matrix's."""
        return (self.n, self.n)

    def std(self) -> np.ndarray:
        """Standard deviation of every entry, sqrt(diag C) [units of y]."""
        return np.sqrt(self.diag())

    def quadratic(self, r) -> np.ndarray | float:
        """r^T C^-1 r for a vector r (a float), or per column of a matrix r (an array)."""
        w = self.whiten(r)
        return float(w @ w) if w.ndim == 1 else np.sum(w * w, axis=0)

    def noise_diag(self) -> np.ndarray:
        """The variances of the measurement noise alone: :meth:`diag` less the variance of nuisance modes (the
        vague prior of a marginalised rigid motion, :class:`~fracid.data.covariance_low_rank.LowRankPlusDiagonal`
        ``nuisance``)."""
        return self.diag()

    def dense(self) -> np.ndarray:
        """The n x n matrix (for reports and tests); ValueError above :data:`DENSE_LIMIT` values."""
        if self.n > DENSE_LIMIT and not isinstance(self, Dense):
            raise ValueError(f"the covariance of {self.n:,} values as a dense matrix would take "
                             f"{8.0 * self.n * self.n / 1e9:.3g} GB; use its solve / whiten / diag "
                             f"(dense() is for n <= {DENSE_LIMIT:,})")
        return self._dense()

    def __array__(self, dtype=None, copy=None):
        array = self.dense()
        return array if dtype is None else array.astype(dtype)

    def __getitem__(self, key):
        """``C[rows, rows]`` is :meth:`take` (a covariance); any other key indexes the dense matrix."""
        if isinstance(key, tuple) and len(key) == 2:
            a, b = key
            same = a is b or (isinstance(a, slice) and a == b) or (
                not isinstance(a, slice) and not isinstance(b, slice) and np.array_equal(np.asarray(a), np.asarray(b)))
            if same:
                return self.take(a)
        return self.dense()[key]

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n={self.n})"


class Diagonal(Covariance):
    """diag(var): independent errors.

    Parameters
    ----------
    var : array_like, shape (n,)
        Variances [units of y squared], finite and > 0.
    """

    def __init__(self, var, *, name: str = "covariance"):
        var = np.array(var, dtype=float)
        if var.ndim != 1 or var.size == 0:
            raise ValueError(f"{name}: the variances must be a non-empty 1-D array, got shape {var.shape}")
        if not np.all(np.isfinite(var)):
            raise ValueError(f"{name} holds {int(np.sum(~np.isfinite(var)))} NaN or infinite variances")
        if np.any(var <= 0.0):
            raise ValueError(f"{name} is not positive definite (a zero or negative variance at {int(np.sum(var <= 0))} "
                             "entries); every measured value needs a std > 0")
        var.setflags(write=False)
        self.var, self.n = var, int(var.size)

    def solve(self, b):
        b = checked_rows(b, self.n, "solve")
        return b / as_column(self.var, b)

    def logdet(self) -> float:
        return float(np.sum(np.log(self.var)))

    def whiten(self, r):
        r = checked_rows(r, self.n, "whiten")
        return r / as_column(np.sqrt(self.var), r)

    def color(self, z):
        z = checked_rows(z, self.n, "color")
        return z * as_column(np.sqrt(self.var), z)

    def diag(self) -> np.ndarray:
        return self.var.copy()

    def _dense(self) -> np.ndarray:
        return np.diag(self.var)

    def take(self, index) -> "Diagonal":
        return Diagonal(self.var[checked_index(index, self.n)])

    def scaled(self, factors) -> "Diagonal":
        """D C D with D = diag(factors) (entry i multiplied by factors[i])."""
        return Diagonal(self.var * np.asarray(factors, float) ** 2)


class Dense(Covariance):
    """Any symmetric positive definite matrix, through its Cholesky factor L (C = L L^T).

    Parameters
    ----------
    C : array_like, shape (n, n)
        The covariance [units of y squared]: finite, symmetric (to 1e-10 relative), positive definite.
    name : str
        Names the argument in error messages.
    """

    def __init__(self, C, *, name: str = "covariance"):
        C = np.array(C, dtype=float)
        if C.ndim != 2 or C.shape[0] != C.shape[1] or C.size == 0:
            raise ValueError(f"{name} has shape {C.shape}; a covariance is a non-empty square (n, n) matrix")
        if not np.all(np.isfinite(C)):
            raise ValueError(f"{name} holds {int(np.sum(~np.isfinite(C)))} NaN or infinite values")
        scale = float(np.max(np.abs(C)))
        if np.any(np.abs(C - C.T) > 1e-10 * np.abs(C) + 1e-12 * scale):
            raise ValueError(f"{name} is not symmetric; a covariance matrix is")
        try:
            self.L = np.linalg.cholesky(C)
        except np.linalg.LinAlgError:
            raise ValueError(f"{name} is not positive definite (a zero or negative variance, or dependent rows); "
                             "every measured value needs a std > 0") from None
        C.setflags(write=False)
        self.C, self.n = C, int(C.shape[0])

    def solve(self, b):
        return scipy.linalg.cho_solve((self.L, True), checked_rows(b, self.n, "solve"))

    def logdet(self) -> float:
        return float(2.0 * np.sum(np.log(np.diag(self.L))))

    def whiten(self, r):
        return scipy.linalg.solve_triangular(self.L, checked_rows(r, self.n, "whiten"), lower=True)

    def color(self, z):
        return self.L @ checked_rows(z, self.n, "color")

    def diag(self) -> np.ndarray:
        return np.diag(self.C).copy()

    def _dense(self) -> np.ndarray:
        return self.C

    def take(self, index) -> "Dense":
        index = checked_index(index, self.n)
        return Dense(self.C[np.ix_(index, index)])

    def scaled(self, factors) -> "Dense":
        f = np.asarray(factors, float)
        return Dense(self.C * np.outer(f, f))


class Block(Covariance):
    """Block diagonal of covariances: no correlation between the blocks (stacked datasets).

    Parameters
    ----------
    blocks : sequence of Covariance or array_like
        The diagonal blocks, in the order of the entries (each through :func:`as_covariance`).
    """

    def __init__(self, blocks, *, name: str = "covariance"):
        blocks = [as_covariance(b, name=f"{name} block {k + 1}") for k, b in enumerate(blocks)]
        if not blocks:
            raise ValueError(f"{name}: a block-diagonal covariance needs at least one block")
        self.blocks = tuple(blocks)
        self.offsets = np.concatenate([[0], np.cumsum([b.n for b in blocks])]).astype(int)
        self.n = int(self.offsets[-1])

    def _split(self, b, what):
        b = checked_rows(b, self.n, what)
        return [(block, b[start:stop]) for block, start, stop in zip(self.blocks, self.offsets[:-1], self.offsets[1:])]

    def solve(self, b):
        return np.concatenate([block.solve(part) for block, part in self._split(b, "solve")])

    def logdet(self) -> float:
        return float(sum(block.logdet() for block in self.blocks))

    def whiten(self, r):
        return np.concatenate([block.whiten(part) for block, part in self._split(r, "whiten")])

    def color(self, z):
        return np.concatenate([block.color(part) for block, part in self._split(z, "color")])

    def diag(self) -> np.ndarray:
        return np.concatenate([block.diag() for block in self.blocks])

    def noise_diag(self) -> np.ndarray:
        return np.concatenate([block.noise_diag() for block in self.blocks])

    def _dense(self) -> np.ndarray:
        return scipy.linalg.block_diag(*[block.dense() for block in self.blocks])

    def take(self, index) -> Covariance:
        """The sub-covariance of the entries ``index``; in increasing order it stays block diagonal,
        otherwise it is the (small) dense matrix of those entries in the order given."""
        index = checked_index(index, self.n)
        if np.any(np.diff(index) < 0):
            order = np.argsort(index, kind="stable")
            sorted_part = self.take(index[order]).dense()
            back = np.empty_like(order)
            back[order] = np.arange(order.size)
            return Dense(sorted_part[np.ix_(back, back)])
        owner = np.searchsorted(self.offsets, index, side="right") - 1
        parts = [block.take(index[owner == k] - self.offsets[k])
                 for k, block in enumerate(self.blocks) if np.any(owner == k)]
        return block_diagonal(parts)

    def scaled(self, factors) -> Covariance:
        f = np.asarray(factors, float)
        return block_diagonal([block.scaled(f[start:stop])
                               for block, start, stop in zip(self.blocks, self.offsets[:-1], self.offsets[1:])])


def block_diagonal(covariances) -> Covariance:
    """The block diagonal of ``covariances`` (objects or arrays): a :class:`Diagonal` when every block is
    diagonal, the block itself when there is one, else a :class:`Block` (nested blocks flattened)."""
    flat = []
    for cov in (as_covariance(c) for c in covariances):
        flat.extend(cov.blocks if isinstance(cov, Block) else [cov])
    if not flat:
        raise ValueError("block_diagonal needs at least one covariance")
    if all(isinstance(c, Diagonal) for c in flat):
        return flat[0] if len(flat) == 1 else Diagonal(np.concatenate([c.var for c in flat]))
    return flat[0] if len(flat) == 1 else Block(flat)


def independent_cuts(C: Covariance) -> np.ndarray:
    """The positions 0 < k < n where ``C`` splits into independent parts (no entry before k correlated with one
    from k on), and 0 and n: every position for a :class:`Diagonal`, the block ends (and the cuts inside each
    block) for a :class:`Block`, none inside any other kind."""
    if isinstance(C, Diagonal):
        return np.arange(C.n + 1)
    if isinstance(C, Block):
        return np.unique(np.concatenate([start + independent_cuts(block)
                                         for block, start in zip(C.blocks, C.offsets[:-1])]))
    return np.array([0, C.n])


def as_covariance(C, n: int | None = None, *, name: str = "covariance") -> Covariance:
    """``C`` as a :class:`Covariance`, checked symmetric positive definite.

    Parameters
    ----------
    C : Covariance or array_like
        A covariance object (returned as is); a 1-D array: the variances (:class:`Diagonal`); a 2-D
        (n, n) array: :class:`Diagonal` when its off-diagonal entries are all zero, else :class:`Dense`
        [units of y squared].
    n : int, optional
        The number of values it must cover.
    name : str
        Names the argument in error messages (e.g. ``"C_exp"``).

    Raises
    ------
    TypeError
        If ``C`` is not an array of numbers.
    ValueError
        If it is not finite, not of size n, not square, not symmetric or not positive definite.
    """
    if not isinstance(C, Covariance):
        try:
            array = np.asarray(C, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"{name} is a {type(C).__name__} that is not a covariance object or an array of "
                            "numbers") from None
        if array.ndim == 1:
            C = Diagonal(array, name=name)
        elif array.ndim == 2 and array.shape[0] == array.shape[1] and np.all(np.isfinite(array)) and (
                np.count_nonzero(array) == np.count_nonzero(np.diagonal(array))):
            C = Diagonal(np.diagonal(array), name=name)
        else:
            C = Dense(array, name=name)
    if n is not None and C.n != n:
        raise ValueError(f"{name} covers {C.n} values, but there are {n}: give the covariance of the {n} values "
                         f"(shape ({n}, {n}), or fracid.data.Diagonal(std**2))")
    return C


__all__ = ["DENSE_LIMIT", "Block", "Covariance", "Dense", "Diagonal", "as_column", "as_covariance", "block_diagonal",
           "checked_index", "checked_rows", "independent_cuts"]
