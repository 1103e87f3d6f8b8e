"""Benchmark: sparse direct solvers on the bordered tangents that the Newton solver factorizes.

A forward run factorizes, at every Newton iteration, the equilibrated bordered tangent S M S (see
``ControlledSystem.scaled_matrix``): nonsymmetric, structurally almost symmetric, with a sparsity
pattern that is fixed for the whole run (and for every run on the same mesh). This script

1. captures such matrices from real forward runs of the gradient damage model (``capture``): a
   linear-solver object passed as ``linear_solver=`` keeps a copy of the matrix and right-hand side
   of the first Newton iteration (virgin elastic state), of the last iteration of the step at the
   peak force, and of the first step whose force has fallen below ``--softening`` times the peak,
   then stops the run; each factorization is delegated to ``--delegate`` (SuperLU by default);
2. times the candidate backends on them (``time``): for each matrix the factorization and one
   solve, best of ``--repeat``, the size of the factors where the backend reports it, and the
   relative residual ||A x - b|| / ||b|| for the captured right-hand side; work that a backend
   does once per sparsity pattern (an ordering, a symbolic analysis) is timed separately, once.

Candidates: superlu (as fracid today: MMD_AT_PLUS_A, diag_pivot_thresh 0.001, SymmetricMode),
superlu-colamd, superlu-mmd-ata, superlu-metis (pymetis nested dissection of A + A^T, computed once,
applied symmetrically, then NATURAL), superlu-rcm (scipy's reverse Cuthill-McKee, once, NATURAL),
superlu-mmd-once (the column order of a first SuperLU factorization reused with NATURAL),
pardiso (fracid's PardisoSolver; ``pardiso-first`` = a new analysis with every factorization;
``pardiso-nomatch*``: the same without scaling and weighted matching),
mumps / mumps-reuse (python-mumps: analysis per factorization / analysis once), umfpack / klu
(kvxopt: symbolic analysis once), pyklu (PyKLU: a whole KLU factorization per call). Candidates
whose package is missing are reported as unavailable. MKL, OpenBLAS and OpenMP threads should be
limited from the environment for single-core numbers.

    python benchmarks/linear_solvers.py capture [--cases peer1,peer05,beam,dogbone] [--dir DIR]
    python benchmarks/linear_solvers.py capture --cases peer033 --max-steps 2
    python benchmarks/linear_solvers.py time [--cases ...] [--candidates superlu,pardiso,...] [--dir DIR]

Cases: peer1 / peer05 / peer033, the Gregoire beam with 1 mm loading and support plates, h_fine = 1,
0.5 and 0.33 mm (12.7k, 27.4k and 47.6k unknowns; peer033 only up to a few elastic steps), with
E = 37000, kappa_i = 1.1e-4, beta = 500, c = 4, CMOD control; beam, the default beam (10.6k unknowns);
dogbone, D = 100 mm (1.9k unknowns).

Single core, as measured for the issue:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 taskset -c 1 python benchmarks/linear_solvers.py time

``capture`` needs fracid; ``time`` reads only the saved matrices (``DIR/CASE.npz``), so it also runs
in an environment without fracid (e.g. one with NumPy 1.x for python-mumps 0.0.2).
"""

from __future__ import annotations

import argparse
import gc
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

STATES = ("first", "peak", "softening", "last")


# --------------------------------------------------------------------------------------------------
# capture


def _cases():
    import fracid
    from fracid.specimens import SPECIMENS

    peer = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=1.1e-4, alpha=0.99, beta=500.0, c=4.0, eta=10.0)
    beam = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=8.4e-5, alpha=0.99, beta=600.0, c=9.0)
    dogbone = fracid.DamageParameters(E=30000.0, nu=0.2, kappa_i=1e-4, alpha=0.99, beta=300.0, c=25.0)
    return {  # name: (specimen factory, parameters, control, target [mm])
        "peer1": (lambda: SPECIMENS["notched-beam"](h_fine=1.0, plate_width=1.0), peer, "cmod", 0.16),
        "peer05": (lambda: SPECIMENS["notched-beam"](h_fine=0.5, plate_width=1.0), peer, "cmod", 0.16),
        # near the size of the 49k-unknown tangent of the issue; capture it with --max-steps (a few elastic steps)
        "peer033": (lambda: SPECIMENS["notched-beam"](h_fine=0.33, plate_width=1.0), peer, "cmod", 0.16),
        "beam": (lambda: SPECIMENS["notched-beam"](), beam, "cmod", 0.5),
        "dogbone": (lambda: SPECIMENS["dogbone"](size=100.0), dogbone, None, 0.3),
    }


