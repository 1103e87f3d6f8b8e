"""Cost and accuracy of the sensitivities on the demo beam: direct differentiation against central differences.

On the demo configuration (the Grégoire notched beam, gradient damage, kappa_i, beta and c identified;
src/fracid/data/gregoire2013_beam4/demo.toml) at the demo's estimate, one process, serial runs:

- the time of one forward run (the data's 24 CMOD checkpoints),
- the time of one run that also returns S = dy/dx by direct differentiation (DDM),
- the time of the 2 n + 1 = 7 runs of central differences (the package's relative step 1e-2),
- the ratio run-with-DDM / run, and how far the central differences are from the DDM S (per parameter,
  max |S_cd - S_ddm| / max |S_ddm|).

Each timing is the best of ``--repeat`` runs (the machines are shared: the minimum is the least disturbed).

    python benchmarks/sensitivities.py [--repeat 3] [--h-fine 2.0]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from fracid.config import build_data, build_operator
from fracid.inverse.core.sensitivity import CentralDifferences
from demo_setup import demo_config

ESTIMATE = {"kappa_i": 4.798e-5, "beta": 1086.5, "c": 21.46}  # docs/demo/result.json (rounded)


def best_time(function, repeat):
    times, out = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        out = function()
        times.append(time.perf_counter() - start)
    return min(times), out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--h-fine", type=float, default=None, help="override the demo mesh's h_fine [mm]")
    args = parser.parse_args(argv)
    cfg = demo_config(args.h_fine)
    data = build_data(cfg)
    operator = build_operator(cfg, data)
    exact = operator.differentiated()
    assert exact.sensitivities, "the demo's model has no direct differentiation"
    x = np.array([ESTIMATE[name] for name in operator.names])

    t_run, plain = best_time(lambda: operator(x), args.repeat)
    t_ddm, record = best_time(lambda: exact(x), args.repeat)
    t_cd, (y, S_cd, records) = best_time(lambda: CentralDifferences()(operator, x), 1)
    assert plain.ok and record.ok and all(r.ok for r in records)
    deviation = np.max(np.abs(record.y - plain.y)) / np.max(np.abs(plain.y))
    errors = {name: float(np.max(np.abs(S_cd[:, j] - record.S[:, j])) / np.max(np.abs(record.S[:, j])))
              for j, name in enumerate(operator.names)}
    out = {"outputs": int(plain.y.size), "parameters": list(operator.names), "x": x.tolist(),
           "run_s": t_run, "run_with_ddm_s": t_ddm, "central_differences_s": t_cd,
           "central_difference_runs": len(records), "ratio_ddm_to_run": t_ddm / t_run,
           "ratio_cd_to_ddm": t_cd / t_ddm, "y_same_within": float(deviation),
           "cd_vs_ddm_relative_difference": errors}
    print(f"demo beam, {plain.y.size} outputs, x = {dict(zip(operator.names, x))}")
    print(f"one run                        {t_run:8.2f} s")
    print(f"one run with DDM sensitivities {t_ddm:8.2f} s   ratio {t_ddm / t_run:.3f}")
    print(f"central differences ({len(records)} runs)   {t_cd:8.2f} s   ratio to DDM {t_cd / t_ddm:.2f}")
    print(f"y of the DDM run equals the plain run's within {deviation:.1e} (relative to the peak)")
    for name, e in errors.items():
        print(f"  S[{name}]: central differences (step 1e-2) differ from DDM by {100 * e:.2f} % of its largest value")
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
