"""Linear-solver backends behind one small interface (:mod:`fracid.fem.path.linear_backend`: a backend has
``solve(matrix, rhs) -> x`` and optionally ``factorize(matrix) -> solve(rhs)``, and raises
:class:`SingularMatrixError` when the matrix cannot be factorized): SuperLU, PARDISO
(:mod:`fracid.fem.path.pardiso`, loaded when asked for) and :func:`linear_solver`, which picks one.
"""

from __future__ import annotations

import functools
import threading

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fracid.fem.path.linear_backend import LinearSolver, SingularMatrixError

__all__ = ["SuperLUSolver", "SymmetricOrdering", "linear_solver"]


class SuperLUSolver:
    """Sparse LU factorization of SciPy (SuperLU), the backend that installs everywhere.

    Parameters
    ----------
    permc_spec : str
        Column ordering passed to :func:`scipy.sparse.linalg.splu`. The default, minimum degree on
        A^T + A, suits finite-element matrices (structurally symmetric).
    diag_pivot_thresh : float
        Threshold for keeping the diagonal pivot. Finite-element tangents are diagonally strong
        enough that a small threshold preserves the fill-reducing ordering: on a damaged dog-bone
        (6149 unknowns) 0.001 gives 1.0e6 factor entries in 0.03 s against 2.4e6 in 0.13 s with
        partial pivoting (1.0), at the same residual (1e-15).
    ordering : {"auto", "metis", "superlu"}
        ``"metis"``: a nested-dissection ordering of A + A^T by METIS (pymetis, a dependency where it has wheels),
        computed once per sparsity pattern and applied symmetrically; SuperLU then keeps it. On the
        damage tangents of the notched beam it factorizes 1.35 (10k unknowns) to 1.8 (48k) times
        faster than ``permc_spec``, with less fill (docs/speed/linear_solvers.md). ``"superlu"``:
        SuperLU orders with ``permc_spec`` at every factorization. ``"auto"``: METIS when pymetis is
        installed.
    """

    name = "superlu"

    def __init__(self, permc_spec: str = "MMD_AT_PLUS_A", diag_pivot_thresh: float = 0.001, ordering: str = "auto"):
        if ordering not in ("auto", "metis", "superlu"):
            raise ValueError(f"ordering = {ordering!r}; choose 'auto', 'metis' or 'superlu'")
        if ordering == "metis":
            _pymetis()  # a clear error now rather than at the first factorization
        self.permc_spec = permc_spec
        self.diag_pivot_thresh = diag_pivot_thresh
        self.ordering = ordering if ordering != "auto" else ("metis" if _has_pymetis() else "superlu")
        self._order = None  # the symmetric ordering of the last pattern seen

    def solve(self, matrix, rhs):
        return self.factorize(matrix)(rhs)

    def factorize(self, matrix):
        """The LU factors' solve function ``rhs -> x``."""
        if self.ordering == "metis":
            order = self._order if self._order is not None and self._order.fits(matrix) else None
            self._order = order = order or SymmetricOrdering.of(matrix)
            lu = self._splu(order.permuted(matrix), "NATURAL")
            return order.wrap(lu.solve)
        return self._splu(matrix, self.permc_spec).solve

    def _splu(self, matrix, permc_spec):
        try:
            return spla.splu(matrix, permc_spec=permc_spec, diag_pivot_thresh=self.diag_pivot_thresh,
                             options={"SymmetricMode": self.diag_pivot_thresh < 1.0})
        except RuntimeError as err:  # "Factor is exactly singular"
            raise SingularMatrixError(str(err)) from err


