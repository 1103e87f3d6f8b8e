"""K-nearest-neighbour search over a population of forward runs (the discrete grid method, docs/theory.md, section 4.2)."""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

from fracid.inverse.core.misfit import objective
from fracid.inverse.core.space import ParameterSpace


def design(space: ParameterSpace, n: int, method: str = "sobol", seed: int = 0) -> np.ndarray:
    """A population of parameter sets within the bounds.

    Parameters
    ----------
    n : int
        Number of points (``"grid"``: points per parameter, so n ** p in all).
    method : {"sobol", "lhs", "grid"}
        Scrambled Sobol sequence, Latin hypercube (scipy.stats.qmc) or full grid (cell centres
        excluded: the grid includes the bounds).
    """
    p = len(space.names)
    if int(n) != n or n < 1:
        raise ValueError(f"population size n = {n!r} must be a positive integer")
    if method == "grid":
        if n < 2:
            raise ValueError("a full grid needs at least 2 points per parameter")
        axes = np.meshgrid(*[np.linspace(0.0, 1.0, int(n))] * p, indexing="ij")
        unit = np.column_stack([a.ravel() for a in axes])
    elif method == "lhs":
        unit = qmc.LatinHypercube(d=p, seed=seed).random(int(n))
    elif method == "sobol":
        sampler = qmc.Sobol(d=p, scramble=True, seed=seed)
        m = int(np.ceil(np.log2(n)))
        unit = sampler.random_base2(m)[: int(n)]  # balanced for powers of 2
    else:
        raise ValueError(f"design method {method!r}; choose 'sobol', 'lhs' or 'grid'")
    return space.from_unit(unit)


@dataclass
class KnnResult:
    """Outcome of a KNN search.

    Attributes
    ----------
    space : ParameterSpace
    points : ndarray, shape (N, p)
        The population.
    f : ndarray, shape (N,)
        Objective of every point (inf for failed runs).
    status, errors : list of str
        Per point: "ok" or "failed", and the failure reason.
    order : ndarray of int
        Points ranked by f (failed ones last).
    k : int
    x0, C0 : ndarray
        Mean and covariance of the k nearest neighbours (the Kalman filter's prior).
    Y : ndarray, shape (N, n_outputs), optional
        Computed values of every point (NaN rows for failed runs).
    """

    space: ParameterSpace
    points: np.ndarray
    f: np.ndarray
    status: list
    errors: list
    order: np.ndarray
    k: int
    x0: np.ndarray
    C0: np.ndarray
    Y: np.ndarray | None = None

    @property
    def neighbours(self) -> np.ndarray:
        return self.points[self.order[: self.k]]

    @property
    def n_failed(self) -> int:
        return sum(s != "ok" for s in self.status)

    def next_starts(self, m: int, avoid=(), separation: float = 0.25) -> list:
        """Indices of up to m successful points in the order of f, each at least ``separation`` away (in unit
        coordinates) from the points ``avoid`` and from the ones already chosen: starting points that probe
        different parts of the space (multi-start check, restarts of the Kalman filter)."""
        unit = self.space.to_unit(self.points)
        taken = [u for u in self.space.to_unit(np.asarray(avoid, float).reshape(-1, self.points.shape[1]))]
        chosen = []
        for i in self.order:
            if len(chosen) == m or not np.isfinite(self.f[i]):
                break
            if all(np.linalg.norm(unit[i] - u) >= separation for u in taken):
                chosen.append(int(i))
                taken.append(unit[i])
        return chosen

    def table(self, rows: int | None = None) -> str:
        """Ranked table: rank, objective, parameters, status."""
        header = f"{'rank':>4} {'f':>12} " + " ".join(f"{n:>12}" for n in self.space.names) + "  status"
        lines = [header]
        for rank, i in enumerate(self.order[: rows or len(self.order)], start=1):
            values = " ".join(f"{v:12.5g}" for v in self.points[i])
            note = self.status[i] if self.status[i] == "ok" else f"failed: {self.errors[i][:60]}"
            lines.append(f"{rank:4d} {self.f[i]:12.5g} {values}  {note}")
        return "\n".join(lines)


