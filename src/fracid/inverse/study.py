"""The identification strategy as one study (docs/theory.md, section 4.4), ending in a verdict per parameter.

KNN over a population (overview, prior) -> sensitivity along the load history at the KNN estimate
(which stage of the test informs which parameter) -> Kalman filter -> uniqueness (valley of the
objective over the population, measured from the estimate and its objective) -> multi-start check -> stability under noise -> prediction of data not
used for calibration -> verdict. The sensitivities need a point, which is why they follow the KNN
search rather than precede it; every other stage runs in the order of the thesis's strategy (docs/theory.md, section 4.4).

When asked (``StudySettings.posterior``), the posterior of the parameters is sampled on the exact model
(:func:`fracid.inverse.posterior.posterior`, started from the Kalman filter's Gaussian) after the checks
and predictions, its runs through the same run store under the label "posterior" (those of ``fracid
posterior`` in the same directory: either reuses the other's runs); the verdict then reads its 90 %
credible intervals instead of the Gaussian std (:mod:`fracid.inverse.verdict`) and says so.
"""

from __future__ import annotations

import json
import time
from contextlib import contextmanager
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from fracid.inverse.knn import objective
from fracid.inverse.method import check_problem, identification_bounds
from fracid.inverse.posterior import PosteriorSettings, sample_posterior
from fracid.inverse.sensitivity import ForwardRunError, exact_sensitivity, sensitivity_history
from fracid.inverse.stability import stability as stability_check
from fracid.inverse.runs import StoredOperator
from fracid.inverse.strategy import KalmanSettings, KnnKalman, KnnSettings
from fracid.inverse.uniqueness import bounds_covariance, multi_start, objective_maps, starting_points, valley_extent
from fracid.inverse.verdict import DataDescription, parameter_verdicts
from fracid.tables import without_nan, write_csv_table


@dataclass
class Prediction:
    """Data not used for calibration, computed at the estimate.

    Attributes
    ----------
    name : str
    control, y_exp, std_exp : ndarray
        The held-out data.
    y, std : ndarray
        Computed at the estimate, and its standard deviation from the estimate's covariance
        (S C S^T, linearised).
    status : str
        "ok" or the failure reason.
    """

    name: str
    control: np.ndarray
    y_exp: np.ndarray
    std_exp: np.ndarray
    y: np.ndarray
    std: np.ndarray
    status: str = "ok"

    @property
    def relative_rms(self) -> float:
        """RMS of (computed - measured) / max |measured|."""
        return float(np.sqrt(np.mean((self.y - self.y_exp) ** 2)) / np.max(np.abs(self.y_exp)))

    @property
    def chi2_per_point(self) -> float:
        """Mean of ((computed - measured) / sqrt(std_exp^2 + std^2))^2: about 1 when the prediction holds."""
        return float(np.mean((self.y - self.y_exp) ** 2 / (self.std_exp**2 + self.std**2)))


def predict(operator, data, x, C, *, executor=None, name="prediction") -> Prediction:
    """Compute held-out data at the estimate x with the uncertainty propagated from C."""
    nan = np.full(data.n_y, np.nan)
    try:
        evaluate, sensitivity = exact_sensitivity(operator)
        y, S, _ = sensitivity(evaluate, x, None, executor)
    except ForwardRunError as err:
        return Prediction(name, data.control, data.y, data.std, nan, nan, status=str(err))
    std = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", S, C, S), 0.0))
    return Prediction(name, data.control, data.y, data.std, y, std)


def estimate_objective(ident, y, C):
    """(x, f): the identification's estimate and its objective (y - y_fit)^T C^-1 (y - y_fit), the centre of
    the objective maps and valley; None when the run at the estimate failed."""
    y_fit = np.asarray(ident.y_fit, float) if ident.y_fit is not None else None
    if y_fit is None or not np.all(np.isfinite(y_fit)):
        return None
    return np.asarray(ident.x, float), float(objective(y, C, y_fit)[0])


def describe_data(operator) -> DataDescription:
    """Number of specimens with a force curve and whether local data are present."""
    sizes = {obs.run_key[0] for obs in operator.observations if obs.quantity == "force"}
    return DataDescription(sizes=max(len(sizes), 1), local=any(o.quantity != "force" for o in operator.observations))


