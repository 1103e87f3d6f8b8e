"""A configuration's bounds fitted to its mesh (:func:`fit_to_mesh`): the range of the parameter that sets the
length a model's mesh must resolve (its :class:`~fracid.models.protocol.MeshLength`: c of gradient and integral
damage, l of the PF-CZM) cut to the values the specimen's elements resolve, or the model left out when none is.

``fracid compare`` gives every model bounds by one rule (:func:`fracid.cli.init.default_identification`), not
checked against the mesh as a configuration's own are when it is loaded (:mod:`fracid.config.loading`); a lower
bound the mesh cannot resolve lets the search and the posterior visit mesh-dependent results.

Units: element sizes and lengths in mm; the parameter in its own unit.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

from fracid.config.builders import build_specimen
from fracid.config.registry import model_of, model_parameters
from fracid.models.protocol import declared

__all__ = ["MeshFit", "fit_to_mesh", "smallest_resolved"]


class MeshFit(NamedTuple):
    """The outcome of :func:`fit_to_mesh`.

    Attributes
    ----------
    config : Config or None
        The configuration with its bounds cut to the mesh (itself when nothing changed); None: the model is left
        out (no value of its parameter is resolved).
    text : str or None
        What was changed or why the model is left out, in words (None when nothing was).
    """

    config: object
    text: str | None


def smallest_resolved(length, h: float, lower: float, upper: float, digits: int = 3) -> float | None:
    """The smallest value v in [lower, upper] with ``length(v) >= h`` (``length`` increasing), rounded up to
    ``digits`` significant digits; None when even ``length(upper) < h``.

    Examples
    --------
    >>> smallest_resolved(lambda c: (2.0 * c) ** 0.5, 5.0, 0.33, 30.0)   # l = sqrt(2 c) >= 5 mm: c >= 12.5 mm^2
    12.5
    >>> smallest_resolved(lambda c: (2.0 * c) ** 0.5, 5.0, 0.33, 3.0) is None
    True
    """
    if length(upper) < h:
        return None
    if length(lower) >= h:
        return float(lower)
    lo, hi = float(lower), float(upper)
    for _ in range(200):  # bisection to a relative 1e-12 of the span
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if length(mid) >= h else (mid, hi)
        if hi - lo <= 1e-12 * abs(hi):
            break
    rounded = float(f"{hi:.{digits}g}")
    while length(rounded) < h:  # rounding to fewer digits went below: one step of the last digit up
        rounded = float(f"{rounded * (1.0 + 10.0 ** (1 - digits)):.{digits}g}")
    return min(rounded, float(upper))


def _element_size(cfg) -> tuple[float, str]:
    """The largest element size where the crack runs over the calibration specimens [mm], and its words."""
    specimens = [build_specimen(cfg, exp) for exp in cfg.calibration] or [build_specimen(cfg)]
    resolutions = [s.resolution() for s in specimens]
    worst = max(resolutions, key=lambda r: r.h)
    return worst.h, worst.text


def fit_to_mesh(cfg) -> MeshFit:
    """``cfg`` with the bounds of its mesh-length parameter cut to the values its mesh resolves (module docstring).

    The element size is the largest over the calibration specimens (:meth:`~fracid.specimens.protocol.Specimen.
    resolution`). An identified parameter keeps [lower, upper] when its lower bound is resolved, gets its lower
    bound raised to the smallest resolved value (:func:`smallest_resolved`) when only part of the range is, and
    leaves the model out when not even the upper bound is; a parameter that is not identified leaves the model
    out when its value is not resolved. A model without a mesh length is kept as it is.
    """
    mesh_length = declared(model_of(cfg.model.type, cfg.model.law)).mesh_length
    if mesh_length is None:
        return MeshFit(cfg, None)
    h, words = _element_size(cfg)
    name, unit, identify = mesh_length.parameter, mesh_length.unit, cfg.identify
    what = f"{words} is larger than {mesh_length.text}"
    if name not in identify.parameters:
        value = getattr(model_parameters(cfg.model), name)
        if mesh_length.length(value) >= h:
            return MeshFit(cfg, None)
        return MeshFit(None, f"{what} = {mesh_length.length(value):.3g} mm at {name} = {value:g} {unit}, "
                             f"so {mesh_length.band} is not resolved")
    i = identify.parameters.index(name)
    lower, upper = identify.lower[i], identify.upper[i]
    cut = smallest_resolved(mesh_length.length, h, lower, upper)
    if cut is None:
        return MeshFit(None, f"{what} = {mesh_length.length(upper):.3g} mm even at the upper bound {name} = "
                             f"{upper:g} {unit}, so {mesh_length.band} is not resolved anywhere in "
                             f"[{lower:g}, {upper:g}]")
    if cut == lower:
        return MeshFit(cfg, None)
    bounds = replace(identify, lower=tuple(cut if j == i else v for j, v in enumerate(identify.lower)))
    return MeshFit(replace(cfg, identify=bounds),
                   f"{name} in [{lower:g}, {upper:g}] {unit} cut to [{cut:g}, {upper:g}]: {what} = "
                   f"{mesh_length.length(lower):.3g} mm at {name} = {lower:g} {unit}, so {mesh_length.band} is not "
                   f"resolved below {name} = {cut:g} {unit}")
