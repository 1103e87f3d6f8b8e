"""The KNN population on a screening mesh: a mesh ``screening`` times coarser ranks the population (each run costs
less), the local fit then runs on the configured mesh, so that the estimate is the configured mesh's (issue 39).

:func:`screened` gives the operator the population runs with and what the stage says about it: the screening
mesh (:func:`~fracid.inverse.likelihood.discretisation.refined_operator` with ``1 / screening``), or the
configured one, said once, where the specimen cannot be coarsened (a mesh file) or the screening mesh would leave
the model's internal length unresolved over more than :data:`RESOLVED_SHARE` of its range
(:class:`~fracid.models.protocol.MeshLength`, the length :mod:`fracid.config.mesh_bounds` checks the configured
mesh against).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.inverse.likelihood.discretisation import refined_operator
from fracid.models.protocol import declared

#: the screening mesh must resolve the internal length over at least this share of the identified range of its
#: parameter (in the population's scale, log where the space is): below it, most of the population would rank
#: mesh-dependent curves. Above it, the under-resolved part only ranks the start (the fit runs on the configured mesh)
RESOLVED_SHARE = 0.5


@dataclass(frozen=True)
class Screening:
    """The mesh a KNN population runs on.

    Attributes
    ----------
    operator : ForwardOperator
        The operator of the population's runs (the identification's own when ``factor`` is 1).
    factor : float
        h_population / h_configured (1: the configured mesh).
    text : str
        The population's mesh in words, for the stage line, the notes and the report
        (e.g. ``"on a screening mesh 2 times coarser (h_fine = 4 mm)"``).
    fallback : bool
        Whether a screening mesh was asked for but the configured one is used (``text`` says why).
    """

    operator: object
    factor: float
    text: str
    fallback: bool = False

    @property
    def coarse(self) -> bool:
        return self.factor > 1.0


def screened(operator, screening: float, space) -> Screening:
    """The :class:`Screening` of a population asked to run ``screening`` times coarser (>= 1) over ``space``.

    Never raises for a specimen or model that cannot be screened: the configured mesh then, with the reason.
    """
    if screening <= 1.0 or not hasattr(operator, "observations"):
        return Screening(operator, 1.0, "on the configured mesh")
    asked = f"[identify.knn] screening = {screening:g}"
    try:
        coarse = refined_operator(operator, 1.0 / screening)
    except ValueError as err:
        return _fallback(operator, f"{asked} cannot coarsen it: {err}")
    h, h_coarse = (_resolution(op) for op in (operator, coarse))
    unresolved, partly = _resolved(operator, space, h_coarse.h)
    if unresolved:
        return _fallback(operator, f"{asked} would mesh it with {_size(h_coarse)}, and {unresolved}")
    factor = h_coarse.h / h.h
    return Screening(coarse, factor, f"on a screening mesh {factor:.3g} times coarser ({_size(h_coarse)}, the "
                                     f"configured {h.h:.3g} mm; {asked}{partly}); the fit runs on the configured mesh")


def _fallback(operator, why: str) -> Screening:
    return Screening(operator, 1.0, f"on the configured mesh: {why}", fallback=True)


def _resolution(operator):
    return operator.observations[0].specimen.resolution()


def _size(resolution) -> str:
    field = resolution.field if resolution.field and resolution.field != "n_elements" else "element size"
    return f"{field} = {resolution.h:.3g} mm"


def _resolved(operator, space, h: float) -> tuple[str, str]:
    """How far a mesh of element size ``h`` [mm] resolves the model's internal length over its parameter's range:
    (why it resolves too little, more than 1 - :data:`RESOLVED_SHARE` of the range left out, or ""; the part it
    leaves out in words, or ""). Both "" for a model without an internal length."""
    length = declared(operator.model).mesh_length
    if length is None:
        return "", ""
    name, unit = length.parameter, length.unit
    if name not in space.names:
        value = float(getattr(operator.base, name))
        if length.length(value) >= h:
            return "", ""
        return f"{length.text} = {length.length(value):.3g} mm at {name} = {value:g} {unit} would not be resolved", ""
    i = list(space.names).index(name)
    unit_points = np.full((201, len(space.names)), 0.5)
    unit_points[:, i] = np.linspace(0.0, 1.0, 201)
    values = space.from_unit(unit_points)[:, i]
    resolved = np.array([length.length(float(v)) >= h for v in values])
    share = float(resolved.mean())
    if share < RESOLVED_SHARE:
        return (f"{length.text} would be resolved over {share:.0%} of the range of {name} [{space.lower[i]:g}, "
                f"{space.upper[i]:g}] {unit} only (at least {RESOLVED_SHARE:.0%} needed)"), ""
    if share == 1.0:
        return "", ""
    return "", (f"; {length.text} is not resolved there below {name} = {values[resolved].min():.3g} {unit} "
                f"({1.0 - share:.0%} of the range): those points only rank the start")


__all__ = ["RESOLVED_SHARE", "Screening", "screened"]
