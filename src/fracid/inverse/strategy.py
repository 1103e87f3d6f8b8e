"""The identification strategy: KNN population search, then the Kalman filter (SPEC section 4)."""

from __future__ import annotations

import json
import math
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fracid.inverse.kalman import GaussianEstimate, kalman_filter

#: RMS fit error [% of the measured peak] above which a fit is reported as poor
POOR_FIT_PERCENT = 10.0
from fracid.inverse.knn import ParameterSpace, knn_search
from fracid.inverse.runs import StoredOperator
from fracid.parallel import BatchStats


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
    status: str = ""
    at_bound: list = field(default_factory=list)
    bounds: tuple = ()

    @property
    def rms_percent(self) -> float:
        """RMS of (measured - computed) in per cent of the largest |measured| value (NaN if not computed)."""
        y_exp, y_fit = np.asarray(self.y_exp, float), np.asarray(self.y_fit, float)
        scale = np.max(np.abs(y_exp)) if y_exp.size else 0.0
        rms = np.sqrt(np.mean((y_fit - y_exp) ** 2))
        return float(100 * rms / scale) if scale > 0 else float("nan")

    def warnings(self, poor_fit_percent: float = POOR_FIT_PERCENT) -> list[str]:
        """What a user must know before trusting the result: a non-finite or poor fit, estimates at a
        bound, a filter that did not converge or stopped, failed forward runs."""
        out = []
        rms = self.rms_percent
        if not np.all(np.isfinite(np.asarray(self.x, float))) or not math.isfinite(rms):
            out.append("the result is not finite: no forward run succeeded at the estimate")
        elif rms > poor_fit_percent:
            out.append(f"the fit is poor: RMS error {rms:.3g} % of the measured peak (above {poor_fit_percent:g} %). "
                       "Check the data's units (force_unit, control_unit) and sign, the bounds and the model")
        if self.at_bound:
            where = ", ".join(f"{n} = {v:.6g}" for n, v in zip(self.names, self.x) if n in self.at_bound)
            out.append(f"estimate at a bound of [identify.bounds]: {where}; the data pull it outside the bounds "
                       "(widen them if that is physical); its std is the curvature there, not a spread")
        if self.status and not self.converged:
            out.append(f"Kalman filter {self.status}")
        failed = {k: (self.runs or {}).get(k, 0) for k in ("knn_failed", "kalman_failed")}
        if any(failed.values()):
            out.append(f"failed forward runs: {failed['knn_failed']} of {self.runs.get('knn', 0)} KNN, "
                       f"{failed['kalman_failed']} in the Kalman stage (recorded; see report.html)")
        return out

    def summary(self) -> str:
        units = self.units
        lines = []
        for name, v, s in zip(self.names, self.x, self.std):
            flag = "  (at a bound: the std is not a spread)" if name in self.at_bound else ""
            lines.append(f"{name:>8} = {v:.6g} +- {s:.3g} {units.get(name, '')}{flag}".rstrip())
        lines.append("correlation:\n" + np.array2string(self.correlation, precision=3))
        if self.status:
            lines.append(f"Kalman filter: {self.status}")
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


def identification_bounds(operator, space: ParameterSpace) -> tuple[np.ndarray, np.ndarray]:
    """The box the Kalman filter keeps its estimates in: the space's bounds within the parameters' valid ranges."""
    lower, upper = operator.valid_bounds()
    return np.maximum(space.lower, lower), np.minimum(space.upper, upper)


def identify(operator, y_exp, C_exp, space: ParameterSpace, *, n=64, method="sobol", seed=0, k=5,
             groups=None, max_iterations=10, tol=0.01, restart="linearize", executor=None, store=None, blocks=(), notes=(),
             progress=None, retry_failed=False) -> IdentificationResult:
    """KNN over a population for a global overview and the prior, then the Kalman filter to refine.

    Parameters
    ----------
    operator : ForwardOperator
    y_exp, C_exp : ndarray
        Measured data and covariance (e.g. from :mod:`fracid.data`).
    space : ParameterSpace
        Bounds of the population and of the Kalman filter's estimates (:func:`identification_bounds`).
    n, method, seed, k
        KNN population and neighbours (:func:`~fracid.inverse.knn.knn_search`).
    groups, max_iterations, tol, restart
        Kalman filter settings (:func:`~fracid.inverse.kalman.kalman_filter`).
    executor, store
        Parallel execution and the persistent run store (KNN and Kalman runs are stored).
    progress : None, bool
        Progress bars of both stages (None: on a terminal).
    retry_failed : bool
        Run again the runs stored as failed.

    Raises
    ------
    AllRunsFailed
        When fewer than k population runs succeeded. A failed run of the Kalman stage never raises:
        see :func:`refine`.
    """
    start = time.perf_counter()
    y_exp, C_exp = np.asarray(y_exp, float), np.asarray(C_exp, float)
    stats = BatchStats()
    knn = knn_search(operator, y_exp, C_exp, space, n=n, method=method, seed=seed, k=k, executor=executor,
                     store=store, progress=progress, stats=stats, retry_failed=retry_failed)
    evaluate = StoredOperator(operator, store, retry_failed=retry_failed)
    result = refine(evaluate, y_exp, C_exp, knn, groups=groups, max_iterations=max_iterations, tol=tol,
                    restart=restart, executor=executor, blocks=blocks, notes=notes, method=method, seed=seed,
                    started=start, progress=progress)
    result.runs.update(knn_computed=stats.computed, knn_reused=stats.reused)
    return result