class _Stop(Exception):
    pass


class Capture:
    """A linear solver that keeps copies of the matrices it is given and delegates the solves."""

    def __init__(self, delegate, softening: float):
        self.delegate, self.softening = delegate, softening
        self.name = "capture"
        self.calls, self.latest, self.kept, self.peak, self.info = 0, None, {}, 0.0, {}
        self.step_calls = []  # factorizations up to each converged step

    def solve(self, matrix, rhs):
        self.calls += 1
        self.latest = (matrix.copy(), np.array(rhs, copy=True), self.calls)
        if "first" not in self.kept:
            self.kept["first"] = self.latest
        return self.delegate.solve(matrix, rhs)

    def callback(self, step, tau, force):
        self.step_calls.append(self.calls)
        if abs(force) >= self.peak:
            self.peak = abs(force)
            self.kept["peak"] = self.latest
            self.info["peak"] = {"step": step, "control": tau, "force": force}
        elif abs(force) < self.softening * self.peak:
            self.kept["softening"] = self.latest
            self.info["softening"] = {"step": step, "control": tau, "force": force}
            raise _Stop


def capture(names, directory: Path, delegate: str, softening: float, max_steps: int):
    from fracid.fem.path.linear_solvers import linear_solver
    from fracid.models import DamageModel

    cases = _cases()
    directory.mkdir(parents=True, exist_ok=True)
    for name in names:
        factory, params, control, target = cases[name]
        cap = Capture(linear_solver(delegate), softening)
        start = time.perf_counter()
        try:
            result = DamageModel("gradient").simulate(factory(), params, control=control, target=target,
                                                      linear_solver=cap, callback=cap.callback, stop_force_fraction=None,
                                                      max_steps=max_steps)
            status = result.status
            cap.kept["last"] = cap.latest  # not past the peak: the last matrix instead of peak and softening
            cap.kept.pop("peak", None)
            cap.info["last"] = cap.info.pop("peak", {})
        except _Stop:
            status = f"stopped below {softening:g} of the peak"
        wall = time.perf_counter() - start
        arrays = {}
        for state, (matrix, rhs, call) in cap.kept.items():
            matrix = sp.csc_matrix(matrix)
            arrays[f"{state}_data"] = matrix.data
            arrays[f"{state}_indptr"] = matrix.indptr
            arrays[f"{state}_indices"] = matrix.indices
            arrays[f"{state}_rhs"] = rhs
            cap.info.setdefault(state, {})["call"] = call
        n = cap.kept["first"][0].shape[0]
        meta = {"case": name, "unknowns": n, "status": status, "wall": wall, "factorizations": cap.calls,
                "steps": len(cap.step_calls), "delegate": delegate, "states": cap.info}
        arrays["meta"] = np.array(json.dumps(meta))
        np.savez(directory / f"{name}.npz", **arrays)
        print(f"{name:8s} unknowns {n:6d}  nnz {cap.kept['first'][0].nnz:8d}  steps {len(cap.step_calls):3d}  "
              f"factorizations {cap.calls:4d}  wall {wall:6.1f} s  ({status})  kept {sorted(cap.kept)}  {cap.info}")


def load(directory: Path, name: str):
    """{state: (csc matrix, rhs)} and the metadata of a captured case."""
    with np.load(directory / f"{name}.npz") as f:
        meta = json.loads(str(f["meta"]))
        n = meta["unknowns"]
        out = {}
        for state in STATES:
            if f"{state}_data" in f:
                matrix = sp.csc_matrix((f[f"{state}_data"], f[f"{state}_indices"], f[f"{state}_indptr"]), shape=(n, n))
                out[state] = (matrix, f[f"{state}_rhs"])
    return out, meta


# --------------------------------------------------------------------------------------------------
# candidates: prepare(matrix) once per pattern (returns an info string), factor(matrix) -> (solve, info)


