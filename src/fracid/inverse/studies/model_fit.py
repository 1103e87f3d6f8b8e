"""One forward model fitted to one data set: the candidate, its identification and its run at the estimate.

:func:`fit_model` identifies a :class:`Candidate` with :func:`fracid.inverse.methods.strategy.identify_data`
(the inverse method's stages) and then runs the model once more at its estimate, to the last
control value of the data (:func:`run_to_end`), to read the energy it dissipated
(``observables["dissipated_energy"]``: external work minus elastic energy, [N mm]) and its peak force
(:class:`ModelFit`). The studies that compare models are in :mod:`fracid.inverse.studies.cross_model`.

Units: control (CMOD) [mm], force [N], energy [N mm]; parameters in the units of their class.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from fracid.data import ExperimentalData
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.core.method import MethodResult
from fracid.inverse.methods.strategy import identify_data
from fracid.models import ConvergenceError

__all__ = ["Candidate", "ModelFit", "candidate_operator", "fit_model", "relative_rms", "run_to_end"]


@dataclass(frozen=True)
class Candidate:
    """A model to fit: its forward model, fixed parameters, identified names and search space.

    Parameters
    ----------
    label : str
        Name of the row in tables and figures.
    model : ForwardModel
        E.g. ``DamageModel("gradient")`` or ``CohesiveCrackModel()`` (:mod:`fracid.models`).
    base : parameter object
        Values of the parameters that are not identified (an instance of ``model.parameters``).
    names : sequence of str
        Identified parameters.
    space : ParameterSpace
        Bounds (and log flags) of the identification (and of its search) over ``names``.
    specimen : object, optional
        The specimen this model runs on (e.g. its own mesh); None: the one given to the caller.
    settings : dict, optional
        Settings of :func:`~fracid.inverse.methods.strategy.identify` for this candidate only (``n``, ``k``,
        ``groups``, ...), overriding the shared ones.
    """

    label: str
    model: object
    base: object
    names: tuple
    space: ParameterSpace
    specimen: object = None
    settings: dict = field(default_factory=dict)

    def __post_init__(self):
        object.__setattr__(self, "names", tuple(self.names))
        if tuple(self.space.names) != self.names:
            raise ValueError(f"candidate {self.label!r}: the space is over {tuple(self.space.names)} but the "
                             f"identified parameters are {self.names}")


@dataclass
class ModelFit:
    """One model fitted to one data set, and its run at the estimate.

    Attributes
    ----------
    label, model_key : str
        The candidate's label and the model's ``key``.
    identification : MethodResult
        Estimate ``x``, covariance ``C``, the fit ``y_fit`` at the data's points, runs, ...
    params : parameter object
        The full parameter set at the estimate.
    control, force : ndarray
        Curve of the run at the estimate from 0 to the last data control value [mm], [N].
    rms_relative : float
        RMS of ``y_fit - y`` over the data points divided by the data's largest ``|y|`` [-].
    peak_force : float
        Largest force of the run at the estimate [N].
    dissipated_energy : float
        Energy dissipated by the run at the estimate up to the last data control value [N mm]
        (NaN if that run stopped before it).
    forward_runs : int
        Forward runs of the identification, all its stages (the run at the estimate is not counted).
    seconds : float
        Wall time of the identification and of the run at the estimate [s].
    """

    label: str
    model_key: str
    identification: MethodResult
    params: object
    control: np.ndarray
    force: np.ndarray
    rms_relative: float
    peak_force: float
    dissipated_energy: float
    forward_runs: int
    seconds: float

    @property
    def names(self) -> list:
        return list(self.identification.names)

    @property
    def x(self) -> np.ndarray:
        """The estimate (units of the parameters)."""
        return np.asarray(self.identification.x, float)

    @property
    def std(self) -> np.ndarray:
        """Standard deviations of the estimate from the identification's covariance."""
        return np.asarray(self.identification.std, float)

    @property
    def units(self) -> dict:
        return dict(self.identification.units)

    def row(self) -> dict:
        """A plain dict for tables and JSON: ``label``, ``model``, ``parameters`` ({name: {value, std,
        unit}}), ``rms_percent``, ``peak_force_N``, ``dissipated_energy_Nmm``, ``forward_runs``,
        ``converged``, ``status`` (of the stage that gave the estimate), ``seconds``."""
        units = self.units
        return {
            "label": self.label, "model": self.model_key,
            "parameters": {n: {"value": float(v), "std": float(s), "unit": units.get(n, "")}
                           for n, v, s in zip(self.names, self.x, self.std)},
            "rms_percent": 100.0 * self.rms_relative, "peak_force_N": self.peak_force,
            "dissipated_energy_Nmm": self.dissipated_energy, "forward_runs": self.forward_runs,
            "converged": bool(self.identification.converged), "status": self.identification.status,
            "seconds": self.seconds,
        }


