"""The data block of a DIC displacement field: y, covariance, control and the mask of the values the data have.

:func:`field_block` turns a :class:`~fracid.data.dic.data.DicData` (in the specimen frame, mm) into the
:class:`~fracid.data.dataset.ExperimentalData` of one field block and what the matching
:class:`~fracid.inverse.core.field_observations.FieldObservation` needs (its points, frames as control values,
components and ``keep`` mask). Entries are ordered frame slowest, then component, point fastest; the missing
ones (NaN: holes, low quality) are dropped from y and from the covariance, and flagged False in ``keep``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.data.arguments import real_number
from fracid.data.covariance import check_positive_std
from fracid.data.covariance_matrix import Covariance, Diagonal, block_diagonal
from fracid.data.dataset import ExperimentalData
from fracid.data.dic.data import DicData
from fracid.data.errors import DataError, DataTypeError
from fracid.settings.checks import show

#: the largest peak memory [B] the correlated-noise factor of a field block may take (estimated before it is built:
#: :func:`fracid.data.dic_noise.factor_estimate`); beyond, the block is refused with the advice to thin it
MAX_FACTOR_BYTES = 8e9
#: component names -> indices (0: u_x, 1: u_y)
COMPONENTS = {"u": 0, "v": 1}


@dataclass(frozen=True, eq=False)
class FieldBlock:
    """A field's data block and the geometry of its observation.

    Attributes
    ----------
    data : ExperimentalData
        One block: y the kept displacements [mm], their covariance [mm^2], the frame's control value of every
        entry [mm].
    points : ndarray (n_points, 2)
        The points used [mm] in the specimen frame (points with no kept value dropped).
    frames : ndarray (n_frames,)
        Control value of each frame [mm], strictly increasing.
    frame_numbers : tuple of int
        The frames' numbers in the data.
    components : tuple of int
        0 (u_x), 1 (u_y) or both.
    keep : ndarray of bool (n_frames * n_components * n_points,)
        True for the entries in ``data.y`` (the ``keep`` of the FieldObservation).
    """

    data: ExperimentalData
    points: np.ndarray
    frames: np.ndarray
    frame_numbers: tuple
    components: tuple
    keep: np.ndarray
    dropped_frames: tuple = ()  # the frame numbers without any valid value, left out (a warning note says so)



def component_indices(components) -> tuple[int, ...]:
    """``components`` ("u", "v", 0, 1 or a sequence of them) as distinct indices 0 (u_x) / 1 (u_y)."""
    values = [components] if isinstance(components, (str, int, np.integer)) else list(components)
    indices = [COMPONENTS.get(c, -1) if isinstance(c, str) else c for c in values]
    if not indices or len(set(indices)) != len(indices) or any(i not in (0, 1) for i in indices):
        raise DataError(f"components = {components!r}: give \"u\" (x), \"v\" (y) or both, e.g. [\"u\", \"v\"] "
                        "(or 0, 1)")
    return tuple(int(i) for i in indices)


def frame_controls(dic: DicData, frame_indices: np.ndarray, control: str) -> np.ndarray:
    """The control value [mm] of the selected frames: the load column ``control``, strictly increasing."""
    if control not in dic.load:
        raise DataError(f"control = {show(control)} is not a load column of the frame table; its columns are "
                        f"{sorted(dic.load)}")
    values = np.asarray(dic.load[control][frame_indices], dtype=float)
    if not np.all(np.isfinite(values)):
        raise DataError(f"control column {show(control)}: a selected frame has no value (NaN)")
    steps = np.diff(values)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0))
        numbers = [dic.frames[i] for i in frame_indices]
        raise DataError(f"control column {show(control)} must increase strictly over the frames used, but frame "
                        f"{numbers[k + 1]} ({values[k + 1]:.6g} mm) does not exceed frame {numbers[k]} "
                        f"({values[k]:.6g} mm)")
    return values


def entry_std(dic: DicData, frame_indices: np.ndarray, components: tuple, std) -> tuple[np.ndarray, str]:
    """The standard deviation [mm] of every entry (frame, component, point order) and a note on its origin:
    the declared ``std`` [mm], else the files' per-point sigma."""
    n = len(frame_indices) * len(components) * dic.n_points
    if std is not None:
        value = real_number(std, "std")
        check_positive_std(value, "std")
        return np.full(n, value), f"std {value:g} mm declared for every value"
    if dic.std is None:
        raise DataError("the DIC data have no per-point sigma: give std [mm] (the displacement error), or read "
                        "the files with the sigma column")
    sigma = dic.std[frame_indices][:, :, list(components)].transpose(0, 2, 1).reshape(-1)
    return sigma, "std: the per-point sigma of the files"