class SuperLU:
    def __init__(self, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.001, symmetric_mode=True):
        self.permc_spec, self.thresh, self.symmetric_mode = permc_spec, diag_pivot_thresh, symmetric_mode

    def prepare(self, matrix):
        return ""

    def _splu(self, matrix, permc_spec=None):
        return spla.splu(matrix, permc_spec=permc_spec or self.permc_spec, diag_pivot_thresh=self.thresh,
                         options={"SymmetricMode": self.symmetric_mode})

    def factor(self, matrix):
        lu = self._splu(matrix)
        return lu.solve, lambda: f"factor nnz {lu.L.nnz + lu.U.nnz:.3e}"


class PermutedSuperLU(SuperLU):
    """SuperLU with NATURAL on P A P^T, the permutation computed once per pattern; the permuted
    matrix's data is a gather of A's data through an index map also built once."""

    def __init__(self, ordering, diag_pivot_thresh=0.001):
        super().__init__("NATURAL", diag_pivot_thresh, True)
        self.ordering = ordering

    def prepare(self, matrix):
        self.perm = np.asarray(self.ordering(matrix), dtype=np.int64)
        n = matrix.shape[0]
        if not np.array_equal(np.sort(self.perm), np.arange(n)):
            raise ValueError("the ordering is not a permutation")
        index = sp.csc_matrix((np.arange(1, matrix.nnz + 1, dtype=np.float64), matrix.indices, matrix.indptr), shape=matrix.shape)
        permuted = index[self.perm][:, self.perm].tocsc()
        permuted.sort_indices()
        self.map = permuted.data.astype(np.int64) - 1
        self.indices, self.indptr = permuted.indices.copy(), permuted.indptr.copy()
        return f"ordering of {n} unknowns"

    def factor(self, matrix):
        permuted = sp.csc_matrix((matrix.data[self.map], self.indices, self.indptr), shape=matrix.shape)
        lu = self._splu(permuted)
        perm = self.perm

        def solve(rhs):
            x = np.empty_like(rhs)
            x[perm] = lu.solve(rhs[perm])
            return x

        return solve, lambda: f"factor nnz {lu.L.nnz + lu.U.nnz:.3e}"


def _graph(matrix):
    """The adjacency (CSR) of the graph of A + A^T without the diagonal."""
    pattern = sp.csr_matrix((np.ones(matrix.nnz), matrix.indices, matrix.indptr), shape=matrix.shape).T.tocsr()
    graph = (pattern + pattern.T).tocsr()
    graph.setdiag(0)
    graph.eliminate_zeros()
    graph.sort_indices()
    return graph


def metis_order(matrix):
    import pymetis

    graph = _graph(matrix)
    perm, iperm = pymetis.nested_dissection(adjacency=pymetis.CSRAdjacency(graph.indptr, graph.indices))
    return perm  # A' = A[perm][:, perm] (with iperm instead, the fill of peer1 grows 50-fold)


def rcm_order(matrix):
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    return reverse_cuthill_mckee(_graph(matrix), symmetric_mode=True)


def mmd_once_order(matrix):
    """The column order SuperLU chose (MMD on A^T + A, postordered) in one full factorization."""
    lu = spla.splu(matrix, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.001, options={"SymmetricMode": True})
    return np.argsort(lu.perm_c)  # column j of A Pc is column argsort(perm_c)[j] of A


class Pardiso:
    """fracid's PardisoSolver. ``reuse``: the analysis of the first matrix given to prepare is kept
    (as in a run); otherwise a new solver (analysis + factorization) for every factorization."""

    def __init__(self, reuse=True, iparm=None):
        self.reuse, self.iparm = reuse, dict(iparm or {})

    def _new(self):
        solver = self.cls()
        for index, value in self.iparm.items():
            solver.iparm[index] = value
        return solver

    def prepare(self, matrix):
        from fracid.fem.path.pardiso import PardisoSolver

        self.cls = PardisoSolver
        self.solver = self._new()
        if self.reuse:
            self.solver._prepare(matrix)  # phase 11 on this matrix's values (the virgin state in a run)
        return "analysis (phase 11)"

    def factor(self, matrix):
        solver = self.solver if self.reuse else self._new()
        solve = solver.factorize(matrix)
        if not self.reuse:
            self._keep = solver
        iparm = solver.iparm
        return solve, lambda: (f"factor nnz {int(iparm[17]):.3e}  peak analysis {iparm[14] / 1024:.0f} MiB, "
                               f"factor {(iparm[15] + iparm[16]) / 1024:.0f} MiB, perturbed {int(iparm[13])}, "
                               f"analyses {solver.n_analyses}")


