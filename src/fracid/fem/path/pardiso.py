"""Intel MKL PARDISO backend (optional: ``pip install 'fracid[pardiso]'``, which pulls pypardiso and MKL).

:class:`PardisoSolver` factorizes real unsymmetric matrices (PARDISO matrix type 11). The symbolic
analysis (phase 11: fill-reducing ordering) runs once per sparsity pattern;
while the pattern stays the same, as it does for the tangents of a forward analysis, each call only
refactorizes and solves (phase 23); the analysis puts the rows of a zero diagonal (the border of the
solver's bordered tangent) last in PARDISO's ordering, so that no pivot is perturbed. pypardiso is used
for locating MKL and for the ctypes prototype of ``pardiso``; the calls are made here, because pypardiso
(0.4.7) leaves ``iparm[0] = 0``, with which MKL 2025+ resets every parameter to its defaults, including
the transpose flag that pypardiso's CSC path relies on: its solutions of unsymmetric CSC systems are then
wrong (checked with MKL 2026.2; see haasad/PyPardiso#87). Every parameter is therefore set explicitly here.
"""

from __future__ import annotations

import ctypes
import functools
import weakref

import numpy as np
import scipy.sparse as sp

from fracid.fem.path.linear_backend import SingularMatrixError, refine

_MTYPE = 11  # real unsymmetric
_ERRORS = {
    -1: "input inconsistent",
    -2: "not enough memory",
    -3: "reordering problem",
    -4: "zero pivot, numerical factorization or iterative refinement problem",
    -5: "unclassified (internal) error",
    -6: "reordering failed",
    -7: "diagonal matrix is singular",
    -8: "32-bit integer overflow problem",
    -9: "not enough memory for OOC",
    -10: "error opening OOC files",
    -11: "read/write error with OOC files",
}
#: most rows of a zero diagonal that the analysis moves to the end of the ordering (more: a zero block,
#: left to PARDISO's ordering and pivot perturbation)
MAX_DEFERRED_ZEROS = 8
#: relative residual below which a solution after perturbed pivots is not refined further
REFINE_RTOL = 1e-10
_I32 = ctypes.POINTER(ctypes.c_int32)
_F64 = ctypes.POINTER(ctypes.c_double)


@functools.cache
def _mkl_pardiso():
    """The ctypes ``pardiso`` function, the C type of the handle and MKL's ``MKL_Set_Num_Threads_Local``
    (located once: it takes ~0.3 s)."""
    try:
        from pypardiso.pardiso_wrapper import PyPardisoSolver

        loader = PyPardisoSolver(mtype=_MTYPE)
    except (ImportError, OSError) as err:
        raise ImportError(f"the PARDISO linear solver needs pypardiso and MKL: pip install 'fracid[pardiso]' ({err})") from err
    set_threads = loader.libmkl.MKL_Set_Num_Threads_Local  # the C interface (by value)
    set_threads.argtypes, set_threads.restype = [ctypes.c_int], ctypes.c_int
    return loader._mkl_pardiso, loader._pt_type, set_threads


def _default_iparm() -> np.ndarray:
    iparm = np.zeros(64, dtype=np.int32)
    iparm[0] = 1  # all values below are supplied (iparm[0] = 0 would reset them to MKL's defaults)
    iparm[1] = 2  # nested dissection ordering (METIS)
    iparm[7] = 2  # steps of PARDISO's iterative refinement; set per call (_checked_solve)
    iparm[9] = 13  # pivot perturbation 1e-13
    # no scaling (iparm[10]) and no weighted matching (iparm[12]): both are computed from the values the
    # analysis sees and then reused for every later matrix of the pattern; on the peer beam (27k and 48k
    # unknowns, equilibrated damage tangents) they made every factorization perturb pivots and fail
    # the residual check, while without them the residuals equal SuperLU's (1e-10) and the
    # factorization is as fast (benchmarks/linear_solvers.py)
    iparm[10] = 0
    iparm[12] = 0
    iparm[11] = 2  # solve with the transpose: CSC arrays read as CSR describe A^T
    iparm[17] = -1  # report the nonzeros of the factors in iparm[17]
    iparm[34] = 1  # zero-based indices
    return iparm


