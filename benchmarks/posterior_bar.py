"""Benchmark: the posterior of (c, beta) of the bar by adaptive importance sampling, against references on the
exact model, and the coverage of its credible intervals.

The bar with a weak zone (60 elements), force-elongation curve at 12 points up to 0.03 mm, std 0.02 N, truth
(c, beta) = (2, 250) mm^2 and -, bounds c in [0.5, 4], beta in [100, 500]: c and beta lie along a curved valley.

1. ``reference``: one noisy data set; the identification (KNN 16 + Kalman filter) gives the Gaussian seed; the
   posterior by :func:`fracid.inverse.sampling.posterior.posterior`; the reference by quadrature on a grid of the exact
   model that follows the valley (``--grid`` x ``--grid`` points, see :func:`grid_reference`) and, with ``--emcee``, a long emcee run on the exact
   model. Prints means, stds, 90 % intervals and the differences in reference stds; writes the figure
   docs/posterior/bar_reference.png (the draws over the reference density).
2. ``coverage``: ``--replicates`` noisy data sets; per set the identification and the posterior; counts how
   often the 90 % credible interval and the Kalman filter's Gaussian 90 % interval (estimate +- 1.645 std)
   contain the truth, per parameter.

    python benchmarks/posterior_bar.py reference [--grid 61] [--emcee 2000] [--workers 2]
    python benchmarks/posterior_bar.py coverage [--replicates 20] [--first 0] [--workers 2] [--screening 2]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.data.covariance_matrix import as_covariance
from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.sampling.posterior import PosteriorSettings, posterior
from fracid.inverse.sampling.sample import sample_posterior
from fracid.inverse.core.sensitivity import evaluate_points
from fracid.inverse.methods.strategy import identify
from fracid.runtime.executors import executor_session

TRUTH = np.array([2.0, 250.0])
POINTS = np.linspace(0.0025, 0.03, 12)
STD = 0.02
SPACE = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])
SETTINGS = PosteriorSettings(samples_per_round=200, max_rounds=12, target_ess=800)
DOCS = Path(__file__).resolve().parents[1] / "docs" / "posterior"


def bar_operator():
    bar = fracid.BarWithWeakZone(n_elements=60)
    return ForwardOperator([Observation(bar, POINTS)], fracid.DamageParameters(c=2.0, beta=250.0), SPACE.names)


def noisy_data(operator, seed):
    clean = operator(TRUTH).y
    return clean + STD * np.random.default_rng(seed).standard_normal(clean.size), np.eye(clean.size) * STD**2


def identify_and_sample(operator, y, C, executor, seed=0, settings=SETTINGS):
    """The identification and the posterior; with ``settings.screening`` > 1 the two-level posterior of
    :func:`~fracid.inverse.sampling.sample.sample_posterior` (the bar's mesh coarsened for screening)."""
    start = time.perf_counter()
    estimate = identify(operator, y, C, SPACE, n=16, k=4, groups=[np.arange(0, 4), np.arange(4, 8), np.arange(8, 12)], executor=executor, progress=False)
    t_kf = time.perf_counter() - start
    if settings.screening > 1:
        data = SimpleNamespace(y=y, covariance=as_covariance(C, y.size), blocks=[("global", 0, y.size)])
        seed_of = SimpleNamespace(x=estimate.x, C=estimate.C, control=POINTS, units={}, error_terms=None)
        result = sample_posterior(StoredOperator(operator), data, SPACE, seed_of, settings.replace(seed=seed),
                                  executor=executor, progress=False)
    else:
        result = posterior(operator, y, C, SPACE, estimate.x, estimate.C, settings=settings.replace(seed=seed),
                           executor=executor)
    return estimate, result, t_kf, time.perf_counter() - start - t_kf


def grid_reference(operator, y, C, executor, n, draws, weights):
    """The posterior density by quadrature on a grid that follows the valley: c on n points over the draws'
    range (within the bounds), and at each c, beta on n points of beta_valley(c) +- 8 conditional stds, with
    beta_valley a weighted quadratic fit of the draws (a sheared grid: unit Jacobian, the thin valley resolved).
    Returns the points, their normalised weights and the grid's (c, offset) axes."""
    c_lo, c_hi = (max(SPACE.lower[0], draws[weights > 0, 0].min() - 0.2 * np.ptp(draws[:, 0])),
                  min(SPACE.upper[0], draws[weights > 0, 0].max() + 0.2 * np.ptp(draws[:, 0])))
    fit = np.polyfit(draws[:, 0], draws[:, 1], 2, w=np.sqrt(weights))
    spread = np.sqrt(weights @ (draws[:, 1] - np.polyval(fit, draws[:, 0])) ** 2)
    axes = [np.linspace(c_lo, c_hi, n), np.linspace(-8 * spread, 8 * spread, n)]
    c, offset = np.meshgrid(*axes, indexing="ij")
    points = np.column_stack([c.ravel(), np.polyval(fit, c.ravel()) + offset.ravel()])
    inside = np.all((points >= SPACE.lower) & (points <= SPACE.upper), axis=1)
    records = evaluate_points(operator, points[inside], None, executor)
    ll = np.full(len(points), -np.inf)
    r = np.array([rec.y for rec in records]) - y
    ll[inside] = -0.5 * np.einsum("ni,ij,nj->n", r, np.linalg.inv(C), r)
    ll = np.where(np.isfinite(ll), ll, -np.inf)
    p = np.exp(ll - ll.max())
    edge = p.reshape(n, n)[:, [0, -1]].max() / p.max()
    return points, p / p.sum(), axes, edge


class LogProbability:
    """log p(x | y) of the bar on the exact model (picklable, for emcee's pool)."""

    def __init__(self, operator, y, C):
        self.operator, self.y, self.inverse = operator, y, np.linalg.inv(C)

    def __call__(self, x):
        if np.any(x < SPACE.lower) or np.any(x > SPACE.upper):
            return -np.inf
        record = self.operator(x)
        return -0.5 * (record.y - self.y) @ self.inverse @ (record.y - self.y) if record.ok else -np.inf


def emcee_reference(operator, y, C, steps, executor, start_at, seed=0):
    """emcee's affine-invariant ensemble (16 walkers started around ``start_at``) on the exact model."""
    import emcee

    walkers = 16
    rng = np.random.default_rng(seed)
    start = start_at + rng.standard_normal((walkers, 2)) * [0.05, 2.0]
    sampler = emcee.EnsembleSampler(walkers, 2, LogProbability(operator, y, C), pool=executor)
    sampler.run_mcmc(start, steps, progress=False)
    tau = sampler.get_autocorr_time(quiet=True)
    burn = int(5 * np.max(tau))
    return sampler.get_chain(discard=burn, flat=True), tau


def moments(points, weights):
    from fracid.inverse.sampling.mixture import weighted_quantile

    mean = weights @ points
    std = np.sqrt(weights @ (points - mean) ** 2)
    q = np.array([weighted_quantile(points[:, j], weights, [0.05, 0.95]) for j in range(points.shape[1])])
    return mean, std, q


def reference(args):
    operator = bar_operator()
    y, C = noisy_data(operator, seed=1)
    with executor_session(args.workers) as executor:
        estimate, result, t_kf, t_post = identify_and_sample(operator, y, C, executor)
        start = time.perf_counter()
        points, p, axes, edge = grid_reference(operator, y, C, executor, args.grid, result.x, result.weights)
        t_grid = time.perf_counter() - start
    print(f"Kalman filter: {estimate.x} +- {estimate.std} (corr {estimate.correlation[0, 1]:+.3f}), {t_kf:.0f} s")
    print(f"posterior: {len(result.x)} runs, ESS {result.ess:.0f}, {result.failed} failed, {t_post:.0f} s; "
          f"{result.status}")
    g_mean, g_std, g_q = moments(points, p)
    print(f"grid {args.grid} x {args.grid} along the valley ({args.grid ** 2} runs, {t_grid:.0f} s; density on the "
          f"band's edges / peak {edge:.1e}): mean {g_mean}, std {g_std}")
    rows = [("posterior", result.mean, result.std, result.credible_intervals(0.9)), ("grid", g_mean, g_std, g_q)]
    if args.emcee:
        start = time.perf_counter()
        with executor_session(args.workers) as executor:
            chain, tau = emcee_reference(operator, y, C, args.emcee, executor, result.mean)
        print(f"emcee: 16 walkers x {args.emcee} steps ({16 * args.emcee} runs, {time.perf_counter() - start:.0f} s), "
              f"autocorrelation times {tau}, {len(chain)} draws kept")
        w = np.ones(len(chain)) / len(chain)
        rows.append(("emcee", *moments(chain, w)))
    for name, mean, std, q in rows:
        print(f"{name:10s} mean {np.array2string(mean, precision=5)} std {np.array2string(std, precision=4)} "
              f"90 % {np.array2string(q, precision=4)}  (mean - grid) / grid std "
              f"{np.array2string((mean - g_mean) / g_std, precision=3)}  std / grid std - 1 "
              f"{np.array2string(std / g_std - 1, precision=3)}")
    figure(result, estimate, points, p)


def figure(result, estimate, points, p):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.5))
    n = int(round(np.sqrt(len(p))))  # the sheared n x n grid of grid_reference, in its (c, offset) order
    ax.contourf(points[:, 0].reshape(n, n), points[:, 1].reshape(n, n), p.reshape(n, n), levels=12, cmap="Greys")
    big = result.weights > np.quantile(result.weights, 0.5)
    ax.scatter(result.x[big, 0], result.x[big, 1], s=4, c="tab:red", alpha=0.4, label="importance draws (upper half of weights)")
    angles = np.linspace(0, 2 * np.pi, 200)
    vals, vecs = np.linalg.eigh(estimate.C)
    ellipse = estimate.x[:, None] + 2 * vecs @ (np.sqrt(vals)[:, None] * np.vstack([np.cos(angles), np.sin(angles)]))
    ax.plot(*ellipse, "b-", label="Kalman filter: 2 std ellipse")
    ax.plot(*TRUTH, "k*", ms=10, label="truth")
    ax.set(xlabel="c [mm$^2$]", ylabel="beta [-]", title="bar: posterior of (c, beta); shaded: quadrature reference")
    ax.legend(fontsize=7, loc="upper right")
    DOCS.mkdir(parents=True, exist_ok=True)
    fig.savefig(DOCS / "bar_reference.png", dpi=110, bbox_inches="tight")


