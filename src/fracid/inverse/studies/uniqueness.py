"""Uniqueness of the estimate (docs/theory.md, section 4.6): maps of the objective, its valley, multi-start.

The population of the method's search is an overview of the objective f over the parameter space. Its
*valley* is the set of parameter sets the data cannot tell from the estimate (the identification's, when
given; else the best population point): f - f_estimate below the
95 % quantile of chi^2 with p degrees of freedom (the likelihood-ratio confidence region of a
Gaussian measurement error; p the number of identified parameters). A valley stretched along a line
means correlated parameters; several separated pieces mean several minima.

The multi-start check runs the method's local fit from several distinct starting points of the
population: ends that differ by more than their standard deviations expose a non-unique estimate.
"""

from __future__ import annotations


from dataclasses import dataclass, field
from itertools import combinations

import numpy as np
from scipy.stats import chi2

from fracid.inverse.core.misfit import objective
from fracid.runtime.executors import concurrently
from fracid.inverse.core.sensitivity import ForwardRunError


def valley_level(p: int, confidence: float = 0.95) -> float:
    """f - f_min at the edge of the valley: the chi^2 quantile with p degrees of freedom."""
    return float(chi2.ppf(confidence, p))


@dataclass
class ObjectiveMap:
    """The objective over a pair of parameters, from an evaluated population.

    Attributes
    ----------
    names : tuple of str
        The pair (x axis, y axis).
    points : ndarray, shape (N, 2)
        The pair's values of every successful population point.
    f : ndarray, shape (N,)
        Objective at those points.
    valley : ndarray of bool, shape (N,)
        f - f_min <= level.
    level : float
        Valley threshold on f - f_min.
    correlation : float
        Correlation of the pair over the valley points (in the population's unit coordinates);
        NaN with fewer than 3 valley points.
    centred : bool
        The first point is the identification's estimate (the centre of the map), the others the
        population's; f_min is then the estimate's objective unless a population point fits better.
    """

    names: tuple
    points: np.ndarray
    f: np.ndarray
    valley: np.ndarray
    level: float
    correlation: float
    centred: bool = False

    @property
    def best(self) -> np.ndarray:
        return self.points[np.argmin(self.f)]


def centred_population(knn, centre=None):
    """The successful population points and their objective, with the estimate ``centre`` = (x, f) first
    when given: the reference of the valley (f - f_ref <= level) is then the estimate's objective
    (or the best point's, if a population point fits better).

    Returns
    -------
    points : ndarray, shape (N, p)
    f : ndarray, shape (N,)
    reference : float
        The objective the valley is measured from.
    """
    ok = np.isfinite(knn.f)
    points, f = knn.points[ok], knn.f[ok]
    if centre is not None and np.isfinite(centre[1]):
        x, f_x = centre
        points, f = np.vstack([np.asarray(x, float)[None, :], points]), np.concatenate([[float(f_x)], f])
    return points, f, float(f.min())


def objective_maps(knn, level: float | None = None, centre=None) -> list[ObjectiveMap]:
    """Objective maps of every parameter pair of a :class:`~fracid.inverse.methods.knn.KnnResult`.

    The valley is taken in the full parameter space (all p parameters), then shown per pair. ``centre``
    = (x, f): the identification's estimate and its objective, the centre of the maps and the reference
    of the valley (see :func:`centred_population`); without it, the best population point.
    """
    names = knn.space.names
    points, f, reference = centred_population(knn, centre)
    level = valley_level(len(names)) if level is None else float(level)
    valley = f - reference <= level
    unit = knn.space.to_unit(points)
    maps = []
    for i, j in combinations(range(len(names)), 2):
        corr = float(np.corrcoef(unit[valley, i], unit[valley, j])[0, 1]) if valley.sum() >= 3 else float("nan")
        maps.append(ObjectiveMap((names[i], names[j]), points[:, [i, j]], f, valley, level, corr,
                                 centred=len(f) > int(np.isfinite(knn.f).sum())))
    return maps


