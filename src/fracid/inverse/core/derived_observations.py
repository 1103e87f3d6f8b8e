"""Observation kinds of local data derived from a displacement field: the model side of :mod:`fracid.data.dic.derived`.

:class:`DerivedFieldObservation` wraps a :class:`~fracid.inverse.core.field_observations.FieldObservation` of the
crack's normal displacement u_n at the DIC points (its sparse probe matrix, applied by the run at the
frames) and applies to the model's u_n the estimator the data went through (:class:`~fracid.data.dic.estimators.
Extensometers`: the crack-opening profile; :class:`~fracid.data.dic.estimators.StrainTransects`: the
process-zone width), with the points present at each frame: data and model are processed identically.
Sensitivities follow by the chain rule, S_k = J_k dU_k, from the run's exact derivatives of the probed
displacements dU_k at frame k and the estimator's Jacobian J_k (the estimate's weights for the opening).

On a symmetric half model, DIC points on the other side of the crack line (data covering the whole face)
are sampled at their mirror image in the modelled half, u_n changing sign (u_n(-d) = -u_n(+d)).

Use (``tests/test_dic_derived.py``)::

    field = field_block(dic, std=1e-3, subset_size=6.0)              # the DIC field, its covariance
    block = opening_profile(field, beam, [27.5, 32, 37, 42], 6.0, radius=5.0)
    operator = ForwardOperator([derived_observation(block, beam, control="cmod")], base, names)
    # block.data: y, covariance W C W^T, control; operator(x): the model's profile, exact S when differentiated
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fracid.inverse.core.field_observations import FieldObservation, check_points
from fracid.inverse.core.observations import check_control_points


def _present(present, shape: tuple) -> np.ndarray:
    """``present`` as a read-only boolean (n_frames, n_points) array (all True if None), or a ValueError."""
    if present is None:
        mask = np.ones(shape, dtype=bool)
    else:
        mask = np.array(present)
        if mask.dtype != bool or mask.shape != shape:
            raise ValueError(f"present has dtype {mask.dtype} and shape {mask.shape}; give booleans of shape {shape} "
                             "(frames, points), True where the data have u_n")
    mask.setflags(write=False)
    return mask


@dataclass(frozen=True, eq=False)
class DerivedFieldObservation:
    """Local data derived from the model's displacement field at the DIC points, at the frames.

    Parameters
    ----------
    specimen
        The plane specimen (its crack line is the estimator's).
    points : array_like, shape (n_points, 2)
        The DIC points [mm] the estimator reads (specimen frame; on the other side of a symmetry line they
        are sampled at their mirror image).
    frames : array_like
        Increasing control values of the frames [mm].
    estimator : fracid.data.dic.estimators.Extensometers or StrainTransects
        ``evaluate(points, present, u_n) -> (values (m,), d values / d u_n (m, n_points))``, ``size`` (m),
        ``line`` (a :class:`~fracid.specimens.crack_line.CrackLine`), ``coordinates()`` and ``key()``.
    present : array_like of bool, shape (n_frames, n_points), optional
        The points the data had at each frame (the estimator uses these only); None: all.
    control : str or None
        The specimen's control quantity (its default if None).
    name : str
        Label of the block (and of its probes in the run).

    Notes
    -----
    A block of n_frames x m values (frame slowest). The run applies :meth:`probe_matrix` (the wrapped field
    observation's, u_n at the points) at the frames; :meth:`sample` applies the estimator frame by frame.
    """

    specimen: object
    points: np.ndarray
    frames: np.ndarray
    estimator: object
    present: np.ndarray | None = None
    control: str | None = None
    name: str = "derived"

    def __post_init__(self):
        points = check_points(self.points)
        frames = check_control_points(self.frames, "frames")
        line = self.estimator.line  # points on the other side of a symmetry line: mirrored by the field
        field = FieldObservation(self.specimen, points, frames, (line.normal,), control=self.control, name=self.name)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "frames", frames)
        object.__setattr__(self, "present", _present(self.present, (frames.size, len(points))))
        object.__setattr__(self, "field", field)

    def probe_matrix(self) -> sp.csr_matrix:
        """The wrapped field observation's: u_n at the (mirrored) points, one row per point [mm]."""
        return self.field.probe_matrix()

    quantity = property(lambda self: self.name)  # what the block measures, as a curve kind's ``quantity``
    measures_force = False  # lengths [mm]

    @property
    def run_key(self) -> tuple:
        return self.field.run_key

    @property
    def size(self) -> int:
        return int(self.frames.size * self.estimator.size)

    @property
    def controls(self) -> np.ndarray:
        return np.repeat(self.frames, self.estimator.size)

    control_points = controls  # the control value of every entry, as a curve kind's

    @property
    def observables(self) -> tuple:
        return ()

    @property
    def probes(self) -> dict:
        return {}  # the run applies probe_matrix() at the frames

    def coordinates(self) -> dict:
        m = self.estimator.size
        own = {name: np.tile(values, self.frames.size) for name, values in self.estimator.coordinates().items()}
        return {"control": self.controls, "frame": np.repeat(np.arange(self.frames.size), m), **own}

    def differentiable_with(self, model) -> bool:
        return True  # functions of the displacements

    def key(self) -> dict:
        return {"kind": "derived-field", **self.field.key(), **self.estimator.key(),
                "points": self.points.tolist(), "present": np.flatnonzero(~self.present).tolist()}

    def sample(self, run) -> tuple:
        """``(y, S)``: the estimator applied to the model's u_n at every frame, S = J_k dU_k; NaN for frames
        not reached."""
        values, derivatives = self.field.sample(run)
        n_frames, n_points = self.present.shape
        u = values.reshape(n_frames, n_points)
        du = None if derivatives is None else derivatives.reshape(n_frames, n_points, -1)
        y, S = [], []
        for k in range(n_frames):
            y_k, J_k = self.estimator.evaluate(self.points, self.present[k], u[k])
            y.append(y_k)
            if du is not None:
                S.append(J_k @ np.where(self.present[k][:, None], du[k], 0.0))
        return np.concatenate(y), (None if du is None else np.concatenate(S))


def derived_observation(block, specimen, *, control: str | None = None, name: str | None = None
                        ) -> DerivedFieldObservation:
    """The :class:`DerivedFieldObservation` of a derived data block (:func:`fracid.data.dic.derived.opening_profile`,
    :func:`~fracid.data.dic.derived.process_zone_width`: its points, frames, estimator and points present)."""
    return DerivedFieldObservation(specimen, block.points, block.frames, block.estimator, present=block.present,
                                   control=control, name=block.data.blocks[0][0] if name is None else name)


__all__ = ["DerivedFieldObservation", "derived_observation"]
