"""The study's verdict with and without a DIC field on a noisy twin of the demo beam (fracid issue 27, done-when).

The demo's notched beam (Grégoire geometry, half model, gradient damage, h_fine 2 mm), (kappa_i, beta, c) at the
demo's estimate (4.798e-5, 1086.5, 21.46). The twin's data go through the files and the readers a lab's data
take:

- curve: force-CMOD at 12 CMOD values in [0.01, 0.2] mm, Gaussian noise of 1 % of the peak force (its std);
- field: :func:`~fracid.inverse.studies.dic_twin.synthetic_dic` written as per-frame CSV point clouds
  (:func:`~fracid.inverse.studies.dic_twin.write_dic`) and read back (:func:`fracid.data.dic.read_dic_frames`):
  the design of docs/dic/design.md that decorrelates beta and c: a 1.5 mm grid (0.05 mm/px, 31 px subsets,
  step half a subset), subset 3 mm, 40 frames at every 0.005 mm of CMOD, noise std 1 micrometre correlated over
  the subset, holes within 1 mm of the crack, the support's rigid motion growing to (4, -12) micrometre and
  5e-5 rad; the region of interest 2 to 20 mm from the crack line (``field_block(region=...)``); the rigid
  motion of every frame marginalised (``rigid_std`` = 1 mm).

:func:`fracid.inverse.studies.study.run_study` (knn-kalman, population ``--n``, ``--groups`` 4 steps per
pass of the Kalman filter, ``--starts`` 3, ``--replicates`` 3 noisy replicates)
runs on the curve alone and on curve + field. Printed: each study's verdict (its ``summary()``), the
correlations r(beta, c) and r(kappa_i, c) of the identification's covariance, the squared Mahalanobis distance
of the truth (99 % joint region of chi^2(3): 11.34), forward runs and wall times, the load average. The issue
asks r(beta, c) >= 0.95 with the curve alone and <= 0.8 with curve + field, as the study's verdict prints.

    python benchmarks/dic_verdict.py [--n 16] [--groups 4] [--starts 3] [--replicates 3] [--h-fine 2.0] [--seed 11]
        [--json out.json] [--advised truth|nominal]

With ``--advised`` the field's frames are first ranked by their Fisher information at the truth or at the
nominal parameters (:mod:`fracid.inverse.studies.frame_information`, what ``fracid check`` prints), and the study
runs on the curve with the advised frames only (the same noisy twin).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import tempfile
import time

import numpy as np

from fracid.data import Diagonal, ExperimentalData, stack
from fracid.data.dic import field_block, read_dic_frames
from fracid.fem.material.parameters import DamageParameters
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.field_observations import field_observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.studies.dic_twin import synthetic_dic, write_dic
from fracid.inverse.studies.study import StudySettings, run_study
from fracid.specimens.beam import NotchedBeam

BASE = DamageParameters(E=36250.0, nu=0.2, kappa_i=6.6e-5, alpha=0.99, beta=600.0, c=9.0, eta=10.0)  # demo.toml
NAMES = ("kappa_i", "beta", "c")
TRUTH = np.array([4.798e-5, 1086.5, 21.46])  # the demo's estimate (docs/demo/result.json, rounded)
SPACE = ParameterSpace(NAMES, [4e-5, 200.0, 4.0], [1e-4, 3000.0, 30.0], log=(False, True, False))  # the demo's bounds
CURVE = np.linspace(0.01, 0.2, 12)  # CMOD [mm]
FRAMES = np.round(np.arange(0.005, 0.2001, 0.005), 6)  # 40 frames [mm]
RIGID = np.outer(np.linspace(0.0, 1.0, FRAMES.size), [0.004, -0.012, 5e-5])  # tx, ty [mm], theta [rad]
SPACING, SUBSET, DIC_STD = 1.5, 3.0, 1e-3  # mm
REGION = (2.0, 20.0)  # mm from the crack line x = 0


def twin(beam, seed: int, folder, frames=None) -> tuple[ExperimentalData, ExperimentalData, list]:
    """(curve data, curve + field data, [curve kind, field kind]) of the noisy twin (its field at ``frames``,
    frame numbers from 1, or all)."""
    params = dataclasses.replace(BASE, **dict(zip(NAMES, TRUTH)))
    curve = Observation(beam, CURVE, control="cmod", name="curve")
    force = ForwardOperator([curve], BASE, NAMES)(TRUTH).y
    std = 0.01 * force.max()
    noisy = force + np.random.default_rng(seed).normal(0.0, std, force.size)
    curve_data = ExperimentalData(control=CURVE, y=noisy, covariance=Diagonal(np.full(CURVE.size, std**2)),
                                  blocks=(("curve", 0, CURVE.size),))
    synthetic = synthetic_dic(beam, params, frames=FRAMES, spacing=SPACING, std=DIC_STD, subset_size=SUBSET,
                              holes=1.0, rigid_body=RIGID, seed=seed + 1)
    write_dic(folder, synthetic)
    dic = read_dic_frames(os.path.join(folder, "frames.csv"), sigma="sigma")
    lo, hi = REGION
    block = field_block(dic, frames=frames, control="cmod_mm", subset_size=SUBSET, rigid_std=1.0, name="field",
                        region=lambda p: (np.abs(p[:, 0]) >= lo) & (np.abs(p[:, 0]) <= hi))
    field = field_observation(block, beam, control="cmod")
    return curve_data, stack(curve_data, block.data), [curve, field]


def advised_frames(kinds, data, at) -> list:
    """The frames :func:`~fracid.inverse.studies.frame_information.rank_frames` advises at the parameters ``at``
    (the curve's information and the bounds' uniform prior as its prior), printed as `fracid check` would."""
    from fracid.inverse.core.sensitivity import exact_sensitivity
    from fracid.inverse.studies.frame_information import frame_information, rank_frames

    operator = ForwardOperator(kinds, BASE, NAMES)
    evaluate, sensitivity = exact_sensitivity(operator)
    start = time.perf_counter()
    _, S, _ = sensitivity(evaluate, np.asarray(at, float), None, None)
    n_curve = CURVE.size
    field = kinds[1]
    keep = field.keep if field.keep is not None else np.ones(FRAMES.size * len(field.components) * len(field.points))
    per_frame = np.asarray(keep).reshape(FRAMES.size, -1).sum(axis=1)
    ends = n_curve + np.cumsum(per_frame)
    slices = [slice(a, b) for a, b in zip(np.concatenate([[n_curve], ends[:-1]]), ends)]
    C = data.covariance
    curve_info = frame_information(S, C, [slice(0, n_curve)])[0]
    width = (SPACE.upper - SPACE.lower) / np.sqrt(12.0)  # the bounds as a uniform prior's std
    ranking = rank_frames(frame_information(S, C, slices), NAMES, curve_info + np.diag(1.0 / width**2),
                          labels=[f"frame {k + 1} (CMOD {f:g} mm)" for k, f in enumerate(FRAMES)])
    print(f"\nframes ranked at {dict(zip(NAMES, np.round(at, 8).tolist()))} (one run with sensitivities, "
          f"{time.perf_counter() - start:.0f} s):", *ranking.lines(), sep="\n", flush=True)
    return sorted(int(k) + 1 for k in ranking.advised)


def study(label, kinds, data, args) -> dict:
    operator = ForwardOperator(kinds, BASE, NAMES)
    groups = np.array_split(np.arange(data.n_y), args.groups)  # as [identify.kalman] groups = 4 does
    settings = StudySettings().replace(n=args.n, groups=groups, starts=args.starts, replicates=args.replicates)
    start = time.perf_counter()
    result = run_study(operator, data, SPACE, settings, progress=False)
    wall = time.perf_counter() - start
    ident = result.identification
    s = np.sqrt(np.diag(ident.C))
    r = ident.C / np.outer(s, s)
    d = ident.x - TRUTH
    print(f"\n=== {label}: {data.n_y} values ===\n{result.summary()}", flush=True)
    return {"data": label, "values": int(data.n_y), "estimate": ident.x.tolist(), "std": s.tolist(),
            "error_percent": (100 * (ident.x / TRUTH - 1)).tolist(), "r_beta_c": float(r[1, 2]),
            "r_kappa_c": float(r[0, 2]), "r_kappa_beta": float(r[0, 1]),
            "mahalanobis2": float(d @ np.linalg.solve(ident.C, d)), "wall_s": wall,
            "runs": {k: v for k, v in ident.runs.items() if isinstance(v, (int, float))}}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h-fine", type=float, default=2.0)
    parser.add_argument("--n", type=int, default=16, help="population of the KNN stage")
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--groups", type=int, default=4, help="steps per pass of the Kalman filter")
    parser.add_argument("--starts", type=int, default=3, help="multi-start check")
    parser.add_argument("--replicates", type=int, default=3, help="noisy replicates of the stability check")
    parser.add_argument("--json", default=None)
    parser.add_argument("--advised", choices=("truth", "nominal"), default=None,
                        help="then curve + the frames the ranking advises at the truth or at the nominal parameters "
                             "(demo.toml's: 6.6e-5, 600, 9), and curve + field is not run")
    args = parser.parse_args(argv)
    load_before = os.getloadavg()
    beam = NotchedBeam(h_fine=args.h_fine, h_coarse=3.0 * args.h_fine)
    with tempfile.TemporaryDirectory() as folder:
        curve_data, both_data, kinds = twin(beam, args.seed, folder)
    if args.advised:
        at = TRUTH if args.advised == "truth" else np.array([getattr(BASE, name) for name in NAMES])
        frames = advised_frames(kinds, both_data, at)
        with tempfile.TemporaryDirectory() as folder:
            _, advised_data, advised_kinds = twin(beam, args.seed, folder, frames=frames)
        rows = [study(f"curve + {len(frames)} advised frames", advised_kinds, advised_data, args)]
    else:
        rows = [study("curve alone", kinds[:1], curve_data, args), study("curve + field", kinds, both_data, args)]
    out = {"h_fine": args.h_fine, "points": len(kinds[1].points), "frames": FRAMES.size, "rows": rows,
           "loadavg_before": load_before, "loadavg_after": os.getloadavg()}
    print()
    for row in rows:
        print(f"{row['data']:>14}: r(beta, c) = {row['r_beta_c']:+.3f}, r(kappa_i, c) = {row['r_kappa_c']:+.3f}, "
              f"errors {np.round(row['error_percent'], 2).tolist()} %, stds {np.round(100 * np.array(row['std']) / TRUTH, 2).tolist()} %, "
              f"d2 = {row['mahalanobis2']:.2f}, {row['wall_s']:.0f} s")
    print(f"load average before {load_before}, after {out['loadavg_after']}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
