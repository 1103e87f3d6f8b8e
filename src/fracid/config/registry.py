"""The model and specimen types a configuration may name.

The model types are read from :data:`fracid.models.MODEL_TYPES` at each call (a model registered
there needs no change here); the specimen classes are imported from :mod:`fracid.specimens` when
first asked for.
"""

from __future__ import annotations


def _model_types() -> tuple:
    """The ``[model] type`` names: those of :data:`fracid.models.MODEL_TYPES` at the time of the call,
    so that a model registered there needs no change here."""
    from fracid.models import MODEL_TYPES

    return tuple(MODEL_TYPES)


def _model_of(kind: str):
    from fracid.models import model_from_type

    return model_from_type(kind)


def _specimen_class(kind: str):
    if kind == "notched-beam":
        from fracid.specimens.beam import NotchedBeam

        return NotchedBeam
    if kind == "dogbone":
        from fracid.specimens.dogbone import DogBone

        return DogBone
    from fracid.specimens.bar import BarWithWeakZone

    return BarWithWeakZone


#: specimen type -> (controls, the first being the default; local observables [mm])
_SPECIMENS = {
    "notched-beam": (("cmod", "deflection"), ("fpz_width",)),
    "dogbone": (("elongation", "platen_displacement"), ("fpz_width",)),
    "bar": (("end_displacement", "weak_zone_elongation"), ("damaged_zone_width",)),
}