def coverage(args):
    operator = bar_operator()
    inside_post, inside_kf, ess = np.zeros(2, int), np.zeros(2, int), []
    settings = SETTINGS.replace(target_ess=args.target, screening=args.screening,
                                samples_per_round=100 if args.screening > 1 else 200)
    with executor_session(args.workers) as executor:
        for replicate in range(args.first, args.first + args.replicates):
            y, C = noisy_data(operator, seed=100 + replicate)
            estimate, result, _, t_post = identify_and_sample(operator, y, C, executor, seed=replicate, settings=settings)
            interval = result.credible_intervals(0.9)
            inside_post += (interval[:, 0] <= TRUTH) & (TRUTH <= interval[:, 1])
            inside_kf += np.abs(estimate.x - TRUTH) <= 1.645 * estimate.std
            ess.append(result.ess)
            runs = len(result.x) if result.levels is None else \
                f"{len(result.levels.x)} coarse and {len(np.unique(result.x, axis=0))} fine"
            print(f"replicate {replicate + 1}: posterior 90 % {np.array2string(interval, precision=4)} "
                  f"(ESS {result.ess:.0f}, {runs} runs, {t_post:.0f} s){''.join(result.notes)}; Kalman {estimate.x} +- "
                  f"{1.645 * estimate.std}; counts posterior {inside_post}, Kalman {inside_kf}", flush=True)
    print(f"coverage of the truth by the 90 % intervals over {args.replicates} replicates (c, beta): posterior "
          f"{inside_post.tolist()}, Kalman filter Gaussian {inside_kf.tolist()}; ESS median {np.median(ess):.0f}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=["reference", "coverage"])
    parser.add_argument("--grid", type=int, default=61)
    parser.add_argument("--emcee", type=int, default=0, help="emcee steps of 16 walkers (0: no emcee run)")
    parser.add_argument("--replicates", type=int, default=20)
    parser.add_argument("--first", type=int, default=0,
                        help="coverage: the first replicate's index (its noise seed is 100 + index; to go on later)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--target", type=float, default=400.0, help="coverage: the posterior's target_ess")
    parser.add_argument("--screening", type=float, default=1.0,
                        help="coverage: screen on a mesh this many times coarser (1: every draw a fine run)")
    args = parser.parse_args(argv)
    reference(args) if args.what == "reference" else coverage(args)


if __name__ == "__main__":
    main()
