"""Cost and accuracy of the sensitivities on the demo beam: direct differentiation against central differences.

On the demo configuration (the Grégoire notched beam, gradient damage, kappa_i, beta and c identified;
src/fracid/datasets/gregoire2013_beam4/demo.toml) at the demo's estimate, one process, serial runs, for each
linear-solver backend:

- the time of one forward run (the data's 24 CMOD checkpoints),
- the time of one run that also returns S = dy/dx by direct differentiation (DDM), with the derivatives
  beside the path in a thread of their own (the default, ``fracid.fem.path.ddm.BESIDE_PATH``) and in the
  path's thread (each step's factorization then starts the next increment),
- the time of the 2 n + 1 = 7 runs of central differences (the package's relative step 1e-2; first backend),
- the ratios run-with-DDM / run, and how far the central differences are from the DDM S (per parameter,
  max |S_cd - S_ddm| / max |S_ddm|).

Each timing is the best of ``--repeat`` runs (the machines are shared: the minimum is the least disturbed).
With ``--figure`` the ratios are drawn (docs/speed/sensitivities.png).

    python benchmarks/sensitivities.py [--repeat 3] [--h-fine 2.0] [--backends pardiso,superlu] [--figure F]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from fracid.config import build_data, build_operator
from fracid.fem.path import ddm, linear_solvers
from fracid.inverse.core.sensitivity import CentralDifferences
from demo_setup import demo_config

ESTIMATE = {"kappa_i": 4.798e-5, "beta": 1086.5, "c": 21.46}  # docs/demo/result.json (rounded)
MODES = {"beside the path": True, "in the path's thread": False}


def best_time(function, repeat):
    times, out = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        out = function()
        times.append(time.perf_counter() - start)
    return min(times), out


def use_backend(name):
    """Make ``name`` the backend the forward runs get (they ask for the default one)."""
    backend = linear_solvers._BACKENDS[name]
    linear_solvers._fastest = backend


def measure(operator, exact, x, repeat):
    t_run, plain = best_time(lambda: operator(x), repeat)
    out = {"run_s": t_run}
    for mode, beside in MODES.items():
        ddm.BESIDE_PATH = beside
        t_ddm, record = best_time(lambda: exact(x), repeat)
        assert plain.ok and record.ok
        out[mode] = {"run_with_ddm_s": t_ddm, "ratio_ddm_to_run": t_ddm / t_run,
                     "y_same_within": float(np.max(np.abs(record.y - plain.y)) / np.max(np.abs(plain.y)))}
    ddm.BESIDE_PATH = True
    return out, record


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--h-fine", type=float, default=None, help="override the demo mesh's h_fine [mm]")
    parser.add_argument("--backends", default="pardiso,superlu")
    parser.add_argument("--figure", default=None, help="write the ratios' figure here (png)")
    args = parser.parse_args(argv)
    cfg = demo_config(args.h_fine)
    data = build_data(cfg)
    operator = build_operator(cfg, data)
    exact = operator.differentiated()
    assert exact.sensitivities, "the demo's model has no direct differentiation"
    x = np.array([ESTIMATE[name] for name in operator.names])
    out = {"parameters": list(operator.names), "x": x.tolist(), "backends": {}}
    print(f"demo beam, x = {dict(zip(operator.names, x))}")
    for k, backend in enumerate(args.backends.split(",")):
        use_backend(backend)
        result, record = measure(operator, exact, x, args.repeat)
        out["backends"][backend] = result
        print(f"{backend:8s} one run {result['run_s']:6.2f} s")
        for mode in MODES:
            r = result[mode]
            print(f"{backend:8s} with DDM sensitivities, {mode:21s} {r['run_with_ddm_s']:6.2f} s   ratio "
                  f"{r['ratio_ddm_to_run']:.3f}   y equals the plain run's within {r['y_same_within']:.1e}")
        if k == 0:
            t_cd, (y, S_cd, records) = best_time(lambda: CentralDifferences()(operator, x), 1)
            errors = {name: float(np.max(np.abs(S_cd[:, j] - record.S[:, j])) / np.max(np.abs(record.S[:, j])))
                      for j, name in enumerate(operator.names)}
            out.update(central_differences_s=t_cd, central_difference_runs=len(records),
                       cd_vs_ddm_relative_difference=errors)
            print(f"{backend:8s} central differences ({len(records)} runs) {t_cd:6.2f} s")
            for name, e in errors.items():
                print(f"  S[{name}]: central differences (step 1e-2) differ from DDM by {100 * e:.2f} % of its largest value")
    if args.figure:
        draw(out, args.figure)
    print(json.dumps(out))
    return out


def draw(out, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    backends = list(out["backends"])
    fig, ax = plt.subplots(figsize=(6.0, 3.4))
    width = 0.38
    for k, mode in enumerate(MODES):
        ratios = [out["backends"][b][mode]["ratio_ddm_to_run"] for b in backends]
        bars = ax.bar(np.arange(len(backends)) + (k - 0.5) * width, ratios, width, label=f"derivatives {mode}")
        ax.bar_label(bars, fmt="%.2f")
    ax.axhline(1.3, color="k", ls="--", lw=1, label="target 1.3")
    ax.axhline(1.0, color="0.6", lw=1)
    ax.set_xticks(np.arange(len(backends)), backends)
    ax.set_ylabel("run with sensitivities / run")
    ax.set_title("Exact sensitivities (3 parameters) on the demo beam, 2 cores")
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=130)


if __name__ == "__main__":
    main()
