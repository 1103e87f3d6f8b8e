"""The model types a configuration names (``[model] type``) and their laws (``[model] law``).

:data:`MODEL_TYPES` is the registry: one line per model, a name and a factory of its default instance. A model
registered there (from a test file too) is offered by ``fracid init``, read and checked by the configuration
and ranked by ``fracid compare``: what they need they ask the model (:class:`~fracid.models.protocol.ForwardModel`).
"""

from __future__ import annotations

from dataclasses import replace

from fracid.models.crack import CohesiveCrackModel, CrackBandModel
from fracid.models.damage import DamageModel
from fracid.models.phase_field import PhaseFieldModel
from fracid.models.protocol import declared

# ``[model] type`` of a configuration -> the forward model (one line per model)
MODEL_TYPES = {
    "gradient-damage": lambda: DamageModel("gradient"),
    "local-damage": lambda: DamageModel("local"),
    "integral-damage": lambda: DamageModel("integral"),
    "cohesive-crack": lambda: CohesiveCrackModel(),
    "crack-band": lambda: CrackBandModel(),
    "pf-czm": lambda: PhaseFieldModel(),
}
#: the ``[model] type`` of a configuration that gives none (the thesis's model)
DEFAULT_MODEL_TYPE = "gradient-damage"


def model_laws(model) -> dict:
    """The laws a configuration may give ``model`` by name (``[model] law``): those it declares (its ``laws``:
    the damage laws, the traction-separation laws, the PF-CZM's softening shapes; none for a model of its own
    that declares none)."""
    return dict(declared(model).laws)


def model_from_type(name: str, law: str | None = None):
    """The forward model named ``name`` in a configuration's ``[model] type`` (see :data:`MODEL_TYPES`), with
    the law named ``law`` among its :func:`model_laws` (None: its default law)."""
    try:
        model = MODEL_TYPES[name]()
    except KeyError:
        raise ValueError(f"model type = {name!r}; choose one of {sorted(MODEL_TYPES)}") from None
    if law is None:
        return model
    laws = model_laws(model)
    if law not in laws:
        allowed = ", ".join(map(repr, laws)) or "none: its law is fixed"
        raise ValueError(f"law = {law!r} for model type {name!r}; choose one of {allowed}")
    return replace(model, law=laws[law]())


def parameter_classes() -> list:
    """The parameter classes of the registered models' default instances, in the order of :data:`MODEL_TYPES`."""
    return [declared(make()).parameters for make in MODEL_TYPES.values()]


def known_units() -> dict:
    """Unit of every parameter name of the registered models (:data:`MODEL_TYPES`), those of the
    damage model first where two models share a name."""
    units = {}
    for cls in parameter_classes():
        for name, unit in cls.units().items():
            units.setdefault(name, unit)
    return units


def parameter_units(model) -> dict:
    """Units of a forward model's parameters (of its declared parameter class): name -> unit."""
    return dict(declared(model).parameters.units())
