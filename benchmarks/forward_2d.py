"""Benchmark: forward analyses of the 2D specimens, for each linear-solver backend.

Cases: the notched beam (Gregoire geometry) and the D = 100 mm dog-bone, loaded past the peak and down to
20 % of it; the peer beam of the OOFEM comparison (E 37000, nu 0.2, kappa_i 1.1e-4, alpha 0.99, beta 500,
c 4, eta 10, 1 mm plates, CMOD control to 0.16 mm) at h_fine 1 (``peer1``) and 0.5 mm (``peer05``).
Per case, Newton variant and backend it prints: unknowns, steps, iterations, factorizations, time per
factorization, time per solve, wall time, peak memory (resident set size of this process), wall / time in
linear solves, and, once every backend of a case ran, wall / (factorizations x the fastest time per
factorization measured for that case): how far the run is from the sparse-solver floor. ``--newton``:
``modified`` (the default, ``NewtonOptions()``: a factorization is kept while the residual falls fast) and
``full`` (``reuse_ratio=0``: one factorization per iteration but the first of a step).

    python benchmarks/forward_2d.py [--specimen beam,dogbone,peer1,peer05,dogbone1600|all]
                                    [--solvers superlu,pardiso,superlu-own] [--newton modified,full]
                                    [--figure docs/speed/forward_2d.png]

``--figure``: each run's wall time split into factorizations, solves and the rest (residuals, tangents,
history and records), with the ratio to the factorizations written over the bar.

``superlu`` is SciPy's SuperLU in a METIS ordering when pymetis (the ``metis`` extra) is installed;
``superlu-own`` is SuperLU in its own ordering (``pip install fracid`` where pymetis has no wheel, e.g. Windows).
"""

from __future__ import annotations

import argparse
import resource
import time

import fracid
from fracid.models import DamageModel
from fracid.fem.path.linear_solvers import SuperLUSolver, linear_solver
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.dogbone import DogBone

PEER = fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=1.1e-4, alpha=0.99, beta=500.0, c=4.0, eta=10.0)

# name -> (specimen, parameters, target [mm] or None (the default), stop_force_fraction)
CASES = {
    # Gregoire beam: E = 37 GPa, ft ~ 3 MPa (kappa_i = ft / E), internal length 4.2 mm
    "beam": (NotchedBeam(), fracid.DamageParameters(E=37000.0, nu=0.2, kappa_i=8.4e-5, alpha=0.99, beta=600.0, c=9.0),
             0.5, 0.2),
    "dogbone": (DogBone(size=100.0), fracid.DamageParameters(E=30000.0, nu=0.2, kappa_i=1e-4, alpha=0.99, beta=300.0,
                                                             c=25.0), 0.3, 0.2),
    # the peer case: the beam OOFEM traced with the same model (point-like plates, CMOD to 0.16 mm)
    "peer1": (NotchedBeam(h_fine=1.0, plate_width=1.0), PEER, 0.16, None),
    "peer05": (NotchedBeam(h_fine=0.5, plate_width=1.0), PEER, 0.16, None),
    # the snap-back case of the tests on a mesh refined by two (h = 5 mm in the process zone)
    "dogbone1600": (DogBone(size=1600.0, h_fine=5.0, gauge_length=200.0),
                    fracid.DamageParameters(E=30000.0, nu=0.2, kappa_i=1e-4, alpha=0.99, beta=1000.0, c=100.0), None,
                    0.2),
}


def peak_rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


NEWTON = {"modified": fracid.NewtonOptions(), "full": fracid.NewtonOptions(reuse_ratio=0.0)}


def run(name, solver_name, newton="modified"):
    """One forward run; returns (wall [s], factorizations, time per factorization [s]) or None."""
    specimen, params, target, stop = CASES[name]
    try:
        # superlu-own: SuperLU in its own ordering, what `pip install fracid` gives where pymetis has no wheel (Windows)
        solver = SuperLUSolver(ordering="superlu") if solver_name == "superlu-own" else linear_solver(solver_name)
    except (ValueError, ImportError) as err:
        print(f"{name:8s} {solver_name:8s} unavailable: {err}")
        return None
    start = time.perf_counter()
    result = fracid.simulate(specimen, params, target=target, stop_force_fraction=stop, linear_solver=solver,
                             newton=NEWTON[newton])
    wall = time.perf_counter() - start
    s = result.stats
    n = DamageModel().build(specimen, params).n_free + 1
    per_factorization = s.time_factorizations / max(s.factorizations, 1)
    per_solve = (s.time_linear - s.time_factorizations) / max(s.linear_solves, 1)
    print(f"{name:8s} {newton:8s} {solver_name:8s} unknowns {n:6d}  steps {s.steps:4d}  iterations {s.iterations:4d}  "
          f"factorizations {s.factorizations:4d} x {per_factorization:6.3f} s  solves x {per_solve:6.4f} s  "
          f"wall {wall:7.1f} s  "
          f"wall/linear {wall / s.time_linear:5.2f}  peak RSS {peak_rss_mib():7.0f} MiB  "
          f"peak force {result.peak_force:9.1f} N  ({result.status})", flush=True)
    return wall, s.factorizations, per_factorization, s.time_factorizations, s.time_linear - s.time_factorizations


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--specimen", default="beam,dogbone", help=f"comma-separated, from {list(CASES)}, or all")
    parser.add_argument("--solvers", default="superlu,pardiso")
    parser.add_argument("--newton", default="modified", help=f"comma-separated, from {list(NEWTON)}")
    parser.add_argument("--figure", default=None, help="write the time split of every run here (png)")
    args = parser.parse_args(argv)
    names = list(CASES) if args.specimen == "all" else args.specimen.split(",")
    bars = []
    for name in names:
        runs = {(newton, solver): run(name, solver, newton) for newton in args.newton.split(",")
                for solver in args.solvers.split(",")}
        runs = {key: r for key, r in runs.items() if r is not None}
        if runs:
            floor = min(r[2] for r in runs.values())
            for (newton, solver), (wall, factorizations, _, t_factor, t_solve) in runs.items():
                ratio = wall / (factorizations * floor)
                print(f"{name:8s} {newton:8s} {solver:8s} wall / (factorizations x fastest factorization "
                      f"{floor:.3f} s) = {ratio:5.2f}")
                bars.append((f"{name}\n{newton}\n{solver}", t_factor, t_solve, wall - t_factor - t_solve, ratio))
    if args.figure and bars:
        draw(bars, args.figure)


def draw(bars, path):
    """Stacked bars: factorizations, solves and the rest of each run's wall time [s], with wall / factorizations."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    labels, factor, solve, rest, ratio = zip(*bars)
    x = np.arange(len(bars))
    fig, ax = plt.subplots(figsize=(max(5.0, 1.3 * len(bars) + 2.0), 3.8))
    ax.bar(x, factor, label="factorizations")
    ax.bar(x, solve, bottom=factor, label="solves")
    ax.bar(x, rest, bottom=np.add(factor, solve), label="residuals, tangents, records")
    for k, r in enumerate(ratio):
        ax.annotate(f"{r:.2f}x", (x[k], factor[k] + solve[k] + rest[k]), ha="center", va="bottom", fontsize=8)
    ax.set_xticks(x, labels, fontsize=7)
    ax.set_ylabel("wall time of one run [s]")
    ax.set_title("Forward runs: time split, and wall / factorizations' time", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=130)


if __name__ == "__main__":
    main()