@dataclass
class StudyResult:
    """Everything a study computed; :meth:`save` writes it, :func:`fracid.report.study` reports it.

    ``posterior`` is the sampled :class:`~fracid.inverse.posterior.PosteriorResult` when the study was
    asked for one and it could be sampled, None otherwise.
    """

    identification: object
    sensitivity: object
    maps: list
    valley_extent: np.ndarray
    multi_start: object
    stability: object
    predictions: list
    verdict: object
    timings: dict = field(default_factory=dict)
    runs: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    posterior: object = None

    @property
    def names(self) -> list:
        return list(self.identification.names)

    def runs_text(self) -> str:
        """One line per stage: forward runs and how many failed."""
        parts = [f"{stage} {total} ({failed} failed)" for stage, (total, failed) in self.runs.items()]
        return "Forward runs: " + ", ".join(parts) if parts else ""

    def summary(self) -> str:
        """The text of verdict.txt: the verdict per parameter, the warnings of the identification (a poor fit,
        estimates at a bound, no convergence, failed runs: those stderr and report.html give), the posterior,
        the forward runs, the status, the notes and the predictions."""
        ident = self.identification
        lines = ["Verdict:", self.verdict.text(ident.units)]
        lines += [f"Warning: {text}" for text in ident.warnings()]
        if self.posterior is not None:
            first = self.posterior.summary().splitlines()[0]
            if not self.posterior.sampling_failed:
                lines.append(f"Verdict measure: {self.verdict.measure} (std-equivalent: half-width / 1.645)")
            lines.append(f"P{first[1:]}")
        if self.runs:
            lines.append(self.runs_text())
        if getattr(ident, "status", ""):
            lines.append(f"{ident.status_label}: {ident.status}")
        lines += [f"Note: {note}" for note in self.notes]
        if self.predictions:
            lines.append("Predictions of data not used for calibration:")
            lines += [f"  {p.name}: RMS {p.relative_rms:.1%} of the peak, chi2/point {p.chi2_per_point:.2f}"
                      for p in self.predictions if p.status == "ok"]
            lines += [f"  {p.name}: failed ({p.status})" for p in self.predictions if p.status != "ok"]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        ident = self.identification.to_dict()
        out = {"identification": ident, "verdict": self.verdict.as_dict(),
               "valley_extent": dict(zip(self.names, self.valley_extent.tolist())),
               "maps": [{"pair": list(m.names), "correlation_in_valley": m.correlation, "valley_points": int(m.valley.sum()),
                         "level": m.level} for m in self.maps],
               "timings_seconds": self.timings,
               "runs": {stage: {"runs": total, "failed": failed} for stage, (total, failed) in self.runs.items()},
               "notes": list(self.notes)}
        if self.sensitivity is not None:
            out["sensitivity"] = {"normalised": self.sensitivity.normalised.tolist(),
                                  "variance_share": self.sensitivity.variance_share.tolist(), "x": self.sensitivity.x.tolist()}
        if self.multi_start is not None:
            ms = self.multi_start
            out["multi_start"] = {"starts": ms.starts.tolist(), "ends": ms.ends.tolist(), "std": ms.stds.tolist(),
                                  "f": ms.f.tolist(), "distance_in_std": ms.distance.tolist()}
        if self.stability is not None:
            st = self.stability
            out["stability"] = {"estimates": st.estimates.tolist(), "errors": st.errors, "seed": st.seed,
                                "noise_level": st.noise_level, "scatter": st.scatter.tolist(),
                                "relative_scatter": st.relative_scatter.tolist(),
                                "amplification": st.amplification.tolist()}
        out["predictions"] = [{"name": p.name, "control": p.control.tolist(), "y_exp": p.y_exp.tolist(),
                               "y": p.y.tolist(), "std": p.std.tolist(), "status": p.status,
                               "relative_rms": p.relative_rms if p.status == "ok" else None,
                               "chi2_per_point": p.chi2_per_point if p.status == "ok" else None}
                              for p in self.predictions]
        if self.posterior is not None:
            out["posterior"] = {**self.posterior.to_dict(), "interval_90_label": "equal-tailed 90 % credible "
                                "interval (weighted 5 % and 95 % quantiles of the importance-weighted draws)"}
        return without_nan(out)

    def save(self, directory) -> Path:
        """Write study.json, verdict.txt and the CSV tables into ``directory``."""
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        (directory / "study.json").write_text(json.dumps(self.to_dict(), indent=1))
        (directory / "verdict.txt").write_text(self.summary() + "\n")
        ident = self.identification
        population = getattr(ident, "knn", None) or {}
        if population.get("points") is not None:
            points, f = np.asarray(population["points"], float), np.asarray(population["f"], float)
            status = population.get("status") or ["ok" if np.isfinite(v) else "failed" for v in f]
            errors = population.get("errors") or [""] * len(f)
            # a failed run has no objective: an empty cell and its status, not "inf"
            write_csv_table(directory / "population.csv", [*self.names, "f", "status", "error"],
                            ([*x, v, s, e or ""] for x, v, s, e in zip(points.tolist(), f.tolist(), status, errors)))
        if self.sensitivity is not None:
            table = np.column_stack([self.sensitivity.normalised, self.sensitivity.variance_share])
            cols = [f"S_{n}" for n in self.names] + [f"variance_removed_{n}" for n in self.names]
            write_csv_table(directory / "sensitivity.csv", cols, table.tolist())
        if self.stability is not None:
            write_csv_table(directory / "stability.csv", self.names, np.asarray(self.stability.estimates).tolist())
        if self.posterior is not None:
            self.posterior.save_csv(directory / "posterior.csv")
        return directory


