"""DIC twin identification on the demo beam: the curve alone versus curve + field (fracid issue 27).

The demo's notched beam (Grégoire geometry, gradient damage, h_fine 2 mm by default), (kappa_i, beta, c) at
the demo's estimate. A realistic noisy twin: the force-CMOD curve at 12 points with a std of 1 % of its peak
[N], and a complete DIC field (:func:`fracid.inverse.studies.dic_twin.synthetic_dic`: no holes, no rigid
motion) at ~300 points and 6 frames, u and v, noise std 1 micrometre correlated over a 6 mm subset
(:func:`fracid.data.dic_noise.dic_frames_covariance`). The same method (knn-gauss-newton, a population of
``--n``) identifies from the curve alone and from curve + field. Printed: estimates, stds and correlations of
each identification, the beta-c and kappa_i-c correlations of the linearised posterior at the truth
(S^T C^-1 S + C0^-1)^-1 with the exact sensitivities, runs and wall times, the cost of one iteration with the
field in plain-run equivalents, and the load average. ``--figure`` writes the (beta, c) ellipses.

    python benchmarks/dic_identification.py [--h-fine 2.0] [--n 8] [--figure docs/dic/beta_c_ellipses.png]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import time

import numpy as np

from fracid.data import Diagonal
from fracid.data.covariance_matrix import block_diagonal
from fracid.data.dic_noise import dic_frames_covariance
from fracid.fem.material.parameters import DamageParameters
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.field_observations import FieldObservation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.strategy import identify
from fracid.inverse.studies.dic_twin import synthetic_dic
from fracid.inverse.studies.uniqueness import bounds_covariance
from fracid.specimens.beam import NotchedBeam

BASE = DamageParameters(E=36250.0, nu=0.2, kappa_i=6.6e-5, alpha=0.99, beta=600.0, c=9.0, eta=10.0)  # demo.toml
NAMES = ("kappa_i", "beta", "c")
TRUTH = np.array([4.798e-5, 1086.5, 21.46])  # the demo's estimate (docs/demo/result.json, rounded)
SPACE = ParameterSpace(NAMES, [4e-5, 200.0, 4.0], [1e-4, 3000.0, 30.0], log=(False, True, False))
CURVE = np.linspace(0.01, 0.2, 12)  # CMOD [mm]
FRAMES = np.linspace(0.025, 0.2, 6)  # CMOD [mm]
DIC_STD, SUBSET, SPACING = 1e-3, 6.0, 3.5  # mm


def correlations(C) -> np.ndarray:
    """Correlation matrix of the covariance ``C``."""
    s = np.sqrt(np.diag(C))
    return C / np.outer(s, s)


def linearised_posterior(S, C) -> np.ndarray:
    """(S^T C^-1 S + C0^-1)^-1, C0 the uniform prior over the bounds."""
    return np.linalg.inv(S.T @ C.solve(S) + np.linalg.inv(bounds_covariance(SPACE)))


def twin(beam, seed: int):
    """(operators (curve, curve + field), noisy data y, covariances, the truth's run, the DIC twin)."""
    params = dataclasses.replace(BASE, **dict(zip(NAMES, TRUTH)))
    dic = synthetic_dic(beam, params, frames=FRAMES, spacing=SPACING, std=DIC_STD, subset_size=SUBSET, holes=None,
                        seed=seed)
    curve = Observation(beam, CURVE, control="cmod", name="curve")
    field = FieldObservation(beam, dic.points, FRAMES, control="cmod", name="dic")
    both = ForwardOperator([curve, field], BASE, NAMES).differentiated()
    alone = ForwardOperator([curve], BASE, NAMES).differentiated()
    truth = both(TRUTH)
    assert truth.ok, truth.error
    n = CURVE.size
    C_curve = Diagonal(np.full(n, (0.01 * truth.y[:n].max()) ** 2))
    C_both = block_diagonal([C_curve, dic_frames_covariance(dic.points, DIC_STD, SUBSET, n_frames=FRAMES.size)])
    noise_curve = np.random.default_rng(seed + 1).standard_normal(n) * np.sqrt(C_curve.diag())
    noise_field = dic.noise.transpose(0, 2, 1).ravel()  # frame x component x point
    y = truth.y + np.concatenate([noise_curve, noise_field])
    return (alone, both), y, (C_curve, C_both), truth, dic


def summary(label, result, truth_C) -> dict:
    """One identification's figures (and the linearised posterior's correlations at the truth)."""
    r, r_lin = correlations(result.C), correlations(truth_C)
    out = {"data": label, "estimate": result.x.tolist(), "std": np.sqrt(np.diag(result.C)).tolist(),
           "error_percent": (100 * (result.x / TRUTH - 1)).tolist(), "r_beta_c": r[1, 2], "r_kappa_c": r[0, 2],
           "r_beta_c_at_truth": r_lin[1, 2], "r_kappa_c_at_truth": r_lin[0, 2],
           "runs": int(result.runs.get("knn", 0) + result.runs.get("gauss_newton_computed", 0)),
           "wall_s": result.runs["wall_seconds"]}
    d = result.x - TRUTH
    out["mahalanobis2"] = float(d @ np.linalg.solve(result.C, d))  # 99 % region of chi2(3): 11.34
    return out


def figure(path, posteriors, labels):
    """The 1-sigma and 2-sigma ellipses of (beta, c) of each linearised posterior at the truth."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    t = np.linspace(0, 2 * np.pi, 200)
    for P, label, color in zip(posteriors, labels, ("tab:red", "tab:blue")):
        w, V = np.linalg.eigh(P[1:, 1:])
        r = correlations(P)[1, 2]
        for k, style in ((1, "-"), (2, "--")):
            e = TRUTH[1:, None] + k * V @ (np.sqrt(w)[:, None] * np.stack([np.cos(t), np.sin(t)]))
            ax.plot(*e, style, color=color, label=f"{label} (r = {r:.3f})" if k == 1 else None)
    ax.plot(*TRUTH[1:], "k+", ms=10, label="truth")
    ax.set_xlabel("beta [-]")
    ax.set_ylabel("c [mm$^2$]")
    ax.set_title("(beta, c): 1 and 2 std ellipses of the linearised posterior")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h-fine", type=float, default=2.0)
    parser.add_argument("--n", type=int, default=8, help="population of the KNN stage")
    parser.add_argument("--seed", type=int, default=5)
    parser.add_argument("--figure", default=None, help="PNG of the (beta, c) ellipses")
    args = parser.parse_args(argv)
    load_before = os.getloadavg()
    beam = NotchedBeam(h_fine=args.h_fine, h_coarse=6.0)
    (alone, both), y, (C_curve, C_both), truth, dic = twin(beam, args.seed)
    n = CURVE.size
    start = time.perf_counter()
    ForwardOperator(alone.observations, BASE, NAMES)(TRUTH)  # a plain run (no sensitivities)
    t_plain = time.perf_counter() - start
    start = time.perf_counter()
    both(TRUTH)
    t_field = time.perf_counter() - start
    P_curve, P_both = linearised_posterior(truth.S[:n], C_curve), linearised_posterior(truth.S, C_both)
    rows = []
    for label, op, data, C, P in (("curve", alone, y[:n], C_curve, P_curve), ("curve + field", both, y, C_both, P_both)):
        result = identify(op, data, C, SPACE, method="knn-gauss-newton", n=args.n, k=3, progress=False)
        rows.append(summary(label, result, P))
    out = {"h_fine": args.h_fine, "points": len(dic.points), "frames": FRAMES.size, "field_outputs": y.size - n,
           "plain_run_s": t_plain, "run_with_field_and_ddm_s": t_field, "iteration_in_plain_runs": t_field / t_plain,
           "rows": rows, "loadavg_before": load_before, "loadavg_after": os.getloadavg()}
    for row in rows:
        print(f"{row['data']:14s} x = {np.array2string(np.array(row['estimate']), precision=5)} "
              f"std = {np.array2string(np.array(row['std']), precision=3)} error % = "
              f"{np.array2string(np.array(row['error_percent']), precision=2)} r(beta,c) = {row['r_beta_c']:.3f} "
              f"r(kappa_i,c) = {row['r_kappa_c']:.3f} at truth: {row['r_beta_c_at_truth']:.3f}, "
              f"{row['r_kappa_c_at_truth']:.3f}; d2 = {row['mahalanobis2']:.2f}; {row['runs']} runs, "
              f"{row['wall_s']:.0f} s")
    print(f"plain run {t_plain:.2f} s, run with DDM and the field {t_field:.2f} s: one iteration = "
          f"{t_field / t_plain:.2f} plain runs; load average {load_before} -> {out['loadavg_after']}")
    if args.figure:
        figure(args.figure, (P_curve, P_both), ("curve alone", "curve + DIC field"))
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