def _call(pardiso, pt_type, pt, iparm, phase, n, data, indptr, indices, b, x, perm=None) -> int:
    error = ctypes.c_int32(0)
    one = ctypes.c_int32(1)
    pardiso(
        pt.ctypes.data_as(ctypes.POINTER(pt_type)),
        ctypes.byref(one),  # maxfct
        ctypes.byref(one),  # mnum
        ctypes.byref(ctypes.c_int32(_MTYPE)),
        ctypes.byref(ctypes.c_int32(phase)),
        ctypes.byref(ctypes.c_int32(n)),
        data.ctypes.data_as(_F64),
        indptr.ctypes.data_as(_I32),
        indices.ctypes.data_as(_I32),
        None if perm is None else perm.ctypes.data_as(_I32),  # the ordering (iparm[4] = 1) or where it is returned (2)
        ctypes.byref(ctypes.c_int32(1 if b.ndim == 1 else b.shape[1])),
        iparm.ctypes.data_as(_I32),
        ctypes.byref(ctypes.c_int32(0)),  # msglvl
        b.ctypes.data_as(_F64),
        x.ctypes.data_as(_F64),
        ctypes.byref(error),
    )
    return error.value


def _pattern_keys(indptr, indices) -> np.ndarray:
    """column * n + row of every entry of a canonical CSC pattern: sorted, as the entries are stored."""
    n = indptr.size - 1
    return np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr)) * n + indices


def _release(pardiso, pt_type, pt, iparm):
    """Free PARDISO's internal memory (phase -1) held by the handle ``pt``, if any."""
    if pt.any():
        dummy_i, dummy_f = np.zeros(1, dtype=np.int32), np.zeros(1)
        _call(pardiso, pt_type, pt, iparm, -1, 0, dummy_f, dummy_i, dummy_i, dummy_f, dummy_f)
        pt[:] = 0