def field_covariance(points, sigma: np.ndarray, n_frames: int, components: tuple, subset_size,
                     rigid_std=None) -> tuple[Covariance, str]:
    """The covariance [mm^2] of all entries (frame, component, point order): diag(sigma^2), or with
    ``subset_size`` [mm] the spatially correlated model of :mod:`fracid.data.dic_noise` (a sparse correlation
    K per frame and component, scaled by sigma: C = D K D, D = diag(sigma); K factorised once for all of them);
    with ``rigid_std`` [mm] the rigid motion of every frame marginalised (:mod:`fracid.data.dic.rigid`: its
    prior's columns added to each frame's block, both components). ``sigma`` NaN (missing values) are set to 1:
    those entries are dropped."""
    sigma = np.where(np.isnan(sigma), 1.0, sigma)
    n_c = len(components)
    if subset_size is None:
        note, correlation = "independent errors (diagonal covariance)", None
    else:
        correlation, note = _correlation(points, subset_size)
    per_frame = sigma.reshape(n_frames, n_c, len(points))
    if rigid_std is None:
        if correlation is None:
            return Diagonal(sigma**2), note
        return block_diagonal([correlation.scaled(s) for s in per_frame.reshape(-1, len(points))]), note
    from fracid.data.dic.rigid import with_rigid_motion

    std = real_number(rigid_std, "rigid_std")
    check_positive_std(std, "rigid_std")
    bases = ([Diagonal(s.reshape(-1) ** 2) for s in per_frame] if correlation is None else
             [block_diagonal([correlation.scaled(c) for c in s]) for s in per_frame])
    frames = [with_rigid_motion(base, points, components, std) for base in bases]
    return block_diagonal(frames), (f"{note}; the rigid motion of every frame (t_x, t_y, theta) marginalised: "
                                    f"prior std {std:g} mm, removed from data and model alike")


def _correlation(points, subset_size) -> tuple:
    """The unit-std sparse covariance of one component at the points and its note."""
    from fracid.data.dic_noise import NUGGET, dic_covariance, factor_estimate, support_radius

    size = real_number(subset_size, "subset_size")
    if not (np.isfinite(size) and size > 0):
        raise DataError(f"subset_size = {subset_size!r} [mm]: give a finite number > 0 (the DIC subset size)")
    cost = factor_estimate(points, size)
    low, high = (b / 1e9 for b in cost["peak"])
    where = (f"{len(points)} points a frame, {cost['neighbours']:.0f} neighbours a point within "
             f"{support_radius(size):.3g} mm")
    if cost["peak"][0] > MAX_FACTOR_BYTES:
        raise DataError(f"subset_size = {size:g} mm: the correlated covariance of the field would take {low:.3g} "
                        f"to {high:.3g} GB ({where}), more than the {MAX_FACTOR_BYTES / 1e9:g} GB fracid allows; "
                        "thin the field (point_spacing, e.g. half the subset size) or keep a region of it")
    correlation = dic_covariance(points, 1.0, size)
    return correlation, (f"errors correlated over the subset size {size:g} mm (compactly supported kernel, "
                         f"l = {size / 2:g} mm: {where}; {NUGGET:g} of the variance independent; frames and "
                         f"components independent, one sparse factor for all: "
                         f"{low:.2g} to {high:.2g} GB at its peak, estimated)")


def _without_empty_frames(indices, controls, values, missing, sigma) -> tuple:
    """The frames that hold at least one value: (their positions, their controls, (values, missing, sigma) of
    their entries, the positions of the frames dropped). All frames empty: none dropped (the caller refuses)."""
    present = (~missing).reshape(len(indices), -1).any(axis=1)
    if present.all() or not present.any():
        return indices, controls, (values, missing, sigma), indices[:0]
    kept = [a.reshape(len(indices), -1)[present].reshape(-1) for a in (values, missing, sigma)]
    return indices[present], controls[present], tuple(kept), indices[~present]


def empty_frames_text(dic: DicData, empty, control: str, name: str) -> str:
    """What the warning of frames without a value says: the frames, their files and control values."""
    files = dic.source[len(dic.source) - dic.n_frames:] if len(dic.source) >= dic.n_frames else ()
    listed = ", ".join(f"{dic.frames[i]} ({control} = {dic.load[control][i]:.6g} mm"
                       + (f", {files[i]}" if files else "") + ")" for i in empty)
    return (f"field {name!r}: {len(empty)} frame(s) without any valid value (every displacement NaN, of low "
            f"quality or without sigma) dropped: frame {listed}; the other frames are used")