def valley_extent(knn, level: float | None = None, centre=None) -> np.ndarray:
    """Per parameter: range of the valley points / range of the population (0 = pinned, 1 = anywhere);
    ``centre`` as in :func:`objective_maps`."""
    points, f, reference = centred_population(knn, centre)
    unit = knn.space.to_unit(points)
    level = valley_level(len(knn.space.names)) if level is None else float(level)
    valley = f - reference <= level
    return unit[valley].max(axis=0) - unit[valley].min(axis=0)


def starting_points(knn, m: int = 3, separation: float = 0.25) -> np.ndarray:
    """m starting points: the best population points, each at least ``separation`` away from the
    ones already chosen (in unit coordinates), so the starts probe different parts of the valley."""
    return knn.points[knn.next_starts(m, separation=separation)]


@dataclass
class MultiStart:
    """Ends of the Kalman filter from several starting points.

    Attributes
    ----------
    starts, ends : ndarray, shape (m, p)
    stds : ndarray, shape (m, p)
        Posterior standard deviations at each end.
    f : ndarray, shape (m,)
        Objective at each end.
    distance : ndarray, shape (p,)
        Per parameter: the largest difference between ends, in units of the smallest posterior
        standard deviation of the two ends.
    results : list of KalmanResult
    failed : list of str
        Starts whose filter failed (not in ``ends``).
    """

    starts: np.ndarray
    ends: np.ndarray
    stds: np.ndarray
    f: np.ndarray
    distance: np.ndarray
    results: list = field(default_factory=list, repr=False)
    failed: list = field(default_factory=list)

    def unique(self, tolerance: float = 1.0) -> np.ndarray:
        """Per parameter: all ends agree within ``tolerance`` standard deviations."""
        return self.distance <= tolerance


def multi_start(evaluate, y_exp, C_exp, starts, C0, *, fit, bounds=None, executor=None, progress=None) -> MultiStart:
    """Run the local fit ``fit`` from every starting point with the prior covariance C0.

    Parameters
    ----------
    starts : ndarray, shape (m, p)
        E.g. from :func:`starting_points`.
    C0 : ndarray, shape (p, p)
        Prior covariance of every start (wide, e.g. from the bounds: a tight prior would pin each
        end to its start).
    progress : callable(done, total), optional
        Called after each fit.
    fit : callable
        The local fit from a start, ``fit(evaluate, y_exp, C_exp, x, C0, bounds=, executor=)`` (an inverse
        method's ``fit_from``) giving ``x``, ``std``, ``y``, ``failed`` and ``status``.
    """
    starts, results, failed = np.atleast_2d(starts), [], []

    def run(x):
        return fit(evaluate, y_exp, C_exp, x, C0, bounds=bounds, executor=executor)

    for x, result in zip(starts, concurrently(run, starts, executor, progress)):  # the fits side by side
        if result.failed:  # recorded; the other starts still tell
            failed.append(f"start {x.tolist()}: {result.status}")
        else:
            results.append(result)
    if not results:
        raise ForwardRunError("the local fit failed from every starting point: " + "; ".join(failed))
    ends = np.array([r.x for r in results])
    stds = np.array([r.std for r in results])
    f = objective(y_exp, C_exp, np.array([r.y for r in results]))
    m, p = ends.shape
    distance = np.zeros(p)
    for a, b in combinations(range(m), 2):
        distance = np.maximum(distance, np.abs(ends[a] - ends[b]) / np.minimum(stds[a], stds[b]))
    return MultiStart(starts, ends, stds, f, distance, results, failed)


def bounds_covariance(space) -> np.ndarray:
    """Covariance of a uniform distribution over the bounds: diag((upper - lower)^2 / 12)."""
    return np.diag((space.upper - space.lower) ** 2 / 12.0)