class PardisoSolver:
    """Sparse LU of Intel MKL PARDISO, reusing the symbolic analysis while the pattern is unchanged.

    Parameters
    ----------
    threads : int
        MKL threads of this solver's calls (0: MKL's default, all cores). On the 2-core machines of
        benchmarks/forward_2d.py one thread factorizes the beam's tangents as fast as two and
        solves 3.6 times faster (2.9 ms against 10.5 ms at 10.6k unknowns), and a population
        runs one forward run per core anyway.
    residual_rtol : float
        When PARDISO had to perturb pivots (it never stops on a zero pivot: it perturbs it and
        refines), the solution is accepted only if ``||A x - b|| <= residual_rtol ||b||``; otherwise
        the analysis is redone with the current values and, if that does
        not help either, :class:`~fracid.fem.path.linear_backend.SingularMatrixError` is raised.
        The default is loose on purpose: the damage tangents mix rows of order E t (equilibrium)
        with rows of order mm^2 (diffusion), so even a sound factorization of the virgin state
        leaves relative residuals near 1e-7 (SuperLU too), and the Newton iteration only needs a
        descent direction; a truly singular matrix leaves residuals of order one.

    Attributes
    ----------
    n_analyses, n_factorizations : int
        Symbolic analyses (phase 11) and numeric factorizations performed.
    perturbed_pivots : int
        Perturbed pivots in the last factorization.
    """

    name = "pardiso"

    def __init__(self, *, threads: int = 1, residual_rtol: float = 1e-4):
        if int(threads) != threads or threads < 0:
            raise ValueError(f"threads = {threads!r}; give a non-negative integer (0: MKL's default)")
        self.threads = int(threads)
        self._pardiso, pt_type, self._set_threads = _mkl_pardiso()
        self._pt_type = pt_type[0]
        self.pt = np.zeros(64, dtype=pt_type[1])
        self.iparm = _default_iparm()
        self.residual_rtol = residual_rtol
        self.n_analyses = self.n_factorizations = self.perturbed_pivots = 0
        self._shape = None
        self._indptr = self._indices = self._perm = None
        self._base = None  # (pattern keys, ordering without the zero diagonal) of the last nested dissection
        self._finalizer = weakref.finalize(self, _release, self._pardiso, self._pt_type, self.pt, self.iparm)
        self._finalizer.atexit = False

    def _run(self, phase, data, b, x):
        n = self._shape[0]
        previous = self._set_threads(self.threads)  # this thread's MKL threads, for this call only
        try:
            error = _call(self._pardiso, self._pt_type, self.pt, self.iparm, phase, n, data, self._indptr,
                          self._indices, b, x, self._perm)
        finally:
            self._set_threads(previous)
        if error == 0:
            return
        message = f"PARDISO phase {phase} failed with error {error} ({_ERRORS.get(error, 'unknown error')})"
        if phase == 11:
            self._shape = None  # no valid analysis any more
        if error in (-4, -7):
            raise SingularMatrixError(message)
        if error in (-2, -9):
            raise MemoryError(message)
        raise RuntimeError(message)

    def _same_pattern(self, matrix) -> bool:
        return (
            matrix.shape == self._shape
            and np.array_equal(matrix.indptr, self._indptr)
            and np.array_equal(matrix.indices, self._indices)
        )

    def _analyse(self, matrix, data):
        """Phase 11 for the pattern of ``matrix``: PARDISO's nested dissection, with the few rows and
        columns of a zero diagonal moved last."""
        self.free()
        indptr = np.ascontiguousarray(matrix.indptr, dtype=np.int32)
        indices = np.ascontiguousarray(matrix.indices, dtype=np.int32)
        n = matrix.shape[0]
        if np.any(indptr[1:] == indptr[:-1]) or np.bincount(indices, minlength=n).min(initial=1) == 0:
            raise SingularMatrixError("the matrix is structurally singular (an empty row or column)")
        self._shape, self._indptr, self._indices = matrix.shape, indptr.copy(), indices.copy()
        dummy = np.zeros(1)
        self.iparm[4], self._perm = 0, None
        zero_diagonal = np.flatnonzero(matrix.diagonal() == 0.0).astype(np.int32)
        grown = self._grown_order(indptr, indices, zero_diagonal)
        if grown is not None:
            self.iparm[4], self._perm = 1, grown
        elif 0 < zero_diagonal.size <= MAX_DEFERRED_ZEROS:
            # PARDISO's fill-reducing ordering (returned with iparm[4] = 2), with the few rows and columns
            # of a zero diagonal (the border of the bordered tangent) moved last. Where the ordering put
            # the border (early: it has few entries), its pivot was an exact zero that PARDISO perturbed,
            # and every solution needed a refinement (two solves and two products); last, its pivot
            # is the Schur complement v^T K^-1 f and no pivot is perturbed (demo beam: the solves' relative
            # residuals 1e-13 to 3e-11 without refinement, against up to 1e-10 with it; a solve costs half)
            self.iparm[4], self._perm = 2, np.zeros(n, dtype=np.int32)
            self._run(11, data, dummy, dummy)
            _release(self._pardiso, self._pt_type, self.pt, self.iparm)
            order = self._perm[~np.isin(self._perm, zero_diagonal)]
            self.iparm[4], self._perm = 1, np.concatenate([order, zero_diagonal]).astype(np.int32)
            self._base = (_pattern_keys(indptr, indices), order, zero_diagonal)
        self._run(11, data, dummy, dummy)
        self.n_analyses += 1

    def _grown_order(self, indptr, indices, zero_diagonal):
        """The ordering of a pattern that holds the last one PARDISO ordered itself plus entries (the
        integral model's nonlocal coupling, which grows with the damaged zone), or None.

        That ordering is kept, the rows (or the columns, whichever are fewer) that gained entries
        are moved after it and the zero diagonal last. The coupling is a dense block between the
        dofs of the loading points and those they average over, so this is the ordering a fill-reducing
        one finds (on the demo beam the same nonzeros in the factors, 4.1 million), without its
        nested dissection: the analysis costs a third.
        """
        if self._base is None:
            return None
        base, order, base_zeros = self._base
        keys = _pattern_keys(indptr, indices)
        at = np.minimum(np.searchsorted(keys, base), keys.size - 1)
        if order.size + base_zeros.size != indptr.size - 1 or not np.array_equal(base_zeros, zero_diagonal) \
                or not np.array_equal(keys[at], base):
            return None  # another size, other zero pivots or not a superset of the base pattern: a new base
        extra = np.ones(keys.size, dtype=bool)
        extra[at] = False
        n = indptr.size - 1
        columns, rows = np.divmod(keys[extra], n)
        moved = min((np.unique(rows), np.unique(columns)), key=np.size)
        moved = moved[~np.isin(moved, zero_diagonal)]  # (a superset: the zero diagonal is the base's)
        return np.concatenate([order[~np.isin(order, moved)], moved, zero_diagonal]).astype(np.int32)

    def _checked_solve(self, matrix, data, b, phase):
        """Phase 23 (factorize and solve) or 33 (solve with the last factorization), with the check.

        After a factorization that perturbed pivots (a zero pivot: the analysis orders the few rows of a
        zero diagonal last, so that a bordered tangent has none, see :meth:`_analyse`), the solution
        of phase 33 is refined here, against ``matrix``, while its residual is above ``REFINE_RTOL``
        (at most two steps): PARDISO's own refinement (``iparm[7]``) runs at every solve once asked
        for, and made a solve of the beam's tangent cost 2.3 times one solve.
        """
        self.iparm[7] = 2 if phase == 23 else 0
        x = self._phase(phase, data, b)
        if phase == 23:
            self.n_factorizations += 1
            self.perturbed_pivots = int(self.iparm[13])
        residual = None
        if self.perturbed_pivots and np.all(np.isfinite(x)):
            x, residual, scale = refine(lambda r: self._phase(33, data, np.asfortranarray(r)), matrix, b, x,
                                        REFINE_RTOL, 2 if phase == 33 else 0)
        if not np.all(np.isfinite(x)) or (residual is not None and residual > self.residual_rtol * scale):
            raise SingularMatrixError(
                f"PARDISO solution rejected ({self.perturbed_pivots} perturbed pivots): the matrix is numerically singular"
            )
        return x

    def _phase(self, phase, data, b):
        x = np.zeros_like(b, order="F")
        self._run(phase, data, b, x)
        return x

    def solve(self, matrix, rhs):
        """Solve ``matrix @ x = rhs`` for a square sparse matrix (CSC preferred) and rhs of shape (n,) or (n, k)."""
        matrix, data, fresh = self._prepare(matrix)
        b = self._rhs(matrix, rhs)
        try:
            return self._checked_solve(matrix, data, b, phase=23)
        except SingularMatrixError:
            if fresh:
                raise
        self._analyse(matrix, data)  # an analysis of an earlier matrix may not suit this one
        return self._checked_solve(matrix, data, b, phase=23)

    def factorize(self, matrix):
        """Factorize ``matrix`` (phase 22) and return ``rhs -> x`` (phase 33), valid until the next
        factorization of this solver (it raises RuntimeError after one).

        A solution with perturbed pivots is checked as in :meth:`solve`; a rejected one redoes the
        analysis with these values once before raising
        :class:`~fracid.fem.path.linear_backend.SingularMatrixError`.
        """
        matrix, data, fresh = self._prepare(matrix)
        self._factor(data)
        state = {"count": self.n_factorizations, "retried": fresh}

        def solve(rhs):
            b = self._rhs(matrix, rhs)
            if self.n_factorizations != state["count"]:
                raise RuntimeError("this PARDISO factorization was replaced by a later one")
            try:
                return self._checked_solve(matrix, data, b, phase=33)
            except SingularMatrixError:
                if state["retried"]:
                    raise
            state["retried"] = True  # an analysis of an earlier matrix may not suit this one
            self._analyse(matrix, data)
            self._factor(data)
            state["count"] = self.n_factorizations
            return self._checked_solve(matrix, data, b, phase=33)

        return solve

    def _prepare(self, matrix):
        """The matrix as canonical CSC, its data, and whether its pattern needed a new analysis (done here)."""
        if not sp.issparse(matrix) or matrix.format != "csc":
            matrix = sp.csc_matrix(matrix)
        if matrix.shape[0] != matrix.shape[1]:
            raise ValueError(f"the matrix must be square; got shape {matrix.shape}")
        fresh = not self._same_pattern(matrix)
        if fresh and not matrix.has_canonical_format:  # PARDISO needs sorted indices without duplicates
            matrix = matrix.copy()
            matrix.sum_duplicates()
            fresh = not self._same_pattern(matrix)
        data = np.ascontiguousarray(matrix.data, dtype=np.float64)
        if fresh:
            self._analyse(matrix, data)
        return matrix, data, fresh

    @staticmethod
    def _rhs(matrix, rhs):
        b = np.asfortranarray(rhs, dtype=np.float64)
        if b.shape[0] != matrix.shape[0] or b.ndim not in (1, 2):
            raise ValueError(f"rhs of shape {np.shape(rhs)} does not match the matrix of shape {matrix.shape}")
        return b

    def _factor(self, data):
        dummy = np.zeros(1)
        self._run(22, data, dummy, dummy)
        self.n_factorizations += 1
        self.perturbed_pivots = int(self.iparm[13])

    def free(self):
        """Release PARDISO's memory; the next solve starts with a new analysis."""
        _release(self._pardiso, self._pt_type, self.pt, self.iparm)
        self._shape = None
