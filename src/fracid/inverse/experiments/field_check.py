"""What ``fracid check`` says of a field block: its frames, points, noise, placement, and its frames' slices.

:func:`field_check_lines` describes the block as the identification will use it (after the region, the
placement on the mesh, thinning and the frames without a value): frames and their control values, points a
frame, values, the noise as given (the key ``std`` or the files' sigma) and the covariance's note (its
correlation, the factor's estimated memory, the rigid motion), the camera placement and the points dropped
outside the mesh or computed as the mirror image. :func:`field_frame_slices` gives each frame's entries in the
stacked data, for the frame ranking of :mod:`fracid.inverse.studies.frame_information`. Both are given the
block built once per process (:func:`~fracid.inverse.experiments.field.placed_field_block`).
"""

from __future__ import annotations

import numpy as np


def field_check_lines(exp, block, warnings, specimen) -> list:
    """The lines of the field block ``exp`` (a FieldExperimentConfig; ``block`` its FieldBlock, ``warnings`` those
    of its placement) on ``specimen``, in the units of its keys."""
    n_c, n_p = len(block.components), len(block.points)
    present = np.asarray(block.keep).reshape(len(block.frames), n_c, n_p).any(axis=1).sum(axis=1)
    controls = ", ".join(f"{c:.4g}" for c in block.frames)
    notes = [n.split("] ", 1)[-1] for n in block.data.notes]
    std = np.sqrt(block.data.covariance.noise_diag())  # without the rigid motion's vague prior
    source = f"std = {exp.std:g} mm declared" if exp.std is not None else "the files' sigma"
    correlation = next((n for n in notes if n.startswith(("errors correlated", "independent errors"))), "")
    lines = [f"field block {exp.name!r}: {len(block.frames)} frames at {exp.control_column} = {controls} mm; "
             f"{n_p} points, {present.min()} to {present.max()} with a value a frame; components "
             f"{', '.join('uv'[c] for c in block.components)}; {block.data.n_y} values",
             f"  noise: std {std.min():.3g} to {std.max():.3g} mm ({source}); {correlation}"]
    lines.append("  " + _placement_text(exp.placement, block.points, specimen))
    lines += [f"  read: {n}" for n in notes if "dropped: " in n or n.startswith("region of interest")]
    lines += [f"  note: {w}" for w in warnings]
    return lines


def _placement_text(placement, points, specimen) -> str:
    """The camera's placement on the specimen and the points the model computes as the mirror image."""
    from fracid.inverse.core.field_observations import mirrored_points
    from fracid.inverse.core.probed import describe

    if placement is None:
        text = "placement: none (the files' coordinates are the specimen's, mm)"
    else:
        text = (f"placement: camera point {tuple(placement.origin_camera)} at specimen point "
                f"{tuple(placement.origin_specimen)} mm, scale {placement.scale:g} mm per camera unit, rotation "
                f"{np.degrees(placement.rotation):.3g} deg")
    _, sign = mirrored_points(describe(specimen), points)
    mirrored = int(np.count_nonzero(np.asarray(sign.get(0, np.ones(len(points)))) < 0))
    return text + (f"; {mirrored} of {len(points)} points on the other half, computed as the mirror image"
                   if mirrored else "")


def field_frame_slices(exp, block, start: int) -> tuple:
    """(labels, slices) of each frame's entries of the FieldBlock, which starts at entry ``start`` of the data."""
    per_frame = np.asarray(block.keep).reshape(len(block.frames), -1).sum(axis=1)
    ends = start + np.cumsum(per_frame)
    slices = [slice(int(a), int(b)) for a, b in zip(np.concatenate([[start], ends[:-1]]), ends)]
    labels = [f"frame {number} ({exp.control_column} {c:.4g} mm)" for number, c in zip(block.frame_numbers,
                                                                                        block.frames)]
    return labels, slices


__all__ = ["field_check_lines", "field_frame_slices"]
