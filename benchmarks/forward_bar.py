"""Benchmark: full forward analysis of the bar with a weak zone (200 elements) until F < 10 % of the peak.

Prints the wall time of one analysis (median of several repeats, after a warm-up run) and the share
of it spent in the sparse factorizations and solves (``SolverStatistics.time_linear``).

    python benchmarks/forward_bar.py [--elements 200] [--repeats 20] [--solver superlu]
"""

from __future__ import annotations

import argparse
import statistics

import fracid
from fracid.models import DamageModel


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elements", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--solver", default="superlu")
    args = parser.parse_args(argv)

    params = fracid.DamageParameters()
    bar = fracid.BarWithWeakZone(n_elements=args.elements)
    fracid.simulate(bar, params, linear_solver=args.solver)  # warm-up (imports, caches)
    totals, shares = [], []
    for _ in range(args.repeats):
        result = fracid.simulate(bar, params, stop_force_fraction=0.1, linear_solver=args.solver)
        totals.append(result.stats.time_total)
        shares.append(result.stats.time_linear / result.stats.time_total)
    s = result.stats
    print(f"bar, {args.elements} elements, {DamageModel().build(bar, params).n_free + 1} unknowns, solver {args.solver}")
    print(f"steps {s.steps}, Newton iterations {s.iterations}, failed increments {s.failed_increments}")
    print(f"peak force {result.peak_force:.4f} N, final force {result.force[-1]:.4f} N ({result.status})")
    print(f"wall time per analysis: median {statistics.median(totals) * 1e3:.1f} ms, min {min(totals) * 1e3:.1f} ms over {args.repeats} runs")
    print(f"share of time in sparse factorizations + solves: median {statistics.median(shares):.2f}")
    print(f"time per Newton iteration: {statistics.median(totals) / s.iterations * 1e6:.0f} us, "
          f"of which linear algebra {statistics.median(shares) * statistics.median(totals) / s.iterations * 1e6:.0f} us")


if __name__ == "__main__":
    main()
