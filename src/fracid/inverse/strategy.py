"""The identification strategy: KNN population search, then the Kalman filter (SPEC section 4)."""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fracid.inverse.kalman import GaussianEstimate, kalman_filter
from fracid.inverse.knn import ParameterSpace, knn_search


@dataclass
class IdentificationResult(GaussianEstimate):
    """Identified parameters with their uncertainty, the fit and how it was obtained.

    Attributes
    ----------
    names : list of str
    x, C : ndarray
        Estimate and covariance (units of the parameters).
    y_exp, y_fit, std_exp : ndarray
        Measured values, values computed at the estimate, and the measurement standard deviations.
    blocks : list of (name, start, stop)
        Data blocks in y.
    history : list of dict
        Kalman estimate and covariance after every step of every global iteration.
    knn : dict
        Population, objective values, statuses, ranking, k, x0, C0.
    runs : dict
        Forward runs: KNN population, Kalman filter, failures; wall time [s].
    notes : list of str
        Rules applied to the data and the methods' settings.
    """

    names: list
    x: np.ndarray
    C: np.ndarray
    y_exp: np.ndarray
    y_fit: np.ndarray
    std_exp: np.ndarray
    blocks: list = field(default_factory=list)
    history: list = field(default_factory=list)
    knn: dict = field(default_factory=dict)
    runs: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    converged: bool = False
    units: dict = field(default_factory=dict)

    def summary(self) -> str:
        units = self.units
        lines = [f"{n:>8} = {v:.6g} +- {s:.3g} {units.get(n, '')}" for n, v, s in zip(self.names, self.x, self.std)]
        lines.append("correlation:\n" + np.array2string(self.correlation, precision=3))
        return "\n".join(lines)

    def to_dict(self) -> dict:
        def plain(v):
            if isinstance(v, np.ndarray):
                return v.tolist()
            if isinstance(v, dict):
                return {k: plain(w) for k, w in v.items()}
            if isinstance(v, (list, tuple)):
                return [plain(w) for w in v]
            if isinstance(v, (np.floating, np.integer)):
                return v.item()
            return v

        d = {k: plain(getattr(self, k)) for k in self.__dataclass_fields__}
        d["std"], d["correlation"] = self.std.tolist(), self.correlation.tolist()
        d["f_fit"] = float(np.sum(((self.y_exp - self.y_fit) / self.std_exp) ** 2))
        return json.loads(json.dumps(d, allow_nan=True).replace("Infinity", "null"))

    def save(self, path) -> Path:
        """Write the result as JSON."""
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1))
        return path


def identify(operator, y_exp, C_exp, space: ParameterSpace, *, n=64, method="sobol", seed=0, k=5,
             groups=None, max_iterations=10, tol=0.01, restart="linearize", executor=None, store=None, blocks=(), notes=(),
             progress=None) -> IdentificationResult:
    """KNN over a population for a global overview and the prior, then the Kalman filter to refine.

    Parameters
    ----------
    operator : ForwardOperator
    y_exp, C_exp : ndarray
        Measured data and covariance (e.g. from :mod:`fracid.data`).
    space : ParameterSpace
        Bounds of the population (the filter may leave them, within the parameters' valid ranges).
    n, method, seed, k
        KNN population and neighbours (:func:`~fracid.inverse.knn.knn_search`).
    groups, max_iterations, tol, restart
        Kalman filter settings (:func:`~fracid.inverse.kalman.kalman_filter`).
    executor, store
        Parallel execution and the persistent run store.
    """
    start = time.perf_counter()
    y_exp, C_exp = np.asarray(y_exp, float), np.asarray(C_exp, float)
    knn = knn_search(operator, y_exp, C_exp, space, n=n, method=method, seed=seed, k=k, executor=executor,
                     store=store, progress=progress)
    return refine(operator, y_exp, C_exp, knn, groups=groups, max_iterations=max_iterations, tol=tol,
                  restart=restart, executor=executor, blocks=blocks, notes=notes, method=method, seed=seed,
                  started=start)


def refine(operator, y_exp, C_exp, knn, *, groups=None, max_iterations=10, tol=0.01, restart="linearize",
           executor=None, blocks=(), notes=(), method="", seed=0, started=None, C0=None) -> IdentificationResult:
    """The Kalman filter from the prior of a KNN search (x0, C0): the second stage of :func:`identify`.

    ``C0`` replaces the KNN covariance as the prior's (e.g. the bounds' covariance, so that the
    posterior holds the information of the data alone).
    """
    start = time.perf_counter() if started is None else started
    bounds = operator.valid_bounds()
    C0 = knn.C0 if C0 is None else np.asarray(C0, float)
    kalman = kalman_filter(operator, y_exp, C_exp, knn.x0, C0, groups=groups, max_iterations=max_iterations,
                           tol=tol, restart=restart, executor=executor, bounds=bounds)
    knn_summary = {"points": knn.points, "f": knn.f, "status": knn.status, "errors": knn.errors,
                   "order": knn.order, "k": knn.k, "x0": knn.x0, "C0": knn.C0, "method": method, "seed": seed}
    runs = {"knn": len(knn.points), "knn_failed": knn.n_failed, "kalman": kalman.runs,
            "kalman_run_equivalents": kalman.run_equivalents, "kalman_iterations": kalman.iterations,
            "wall_seconds": time.perf_counter() - start}
    return IdentificationResult(
        names=list(knn.space.names), x=kalman.x, C=kalman.C, y_exp=y_exp, y_fit=kalman.y,
        std_exp=np.sqrt(np.diag(C_exp)), blocks=list(blocks), history=kalman.history, knn=knn_summary, runs=runs,
        notes=list(notes) + [f"KNN: {method} population of {len(knn.points)}, k = {knn.k}",
                             f"Kalman filter: step by step, {kalman.iterations} global iteration(s), tol {tol} std"],
        converged=kalman.converged, units=dict(operator.units),
    )


def identify_data(operator, data, space: ParameterSpace, **settings) -> IdentificationResult:
    """:func:`identify` with measured data from :mod:`fracid.data` (its blocks and notes are kept).

    ``data`` is an :class:`~fracid.data.ExperimentalData`; its blocks must line up with the
    operator's observations (same number of values, in order).
    """
    if data.y.size != operator.n_outputs:
        raise ValueError(f"the data hold {data.y.size} values but the observations compute {operator.n_outputs}")
    for block, part in zip(data.blocks, operator.slices()):
        name, start, stop = block
        if (start, stop) != (part.start, part.stop):
            raise ValueError(f"data block {name!r} spans [{start}, {stop}) but its observation spans [{part.start}, {part.stop})")
    return identify(operator, data.y, data.covariance, space, blocks=list(data.blocks), notes=list(data.notes), **settings)
