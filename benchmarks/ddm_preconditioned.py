"""Alternatives to a fresh factorization in the sensitivity step of direct differentiation (fracid issue 27).

The derivatives' solve at each converged step (:mod:`fracid.fem.path.ddm`) factorizes the converged
tangent; that factorization is the floor of a run with sensitivities. This measures, on the demo beam
at the demo's estimate (serial, one process), a plain run, a run with sensitivities as fracid does it,
and a run whose sensitivity solve is instead PARDISO's CGS iteration preconditioned by the LU PARDISO
holds (Newton's last factorization; ``iparm[3] = 10 L + 1``: stop at 10^-L, a new LU when CGS fails),
and prints the times, the CGS iteration counts (PARDISO's ``iparm[19]``; < 0: it factorized) and the
largest difference of the sensitivities from fracid's.

    python benchmarks/ddm_preconditioned.py [--digits 10] [--repeat 3]
"""

from __future__ import annotations

import argparse
import collections
import os

import numpy as np

import fracid.fem.path.ddm as ddm
from fracid.config import build_data, build_operator
from fracid.fem.path.pardiso import PardisoSolver
from demo_setup import demo_config
from dic_field import ESTIMATE, best_time


def cgs_factorize(digits: int, counts: collections.Counter):
    """A stand-in for ``ddm.factorize``: its first solve runs PARDISO's preconditioned CGS on the new
    values; later solves (Newton's, in the next increment) use the LU PARDISO then holds."""
    fresh = ddm.factorize

    def factorize(solver, matrix):
        if not isinstance(solver, PardisoSolver) or solver._shape is None:
            return fresh(solver, matrix)
        matrix, data, _ = solver._prepare(matrix)
        first = [True]

        def solve(rhs):
            b = solver._rhs(matrix, rhs)
            if not first[0]:
                return solver._phase(33, data, b)
            first[0] = False
            solver.iparm[3], solver.iparm[7] = 10 * digits + 1, 0
            try:
                x = solver._phase(23, data, b)
            finally:
                solver.iparm[3] = 0
            counts[int(solver.iparm[19])] += 1
            return x
        return solve
    return factorize


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--digits", type=int, default=10, help="CGS stops at a relative residual 10^-digits")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    cfg = demo_config(None)
    operator = build_operator(cfg, build_data(cfg))
    exact = operator.differentiated()
    x = np.array([ESTIMATE[name] for name in operator.names])
    load = os.getloadavg()
    t_run, _, _ = best_time(lambda: operator(x), args.repeat)
    t_ddm, _, reference = best_time(lambda: exact(x), args.repeat)
    counts = collections.Counter()
    fresh, ddm.factorize = ddm.factorize, cgs_factorize(args.digits, counts)
    try:
        t_cgs, _, record = best_time(lambda: exact(x), args.repeat)
    finally:
        ddm.factorize = fresh
    difference = np.abs(record.S - reference.S).max() / np.abs(reference.S).max()
    print(f"plain run {t_run:.3f} s; with sensitivities: fresh factorization {t_ddm:.3f} s ({t_ddm / t_run:.2f} plain "
          f"runs), CGS to 1e-{args.digits} preconditioned by the held LU {t_cgs:.3f} s ({t_cgs / t_run:.2f})")
    print(f"CGS iterations per sensitivity solve (count): {dict(sorted(counts.items()))}; largest relative "
          f"difference of the sensitivities {difference:.1e}; load average {load} -> {os.getloadavg()}")


if __name__ == "__main__":
    main()