class SymmetricOrdering:
    """A fill-reducing ordering of one sparsity pattern, applied as P A P^T (rows and columns alike).

    Attributes
    ----------
    perm : ndarray of int
        New position k holds the old row/column ``perm[k]``.
    """

    def __init__(self, matrix, perm):
        self.shape, self.indptr, self.indices = matrix.shape, matrix.indptr.copy(), matrix.indices.copy()
        self.perm = np.asarray(perm, dtype=np.int64)
        # the permuted pattern once, with the position of every entry in the original data
        positions = sp.csc_matrix((np.arange(matrix.nnz, dtype=float) + 1.0, matrix.indices, matrix.indptr),
                                  shape=matrix.shape)[self.perm][:, self.perm].tocsc()
        positions.sort_indices()
        self._source = positions.data.astype(np.int64) - 1
        self._indices, self._indptr = positions.indices, positions.indptr

    @classmethod
    def of(cls, matrix) -> "SymmetricOrdering":
        """METIS nested dissection of the graph of A + A^T (without the diagonal)."""
        pymetis = _pymetis()
        pattern = sp.csr_matrix((np.ones(matrix.nnz), matrix.indices, matrix.indptr), shape=matrix.shape)
        graph = (pattern + pattern.T).tocsr()
        graph.setdiag(0.0)
        graph.eliminate_zeros()
        perm, _ = pymetis.nested_dissection(adjacency=pymetis.CSRAdjacency(graph.indptr, graph.indices))
        return cls(matrix, perm)

    def fits(self, matrix) -> bool:
        return (matrix.shape == self.shape and np.array_equal(matrix.indptr, self.indptr)
                and np.array_equal(matrix.indices, self.indices))

    def permuted(self, matrix):
        """P A P^T of a matrix of this pattern (CSC)."""
        return sp.csc_matrix((matrix.data[self._source], self._indices, self._indptr), shape=self.shape)

    def wrap(self, solve):
        """``rhs -> x`` of A from ``solve`` of P A P^T."""
        perm = self.perm

        def solve_original(rhs):
            x = np.empty_like(rhs, dtype=float)
            x[perm] = solve(np.ascontiguousarray(rhs[perm]))
            return x

        return solve_original


def _has_pymetis() -> bool:
    try:
        _pymetis()
    except ImportError:
        return False
    return True


def _pymetis():
    try:
        import pymetis
    except ImportError as err:
        raise ImportError(f"the METIS ordering needs pymetis (installed with fracid where it has wheels: Linux and "
                          f"macOS on x86_64, macOS arm64; elsewhere pip install pymetis builds it) ({err})") from err
    return pymetis


_SHARED = threading.local()


def _per_thread(name, make):
    """This thread's shared backend ``name``: the forward runs of a population on one mesh (one after
    the other in a worker) share it, so its per-pattern work (PARDISO's symbolic analysis, SuperLU's
    METIS ordering) is done once per mesh, not once per run."""
    solver = getattr(_SHARED, name, None)
    if solver is None:
        solver = make()
        setattr(_SHARED, name, solver)
    return solver


def _pardiso():
    from fracid.fem.path.pardiso import PardisoSolver  # lazy: pypardiso is an optional extra

    return _per_thread("pardiso", PardisoSolver)


def _superlu():
    return _per_thread("superlu", SuperLUSolver)


@functools.cache
def _has_pardiso() -> bool:
    try:
        _pardiso()
    except ImportError:
        return False
    return True


def _fastest():
    """PARDISO where the ``pardiso`` extra is installed (2.8 times faster factorizations than SuperLU on
    the beams' tangents, docs/speed), else SuperLU (in a METIS ordering with the ``metis`` extra)."""
    return _pardiso() if _has_pardiso() else _superlu()


_BACKENDS = {"auto": _fastest, "superlu": _superlu, "pardiso": _pardiso}


def linear_solver(spec=None) -> LinearSolver:
    """Return a backend from a name (``"auto"``, ``"superlu"``, ``"pardiso"``), an instance (returned as
    is), or None (``"auto"``: the fastest installed, see :func:`_fastest`)."""
    if spec is None:
        return _fastest()
    if isinstance(spec, str):
        try:
            return _BACKENDS[spec.lower()]()
        except KeyError:
            raise ValueError(f"unknown linear solver {spec!r}; available: {sorted(_BACKENDS)}") from None
    if not callable(getattr(spec, "solve", None)):
        raise TypeError(f"a linear solver needs a solve(matrix, rhs) method; got {type(spec).__name__}")
    return spec
