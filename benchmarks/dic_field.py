"""Cost of a full-field (DIC-scale) observation with exact sensitivities on the demo beam (fracid issue 27).

On the demo configuration (the Grégoire notched beam, gradient damage, h_fine 2 mm, kappa_i, beta and c;
src/fracid/datasets/gregoire2013_beam4/demo.toml) at the demo's estimate, one process, serial runs:

- one plain forward run (the data's CMOD checkpoints),
- one run with exact sensitivities (direct differentiation) for (kappa_i, beta, c),
- one run with sensitivities and a displacement field of ``--points`` points (both components) at
  ``--frames`` frames: a sparse probe matrix applied by the run at the frames only
  (``follow_path(probes=...)``), the frames taken among the data's control points (the step sequence is
  the data's; frames elsewhere add one step each).

It prints the times (best wall time of ``--repeat`` calls, and best CPU time of the process), the ratios to
the plain run (issue 27 asks: one identification iteration with the field <= 1.5 plain runs) and the load
average (the machine is shared: read the ratios with it; the CPU times vary less with the load).

    python benchmarks/dic_field.py [--points 2000] [--frames 8] [--repeat 1] [--h-fine 2.0]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import time

import numpy as np

from fracid.config import build_data, build_operator
from fracid.inverse.core.field_observations import FieldObservation
from demo_setup import demo_config

ESTIMATE = {"kappa_i": 4.798e-5, "beta": 1086.5, "c": 21.46}  # docs/demo/result.json (rounded)


def best_time(function, repeat: int):
    """(smallest wall time [s] of ``repeat`` calls, smallest CPU time [s] of this process, the last result).

    The CPU time (all threads of the process) is the steadier figure on a shared machine: another
    job's load stretches the wall time, much less the CPU time of a serial run.
    """
    times, cpu, out = [], [], None
    for _ in range(repeat):
        start, start_cpu = time.perf_counter(), time.process_time()
        out = function()
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return min(times), min(cpu), out


def dic_points(specimen, n: int, seed: int = 0) -> np.ndarray:
    """``n`` random points [mm] over the modelled half beam's face above the notch tip, off the edges."""
    nodes = specimen.describe().nodes
    lo, hi = nodes.min(axis=0), nodes.max(axis=0)
    depth = getattr(specimen, "notch_depth", 0.5 * (hi[1] - lo[1]))
    rng = np.random.default_rng(seed)
    return rng.uniform([lo[0] + 0.2, lo[1] + depth + 0.5], [hi[0] - 0.5, hi[1] - 0.5], (n, 2))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=2000)
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--h-fine", type=float, default=None, help="override the demo mesh's h_fine [mm]")
    args = parser.parse_args(argv)
    cfg = demo_config(args.h_fine)
    operator = build_operator(cfg, build_data(cfg))
    exact = operator.differentiated()
    assert exact.sensitivities, "the demo's model has no direct differentiation"
    curve = operator.observations[0]
    frames = curve.controls[np.linspace(0, curve.size - 1, args.frames).round().astype(int)]
    field = FieldObservation(curve.specimen, dic_points(curve.specimen, args.points), frames, control=curve.control,
                             name="dic")
    with_field = dataclasses.replace(exact, observations=(*operator.observations, field))
    x = np.array([ESTIMATE[name] for name in operator.names])

    load_before = os.getloadavg()
    t_run, c_run, plain = best_time(lambda: operator(x), args.repeat)
    t_ddm, c_ddm, record = best_time(lambda: exact(x), args.repeat)
    t_field, c_field, full = best_time(lambda: with_field(x), args.repeat)
    load_after = os.getloadavg()
    assert plain.ok and record.ok and full.ok and full.S is not None and np.all(np.isfinite(full.S))
    out = {"points": args.points, "frames": args.frames, "field_outputs": field.size, "curve_outputs": plain.y.size,
           "parameters": list(operator.names), "run_s": t_run, "run_with_ddm_s": t_ddm, "run_with_field_s": t_field,
           "ratio_ddm_to_run": t_ddm / t_run, "ratio_field_to_run": t_field / t_run,
           "ratio_field_to_ddm": t_field / t_ddm, "run_cpu_s": c_run, "run_with_ddm_cpu_s": c_ddm,
           "run_with_field_cpu_s": c_field, "cpu_ratio_ddm_to_run": c_ddm / c_run,
           "cpu_ratio_field_to_run": c_field / c_run, "loadavg_before": load_before, "loadavg_after": load_after}
    print(f"demo beam, {plain.y.size} curve outputs; field: {args.points} points x 2 components x {args.frames} "
          f"frames = {field.size} outputs; x = {dict(zip(operator.names, x.tolist()))}")
    print(f"best of {args.repeat}: wall time (CPU time of the process)")
    print(f"one plain run                            {t_run:8.2f} s ({c_run:.2f} s)")
    print(f"one run with DDM sensitivities           {t_ddm:8.2f} s ({c_ddm:.2f} s)   ratio to plain {t_ddm / t_run:.3f}"
          f" (CPU {c_ddm / c_run:.3f})")
    print(f"one run with DDM and the field           {t_field:8.2f} s ({c_field:.2f} s)   ratio to plain "
          f"{t_field / t_run:.3f} (CPU {c_field / c_run:.3f})   (to DDM {t_field / t_ddm:.3f})")
    print(f"load average (1, 5, 15 min) before {load_before}, after {load_after}")
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
