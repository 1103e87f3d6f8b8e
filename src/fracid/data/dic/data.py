"""Displacement fields measured by digital image correlation (DIC), in the specimen frame.

A :class:`DicData` holds the reference points of the correlation (subset centres) and their displacements at
every frame, NaN where the correlation gave none (a hole, a point of low quality), with the load of each frame.
:meth:`DicData.values` flattens a selection in the order of
:class:`fracid.inverse.core.field_observations.FieldObservation`: frame slowest, then component, point fastest.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, field

import numpy as np

from fracid.data.arguments import numeric_array, shown
from fracid.data.dic.placement import planar_points
from fracid.data.errors import DataError, DataTypeError


def _readonly(array: np.ndarray) -> np.ndarray:
    array = np.array(array, dtype=float)
    array.setflags(write=False)
    return array


def _frame_numbers(frames) -> tuple[int, ...]:
    """``frames`` as a tuple of distinct ints."""
    try:
        numbers = tuple(operator.index(f) for f in frames)
    except TypeError:
        raise DataTypeError(f"frames must be integer frame numbers, got {shown(frames)}") from None
    if len(set(numbers)) != len(numbers):
        repeated = sorted({f for f in numbers if numbers.count(f) > 1})
        raise DataError(f"frames: frame numbers {repeated} appear more than once; each frame must be unique")
    return numbers


def _field(values, name: str, shape: tuple) -> np.ndarray:
    """A read-only float array of the given shape (NaN allowed, infinities not)."""
    array = numeric_array(values, name)
    if array.shape != shape:
        raise DataError(f"{name} must have shape {shape} (frames, points, components), got {array.shape}")
    if np.any(np.isinf(array)):
        raise DataError(f"{name} holds an infinite value; use NaN for a missing value")
    return _readonly(array)


@dataclass(frozen=True)
class DicData:
    """DIC displacements at fixed reference points over frames, in the specimen frame.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Reference coordinates of the points in the specimen frame [mm].
    frames : sequence of int
        Frame numbers (distinct).
    u : array_like, shape (n_frames, n, 2)
        Displacements (u_x, u_y) in the specimen frame [mm]; NaN for a missing value.
    std : array_like, shape (n_frames, n, 2), or None
        Standard deviation of each displacement [mm] if the files give one.
    load : dict of str -> array_like
        Load data over frames (e.g. ``"cmod_mm"`` [mm], ``"force_N"`` [N]), each of length n_frames.
    source : tuple of str
        The files read.
    notes : tuple of str
        What was done while reading (units converted, placement, points set missing for quality, ...).
    """

    points: np.ndarray
    frames: tuple
    u: np.ndarray
    std: np.ndarray | None = None
    load: dict = field(default_factory=dict)
    source: tuple = ()
    notes: tuple = ()

    def __post_init__(self):
        points = _readonly(planar_points(self.points, "points"))
        frames = _frame_numbers(self.frames)
        shape = (len(frames), len(points), 2)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "frames", frames)
        object.__setattr__(self, "u", _field(self.u, "u", shape))
        if self.std is not None:
            std = _field(self.std, "std", shape)
            if np.any(std < 0.0):
                raise DataError("std holds a negative value; a standard deviation is >= 0 (NaN if unknown)")
            object.__setattr__(self, "std", std)
        load = {}
        for name, values in dict(self.load).items():
            array = numeric_array(values, f"load[{name!r}]")
            if array.shape != (len(frames),):
                raise DataError(f"load[{name!r}] must have one value per frame ({len(frames)}), got shape "
                                f"{array.shape}")
            load[str(name)] = _readonly(array)
        object.__setattr__(self, "load", load)
        object.__setattr__(self, "source", tuple(str(s) for s in self.source))
        object.__setattr__(self, "notes", tuple(self.notes))

    @property
    def n_points(self) -> int:
        """Number of reference points."""
        return len(self.points)

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return len(self.frames)

    @property
    def missing(self) -> np.ndarray:
        """Boolean mask (n_frames, n, 2): True where a displacement is missing (NaN)."""
        return np.isnan(self.u)

    def _replace(self, **changes) -> DicData:
        values = {name: getattr(self, name) for name in
                  ("points", "frames", "u", "std", "load", "source", "notes")}
        values.update(changes)
        return DicData(**values)

    def frame_indices(self, frames) -> np.ndarray:
        """Positions in :attr:`frames` of the given frame numbers, else a DataError naming the unknown one."""
        position = {f: k for k, f in enumerate(self.frames)}
        wanted = _frame_numbers([frames] if isinstance(frames, int) else frames)
        unknown = [f for f in wanted if f not in position]
        if unknown:
            raise DataError(f"frames {unknown} are not in the data; its frames are {list(self.frames)}")
        return np.array([position[f] for f in wanted], dtype=int)

    def at_frames(self, frames) -> DicData:
        """The data at the given frame numbers (in that order)."""
        k = self.frame_indices(frames)
        return self._replace(
            frames=tuple(self.frames[i] for i in k), u=self.u[k],
            std=None if self.std is None else self.std[k],
            load={name: values[k] for name, values in self.load.items()})

    def region(self, keep) -> DicData:
        """The data at the points of a region of interest.

        Parameters
        ----------
        keep : array_like of bool, shape (n,), or callable
            A mask of the points to keep, or a function of the points (n, 2) [mm] returning it.
        """
        mask = keep(self.points.copy()) if callable(keep) else keep
        mask = np.asarray(mask)
        if mask.dtype != bool or mask.shape != (self.n_points,):
            raise DataError(f"region: the mask must be booleans of shape ({self.n_points},), one per point, got "
                            f"dtype {mask.dtype} and shape {mask.shape}")
        note = f"region of interest: {int(mask.sum())} of {self.n_points} points kept"
        return self._replace(points=self.points[mask], u=self.u[:, mask],
                             std=None if self.std is None else self.std[:, mask], notes=(*self.notes, note))

    def values(self, frame_indices=None, components=(0, 1)) -> tuple[np.ndarray, np.ndarray]:
        """Displacements flattened to 1-D, frame slowest, then component, point fastest (the order of
        :class:`fracid.inverse.core.field_observations.FieldObservation`), and the matching missing mask.

        Parameters
        ----------
        frame_indices : sequence of int or None
            Positions in :attr:`frames` (not frame numbers; see :meth:`frame_indices`); all if None.
        components : int or sequence of int
            0 (u_x), 1 (u_y) or both.

        Returns
        -------
        values : ndarray, shape (n_selected_frames * n_components * n_points,)
            Displacements [mm], NaN where missing.
        missing : ndarray of bool, same shape
        """
        k = np.arange(self.n_frames) if frame_indices is None else np.asarray(frame_indices)
        if k.dtype.kind not in "iu" or k.ndim != 1 or np.any((k < 0) | (k >= self.n_frames)):
            raise DataError(f"frame_indices must be positions 0..{self.n_frames - 1} of the frames, got "
                            f"{shown(frame_indices)}")
        comps = (components,) if isinstance(components, int) else tuple(components)
        if not comps or any(c not in (0, 1) for c in comps) or len(set(comps)) != len(comps):
            raise DataError(f"components must be 0 (u_x), 1 (u_y) or both, got {components!r}")
        flat = self.u[k][:, :, list(comps)].transpose(0, 2, 1).reshape(-1)
        return flat, np.isnan(flat)
