"""DIC frames placed on a testing machine's clock (:class:`~fracid.data.machine_log.MachineLog`), three ways:

- :func:`times_given`: each frame's time stamp (a column of the frame table) on the log's clock;
- :func:`times_from_rate`: frame number ``i`` taken at ``trigger_offset + i / frame_rate``;
- :func:`offset_by_opening`: the frames' times known up to one offset (a frame rate, or the camera's own clock),
  the offset found by matching the opening the DIC measures at a virtual extensometer
  (:func:`extensometer_opening`) to the log's CMOD.

Each frame then gets the log's control and force at its time (:meth:`MachineLog.at
<fracid.data.machine_log.MachineLog.at>`). The uncertainty of the times is given in seconds; it is at least half a
frame interval for a found offset (the misfit cannot tell times within a frame apart when the opening changes
little between frames).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.spatial import cKDTree

from fracid.data.errors import DataError

#: the most offsets tried on the search grid of :func:`offset_by_opening` before its refinement
MAX_GRID = 20000
#: the rise of the misfit, in units of its noise variance, that bounds the offsets fitting as well (2 std)
MISFIT_RISE = 4.0


@dataclass(frozen=True)
class FrameTimes:
    """The frames' times on the log's clock.

    Parameters
    ----------
    frames : tuple of int
        Frame numbers.
    times : numpy.ndarray
        Each frame's time [s] on the log's clock.
    uncertainty : float
        How far the times may be off [s] (0 for given time stamps and a given offset).
    method : str
        "time stamps", "frame rate" or "extensometer".
    offset : float or None
        The offset [s] added to the frames' own times (the log time of frame number 0 for a frame rate).
    notes : tuple of str
        How they were found, warnings prefixed "WARNING: ".
    """

    frames: tuple
    times: np.ndarray
    uncertainty: float = 0.0
    method: str = "time stamps"
    offset: float | None = None
    notes: tuple = ()


def _increasing(frames, times, what: str) -> np.ndarray:
    times = np.asarray(times, dtype=float)
    if times.shape != (len(frames),) or not np.all(np.isfinite(times)):
        raise DataError(f"{what}: one finite time per frame ({len(frames)}) is needed, got {times.tolist()}")
    bad = np.flatnonzero(np.diff(times) <= 0.0)
    if bad.size:
        k = int(bad[0])
        raise DataError(f"{what}: frame {frames[k + 1]} ({times[k + 1]:.6g} s) is not after frame {frames[k]} "
                        f"({times[k]:.6g} s): the frames' times must increase")
    return times


def times_given(frames, times, offset: float = 0.0, what: str = "frame times") -> FrameTimes:
    """The frames at their time stamps ``times`` [s] plus ``offset`` [s] (the log's clock minus the camera's)."""
    frames = tuple(int(f) for f in frames)
    return FrameTimes(frames, _increasing(frames, times, what) + offset, 0.0, "time stamps", offset,
                      (f"frames {list(frames)} at their time stamps ({what}) + {offset:g} s",))


def times_from_rate(frames, rate: float, offset: float) -> FrameTimes:
    """Frame number ``i`` at ``offset + i / rate`` [s] (``rate`` [frames/s]; ``offset``: the log time of frame 0)."""
    if not rate > 0:
        raise DataError(f"frame_rate = {rate!r}: give a number > 0 [frames per second]")
    frames = tuple(int(f) for f in frames)
    times = _increasing(frames, np.array(frames, dtype=float) / rate, "frame numbers") + offset
    return FrameTimes(frames, times, 0.0, "frame rate", offset,
                      (f"frame i at {offset:g} s + i / {rate:g} per s",))


def extensometer_opening(points, u, a, b) -> tuple[np.ndarray, str]:
    """The opening of a virtual extensometer over frames: the displacement of the DIC point nearest ``b`` relative
    to that nearest ``a``, along the direction from ``a`` to ``b`` [mm].

    Parameters
    ----------
    points : array_like, shape (n, 2)
        The DIC points in the specimen frame [mm].
    u : array_like, shape (n_frames, n, 2)
        Their displacements [mm] (NaN: missing).
    a, b : sequence of float
        The extensometer's ends [x, y] in the specimen frame [mm], across the notch.

    Returns
    -------
    (numpy.ndarray of shape (n_frames,), str)
        The opening per frame (NaN where a point has no value) and a note naming the points used.

    Raises
    ------
    DataError
        If the ends coincide or are nearest the same point, or the nearest DIC point is farther from an end than
        3 point spacings.
    """
    points, u = np.asarray(points, dtype=float), np.asarray(u, dtype=float)
    ends = np.array([a, b], dtype=float)
    length = float(np.linalg.norm(ends[1] - ends[0]))
    if not length > 0:
        raise DataError(f"extensometer {ends.tolist()}: its two ends coincide; give two points across the notch [mm]")
    tree = cKDTree(points)
    distance, nearest = tree.query(ends)
    spacing = float(np.median(tree.query(points, k=2)[0][:, 1])) if len(points) > 1 else 0.0
    for end, d in zip(ends, distance):
        if d > 3.0 * spacing:
            raise DataError(f"extensometer end {end.tolist()} mm: the nearest DIC point is {d:.3g} mm away (the points "
                            f"are {spacing:.3g} mm apart): place the extensometer on the measured region")
    if nearest[0] == nearest[1]:
        raise DataError(f"extensometer {ends.tolist()} mm: both ends are nearest the same DIC point "
                        f"{points[nearest[0]].round(4).tolist()} mm: place them on measured points on either side of "
                        "the notch")
    direction = (ends[1] - ends[0]) / length
    opening = (u[:, nearest[1]] - u[:, nearest[0]]) @ direction
    note = (f"extensometer over {length:.4g} mm: points {points[nearest[0]].round(4).tolist()} and "
            f"{points[nearest[1]].round(4).tolist()} mm ({distance.max():.3g} mm from its ends)")
    return opening, note


def _misfit(log_time, log_opening, relative, opening):
    """The sum of squared differences between ``opening`` and the log's at ``offset + relative``, of the offset."""
    def misfit(offset):
        offset = np.atleast_1d(offset)
        model = np.interp(offset[:, None] + relative[None, :], log_time, log_opening)
        return np.sum((model - opening[None, :]) ** 2, axis=1)
    return misfit


