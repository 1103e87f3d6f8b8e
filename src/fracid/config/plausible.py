"""Plausibility of what ``[model.parameters]`` fixes: each value against its usual range (as the bounds of
``[identify.bounds]`` are, :func:`warn_implausible_parameters`), and the band a regularised model spreads its
crack over against the room its specimen leaves it (:func:`check_band_room`).

What each model and specimen declare is read through the registries: the model's
:class:`~fracid.models.protocol.BandWidth` (pi l of the PF-CZM, 2 pi sqrt(c) of gradient and integral damage, none
for local damage and the cracks) with its warning fraction and its reasons, and the specimen's
:meth:`~fracid.specimens.protocol.Specimen.band_room` (a bar's length, a beam's depth, a mesh's bounding box).
"""

from __future__ import annotations

from fracid.config.checker import Checker
from fracid.config.registry import model_of, model_parameters, specimen_class
from fracid.config.schema import ConfigError, ModelConfig, SpecimenConfig
from fracid.config.sections import specimen_variants
from fracid.models.protocol import declared

#: the verdicts of :func:`band_verdict`
REFUSE, WARN = "refuse", "warn"


def warn_implausible_parameters(ck: Checker, model: ModelConfig) -> None:
    """Warn about every value given in ``[model.parameters]`` far outside its usual range
    (:func:`fracid.models.implausible` of the model's parameter class), in the words of the bounds' refusal: a
    fixed value may be meant (a study of extremes), a bound that searches implausible values is refused."""
    from fracid.models import implausible, implausible_text

    cls = model_of(model.type, model.law).parameters
    for name, value in model.parameters:
        reason = implausible(name, value, parameters=cls)
        if reason is not None:
            ck.warn(f"model.parameters.{name} = {value:g} is {implausible_text(reason)}")


def band_verdict(fraction: float, warn: float) -> str | None:
    """:data:`REFUSE` when the band is wider than its room (``fraction`` = width / room > 1: it cannot form inside
    the specimen), :data:`WARN` above the model's ``warn`` fraction, else None."""
    if fraction > 1.0:
        return REFUSE
    return WARN if fraction > warn else None


def band_advice(band, room: float) -> str:
    """What to do about a band too wide for ``room`` [mm]: the parameter's values that fit, e.g. ``"lower l below
    31.8 mm (15.9 mm or less keeps the band within 50% of it) or use a larger specimen"``."""
    return (f"lower {band.parameter} below {band.value_for(room):.3g} {band.unit} ({band.value_for(band.warn * room):.3g}"
            f" {band.unit} or less keeps the band within {band.warn:.0%} of it) or use a larger specimen")


def _band_text(band, value: float, room, where: str) -> str:
    width = band.width(value)
    fraction = width / room.length
    share = f"{100.0 * fraction:.3g}% of" if fraction <= 1.0 else f"{fraction:.3g} times"
    return f"{band.text} = {width:.3g} mm is {share} the room of the specimen{where} for it, {room.text}"


def check_band_room(ck: Checker, model: ModelConfig, specimen: SpecimenConfig, experiments, identify) -> None:
    """Refuse a value of ``[model.parameters]`` whose band is wider than its specimen's room
    (:meth:`~fracid.specimens.protocol.Specimen.band_room`, of ``[specimen]`` and of every experiment's
    overrides): the band cannot form and the model breaks its promise. Warn above the model's fraction of the
    room (:class:`~fracid.models.protocol.BandWidth`), and when the upper bound of an identified parameter's
    band cannot form (the search then runs partly where the model fails)."""
    band = declared(model_of(model.type, model.law)).band_width
    if band is None:
        return
    name, unit = band.parameter, band.unit
    value = float(getattr(model_parameters(model), name))
    key = f"model.parameters.{name}"
    default = "" if name in dict(model.parameters) else " (default)"
    upper = None
    if identify is not None and name in identify.parameters:
        upper = identify.upper[identify.parameters.index(name)]
    cls = specimen_class(specimen.type)
    for prefix, options, _ in specimen_variants(specimen, experiments):
        room = cls(**options).band_room()
        where = f" ({specimen.type})" if prefix == "specimen" else f" of {prefix}"
        limit = room.limit
        if band_verdict(band.width(value) / limit.length, band.warn) == REFUSE:
            raise ConfigError(f"{ck.path}: {key} = {value:g} {unit}{default}: {_band_text(band, value, limit, where)}: "
                              f"the band cannot form inside it, and the model no longer gives {band.promise}; "
                              f"{band_advice(band, limit.length)}")
        if band_verdict(band.width(value) / room.length, band.warn) is not None:
            ck.warn(f"{key} = {value:g} {unit}{default}: {_band_text(band, value, room, where)}, more than the "
                    f"{band.warn:.0%} within which fracid counts on {band.promise} ({band.beyond}); "
                    f"{band_advice(band, room.length)}")
        if upper is not None and band_verdict(band.width(upper) / limit.length, band.warn) == REFUSE:
            ck.warn(f"identify.bounds.{name}: the upper bound {upper:g} {unit}: {_band_text(band, upper, limit, where)}:"
                    f" no band forms inside it there, and the model no longer gives {band.promise}; lower the upper "
                    f"bound below {band.value_for(limit.length):.3g} {unit}")
