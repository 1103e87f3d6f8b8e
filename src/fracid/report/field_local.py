"""What a displacement field was bought to see, measured and computed: strain maps, the crack-opening profile
and the process-zone width, frame by frame.

The same estimators are applied to the measured displacements (the frame's fitted rigid motion removed) and to
those computed at the estimate, at the same points: the strain maps by a local plane fit
(:mod:`fracid.data.dic.strain`, the largest principal strain), the opening profile by virtual extensometers
across the crack and the width by strain transects (:mod:`fracid.data.dic.estimators`), so that their
smoothing biases neither side. The opening and width need the specimen's straight crack line
(:func:`~fracid.specimens.crack_line.crack_line`); without one only the strain maps are drawn.

Units: positions, gauge, radius, opening and width [mm]; strains [10^-3] on the maps.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from fracid.data.dic.estimators import Extensometers, StrainTransects
from fracid.data.dic.strain import principal_strain, strain_components
from fracid.data.errors import DataError
from fracid.report.field_fit import FieldFit
from fracid.report.figures import COMPUTED, MEASURED, new_figure

#: strain unit on the maps
MILLI = 1e3
#: heights of the opening profile and of the width along the ligament (a share of it, away from its ends)
HEIGHTS = np.linspace(0.15, 0.85, 6)
#: the width's threshold, a share of the largest computed strain normal to the crack over the frames (the model's
#: strains are free of noise; a share of the measured ones would follow the noise where the field cannot resolve the
#: zone)
WIDTH_THRESHOLD = 0.3


def frame_displacements(fit: FieldFit, k: int) -> tuple:
    """(points (n, 2), measured (n, 2), computed (n, 2)) of frame ``k`` [mm]: the measured ones less the frame's
    rigid motion; NaN for a component or point without a value."""
    xy = np.column_stack([fit.x, fit.y])
    points, ids = np.unique(np.round(xy, 9), axis=0, return_inverse=True)
    measured, computed = np.full((len(points), 2), np.nan), np.full((len(points), 2), np.nan)
    entries = np.flatnonzero(fit.frame == k)
    measured[ids[entries], fit.component[entries]] = (fit.measured - fit.rigid)[entries]
    computed[ids[entries], fit.component[entries]] = fit.computed[entries]
    return points, measured, computed


def frame_strains(fit: FieldFit, k: int, radius: float) -> tuple:
    """(points, measured, computed) largest principal strain [-] of frame ``k``, both by the same plane fit."""
    points, measured, computed = frame_displacements(fit, k)
    has_v = 1 in fit.components
    out = []
    for field in (measured, computed):
        out.append(principal_strain(*strain_components(points, field[:, 0], field[:, 1] if has_v else None, radius)))
    return points, out[0], out[1]


def strain_figure(fit: FieldFit, k: int, radius: float, draw_map, title: str) -> Figure:
    """Three maps of frame ``k``: measured and computed largest principal strain (shared levels) and their
    difference [10^-3]; ``draw_map(fig, ax, x, y, values, symmetric, label)`` draws one."""
    points, measured, computed = frame_strains(fit, k, radius)
    fig = new_figure(13.0, 4.2)
    axes = fig.subplots(1, 3, squeeze=False)[0]
    shared = np.concatenate([measured, computed]) * MILLI
    for ax, values, what in ((axes[0], measured, "measured"), (axes[1], computed, "computed"),
                             (axes[2], measured - computed, "measured - computed")):
        draw_map(fig, ax, points[:, 0], points[:, 1], MILLI * values, shared if what != "measured - computed" else None,
                 "largest principal strain [10⁻³]")
        ax.set_title(f"{what}", fontsize=10)
    fig.suptitle(f"{title}: strain by a plane fit within {radius:.3g} mm of each point, the same for both",
                 fontsize=10)
    return fig


def _pairs(line, points) -> bool:
    """Whether the points lie on both sides of the crack line (else a symmetric half is used)."""
    offsets = line.offsets(points)
    return bool(np.any(offsets < 0) and np.any(offsets > 0)) or not line.mirrored


def _heights(line, points) -> np.ndarray:
    """Heights along the ligament where the points are: :data:`HEIGHTS` of the overlap of both ranges [mm]."""
    lo, hi = line.extent
    along = points[:, line.along]
    lo, hi = max(lo, float(along.min())), min(hi, float(along.max()))
    return lo + HEIGHTS * (hi - lo)


def local_data(fit: FieldFit, line, radius: float) -> dict:
    """Per frame, measured and computed: the opening profile w(heights) and the process-zone width [mm].

    Returns ``{"heights", "profile": (measured, computed) (n_frames, n_heights), "width": (measured, computed)
    (n_frames,) the mean over the heights, "gauge", "threshold"}``; NaN where an estimate has too few points."""
    points = frame_displacements(fit, 0)[0]
    heights = _heights(line, points)
    gauge = 2.0 * radius
    normal = line.normal
    opening, strain = Extensometers(line, heights, gauge, radius, pairs=_pairs(line, points)), None
    offsets = np.arange(1, 9) * 0.5 * radius
    n = fit.n_frames
    result = {"profile": (np.full((n, heights.size), np.nan), np.full((n, heights.size), np.nan)),
              "width": (np.full(n, np.nan), np.full(n, np.nan))}
    samples, fields = [], [frame_displacements(fit, k)[1:] for k in range(n)]  # each frame's once
    for k, (measured, computed) in enumerate(fields):
        for side, field in enumerate((measured, computed)):
            present = np.isfinite(field[:, normal])
            try:
                result["profile"][side][k] = opening.evaluate(points, present, field[:, normal])[0]
                if side == 1:
                    transects = StrainTransects(line, heights, offsets, radius, 0.0)
                    samples.append(transects.strain_matrix(points, present) @ np.where(present, field[:, normal], 0))
            except DataError:
                continue
    threshold = WIDTH_THRESHOLD * max((float(np.nanmax(s)) for s in samples), default=0.0)
    if threshold > 0:
        strain = StrainTransects(line, heights, offsets, radius, threshold)
        for k, (measured, computed) in enumerate(fields):
            for side, field in enumerate((measured, computed)):
                present = np.isfinite(field[:, normal])
                try:
                    result["width"][side][k] = float(np.mean(strain.evaluate(points, present, field[:, normal])[0]))
                except DataError:
                    continue
    return {**result, "heights": heights, "gauge": gauge, "threshold": threshold}


def local_figure(fit: FieldFit, local: dict, control_label: str) -> Figure:
    """Left: the opening profile w(height) of every frame, measured (dots) and computed (lines); right: the
    process-zone width over the frames' control values, measured and computed."""
    fig = new_figure(12.0, 4.5)
    left, right = fig.subplots(1, 2)
    colours = [f"C{k % 10}" for k in range(fit.n_frames)]
    for k, colour in enumerate(colours):
        left.plot(local["heights"], local["profile"][1][k] * 1e3, "-", color=colour,
                  label=f"frame {k + 1} ({fit.controls[k]:.3g})")
        left.plot(local["heights"], local["profile"][0][k] * 1e3, "o", color=colour, ms=4)
    left.set_xlabel("height along the crack line [mm]")
    left.set_ylabel(f"opening over a {2 * local['gauge']:.3g} mm gauge [µm]")
    left.set_title("crack-opening profile: measured (dots), computed (lines)", fontsize=10)
    left.legend(fontsize=7)
    right.plot(fit.controls, local["width"][0], "o", color=MEASURED, label="measured")
    right.plot(fit.controls, local["width"][1], "-", color=COMPUTED, label="computed")
    right.set_xlabel(control_label)
    right.set_ylabel("process-zone width [mm]")
    right.set_title(f"width where the normal strain exceeds {local['threshold']:.3g} (mean over heights)",
                    fontsize=10)
    right.legend(fontsize=8)
    return fig


__all__ = ["frame_displacements", "frame_strains", "local_data", "local_figure", "strain_figure"]
