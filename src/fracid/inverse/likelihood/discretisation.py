"""The mesh's discretisation error of the computed values, by Richardson extrapolation at the estimate.

With a mesh of element size h the computed value is y_h = y + C h^p (y the mesh-converged value, p the order of
convergence). Runs at the estimate on the identification's mesh (h) and on a refined one (h / r) give the error
of y_h,

    e = y_h - y = (y_h - y_h/r) r^p / (r^p - 1),

per output (:func:`richardson_error`). The order p is observed per data block from a third, coarser mesh
(h r): p = log(``|y_hr - y_h|`` / ``|y_h - y_h/r|``) / log r in RMS norms over the block (:func:`observed_order`),
clipped to :data:`ORDER_RANGE` (a pre-asymptotic sequence gives a low order: the clip keeps the error bounded,
a lower order is the conservative side); where the changes are at round-off level the order is not observable
and the stated nominal order is used (1 by default: e twice the change, conservative for the quadratic
elements' 2 or more). The error term's covariance is correlated along each curve
(:func:`~fracid.inverse.likelihood.correlation.block_modes`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.core.sensitivity import ForwardRunError
from fracid.specimens.protocol import refined

#: an observed order of convergence is clipped to this range [-]
ORDER_RANGE = (0.5, 4.0)
#: changes between meshes below this share of the block's largest |y| are round-off: the order is not observable
ROUND_OFF = 1e-9


def richardson_error(y_h, y_fine, ratio: float, order: float) -> np.ndarray:
    """e = y_h - y (the error of the values on the mesh h) = (y_h - y_fine) r^p / (r^p - 1).

    Parameters
    ----------
    y_h, y_fine : array_like
        Values on the mesh h and on the mesh h / ``ratio`` [units of y].
    ratio : float
        r = h / h_fine (> 1).
    order : float
        p, the order of convergence (> 0).
    """
    gain = ratio**order / (ratio**order - 1.0)
    return (np.asarray(y_h, float) - np.asarray(y_fine, float)) * gain


def observed_order(y_coarse, y_h, y_fine, ratio: float) -> float | None:
    """The order of convergence of three meshes (h r, h, h / r), from the RMS changes, clipped to
    :data:`ORDER_RANGE`; None when not observable (a change at round-off level, or not finite)."""
    y_coarse, y_h, y_fine = (np.asarray(v, float) for v in (y_coarse, y_h, y_fine))
    coarse, fine = (float(np.sqrt(np.mean(d**2))) for d in (y_coarse - y_h, y_h - y_fine))
    floor = ROUND_OFF * max(float(np.max(np.abs(y_h))), np.finfo(float).tiny)
    if not (np.isfinite(coarse) and np.isfinite(fine)) or min(coarse, fine) <= floor:
        return None
    return float(np.clip(np.log(coarse / fine) / np.log(ratio), *ORDER_RANGE))


def refined_operator(operator, factor: float):
    """The forward operator with every observation's specimen meshed ``factor`` times finer (< 1: coarser),
    through :func:`fracid.specimens.protocol.refined`.

    Raises
    ------
    ValueError
        For a specimen without a mesh size to refine, or an observation kind that is not a dataclass with a
        ``specimen`` field (it cannot be given another specimen).
    """
    kinds = []
    for kind in operator.observations:
        if not (dataclasses.is_dataclass(kind) and "specimen" in {f.name for f in dataclasses.fields(kind)}):
            raise ValueError(f"the observation kind {type(kind).__name__} has no specimen field to refine: the "
                             "discretisation error needs its observations on a refined mesh")
        kinds.append(dataclasses.replace(kind, specimen=refined(kind.specimen, factor)))
    return dataclasses.replace(operator, observations=tuple(kinds))


def element_ratio(operator, other) -> float:
    """h / h_other: the ratio of the element sizes of two operators' first specimens (their resolutions)."""
    def size(op):
        return float(op.observations[0].specimen.resolution().h)

    return size(operator) / size(other)


@dataclass
class DiscretisationTerm:
    """The discretisation error at an estimate.

    Attributes
    ----------
    error : ndarray, shape (n,)
        e = y_h - y per output [units of y]: what the identification's mesh adds to the converged value.
    orders : list of float
        The order used per block.
    observed : list of float or None
        The order observed per block (None: not asked, or not observable).
    ratio : float
        h / h_fine of the refined mesh.
    meshes : list of str
        The element sizes run, in words.
    computed : int
        Forward runs computed (the others loaded from the run store).
    """

    error: np.ndarray
    orders: list
    observed: list
    ratio: float
    meshes: list
    computed: int = 0


class _Runs:
    """The runs at the estimate on each mesh, through the run store (label "discretisation"), counted."""

    def __init__(self, x, store, executor, retry_failed):
        self.x, self.store, self.executor, self.retry_failed = x, store, executor, retry_failed
        self.computed = 0

    def __call__(self, operator, what: str) -> np.ndarray:
        """The computed values at x on ``operator``'s mesh, or ForwardRunError naming the mesh (``what``)."""
        stored = StoredOperator(operator, self.store, study="discretisation", retry_failed=self.retry_failed)
        record = stored.evaluate_many([self.x], None, self.executor)[0]
        self.computed += stored.computed
        if not record.ok:
            raise ForwardRunError(f"the discretisation error needs a run at the estimate on {what}, which failed: "
                                  f"{record.error}")
        return np.asarray(record.y, float)


def discretisation_error(operator, x, settings, blocks, *, store=None, executor=None,
                         retry_failed=False) -> DiscretisationTerm:
    """Richardson's estimate of the discretisation error of the values at ``x`` (module docstring).

    Parameters
    ----------
    operator : ForwardOperator
        The identification's operator (its mesh is h).
    x : array_like
        The estimate.
    settings : DiscretisationError
    blocks : sequence of (name, start, stop)
        The data blocks: the order is observed per block.
    store, executor, retry_failed
        The run store (the runs are stored under the label "discretisation"), parallel execution, retry.

    Raises
    ------
    ForwardRunError
        When a run on one of the meshes fails; ValueError when a specimen has no mesh size to refine.
    """
    run = _Runs(np.asarray(x, float), store, executor, retry_failed)
    fine = refined_operator(operator, settings.refinement)
    ratio = element_ratio(operator, fine)
    y_h = run(operator, "the identification's mesh")
    y_fine = run(fine, f"the mesh refined {ratio:.3g} times")
    meshes = [_mesh_text(operator), _mesh_text(fine)]
    y_coarse = None
    if settings.observed_order:
        coarse = refined_operator(operator, 1.0 / settings.refinement)
        y_coarse = run(coarse, "the coarser mesh")
        meshes.insert(0, _mesh_text(coarse))
    error, orders, observed = np.zeros_like(y_h), [], []
    for _, start, stop in blocks:
        part = slice(start, stop)
        seen = None if y_coarse is None else observed_order(y_coarse[part], y_h[part], y_fine[part], ratio)
        order = settings.order if seen is None else seen
        error[part] = richardson_error(y_h[part], y_fine[part], ratio, order)
        orders.append(float(order))
        observed.append(seen)
    return DiscretisationTerm(error, orders, observed, ratio, meshes, run.computed)


def _mesh_text(operator) -> str:
    """The first specimen's element size in words (its resolution's text)."""
    return operator.observations[0].specimen.resolution().text


__all__ = ["ORDER_RANGE", "ROUND_OFF", "DiscretisationTerm", "discretisation_error", "element_ratio", "observed_order",
           "refined_operator", "richardson_error"]
