"""Cross-model calibration and comparison of forward models on one data set.

Two questions about models of different kinds (e.g. the gradient damage continuum and the discrete
cohesive crack, see :mod:`fracid.models`):

* :func:`cross_calibration`: how well can model B reproduce a curve produced by model A, with
  which parameters, and does it dissipate the same energy while doing so?
* :func:`compare_models`: fitted to the same (measured) data, what parameters, fit error, peak
  force and dissipated energy does each model give?

Both identify with :func:`fracid.inverse.methods.strategy.identify_data` (the inverse method's stages) and
then run each model once more at its estimate, to the last control value of the data,
to read the energy it dissipated (``observables["dissipated_energy"]``: external work minus elastic
energy, [N mm]) and its peak force.

Units: control (CMOD) [mm], force [N], energy [N mm]; parameters in the units of their class.

Example
-------
>>> from fracid.inverse.studies.cross_model import compare_models
>>> from fracid.inverse.studies.model_fit import Candidate
>>> table = compare_models(data, beam, [Candidate("cohesive", CohesiveCrackModel(), CohesiveParameters(E=37000.0),
...                                               ("ft", "Gf"), space)], n=16, k=3)   # doctest: +SKIP
>>> table.rows()                                                                     # doctest: +SKIP
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fracid.data import Diagonal, ExperimentalData
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.core.sensitivity import ForwardRunError
from fracid.inverse.studies.model_fit import Candidate, ModelFit, fit_model, run_to_end
from fracid.models import ConvergenceError

__all__ = ["CrossCalibration", "ModelComparison", "compare_models", "cross_calibration"]


@dataclass
class ModelComparison:
    """Models fitted to the same data (:func:`compare_models`)."""

    data: ExperimentalData
    fits: list
    failures: dict = field(default_factory=dict)  # label -> why the fit failed (the other fits are kept)

    def rows(self) -> list[dict]:
        """:meth:`ModelFit.row` of every model, with the data's peak force (``peak_force_data_N``)."""
        peak = float(np.max(np.abs(self.data.y)))
        return [{**fit.row(), "peak_force_data_N": peak} for fit in self.fits]

    def fit(self, label: str) -> ModelFit:
        """The fit of the model labelled ``label``."""
        for fit in self.fits:
            if fit.label == label:
                return fit
        raise KeyError(f"no model labelled {label!r}; labels: {[f.label for f in self.fits]}")


@dataclass
class CrossCalibration:
    """Model B fitted to a curve of model A (:func:`cross_calibration`).

    Attributes
    ----------
    source_label : str
    source_params : parameter object
        Parameters of the source model A.
    source_control, source_force : ndarray
        The source run from 0 to the last control point [mm], [N].
    source_energy : float
        Energy dissipated by the source run up to the last control point [N mm].
    data : ExperimentalData
        The source force sampled at the control points, with the stated (noise-free) covariance.
    fit : ModelFit
        The target model B fitted to ``data``.
    """

    source_label: str
    source_params: object
    source_control: np.ndarray
    source_force: np.ndarray
    source_energy: float
    data: ExperimentalData
    fit: ModelFit

    @property
    def source_peak_force(self) -> float:
        return float(np.max(self.source_force))

    @property
    def energy_ratio(self) -> float:
        """Dissipated energy of the fitted model B over that of the source A [-], both to the last point."""
        return self.fit.dissipated_energy / self.source_energy


def compare_models(data: ExperimentalData, specimen, candidates, *, control="cmod", steps=None, log=None,
                   **settings) -> ModelComparison:
    """Fit every candidate model to the same data; a table of parameters, fit error and energies.

    Parameters
    ----------
    data : ExperimentalData
        Force data [N] at control values [mm] (e.g. ``fracid.datasets.load("gregoire2013-beam4")``).
    specimen : object
        The specimen of the data (candidates may carry their own, e.g. another mesh).
    candidates : sequence of Candidate or of tuples
        ``(label, model, base_params, names, space[, specimen[, settings]])``.
    control : str
        Control quantity of the data.
    steps : StepOptions, optional
        Step rule of every forward run (see :func:`fit_model`).
    log : callable, optional
        Called with a line of text before and after each fit (progress of a long comparison).
    **settings
        Shared settings of :func:`~fracid.inverse.methods.strategy.identify_data`.

    Returns
    -------
    ModelComparison
        One :class:`ModelFit` per candidate that could be fitted, in order; :meth:`ModelComparison.rows`
        gives the table: fitted parameters +- std, relative RMS fit error, peak force, dissipated
        energy to the last data control value [N mm], number of forward runs. A candidate whose fit
        stops on a failed forward run (e.g. at the local fit's estimate) is recorded in
        ``failures`` with the reason, and the comparison goes on.
    """
    fits, failures = [], {}
    candidates = [c if isinstance(c, Candidate) else Candidate(*c) for c in candidates]
    for i, candidate in enumerate(candidates, start=1):
        if log is not None:
            log(f"[{i}/{len(candidates)}] fitting {candidate.label} ({candidate.model.key}): "
                f"{', '.join(candidate.names)}")
        try:
            fit = fit_model(data, candidate, specimen, control=control, steps=steps, **settings)
        except (ForwardRunError, ConvergenceError) as err:
            failures[candidate.label] = f"{type(err).__name__}: {err}"
            if log is not None:
                log(f"[{i}/{len(candidates)}] {candidate.label}: failed ({failures[candidate.label]})")
            continue
        if log is not None:
            log(f"[{i}/{len(candidates)}] {candidate.label}: " + _fit_line(fit))
        fits.append(fit)
    return ModelComparison(data=data, fits=fits, failures=failures)