def refine(operator, y_exp, C_exp, knn, *, groups=None, max_iterations=10, tol=0.01, restart="linearize",
           executor=None, blocks=(), notes=(), method="", seed=0, started=None, C0=None,
           progress=False) -> IdentificationResult:
    """The Kalman filter from the prior of a KNN search (x0, C0): the second stage of :func:`identify`.

    ``C0`` replaces the KNN covariance as the prior's (e.g. the bounds' covariance, so that the
    posterior holds the information of the data alone). ``operator`` may be a
    :class:`~fracid.inverse.runs.StoredOperator` (its runs are then stored and counted).

    The filter stays inside the KNN space's bounds and does not raise on failed forward runs. When
    it could not evaluate any estimate of its own (every run near its points failed), the result is
    the best point of the population, with the KNN prior covariance, and the status says so.
    """
    start = time.perf_counter() if started is None else started
    bounds = identification_bounds(operator, knn.space)
    C0 = knn.C0 if C0 is None else np.asarray(C0, float)
    before = _counters(operator)
    with kalman_progress(progress, groups, y_exp.size, max_iterations) as callback:
        kalman = kalman_filter(operator, y_exp, C_exp, knn.x0, C0, groups=groups, max_iterations=max_iterations,
                               tol=tol, restart=restart, executor=executor, bounds=bounds, callback=callback)
    x, C, y_fit, status = kalman.x, kalman.C, kalman.y, kalman.status
    if kalman.failed and np.isfinite(knn.f[knn.order[0]]):
        best = knn.order[0]
        x, C = knn.points[best], knn.C0
        y_fit = np.asarray(knn_output(knn, best, y_exp.size))
        status = f"{kalman.status}; the result is the best point of the KNN population"
    after = _counters(operator)
    knn_summary = {"points": knn.points, "f": knn.f, "status": knn.status, "errors": knn.errors,
                   "order": knn.order, "k": knn.k, "x0": knn.x0, "C0": knn.C0, "method": method, "seed": seed}
    runs = {"knn": len(knn.points), "knn_failed": knn.n_failed, "kalman": kalman.runs,
            "kalman_failed": len(kalman.failures), "kalman_run_equivalents": kalman.run_equivalents,
            "kalman_iterations": kalman.iterations, "wall_seconds": time.perf_counter() - start}
    if after is not None:
        runs.update(kalman_computed=after[0] - before[0], kalman_reused=after[1] - before[1])
    lower, upper = bounds
    span = np.where(np.isfinite(upper - lower), upper - lower, 1.0)
    at_bound = [n for n, v, lo, hi, w in zip(knn.space.names, x, lower, upper, span)
                if min(v - lo, hi - v) <= 1e-9 * w]
    return IdentificationResult(
        names=list(knn.space.names), x=x, C=C, y_exp=y_exp, y_fit=y_fit,
        std_exp=np.sqrt(np.diag(C_exp)), blocks=list(blocks), history=kalman.history, knn=knn_summary, runs=runs,
        notes=list(notes) + [f"KNN: {method} population of {len(knn.points)}, k = {knn.k}",
                             f"Kalman filter: step by step, {kalman.iterations} global iteration(s), tol {tol} std; "
                             f"{status}"],
        converged=kalman.converged, units=dict(operator.units), status=status, at_bound=at_bound,
        bounds=(lower.tolist(), upper.tolist()),
    )


def knn_output(knn, index, size):
    """The computed values of a population point (NaN when the population did not keep them)."""
    Y = getattr(knn, "Y", None)
    return Y[index] if Y is not None else np.full(size, np.nan)


def _counters(operator):
    if isinstance(operator, StoredOperator):
        return operator.computed, operator.reused
    return None


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


@contextmanager
def kalman_progress(progress, groups, n_outputs, max_iterations):
    """A progress bar of the Kalman stage (linearisations: the first pass's steps, then one per pass);
    yields the filter's callback."""
    from fracid.progress import progress_bar

    steps = n_outputs if groups is None else len(groups)
    total = steps + max_iterations - 1
    with progress_bar(total, "Kalman filter", progress, unit="step") as bar:
        def callback(iteration, step, x, C):
            if iteration == 1 or step == 1:
                bar.update(1)
            bar.set_postfix_str(f"iteration {iteration}, x = " + ", ".join(f"{v:.4g}" for v in x))

        yield callback
        bar.n = bar.total
        bar.refresh()