def knn_from_population(space, points, Y, status, errors, y_exp, C_exp, k) -> KnnResult:
    """Rank an evaluated population against measured data (no forward runs: populations are reusable).

    x0 is the mean of the k best points. C0 is their sample covariance plus, per parameter, the
    squared half-spacing of the population (range / N^(1/p) / 2): a floor that keeps C0 positive
    definite when the neighbours are fewer than p + 1 or aligned, and says that the population
    cannot resolve finer than its spacing.
    """
    points = np.atleast_2d(np.asarray(points, float))
    n, p = points.shape
    ok = np.array([s == "ok" for s in status])
    if not 1 <= k <= n:
        raise ValueError(f"k = {k} must be between 1 and the population size {n}")
    if k > ok.sum():
        raise ValueError(f"k = {k} but only {ok.sum()} of {n} forward runs succeeded")
    f = objective(y_exp, C_exp, Y)
    order = np.argsort(f, kind="stable")
    best = points[order[:k]]
    x0 = best.mean(axis=0)
    spread = np.cov(best.T, ddof=1).reshape(p, p) if k > 1 else np.zeros((p, p))
    spacing = (space.upper - space.lower) / n ** (1.0 / p) / 2.0
    C0 = spread + np.diag(spacing**2)
    return KnnResult(space, points, f, list(status), list(errors), order, k, x0, C0, np.atleast_2d(np.asarray(Y, float)))


def knn_search(operator, y_exp, C_exp, space: ParameterSpace, *, n=64, method="sobol", seed=0, k=5,
               executor=None, store=None, progress=None, stats=None, retry_failed=False) -> KnnResult:
    """Run the forward operator on a population and rank it against the data.

    Parameters
    ----------
    operator : ForwardOperator
        Its ``names`` must be the space's names.
    n, method, seed
        Population design, see :func:`design`.
    k : int
        Neighbours averaged into x0 and C0.
    executor : Executor, optional
        Runs the population in parallel (see :mod:`fracid.runtime.executors`).
    store : RunStore, optional
        Stored runs are reused, new ones stored as they finish (an interrupted population resumes).
    stats : fracid.runtime.batch.BatchStats, optional
        Filled with the numbers of runs computed, reused and failed.
    retry_failed : bool
        Run again the points stored as failed.

    Raises
    ------
    AllRunsFailed
        When fewer than k runs of the population succeeded; the message gives the most common reason.
    """
    if tuple(operator.names) != tuple(space.names):
        raise ValueError(f"operator parameters {operator.names} differ from the space's {space.names}")
    points = design(space, n, method, seed)
    if not 1 <= k <= len(points):
        raise ValueError(f"k = {k} must be between 1 and the population size {len(points)}")
    records = evaluate_population(operator, points, executor=executor, store=store, progress=progress, stats=stats,
                                  retry_failed=retry_failed)
    succeeded = sum(r.ok for r in records)
    if succeeded < k:
        raise AllRunsFailed(succeeded, len(records), k, [r.error for r in records if not r.ok])
    Y = np.array([r.y for r in records])
    return knn_from_population(space, points, Y, [r.status for r in records], [r.error for r in records],
                               y_exp, C_exp, k)


def evaluate_population(operator, points, *, executor=None, store=None, progress=None, stats=None, retry_failed=False):
    """Forward runs of every point, through the executor and the run store when given."""
    from fracid.inverse.core.runs import run_population

    return run_population(operator, points, executor=executor, store=store, progress=progress, stats=stats,
                          retry_failed=retry_failed)


class AllRunsFailed(RuntimeError):
    """Too few forward runs of a population succeeded to rank it; the message names the commonest failure."""

    def __init__(self, succeeded: int, total: int, k: int, errors):
        self.succeeded, self.total, self.k = succeeded, total, k
        examples = {}
        for error in errors:
            examples.setdefault(_reason(error), error or "unknown")
        self.reasons = [(examples[r], n) for r, n in Counter(_reason(e) for e in errors).most_common()]
        common, count = self.reasons[0] if self.reasons else ("unknown", 0)
        super().__init__(
            f"only {succeeded} of {total} forward runs of the KNN population succeeded (k = {k} needed); "
            f"the most common failure ({count} of {total - succeeded} runs), for example: {common}")


def _reason(error: str) -> str:
    """A failure message without the numbers that differ from run to run (so that equal causes count together)."""
    text = re.sub(r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?", "#", str(error) or "unknown")
    return text[:300]


__all__ = ["AllRunsFailed", "KnnResult", "design", "evaluate_population", "knn_from_population", "knn_search"]