def _offset_range(log_time, relative) -> tuple[float, float]:
    low, high = log_time[0] - relative[0], log_time[-1] - relative[-1]
    if high < low:
        raise DataError(f"the frames span {relative[-1] - relative[0]:.6g} s, longer than the log "
                        f"({log_time[-1] - log_time[0]:.6g} s): no offset puts them all in it; check the frame rate")
    return low, high


def offset_by_opening(log_time, log_opening, frames, relative, opening, interval: float | None = None) -> FrameTimes:
    """The offset [s] of the frames' times that best matches the DIC-measured opening to the log's.

    Parameters
    ----------
    log_time, log_opening : array_like, shape (m,)
        The log's time [s] (increasing) and its CMOD [mm].
    frames : sequence of int
        Frame numbers.
    relative : array_like, shape (n_frames,)
        The frames' times up to the offset [s] (``i / frame_rate``, or the camera's time stamps), increasing.
    opening : array_like, shape (n_frames,)
        The opening measured at each frame [mm] (:func:`extensometer_opening`; NaN: the frame is not used).
    interval : float or None
        The frame interval [s] (None: the median of ``relative``'s steps).

    Returns
    -------
    FrameTimes
        ``offset`` minimising the sum of squared differences (a grid over every offset keeping all frames in the
        log, refined by :func:`scipy.optimize.minimize_scalar`); ``uncertainty``: the half width of the offsets
        whose misfit rises less than :data:`MISFIT_RISE` noise variances above the minimum, at least half a frame
        interval; a warning when those offsets are not one interval (another match as good elsewhere).

    Raises
    ------
    DataError
        Fewer than 2 frames with an opening, or frames spanning longer than the log.
    """
    frames = tuple(int(f) for f in frames)
    relative = _increasing(frames, relative, "frame times")
    opening = np.asarray(opening, dtype=float)
    used = np.isfinite(opening)
    if used.sum() < 2:
        raise DataError(f"the extensometer has an opening at {int(used.sum())} frame(s); matching it to the log's CMOD "
                        "needs at least 2: move it onto points measured in every frame")
    log_time, log_opening = np.asarray(log_time, dtype=float), np.asarray(log_opening, dtype=float)
    interval = float(np.median(np.diff(relative))) if interval is None else float(interval)
    low, high = _offset_range(log_time, relative)
    misfit = _misfit(log_time, log_opening, relative[used], opening[used])
    step = min(interval / 20.0, float(np.min(np.diff(log_time)))) if high > low else 1.0
    grid = np.linspace(low, high, int(min(MAX_GRID, max(2, np.ceil((high - low) / step) + 1))))
    values = misfit(grid)
    k = int(np.argmin(values))
    h = grid[1] - grid[0] if len(grid) > 1 else 0.0
    bounds = (max(low, grid[k] - h), min(high, grid[k] + h))
    refined = minimize_scalar(lambda t: float(misfit(t)[0]), bounds=bounds, method="bounded") if h > 0 else None
    best = float(refined.x) if refined is not None and refined.fun <= values[k] else float(grid[k])
    s_min = float(misfit(best)[0])
    noise = s_min / max(int(used.sum()) - 1, 1)
    within = grid[values <= s_min + MISFIT_RISE * max(noise, 1e-300)]
    half_width = 0.5 * float(within.max() - within.min()) if within.size else 0.0
    uncertainty = max(0.5 * interval, half_width, 0.5 * h)
    notes = [f"frames matched to the log's CMOD: offset {best:.6g} s +- {uncertainty:.3g} s, RMS misfit "
             f"{np.sqrt(s_min / used.sum()):.3g} mm over {int(used.sum())} frames"]
    gaps = np.diff(within) > 1.5 * h if within.size > 1 else np.zeros(0, dtype=bool)
    if np.any(gaps) or half_width > 5.0 * interval:
        notes.append(f"WARNING: offsets from {within.min():.6g} to {within.max():.6g} s match the opening about as well "
                     "(the opening changes too little over the frames, or it repeats): the synchronisation is uncertain;"
                     " give the frames' times or a trigger offset instead")
    return FrameTimes(frames, relative + best, uncertainty, "extensometer", best, tuple(notes))


@dataclass(frozen=True)
class SynchronisedFrames:
    """Frames on a log's clock with the log's values at their times (what the check figure draws).

    Parameters
    ----------
    log : MachineLog
        The log.
    times : FrameTimes
        The frames' times.
    control : str
        The log's column of the control [mm].
    force : str or None
        The log's column of the force [N], if read.
    values : dict of str -> numpy.ndarray
        Each log column at the frames' times [mm or N].
    """

    log: object
    times: FrameTimes
    control: str
    force: str | None
    values: dict


def synchronised(log, times: FrameTimes, control: str, force: str | None = None) -> SynchronisedFrames:
    """The log's columns at the frames' ``times`` (:meth:`~fracid.data.machine_log.MachineLog.at`: a frame outside the
    log is refused, naming it)."""
    return SynchronisedFrames(log, times, control, force, log.at(times.times, times.frames))


__all__ = ["FrameTimes", "MAX_GRID", "MISFIT_RISE", "SynchronisedFrames", "extensometer_opening", "offset_by_opening",
           "synchronised", "times_from_rate", "times_given"]
