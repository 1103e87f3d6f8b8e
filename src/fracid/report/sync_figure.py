"""The check figure of DIC frames synchronised with a testing machine's log
(:class:`~fracid.data.dic.synchronise.SynchronisedFrames`): the log's load curve with every frame marked where its
time puts it, and the log's control over time with the frames' times and their uncertainty.

A frame marked where the curve does not match the DIC (a frame before the peak drawn after it, frames bunched at
the start) shows a wrong frame rate, offset or time column at a glance.

Units: time [s], control [mm], force [N].
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fracid.report.figures import COMPUTED, MEASURED, new_figure, to_png


def _mark_frames(ax, x, y, frames) -> None:
    ax.plot(x, y, "o", color=COMPUTED, ms=6, label="frames")
    for xi, yi, frame in zip(x, y, frames):
        ax.annotate(str(frame), (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=8)


def synchronisation_figure(sync) -> Figure:
    """Left: the log's force over its control [N over mm] (its control over time if the log has no force) with
    the frames marked and numbered; right: the log's control over time [mm over s], the frames at their times with
    horizontal bars of their uncertainty.

    Parameters
    ----------
    sync : SynchronisedFrames
        The frames on the log's clock and the log's values at their times.
    """
    log, times = sync.log, sync.times
    control, frame_control = log.columns[sync.control], sync.values[sync.control]
    fig = new_figure(10.0, 4.0)
    left, right = fig.subplots(1, 2)
    if sync.force is not None:
        left.plot(control, log.columns[sync.force], color=MEASURED, lw=1.2, label="log")
        _mark_frames(left, frame_control, sync.values[sync.force], times.frames)
        left.set_xlabel(f"{sync.control} [mm]")
        left.set_ylabel(f"{sync.force} [N]")
        left.set_title("load curve of the log, frames marked", fontsize=10)
    else:
        left.plot(log.time, control, color=MEASURED, lw=1.2, label="log")
        _mark_frames(left, times.times, frame_control, times.frames)
        left.set_xlabel("time [s]")
        left.set_ylabel(f"{sync.control} [mm]")
        left.set_title("control of the log (no force column), frames marked", fontsize=10)
    right.plot(log.time, control, color=MEASURED, lw=1.2, label="log")
    right.errorbar(times.times, frame_control, xerr=np.full(len(times.times), times.uncertainty), fmt="o",
                   color=COMPUTED, ms=5, capsize=3, label=f"frames ({times.method}, +- {times.uncertainty:.3g} s)")
    right.set_xlabel("time on the log's clock [s]")
    right.set_ylabel(f"{sync.control} [mm]")
    offset = "" if times.offset is None else f", offset {times.offset:.6g} s"
    right.set_title(f"frames by {times.method}{offset}", fontsize=10)
    for ax in (left, right):
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    return fig


def write_synchronisation_figure(sync, path, overwrite: bool = False) -> Path:
    """:func:`synchronisation_figure` written as a PNG file at ``path``.

    Raises
    ------
    FileExistsError
        If ``path`` exists and ``overwrite`` is false (fracid writes over its own files only).
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists: not overwritten")
    path.write_bytes(to_png(synchronisation_figure(sync)))
    return path


__all__ = ["synchronisation_figure", "write_synchronisation_figure"]