def _fit_line(fit: ModelFit) -> str:
    units = fit.units
    values = ", ".join(f"{n} = {v:.4g} +- {s:.2g} {units.get(n, '')}".rstrip()
                       for n, v, s in zip(fit.names, fit.x, fit.std))
    return (f"{values}; RMS {100 * fit.rms_relative:.2f} % of the peak; peak {fit.peak_force:.4g} N; "
            f"dissipated {fit.dissipated_energy:.4g} N mm; {fit.forward_runs} runs, {fit.seconds:.0f} s")


def cross_calibration(source_model, source_params, target_model, target_base, target_names, space: ParameterSpace,
                      specimen, cmod_points, *, target_specimen=None, relative_std=0.065, control="cmod", steps=None,
                      source_label=None, target_label=None, log=None, **settings) -> CrossCalibration:
    """Calibrate a target model B on the curve of a source model A.

    Model A runs with ``source_params`` on ``specimen`` to the last of ``cmod_points``; its force at
    those points is the data (no noise added), with the standard deviation ``relative_std`` times
    its peak force at every point. Model B is identified on these data over ``target_names``
    within ``space`` (the other parameters from ``target_base``), then run at its estimate.

    Parameters
    ----------
    source_model, target_model : ForwardModel
    source_params : parameter object
        All parameters of the source model (an instance of ``source_model.parameters``).
    target_base : parameter object
        Fixed parameters of the target model (an instance of ``target_model.parameters``).
    target_names : sequence of str
        Identified parameters of the target model.
    space : ParameterSpace
        Bounds of the identification (and of its search) over ``target_names``.
    specimen : object
        The specimen (and mesh) of the source run; the target's too unless ``target_specimen``.
    cmod_points : array_like
        Increasing control values of the data [mm].
    target_specimen : object, optional
        The target model's specimen (e.g. another mesh).
    relative_std : float
        Standard deviation of the data as a fraction of the source's peak force [-]: the weight
        of the data against the search's prior in the local fit. A mismatch of models is not noise,
        and a small std makes the filter's undamped steps overshoot: fitting gradient damage to
        the cohesive curve of the Gregoire beam (24 points, 4 mm mesh), 3 % left the bounds where
        6.5 % (the default; about the scatter of the measured curves of that beam past the peak)
        settled. The covariance of the estimate is to be read as its sensitivity to the data, not
        as an error bar.
    control : str
        Control quantity (``"cmod"`` for the notched beam).
    steps : StepOptions, optional
        Step rule of every forward run, the source's included (see :func:`fit_model`).
    source_label, target_label : str, optional
        Labels (default: the models' keys).
    log : callable, optional
        Called with a line of text at each stage.
    **settings
        Passed to :func:`~fracid.inverse.methods.strategy.identify_data` (``n``, ``k``, ``groups``,
        ``executor``, ``store``, ``progress``, ...).

    Returns
    -------
    CrossCalibration
        With the target's estimate and covariance (``fit.identification``), ``fit.std``, the fit
        error ``fit.rms_relative`` (RMS of the force residual / the source's peak force) and the
        dissipated energies of both runs to the last point (``source_energy``,
        ``fit.dissipated_energy``) [N mm].

    Raises
    ------
    RuntimeError
        If the source run does not reach the last control point.
    """
    source_label = source_label or source_model.key
    target_label = target_label or target_model.key
    points = np.asarray(cmod_points, float)
    if log is not None:
        log(f"source: {source_label} to {control} = {points[-1]:g} mm")
    run, energy = _source_run(source_model, specimen, source_params, points, source_label, control, steps)
    data = _source_data(points, run, source_label, source_params, relative_std, control)
    candidate = Candidate(target_label, target_model, target_base, target_names, space, target_specimen)
    if log is not None:
        log(f"target: fitting {target_label} ({', '.join(candidate.names)})")
    fit = fit_model(data, candidate, specimen, control=control, steps=steps, **settings)
    if log is not None:
        log(f"target: {target_label}: {_fit_line(fit)}; source dissipated {energy:.4g} N mm")
    return CrossCalibration(source_label=source_label, source_params=source_params,
                            source_control=np.asarray(run.control, float), source_force=np.asarray(run.force, float),
                            source_energy=energy, data=data, fit=fit)


def _source_run(model, specimen, params, points, label, control, steps):
    """The source run to the last of ``points`` and the energy it dissipated there [N mm].

    Raises
    ------
    RuntimeError
        If the run stops before the last point: the data would end early.
    """
    run, energy = run_to_end(model, specimen, params, points, control=control, steps=steps)
    if not np.isfinite(energy):
        raise RuntimeError(f"the source run ({label}, {params}) stopped at {control} = "
                           f"{run.control[-1]:.6g} mm, before the last point {points[-1]:.6g} mm")
    return run, energy


def _source_data(points, run, label, params, relative_std, control) -> ExperimentalData:
    """The source run's force at ``points`` as one block of data, no noise added, with the standard deviation
    ``relative_std`` times its peak at every point."""
    y = np.interp(points, run.control, run.force)
    std = relative_std * float(np.max(np.abs(y)))
    notes = (f"cross-calibration data: force of {label} at {params}, {points.size} {control} points "
             f"from {points[0]:g} to {points[-1]:g} mm, no noise added; std {std:.4g} N "
             f"({relative_std:g} of its peak) at every point",)
    return ExperimentalData(points, y, Diagonal(np.full(points.size, std**2)), (("global", 0, points.size),), notes)
