"""Benchmark: identification costs.

1. A 64-run KNN population of the notched beam (coarse process zone, CMOD up to 0.15 mm) with 1 and
   2 workers: wall times and the speed-up.
2. The Kalman filter's cost per global iteration, in forward-run equivalents (a run to the k-th of n
   observations counts k / n), and the total forward runs and wall time of a twin identification of
   (c, beta) on the beam (KNN 16 + Kalman filter).

    python benchmarks/identify.py [--population 64] [--skip-serial]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.knn import design, evaluate_population
from fracid.inverse.methods.strategy import identify
from fracid.runtime.executors import make_executor
from fracid.specimens.beam import NotchedBeam

SPECIMEN = NotchedBeam(h_fine=2.0, h_coarse=6.0)
BASE = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=8.4e-5, alpha=0.99, beta=600.0, c=9.0)
POINTS = np.linspace(0.01, 0.15, 15)  # CMOD [mm]
SPACE = ParameterSpace(("c", "beta"), [4.0, 300.0], [20.0, 1200.0])


def population_time(operator, points, workers):
    start = time.perf_counter()
    with make_executor(workers) as executor:
        records = evaluate_population(operator, points, executor=executor)
    return time.perf_counter() - start, sum(r.status != "ok" for r in records)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--population", type=int, default=64)
    parser.add_argument("--skip-serial", action="store_true")
    args = parser.parse_args(argv)
    operator = ForwardOperator([Observation(SPECIMEN, POINTS, control="cmod")], BASE, SPACE.names)
    points = design(SPACE, args.population, "sobol")
    times = {}
    for workers in ([2] if args.skip_serial else [1, 2]):
        times[workers], failed = population_time(operator, points, workers)
        print(f"KNN population of {len(points)} beam runs, {workers} worker(s): {times[workers]:.1f} s ({failed} failed)")
    if 1 in times:
        print(f"speed-up with 2 workers: {times[1] / times[2]:.2f}")

    truth = np.array([9.0, 600.0])
    y = operator(truth).y
    std = 0.01 * np.abs(y).max()
    start = time.perf_counter()
    with make_executor(2) as executor:
        result = identify(operator, y, np.eye(y.size) * std**2, SPACE, n=16, k=4,
                          groups=[range(i, i + 5) for i in range(0, 15, 5)], executor=executor)
    wall = time.perf_counter() - start
    runs = result.runs
    per_iteration = runs["kalman_run_equivalents"] / runs["kalman_iterations"]
    print(f"twin identification: c = {result.x[0]:.4g} (truth 9), beta = {result.x[1]:.4g} (truth 600), "
          f"std {np.round(result.std, 4).tolist()}, correlation {result.correlation[0, 1]:.3f}")
    print(f"forward runs: KNN {runs['knn']}, Kalman {runs['kalman']} ({runs['kalman_iterations']} global iterations, "
          f"{per_iteration:.1f} run-equivalents per iteration); wall {wall:.1f} s with 2 workers")


if __name__ == "__main__":
    main()
