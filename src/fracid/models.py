"""The forward models the inverse code sees: one small interface, so a new model touches no inverse code.

A forward model is any object with

``key`` : str
    Names the model (and its variant) in run-store keys: runs of different models never share a key.
``parameters`` : type
    Its parameter class: ``names()``, ``units()``, ``valid_bounds(names)`` as class methods and
    ``replace(**changes)`` on instances, returning a validated copy (ValueError for bad values).
``simulate(specimen, params, *, control, target, stop_force_fraction, steps, field_steps, checkpoints,
damage_threshold)``
    One forward run, returning an object with ``control`` [mm], ``force`` [N] and ``observables``
    (dict of arrays, e.g. ``fpz_width`` [mm]) along the path, raising
    :class:`~fracid.model.path_following.ConvergenceError` (with ``.partial``) when it cannot go on.

:class:`DamageModel` wraps the implicit gradient-enhanced damage model and its local variant.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Protocol

from fracid.model.parameters import DamageParameters


class ForwardModel(Protocol):
    key: str
    parameters: type

    def simulate(self, specimen, params, **options): ...


@dataclass(frozen=True)
class DamageModel:
    """Continuum damage with exponential softening (SPEC 1): ``"gradient"`` (implicit gradient
    enhancement) or ``"local"`` (no regularisation; mesh-dependent, for comparison)."""

    regularization: str = "gradient"
    parameters: ClassVar[type] = DamageParameters

    def __post_init__(self):
        if self.regularization not in ("gradient", "local"):
            raise ValueError(f"regularization = {self.regularization!r}; choose 'gradient' or 'local'")

    @property
    def key(self) -> str:
        return f"{self.regularization}-damage"

    def simulate(self, specimen, params, **options):
        from fracid.forward import simulate

        return simulate(specimen, params, regularization=self.regularization, **options)


def parameter_units(model_or_params) -> dict:
    """Units of a model's parameters (from its parameter class or a parameter object)."""
    cls = getattr(model_or_params, "parameters", None) or type(model_or_params)
    return dict(cls.units())
