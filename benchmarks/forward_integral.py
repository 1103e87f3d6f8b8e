"""Benchmark: the bar with a weak zone, integral-type nonlocal model against the gradient model.

Both models run on the same mesh, with the same parameters (l = sqrt(2 c)), to the same end
displacement. Prints per model the median wall time and the Newton iterations, and for the integral
model the time spent building the averaging matrix A (once per problem) and the nonlocal tangent
coupling (every evaluation), with the ratios integral / gradient.

    python benchmarks/forward_integral.py [--elements 200] [--repeats 5] [--target 0.04]
"""

from __future__ import annotations

import argparse
import statistics
import time

import fracid
from fracid.models import DamageModel
from fracid.fem.formulations import forms
from fracid.fem.formulations import nonlocal_average
from fracid.fem.formulations.nonlocal_average import internal_length, nonlocal_averaging
from timing import Timed


def run(bar, params, regularization, target):
    """Wall time [s], Newton iterations and seconds in the coupling of one analysis."""
    with Timed(forms, "softening_coupling") as coupling:
        t0 = time.perf_counter()
        result = fracid.simulate(bar, params, model=DamageModel(regularization), control="end_displacement",
                                 target=target, stop_force_fraction=None, field_steps=None)
        seconds = time.perf_counter() - t0
    if result.status != "target reached":
        raise RuntimeError(f"{regularization}: {result.status}")
    return seconds, result.stats.iterations, coupling.seconds


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elements", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--target", type=float, default=0.04, help="end displacement [mm]")
    args = parser.parse_args(argv)

    params = fracid.DamageParameters()
    bar = fracid.BarWithWeakZone(n_elements=args.elements)
    runs = {}
    for regularization in ("gradient", "integral"):
        run(bar, params, regularization, args.target)  # warm-up (imports, caches)
        runs[regularization] = [run(bar, params, regularization, args.target) for _ in range(args.repeats)]
    wall = {k: statistics.median(r[0] for r in v) for k, v in runs.items()}
    iterations = {k: v[0][1] for k, v in runs.items()}
    coupling = statistics.median(r[2] for r in runs["integral"])
    problem = DamageModel("integral").build(bar, params)
    builds = []
    for _ in range(args.repeats):
        nonlocal_average._CACHE.clear()  # the build itself, not a hit of the process's cache
        t0 = time.perf_counter()
        nonlocal_averaging(problem.disc, internal_length(params.c), problem.element_dofs, problem.n_free)
        builds.append(time.perf_counter() - t0)
    build = statistics.median(builds)

    print(f"bar, {args.elements} elements, c = {params.c} mm^2 (l = {internal_length(params.c):.3f} mm), "
          f"end displacement 0 -> {args.target} mm, median of {args.repeats} runs")
    print(f"A: {problem.averaging.matrix.shape[0]} points, {problem.averaging.matrix.nnz} entries")
    for k in runs:
        print(f"{k:>9}: wall {wall[k] * 1e3:7.1f} ms, Newton iterations {iterations[k]}")
    print(f"integral / gradient: wall time {wall['integral'] / wall['gradient']:.2f}, "
          f"iterations {iterations['integral'] / iterations['gradient']:.2f}")
    print(f"integral: building A {build * 1e3:.2f} ms ({build / wall['integral']:.3f} of its wall time), "
          f"nonlocal coupling {coupling * 1e3:.1f} ms ({coupling / wall['integral']:.2f} of its wall time)")


if __name__ == "__main__":
    main()