class Mumps:
    def __init__(self, reuse=True, ordering="metis", pivot_tol=0.01):
        self.reuse, self.ordering, self.pivot_tol = reuse, ordering, pivot_tol

    def prepare(self, matrix):
        import mumps

        self.ctx = mumps.Context()
        if self.reuse:
            self.ctx.analyze(matrix.tocoo(), ordering=self.ordering)
        return f"analysis ({self.ordering})"

    def factor(self, matrix):
        ctx = self.ctx
        ctx.factor(matrix.tocoo(), ordering=self.ordering, pivot_tol=self.pivot_tol, reuse_analysis=self.reuse)
        infog = ctx.mumps_instance.infog

        def info():
            entries = infog[29] if infog[29] >= 0 else -infog[29] * 1e6  # INFOG(29): entries in the factors
            return f"factor nnz {entries:.3e}  memory {infog[22]} MB (INFOG(22)), delayed {infog[13]}"

        return (lambda rhs: np.asarray(ctx.solve(rhs)).real.reshape(rhs.shape)), info


def _cvx(matrix, module):
    coo = matrix.tocoo()
    return module.spmatrix(coo.data, coo.row.astype(int), coo.col.astype(int), matrix.shape)


class Kvxopt:
    """UMFPACK or KLU of kvxopt (SuiteSparse): symbolic analysis once, numeric per matrix; the
    conversion of the SciPy matrix to kvxopt's spmatrix is counted in the factorization."""

    def __init__(self, which):
        self.which = which

    def prepare(self, matrix):
        import kvxopt
        from kvxopt import klu, umfpack

        self.kvx, self.mod = kvxopt, {"umfpack": umfpack, "klu": klu}[self.which]
        self.symbolic = self.mod.symbolic(_cvx(matrix, kvxopt))
        return "symbolic analysis"

    def factor(self, matrix):
        t0 = time.perf_counter()
        a = _cvx(matrix, self.kvx)
        convert = time.perf_counter() - t0
        numeric = self.mod.numeric(a, self.symbolic)  # kvxopt 1.3.3.3: no klu_refactor (a third argument is refused)
        args = (a, self.symbolic, numeric) if self.which == "klu" else (a, numeric)

        def solve(rhs):
            b = self.kvx.matrix(np.asfortranarray(rhs, dtype=float))
            self.mod.solve(*args, b)
            return np.asarray(b).reshape(rhs.shape)

        return solve, lambda: f"(of which conversion to spmatrix {convert:.3f} s)"


class PyKLU:
    def prepare(self, matrix):
        import PyKLU

        self.Klu = PyKLU.Klu
        return ""

    def factor(self, matrix):
        klu = self.Klu(sp.csc_matrix(matrix))
        return klu.solve, lambda: ""


CANDIDATES = {
    "superlu": lambda: SuperLU(),
    "superlu-colamd": lambda: SuperLU("COLAMD"),
    "superlu-mmd-ata": lambda: SuperLU("MMD_ATA"),
    "superlu-metis": lambda: PermutedSuperLU(metis_order),
    "superlu-rcm": lambda: PermutedSuperLU(rcm_order),
    "superlu-mmd-once": lambda: PermutedSuperLU(mmd_once_order),
    "pardiso": lambda: Pardiso(reuse=True),
    "pardiso-first": lambda: Pardiso(reuse=False),
    # without the scaling and weighted matching (iparm[10] = iparm[12] = 0) fracid's PARDISO sets
    "pardiso-nomatch": lambda: Pardiso(reuse=True, iparm={10: 0, 12: 0}),
    "pardiso-nomatch-first": lambda: Pardiso(reuse=False, iparm={10: 0, 12: 0}),
    "mumps": lambda: Mumps(reuse=False),
    "mumps-reuse": lambda: Mumps(reuse=True),
    "umfpack": lambda: Kvxopt("umfpack"),
    "klu": lambda: Kvxopt("klu"),
    "pyklu": lambda: PyKLU(),
}


