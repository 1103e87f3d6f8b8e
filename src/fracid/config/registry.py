"""The model and specimen types a configuration may name.

The model types are read from :data:`fracid.models.MODEL_TYPES` at each call, the specimen types and
their controls and observables from :data:`fracid.specimens.SPECIMENS`: a model or specimen registered
there needs no change here.
"""

from __future__ import annotations

from fracid.specimens import SPECIMENS


def _model_types() -> tuple:
    """The ``[model] type`` names: those of :data:`fracid.models.MODEL_TYPES` at the time of the call."""
    from fracid.models import MODEL_TYPES

    return tuple(MODEL_TYPES)


def _model_of(kind: str):
    from fracid.models import model_from_type

    return model_from_type(kind)


def _specimen_class(kind: str):
    if kind == "mesh":  # the user's own (fracid.config.mesh_section), not a built-in geometry
        from fracid.specimens.mesh import MeshSpecimen

        return MeshSpecimen
    return SPECIMENS[kind]


#: specimen type -> (controls, the first being the default; local observables [mm])
_SPECIMENS = {kind: (cls.controls, cls.observables) for kind, cls in SPECIMENS.items()}


def _specimen_observables(specimen) -> tuple:
    """The local observables of a validated ``[specimen]`` (a mesh's depend on its crack line)."""
    if specimen.type == "mesh":
        return _specimen_class("mesh")(**dict(specimen.options)).observables
    return _SPECIMENS[specimen.type][1]