def _selected(dic: DicData, frames, region, spacing) -> tuple[DicData, np.ndarray]:
    """The data in the region (a mask of the points or a function of them), thinned to ``spacing`` [mm] if not
    None, and the positions of ``frames``."""
    if not isinstance(dic, DicData):
        raise DataTypeError(f"dic must be a DicData (read_dic_frames, read_dic_vtk), got {type(dic).__name__}")
    if region is not None:
        dic = dic.region(region)
    if spacing is not None:
        from fracid.data.dic.reduction import thinned

        dic = dic.region(thinned(dic.points, real_number(spacing, "point_spacing")))
    indices = np.arange(dic.n_frames) if frames is None else dic.frame_indices(frames)
    return dic, indices


def field_block(dic: DicData, frames=None, components=("u", "v"), *, control: str = "cmod_mm", std=None,
                subset_size=None, rigid_std=None, region=None, point_spacing=None, name: str = "field") -> FieldBlock:
    """The data block of a DIC field and the geometry of its FieldObservation.

    Parameters
    ----------
    dic : DicData
        The DIC data in the specimen frame [mm].
    frames : sequence of int or None
        Frame numbers to use (all if None), in increasing control.
    components : str, int or sequence
        "u" (x), "v" (y) or both.
    control : str
        The load column giving each frame's control value [mm] (e.g. "cmod_mm").
    std : float or None
        Standard deviation of every displacement [mm]; None: the files' per-point sigma.
    subset_size : float or None
        DIC subset size [mm]: errors correlated over it (:mod:`fracid.data.dic_noise`); None: independent.
    rigid_std : float or None
        Prior std [mm] of the rigid motion of every frame (:mod:`fracid.data.dic.rigid`, e.g. ``RIGID_STD`` = 1
        mm): the specimen's motion on its supports removed from data and model alike; None: the data have no
        rigid motion (the model's supports are the camera's reference).
    region : array_like of bool (n_points,) or callable or None
        Points to keep (a region of interest, or points away from the crack); a callable gets the points
        (n, 2) [mm] and returns the mask.
    point_spacing : float or None
        Thin the points (in the region) to at most one per square of this side [mm]
        (:mod:`fracid.data.dic.reduction`: the covariance is the marginal at the kept points); None: all points.
    name : str
        Name of the block.

    Returns
    -------
    FieldBlock

    Raises
    ------
    DataError
        Naming the argument: unknown frames or control column, a control not increasing, no kept value, a
        missing sigma (with no std), std or subset_size <= 0.
    """
    dic, indices = _selected(dic, frames, region, point_spacing)
    comps = component_indices(components)
    controls = frame_controls(dic, indices, control)
    values, missing = dic.values(indices, comps)
    sigma, std_note = entry_std(dic, indices, comps, std)
    missing = missing | ~(sigma > 0)  # no sigma (0 or NaN): no value
    if std is None:
        check_positive_std(sigma[~missing], "the per-point sigma of the files [mm]")
    indices, controls, (values, missing, sigma), empty = _without_empty_frames(indices, controls, values, missing,
                                                                                sigma)
    per_point = (~missing).reshape(len(indices), len(comps), dic.n_points).any(axis=(0, 1))
    if not per_point.any():
        raise DataError(f"field {name!r}: no value left in the frames and region used (all NaN or without sigma)")
    full = (len(indices), len(comps), dic.n_points)
    keep = (~missing).reshape(full)[:, :, per_point].reshape(-1)
    points = dic.points[per_point]
    sigma = sigma.reshape(full)[:, :, per_point].reshape(-1)
    cov, cov_note = field_covariance(points, sigma, len(indices), comps, subset_size, rigid_std)
    kept = np.flatnonzero(keep)
    n_c, n_p = len(comps), len(points)
    notes = (*dic.notes, f"field {name!r}: frames {[dic.frames[i] for i in indices]} at {control} = "
             f"{np.round(controls, 6).tolist()} mm, components {[('u', 'v')[c] for c in comps]}, {n_p} points",
             f"{kept.size} of {keep.size} values kept ({keep.size - kept.size} missing dropped)", std_note, cov_note,
             *([f"WARNING: {empty_frames_text(dic, empty, control, name)}"] if empty.size else []))
    data = ExperimentalData(control=np.repeat(controls, n_c * n_p)[kept],
                            y=values.reshape(full)[:, :, per_point].reshape(-1)[kept], covariance=cov.take(kept),
                            blocks=((name, 0, kept.size),), notes=notes)
    frame_numbers = tuple(dic.frames[i] for i in indices)
    return FieldBlock(data, points, controls, frame_numbers, comps, keep, tuple(dic.frames[i] for i in empty))