@dataclass(frozen=True)
class StudySettings:
    """What :func:`run_study` computes. Execution (executor, store, progress, log) is not a setting.

    Attributes
    ----------
    knn : KnnSettings
        The population search: overview, prior mean, objective maps and the starting points of the
        multi-start check.
    kalman : KalmanSettings
        The Kalman filter of the identification, of every multi-start filter and of every noisy
        replicate; its ``groups`` may also be ``"blocks"`` (one filter step per data block) or
        ``"all"`` (one step: the batch filter).
    prior : {"knn", "bounds"}
        Covariance of the Kalman filter's prior (mean: the KNN estimate): the spread of the k
        nearest neighbours (the thesis's cascade, docs/theory.md, section 4.4), or the bounds' uniform covariance. The
        neighbours were ranked with the same data, so "bounds" keeps the posterior to what the
        data say, which comparisons of data sets (twin matrices) need.
    starts : int
        Starting points of the multi-start check (0 or 1: skipped).
    replicates : int
        Noisy replicates of the stability check (0: skipped).
    noise_seed : int
        Seed of the replicates' noise.
    tolerance : float
        Largest relative standard deviation std / |estimate| called identified [-] (0.1: 10 %).
    posterior : PosteriorSettings or None
        Sample the posterior on the exact model with these settings after the checks, and give the
        verdict from its 90 % credible intervals; None (default): no posterior, the verdict from the
        Gaussian std.
    """

    knn: KnnSettings = KnnSettings()
    kalman: KalmanSettings = KalmanSettings()
    prior: str = "knn"
    starts: int = 3
    replicates: int = 5
    noise_seed: int = 0
    tolerance: float = 0.1
    posterior: PosteriorSettings | None = None

    def __post_init__(self):
        if self.prior not in ("knn", "bounds"):
            raise ValueError(f"prior = {self.prior!r}; choose 'knn' or 'bounds'")
        if self.posterior is not None and not isinstance(self.posterior, PosteriorSettings):
            raise TypeError(f"posterior = {self.posterior!r}: give PosteriorSettings(...) or None")

    @property
    def identification(self) -> KnnKalman:
        """The inverse method of the identification: :class:`~fracid.inverse.strategy.KnnKalman`."""
        return KnnKalman(self.knn, self.kalman)

    def replace(self, **changes) -> StudySettings:
        """A copy with ``changes``: fields of this class, or settings of its ``knn`` (``n``, ``method``,
        ``seed``, ``k``) and ``kalman`` (``groups``, ``max_iterations``, ``tol``, ``restart``) by
        their own names.

        Raises
        ------
        TypeError
            For a name that is none of these.
        """
        nested = {"knn": {f.name for f in fields(KnnSettings)}, "kalman": {f.name for f in fields(KalmanSettings)}}
        known = {f.name for f in fields(self)}.union(*nested.values())
        unknown = sorted(set(changes) - known)
        if unknown:
            raise TypeError(f"unknown study setting(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")
        for part, names in nested.items():
            own = {name: changes.pop(name) for name in list(changes) if name in names}
            if own:
                changes[part] = replace(changes.get(part, getattr(self, part)), **own)
        return replace(self, **changes)