def _best(fn, repeat, limit):
    """Best wall and CPU times of up to ``repeat`` calls of fn (no more repeats once a call took
    longer than ``limit`` s), and fn's last result. The CPU time of this process equals the wall
    time of a single-threaded call on an idle core; it is barely inflated when another process
    shares the core."""
    best, best_cpu, out = np.inf, np.inf, None
    for _ in range(repeat):
        gc.collect()
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        best, best_cpu = min(best, time.perf_counter() - t0), min(best_cpu, time.process_time() - c0)
        if best > limit:
            break
    return (best, best_cpu), out


def time_case(name, directory, candidates, repeat, limit):
    states, meta = load(directory, name)
    first = states["first"][0]
    print(f"\n== {name}: {meta['unknowns']} unknowns, nnz {first.nnz} (captured: {meta['steps']} steps, "
          f"{meta['factorizations']} factorizations, {meta['delegate']}; states {meta['states']})")
    print(f"{'candidate':21s} {'state':9s} {'factor [s]':>10s} {'(cpu)':>7s} {'solve [s]':>9s} {'(cpu)':>7s} {'residual':>8s}  info")
    rows = []
    for cand_name in candidates:
        try:
            cand = CANDIDATES[cand_name]()
            t_prepare, note = _best(lambda: cand.prepare(first), 1, limit)  # noqa: F821 - called here, before `del cand`
        except ImportError as err:
            print(f"{cand_name:21s} unavailable: {err}")
            continue
        if note:
            print(f"{cand_name:21s} {'once':9s} {t_prepare[0]:10.3f} {t_prepare[1]:7.3f} {'':9s} {'':7s} {'':8s}  {note}")
        for state, (matrix, rhs) in states.items():
            try:
                t_factor, (solve, info) = _best(lambda: cand.factor(matrix), repeat, limit)  # noqa: F821 - as above
                t_solve, x = _best(lambda: solve(rhs), repeat, limit)  # noqa: F821 - called here, before `del solve`
            except Exception as err:  # noqa: BLE001 - report and go on
                print(f"{cand_name:21s} {state:9s} failed: {type(err).__name__}: {err}")
                continue
            residual = np.linalg.norm(matrix @ x - rhs) / np.linalg.norm(rhs)
            print(f"{cand_name:21s} {state:9s} {t_factor[0]:10.3f} {t_factor[1]:7.3f} {t_solve[0]:9.4f} {t_solve[1]:7.4f} "
                  f"{residual:8.1e}  {info()}", flush=True)
            rows.append({"case": name, "candidate": cand_name, "state": state, "prepare": t_prepare,
                         "factor": t_factor, "solve": t_solve, "residual": float(residual), "info": info()})
            del solve, x
        del cand
        gc.collect()
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     epilog="candidates: " + ", ".join(CANDIDATES))
    parser.add_argument("command", choices=["capture", "time"])
    parser.add_argument("--cases", default="peer1,peer05,beam,dogbone", help="comma-separated: peer1, peer05, peer033, beam, dogbone")
    parser.add_argument("--dir", default=Path(tempfile.gettempdir()) / "fracid-linear-solvers", type=Path,
                        help="where the captured matrices are kept (default: %(default)s)")
    parser.add_argument("--delegate", default="superlu", help="backend that solves during the capture")
    parser.add_argument("--softening", type=float, default=0.7, help="stop the capture below this fraction of the peak")
    parser.add_argument("--max-steps", type=int, default=2000, help="stop the capture after this many steps")
    parser.add_argument("--candidates", default=",".join(CANDIDATES), help="comma-separated (default: all)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--limit", type=float, default=20.0, help="no repeats of a call that took longer [s]")
    parser.add_argument("--json", type=Path, help="also write the timings to this file")
    args = parser.parse_args(argv)
    names = args.cases.split(",")
    if args.command == "capture":
        capture(names, args.dir, args.delegate, args.softening, args.max_steps)
        return
    rows = []
    for name in names:
        rows += time_case(name, args.dir, args.candidates.split(","), args.repeat, args.limit)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