def relative_rms(y_fit, y) -> float:
    """RMS of ``y_fit - y`` divided by the largest ``|y|`` [-] (NaN entries of ``y_fit`` count as missing)."""
    y_fit, y = np.asarray(y_fit, float), np.asarray(y, float)
    both = np.isfinite(y_fit) & np.isfinite(y)
    if not both.any():
        return float("nan")
    return float(np.sqrt(np.mean((y_fit[both] - y[both]) ** 2)) / np.max(np.abs(y)))


def run_to_end(model, specimen, params, control_points, *, control="cmod", steps=None):
    """One run of ``model`` from 0 to the last of ``control_points``, landing on each of them.

    Parameters
    ----------
    model : ForwardModel
    specimen : object
    params : parameter object
    control_points : array_like
        Increasing control values [mm]; the run stops at the last one (no stop on the force).
    control : str
        The specimen's control quantity.
    steps : StepOptions, optional
        Step rule (the specimen's default if None).

    Returns
    -------
    run : PathResult
        The run (the partial run if it stopped on a ConvergenceError).
    dissipated_energy : float
        ``observables["dissipated_energy"]`` at the last control point [N mm]; NaN if not reached or
        if the model does not report it.
    """
    points = np.asarray(control_points, float)
    target = float(points[-1])
    try:
        run = model.simulate(specimen, params, control=control, target=target, stop_force_fraction=None,
                             steps=steps, field_steps=None, checkpoints=points)
    except ConvergenceError as err:
        run = err.partial
    reached = run.control.size > 0 and run.control[-1] >= target * (1.0 - 1e-9)
    dissipated = run.observables.get("dissipated_energy")
    energy = float(np.interp(target, run.control, dissipated)) if reached and dissipated is not None else float("nan")
    return run, energy


def candidate_operator(data: ExperimentalData, candidate: Candidate, specimen=None, *, control="cmod",
                       steps=None) -> ForwardOperator:
    """The forward operator of a candidate on force data: one force observation per data block, at its
    control values [mm], on ``candidate.specimen`` (or ``specimen`` when it has none), with the step rule
    ``steps`` (the specimen's default if None).

    Raises
    ------
    ValueError
        When neither the candidate nor the call gives a specimen.
    """
    specimen = candidate.specimen if candidate.specimen is not None else specimen
    if specimen is None:
        raise ValueError(f"candidate {candidate.label!r} has no specimen and none was given")
    observations = [Observation(specimen, data.control[a:b], quantity="force", control=control, name=name)
                    for name, a, b in data.blocks]
    return ForwardOperator(observations, candidate.base, candidate.names, model=candidate.model, steps=steps)


def fit_model(data: ExperimentalData, candidate: Candidate, specimen=None, *, control="cmod", steps=None,
              **settings) -> ModelFit:
    """Identify one candidate model on force data, then run it at the estimate.

    Parameters
    ----------
    data : ExperimentalData
        Force blocks [N] at control values [mm] of one specimen (every block is a force curve).
    candidate : Candidate
    specimen : object, optional
        Used when ``candidate.specimen`` is None.
    control : str
        Control quantity of the data (``"cmod"`` for the notched beam).
    steps : StepOptions, optional
        Step rule of every forward run (the specimen's default if None): the data's control
        values are landed on exactly whatever the rule, so a coarser rule than the default
        changes the computed points little and saves time.
    **settings
        Passed to :func:`~fracid.inverse.methods.strategy.identify_data` (``n``, ``k``, ``groups``,
        ``executor``, ``store``, ``progress``, ...); ``candidate.settings`` override them.

    Returns
    -------
    ModelFit
    """
    start = time.perf_counter()
    operator = candidate_operator(data, candidate, specimen, control=control, steps=steps)
    specimen = operator.observations[0].specimen
    result = identify_data(operator, data, candidate.space, **{**settings, **candidate.settings})
    params = operator.parameters(result.x)
    run, energy = run_to_end(candidate.model, specimen, params, data.control, control=control, steps=steps)
    return ModelFit(
        label=candidate.label, model_key=candidate.model.key, identification=result, params=params,
        control=np.asarray(run.control, float), force=np.asarray(run.force, float),
        rms_relative=relative_rms(result.y_fit, data.y), peak_force=float(np.max(run.force)),
        dissipated_energy=energy, forward_runs=result.forward_runs,
        seconds=time.perf_counter() - start,
    )