def run_study(operator, data, space, settings: StudySettings = StudySettings(), *, held_out=(), executor=None,
              store=None, progress=None, log=None, retry_failed=False) -> StudyResult:
    """Run the identification strategy with its checks and return the verdict.

    Parameters
    ----------
    operator : ForwardOperator
        Computes the calibration data.
    data : ExperimentalData
        Calibration data; its blocks line up with the operator's observations.
    space : ParameterSpace
        Bounds of the population; also the prior of the multi-start filters and the reference of
        the variance removed.
    settings : StudySettings
        The methods' settings and the checks to make (``StudySettings().replace(n=32, starts=0)``).
    held_out : sequence of (ForwardOperator, ExperimentalData)
        Data not used for calibration, predicted at the estimate.
    executor, store
        Parallel execution and the persistent run store.
    progress : None, bool
        Progress bars (None: on a terminal).
    log : callable(str), optional
        Receives one line per stage (the command line prints them); silent if None.
    retry_failed : bool
        Run again the runs stored as failed.

    Every forward run goes through ``store`` (when given). A failed forward run never ends the
    study: the stage that met it records it (``StudyResult.runs`` counts the failures of every stage,
    ``notes`` says which checks could not be made). The same holds for the posterior
    (``settings.posterior``): when it cannot be sampled, a note says why and the verdict reads the
    Gaussian std.
    """
    if data.y.size != operator.n_outputs:
        raise ValueError(f"the data hold {data.y.size} values but the observations compute {operator.n_outputs}")
    check_problem(operator, data.y, data.covariance, space)
    timings, clock = {}, time.perf_counter()
    log = log or (lambda text: None)

    def stage(name):
        nonlocal clock
        now = time.perf_counter()
        timings[name] = now - clock
        clock = now

    y, C = data.y, data.covariance
    method = settings.identification
    kalman = settings.kalman.options(data.n_y, data.blocks)
    bounds = identification_bounds(operator, space)
    C_bounds = bounds_covariance(space)
    # every run after the population carries its sensitivities where the model has them: one stored
    # operator (and its counters) for all stages
    evaluate, _ = exact_sensitivity(StoredOperator(operator, store, retry_failed=retry_failed))
    runs, notes = {}, []

    def count(name, before):
        runs[name] = (evaluate.computed + evaluate.reused - before[0], evaluate.failed - before[1])
        stage(name)

    log(f"KNN: population of {settings.knn.n} ({settings.knn.method})")
    knn = method.search(operator, y, C, space, executor=executor, store=store, progress=progress,
                        retry_failed=retry_failed)
    runs["KNN"] = (len(knn.points), knn.n_failed)
    stage("knn")
    C0 = knn.C0 if settings.prior == "knn" else C_bounds
    log("sensitivity along the load history at the KNN estimate")
    mark = (evaluate.computed + evaluate.reused, evaluate.failed)
    try:
        history = sensitivity_history(evaluate, knn.x0, C, C_bounds, names=space.names, blocks=data.blocks,
                                      executor=executor)
    except ForwardRunError as err:
        history = None
        notes.append(f"sensitivity history skipped: {err}")
    count("sensitivity", mark)
    log("Kalman filter from the KNN prior")
    mark = (evaluate.computed + evaluate.reused, evaluate.failed)
    ident = method.refine(evaluate, y, C, knn, executor=executor, blocks=list(data.blocks), notes=list(data.notes),
                          C0=C0, progress=progress)
    count("Kalman", mark)
    centre = estimate_objective(ident, y, C)
    maps, extent = objective_maps(knn, centre=centre), valley_extent(knn, centre=centre)
    ms = None
    starts, replicates = settings.starts, settings.replicates
    if starts > 1:
        points = starting_points(knn, starts)
        log(f"multi-start check from {len(points)} starting points")
        mark = (evaluate.computed + evaluate.reused, evaluate.failed)
        if len(points) > 1:
            try:
                with stage_bar(progress, len(points), "multi-start filters") as tick:
                    ms = multi_start(evaluate, y, C, points, C_bounds, bounds=bounds, executor=executor,
                                     progress=tick, **kalman)
            except ForwardRunError as err:
                notes.append(f"multi-start check skipped: {err}")
            if ms is not None and ms.failed:
                notes.append(f"multi-start: {len(ms.failed)} of {len(points)} filters failed")
        count("multi-start", mark)
    st = None
    if replicates:
        log(f"stability check: {replicates} noisy replicates")
        mark = (evaluate.computed + evaluate.reused, evaluate.failed)
        with stage_bar(progress, replicates, "noisy replicates") as tick:
            st = stability_check(evaluate, y, C, knn.x0, C0, replicates=replicates, seed=settings.noise_seed,
                                 bounds=bounds, executor=executor, progress=tick, **kalman)
        failed_replicates = sum(bool(e) for e in st.errors)
        if failed_replicates:
            notes.append(f"stability: {failed_replicates} of {replicates} replicates failed")
        count("stability", mark)
    predictions = []
    for op, held in held_out:
        name = ", ".join(b[0] for b in held.blocks)
        log(f"prediction of {name}")
        predictions.append(predict(op, held, ident.x, ident.C, executor=executor, name=name))
    if held_out:
        stage("prediction")
    post = None
    if settings.posterior is not None:
        post = _posterior_stage(operator, data, space, ident, settings.posterior, store=store, executor=executor,
                                progress=progress, log=log, retry_failed=retry_failed, runs=runs, notes=notes)
        stage("posterior")
    if runs["KNN"][1]:
        notes.insert(0, f"{runs['KNN'][1]} of {runs['KNN'][0]} KNN runs failed (they rank last; see population.csv)")
    usable = None if post is None or post.sampling_failed else post  # below the ESS floor: no intervals
    verdict = parameter_verdicts(space.names, ident.x, ident.C, C_bounds, data=describe_data(operator),
                                 tolerance=settings.tolerance, multi_start=ms, stability=st, posterior=usable)
    return StudyResult(ident, history, maps, extent, ms, st, predictions, verdict, timings, runs, notes,
                       posterior=post)


