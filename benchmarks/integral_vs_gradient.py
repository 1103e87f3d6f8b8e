"""Benchmark: integral damage against gradient damage per forward run, plain and with exact sensitivities.

``--specimen beam``: the bundled demo (the Grégoire notched beam, h_fine 2 mm, h_coarse 6 mm, the data's 24
CMOD checkpoints; src/fracid/datasets/gregoire2013_beam4/demo.toml) at the demo's estimate, the same parameters
for both models (the integral model's internal length l = sqrt(2 c)), run through the configuration's forward
operator; with ``--ddm`` also the run that returns S = dy/dx by direct differentiation (kappa_i, beta, c).
``--specimen bar``: the bar with a weak zone of benchmarks/forward_integral.py (``--elements``).

The runs of the two models alternate (gradient, integral, gradient, ...) and each time is the best of
``--repeats`` (the machines are shared: the minimum is the least disturbed). The integral runs after the
first find the averaging matrix in the process's cache (same mesh and l); its cold build is timed apart.
For the integral model the time is split into the evaluations (the residuals, with the product A eps_eq),
the nonlocal coupling of the tangent, the factorizations and the solves.

    OPENBLAS_NUM_THREADS=1 python benchmarks/integral_vs_gradient.py --specimen beam [--repeats 3] [--ddm]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time

import numpy as np

import fracid
from fracid.config import build_data, build_operator
from fracid.fem.formulations import forms, nonlocal_average, problem as problems
from fracid.fem.path import path_following
from fracid.models import DamageModel
from demo_setup import demo_config
from timing import Timed

ESTIMATE = {"kappa_i": 4.798e-5, "beta": 1086.5, "c": 21.46}  # docs/demo/result.json (rounded)
MODELS = ("gradient", "integral")


class _Stats:
    """Keeps the SolverStatistics of the last path (follow_path's result)."""

    def __init__(self):
        self.last = None

    def __enter__(self):
        self.fn = path_following.follow_path
        models = __import__("fracid.models.path_model", fromlist=["follow_path"])
        self.module = models

        def traced(*args, **kwargs):
            result = self.fn(*args, **kwargs)
            self.last = result.stats
            return result

        models.follow_path = traced
        return self

    def __exit__(self, *exc):
        self.module.follow_path = self.fn


def beam_runs(ddm):
    """{model: function() -> None} running the demo beam once (with DDM if asked)."""
    runs = {}
    for model in MODELS:
        cfg = demo_config()
        cfg = dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, type=f"{model}-damage"))
        operator = build_operator(cfg, build_data(cfg))
        x = np.array([ESTIMATE[name] for name in operator.names])
        function = operator.differentiated() if ddm else operator

        def run(function=function, x=x, model=model):
            record = function(x)
            if not record.ok:
                raise RuntimeError(f"{model}: the run failed")
        runs[model] = run
    return runs


def bar_runs(elements, target, ddm):
    bar, params = fracid.BarWithWeakZone(n_elements=elements), fracid.DamageParameters()
    names = ("kappa_i", "beta", "c") if ddm else None

    def runner(model):
        def run():
            result = fracid.simulate(bar, params, model=DamageModel(model), control="end_displacement", target=target,
                                     stop_force_fraction=None, field_steps=None, sensitivities=names)
            if result.status != "target reached":
                raise RuntimeError(f"{model}: {result.status}")
        return run
    return {model: runner(model) for model in MODELS}


def measure(runs, repeats):
    """Best wall time [s] per model over interleaved repeats, and the integral run's split at its best."""
    best = {model: (np.inf, None) for model in runs}
    for _ in range(repeats):
        for model, run in runs.items():
            with Timed(problems, "integral_damage") as evaluations, \
                    Timed(forms, "softening_coupling") as coupling, _Stats() as stats:
                t0 = time.perf_counter()
                run()
                seconds = time.perf_counter() - t0
            if seconds < best[model][0]:
                s = stats.last
                split = {"evaluations": evaluations.calls, "evaluations_s": evaluations.seconds,
                         "coupling_s": coupling.seconds, "couplings": coupling.calls,
                         "factorizations": s.factorizations, "factorizations_s": s.time_factorizations,
                         "solves_s": s.time_linear - s.time_factorizations, "steps": s.steps}
                best[model] = (seconds, split)
    return best


def cold_build(specimen):
    """Seconds to build the integral problem of the demo beam with an empty averaging cache."""
    if specimen != "beam":
        return None
    from fracid.config import build_parameters, build_specimen

    cfg = demo_config()
    params = dataclasses.replace(build_parameters(cfg), **ESTIMATE)
    nonlocal_average._CACHE.clear()
    t0 = time.perf_counter()
    DamageModel("integral").build(build_specimen(cfg), params)
    return time.perf_counter() - t0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--specimen", choices=("beam", "bar"), default="beam")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--ddm", action="store_true", help="also the runs with exact sensitivities")
    parser.add_argument("--elements", type=int, default=200, help="bar only")
    parser.add_argument("--target", type=float, default=0.04, help="bar only: end displacement [mm]")
    args = parser.parse_args(argv)
    out = {"specimen": args.specimen, "repeats": args.repeats, "cold_build_s": cold_build(args.specimen)}
    for mode in ("plain", "ddm") if args.ddm else ("plain",):
        with_ddm = mode == "ddm"
        runs = beam_runs(with_ddm) if args.specimen == "beam" else bar_runs(args.elements, args.target, with_ddm)
        best = measure(runs, args.repeats)
        out[mode] = {model: {"wall_s": t, **split} for model, (t, split) in best.items()}
        out[mode]["ratio"] = best["integral"][0] / best["gradient"][0]
        print(f"{args.specimen}, {mode}: gradient {best['gradient'][0]:.2f} s, integral {best['integral'][0]:.2f} s, "
              f"integral / gradient {out[mode]['ratio']:.2f} (best of {args.repeats}, interleaved)")
        split = best["integral"][1]
        print(f"  integral: {split['steps']} steps, {split['evaluations']} evaluations {split['evaluations_s']:.2f} s, "
              f"{split['couplings']} couplings {split['coupling_s']:.2f} s, {split['factorizations']} factorizations "
              f"{split['factorizations_s']:.2f} s, solves {split['solves_s']:.2f} s")
        split = best["gradient"][1]
        print(f"  gradient: {split['steps']} steps, {split['evaluations']} evaluations, {split['factorizations']} "
              f"factorizations {split['factorizations_s']:.2f} s, solves {split['solves_s']:.2f} s")
    if out["cold_build_s"] is not None:
        print(f"cold build of the integral problem (averaging matrix not cached): {out['cold_build_s']:.2f} s")
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
