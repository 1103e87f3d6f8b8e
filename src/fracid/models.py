"""The forward models the inverse code sees: one small interface, so a new model touches no inverse code.

A forward model is any object with

``key`` : str
    Names the model (and its variant) in run-store keys: runs of different models never share a key.
``parameters`` : type
    Its parameter class: ``names()``, ``units()``, ``valid_bounds(names)`` as class methods and
    ``replace(**changes)`` on instances, returning a validated copy (ValueError for bad values).
``simulate(specimen, params, *, control, target, stop_force_fraction, steps, field_steps, checkpoints,
damage_threshold, observables)``
    One forward run, returning an object with ``control`` [mm], ``force`` [N] and ``observables``
    (dict of arrays, e.g. ``fpz_width`` [mm]) along the path, raising
    :class:`~fracid.model.path_following.ConvergenceError` (with ``.partial``) when it cannot go on.

:class:`DamageModel` wraps the implicit gradient-enhanced damage model, its local variant and the
integral-type nonlocal model.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Protocol

from fracid.model.parameters import DamageParameters


class ForwardModel(Protocol):
    key: str
    parameters: type

    def simulate(self, specimen, params, **options): ...


def runs_on(model, specimen) -> bool:
    """Whether ``model`` can run on ``specimen`` (an instance or its class): the specimen offers the
    builder the model names in ``specimen_builder`` (models without one run on every specimen)."""
    builder = getattr(model, "specimen_builder", None)
    return builder is None or hasattr(specimen, builder)


@dataclass(frozen=True)
class DamageModel:
    """Continuum damage with exponential softening (SPEC 1): ``"gradient"`` (implicit gradient
    enhancement), ``"local"`` (no regularisation; mesh-dependent, for comparison) or ``"integral"``
    (Gaussian average of the equivalent strain, internal length l = sqrt(2 c): same parameters as
    the gradient model)."""

    regularization: str = "gradient"
    parameters: ClassVar[type] = DamageParameters

    def __post_init__(self):
        if self.regularization not in ("gradient", "local", "integral"):
            raise ValueError(f"regularization = {self.regularization!r}; choose 'gradient', 'local' or 'integral'")

    @property
    def key(self) -> str:
        return f"{self.regularization}-damage"

    def simulate(self, specimen, params, **options):
        from fracid.forward import simulate

        return simulate(specimen, params, regularization=self.regularization, **options)


class _HordijkModel:
    """Models whose parameters are those of Hordijk's law and an elastic bulk."""

    @property
    def parameters(self):
        from fracid.model.cohesive import CohesiveParameters

        return CohesiveParameters


@dataclass(frozen=True)
class CohesiveCrackModel(_HordijkModel):
    """Discrete cohesive crack with Hordijk's law along the ligament, elastic bulk (SPEC 5).

    Specimens must offer ``build_cohesive_problem(params)`` (the notched beam does). Observable:
    ``crack_length`` [mm], the length of the ligament whose faces have separated.
    """

    penalty_factor: float = 1000.0
    key: ClassVar[str] = "cohesive-crack-hordijk"
    specimen_builder: ClassVar[str] = "build_cohesive_problem"

    def simulate(self, specimen, params, **options):
        if not runs_on(self, specimen):
            raise TypeError(f"{type(specimen).__name__} has no cohesive crack (build_cohesive_problem)")
        problem = specimen.build_cohesive_problem(params, self.penalty_factor)
        observers = {"crack_length": lambda problem, q, arrays: problem.cracked_length(arrays.kappa)}
        return _follow(problem, specimen, params, observers, **options)


@dataclass(frozen=True)
class CrackBandModel(_HordijkModel):
    """Smeared crack band: a rotating crack with Hordijk's law scaled by the band width (SPEC 5).

    Same parameters as the cohesive crack (:class:`~fracid.model.cohesive.CohesiveParameters`), so the
    two are directly comparable. Specimens must offer ``build_crack_band_problem(params)`` (the notched
    beam and the tension strip do).
    """

    key: ClassVar[str] = "crack-band-hordijk"
    specimen_builder: ClassVar[str] = "build_crack_band_problem"

    def simulate(self, specimen, params, **options):
        if not runs_on(self, specimen):
            raise TypeError(f"{type(specimen).__name__} has no crack band model (build_crack_band_problem)")
        return _follow(specimen.build_crack_band_problem(params), specimen, params, {}, **options)


def _follow(problem, specimen, params, observers, *, control=None, target=None, stop_force_fraction=0.1,
            steps=None, damage_threshold=0.0, observables=None, **options):
    """Path following of a specimen's problem with the specimen's default control, target and steps
    (``damage_threshold`` concerns the damage models' FPZ width only)."""
    from fracid.forward import select_observers
    from fracid.model.path_following import StepOptions, follow_path

    target = target if target is not None else specimen.default_target(params)
    if steps is None:
        steps = specimen.default_steps(target) if hasattr(specimen, "default_steps") else StepOptions()
    return follow_path(problem, control or specimen.default_control, target, steps=steps,
                       stop_force_fraction=stop_force_fraction,
                       observers=select_observers(observers, observables), **options)


def parameter_units(model_or_params) -> dict:
    """Units of a model's parameters (from its parameter class or a parameter object)."""
    cls = getattr(model_or_params, "parameters", None) or type(model_or_params)
    return dict(cls.units())


# ``[model] type`` of a configuration -> the forward model (one line per model)
MODEL_TYPES = {
    "gradient-damage": lambda: DamageModel("gradient"),
    "local-damage": lambda: DamageModel("local"),
    "integral-damage": lambda: DamageModel("integral"),
    "cohesive-crack": lambda: CohesiveCrackModel(),
    "crack-band": lambda: CrackBandModel(),
}


def model_from_type(name: str):
    """The forward model named ``name`` in a configuration's ``[model] type`` (see :data:`MODEL_TYPES`)."""
    try:
        return MODEL_TYPES[name]()
    except KeyError:
        raise ValueError(f"model type = {name!r}; choose one of {sorted(MODEL_TYPES)}") from None