def _posterior_stage(operator, data, space, ident, settings, *, store, executor, progress, log, retry_failed, runs,
                     notes):
    """The posterior sampled from the identification's Gaussian (runs stored under the label "posterior"),
    or None with a note when there is no finite Gaussian to start from or every run failed; a note too
    when its effective sample size is below the floor (the verdict then reads the Gaussian std)."""
    if not (np.all(np.isfinite(ident.x)) and np.all(np.isfinite(ident.C))):
        notes.append("posterior skipped: the identification gave no finite estimate and covariance to start the "
                     "sampler from; the verdict reads the Gaussian std")
        return None
    evaluate = StoredOperator(operator, store, study="posterior", retry_failed=retry_failed)
    try:
        post = sample_posterior(evaluate, data, space, ident, settings, executor=executor, progress=progress, log=log)
    except ForwardRunError as err:
        runs["posterior"] = (evaluate.computed + evaluate.reused, evaluate.failed)
        notes.append(f"posterior skipped: {err}; the verdict reads the Gaussian std")
        return None
    runs["posterior"] = (len(post.x), post.failed)
    if post.sampling_failed:
        notes.append(f"posterior {post.status}; the verdict reads the Gaussian std")
    elif not post.converged:
        notes.append(f"posterior: {post.status}")
    return post


@contextmanager
def stage_bar(progress, total, description):
    """A progress bar over the filters of a study stage; yields its ``progress(done, total)`` callable."""
    from fracid.progress import batch_progress, progress_bar

    with progress_bar(total, description, progress, unit="filter") as bar:
        yield batch_progress(bar)


__all__ = ["Prediction", "StudyResult", "StudySettings", "describe_data", "predict", "run_study"]
