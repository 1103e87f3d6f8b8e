"""The model and specimen types a configuration may name.

The model types are read from :data:`fracid.models.MODEL_TYPES` at each call, the specimen types from
:data:`fracid.specimens.SPECIMENS` (each a :class:`~fracid.specimens.protocol.Specimen`, asked for its
controls, observables, limits and its ``[specimen]`` section): a model or specimen registered there,
from a test file too, needs no change here. A specimen that reads its own ``[specimen]`` table declares the
reader (its ``config_section``), which :mod:`fracid.config.sections` calls.
"""

from __future__ import annotations

from fracid.specimens import SPECIMENS


def model_types() -> tuple:
    """The ``[model] type`` names: those of :data:`fracid.models.MODEL_TYPES` at the time of the call."""
    from fracid.models import MODEL_TYPES

    return tuple(MODEL_TYPES)


def model_of(kind: str, law: str | None = None):
    """The forward model of ``[model] type`` with ``[model] law`` (:func:`fracid.models.model_from_type`)."""
    from fracid.models import model_from_type

    return model_from_type(kind, law)


def model_parameters(model):
    """The parameters of a validated ``[model]`` (a :class:`~fracid.config.schema.ModelConfig`): those given,
    the rest the class's defaults."""
    return model_of(model.type, model.law).parameters(**dict(model.parameters))


def specimen_types() -> tuple:
    """The ``[specimen] type`` names: those of :data:`fracid.specimens.SPECIMENS` at the time of the call."""
    return tuple(SPECIMENS)


def specimen_class(kind: str):
    """The specimen class registered as ``kind`` in :data:`fracid.specimens.SPECIMENS`."""
    try:
        return SPECIMENS[kind]
    except KeyError:
        raise ValueError(f"specimen type = {kind!r}; choose one of {', '.join(map(repr, SPECIMENS))}") from None


def parameter_range(model, identify, name: str, unit: str) -> tuple:
    """((smallest value, where), (largest value, where)) of the model's parameter ``name`` [``unit``] and the bounds
    of ``name`` when it is identified (``where`` in words, e.g. ``"c = 4 mm^2 (default)"``)."""
    value = getattr(model_parameters(model), name)
    values = [(value, f"{name} = {value:g} {unit}" + ("" if name in dict(model.parameters) else " (default)"))]
    if identify is not None and name in identify.parameters:
        i = identify.parameters.index(name)
        values += [(identify.lower[i], f"the lower bound {name} = {identify.lower[i]:g} {unit} of identify.bounds.{name}"),
                   (identify.upper[i], f"the upper bound {name} = {identify.upper[i]:g} {unit} of identify.bounds.{name}")]
    return min(values), max(values)


def _build(specimen):
    """The specimen object of a validated ``[specimen]`` (a :class:`~fracid.config.schema.SpecimenConfig`)."""
    return specimen_class(specimen.type)(**dict(specimen.options))


def specimen_observables(specimen) -> tuple:
    """The local observables of a validated ``[specimen]``, asked of the specimen (a mesh's depend on its crack line)."""
    return tuple(_build(specimen).observables)


#: specimen type -> (control names, the first the default; local observables [mm]) of the default instances
#: registered at import (not the mesh, which has none); the configuration asks the specimen itself, this map
#: is kept for the tests that import it
SPECIMEN_DEFAULTS = {kind: (tuple(instance.control_names), tuple(instance.observables)) for kind, cls in SPECIMENS.items()
              if (instance := cls.default_instance()) is not None}
