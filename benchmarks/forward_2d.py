"""Benchmark: forward analyses of the 2D specimens at their default meshes, for each linear-solver backend.

For the notched beam (Gregoire geometry) and the D = 100 mm dog-bone, loaded past the peak and down to
20 % of it, prints: unknowns, steps, Newton iterations, wall time, peak memory (resident set size of
this process) and the ratio wall time / time in sparse factorizations and solves.

    python benchmarks/forward_2d.py [--specimen beam,dogbone,dogbone1600|all] [--solvers superlu,pardiso]
"""

from __future__ import annotations

import argparse
import resource
import time

import fracid
from fracid.models import DamageModel
from fracid.fem.linear_solvers import linear_solver
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.dogbone import DogBone

CASES = {
    # Gregoire beam: E = 37 GPa, ft ~ 3 MPa (kappa_i = ft / E), internal length 4.2 mm
    "beam": (NotchedBeam(), fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=8.4e-5, alpha=0.99, beta=600.0, c=9.0), 0.5),
    "dogbone": (DogBone(size=100.0), fracid.DamageParameters(E=30000.0, nu=0.2, kappa_i=1e-4, alpha=0.99, beta=300.0, c=25.0), 0.3),
    # the snap-back case of the tests on a mesh refined by two (h = 5 mm in the process zone)
    "dogbone1600": (DogBone(size=1600.0, h_fine=5.0, gauge_length=200.0),
                    fracid.DamageParameters(E=30000.0, nu=0.2, kappa_i=1e-4, alpha=0.99, beta=1000.0, c=100.0), None),
}


def peak_rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def run(name, solver_name):
    specimen, params, target = CASES[name]
    try:
        solver = linear_solver(solver_name)
    except (ValueError, ImportError) as err:
        print(f"{name:8s} {solver_name:8s} unavailable: {err}")
        return
    start = time.perf_counter()
    result = fracid.simulate(specimen, params, target=target, stop_force_fraction=0.2, linear_solver=solver)
    wall = time.perf_counter() - start
    s = result.stats
    n = DamageModel().build(specimen, params).n_free + 1
    print(f"{name:8s} {solver_name:8s} unknowns {n:6d}  steps {s.steps:4d}  iterations {s.iterations:4d}  "
          f"wall {wall:7.1f} s  linear {s.time_linear:7.1f} s  ratio {wall / s.time_linear:5.2f}  "
          f"peak RSS {peak_rss_mib():7.0f} MiB  peak force {result.peak_force:9.1f} N  ({result.status})")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--specimen", default="beam,dogbone", help=f"comma-separated, from {list(CASES)}, or all")
    parser.add_argument("--solvers", default="superlu,pardiso")
    args = parser.parse_args(argv)
    names = list(CASES) if args.specimen == "all" else args.specimen.split(",")
    for name in names:
        for solver_name in args.solvers.split(","):
            run(name, solver_name)


if __name__ == "__main__":
    main()
