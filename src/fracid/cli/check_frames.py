"""The frames a field block should keep, as ``fracid check`` prints them (unless ``--no-time``, or the model
has no exact sensitivities: then a line says why not).

For every data block whose kind gives its frames' entries (``frame_slices``: a DIC field), one run with
sensitivities at the configuration's parameters ranks the frames by their Fisher information
(:mod:`fracid.inverse.studies.frame_information`), the rest of the data (the curves, the other blocks) and the
bounds (as a uniform prior's std, (upper - lower) / sqrt(12)) as the prior. A linearisation at
[model.parameters]: the lines say so, and that a first estimate is the better place to rank at.
"""

from __future__ import annotations

import time

import numpy as np


def framed_blocks(cfg, data) -> list:
    """(name, first entry, experiment) of every data block whose kind gives its frames' entries."""
    kinds = {getattr(exp, "name", None): exp for exp in cfg.experiments}
    return [(name, a, kinds[name]) for name, a, _ in data.blocks if hasattr(kinds.get(name), "frame_slices")]


def skipped_ranking_lines(cfg, data) -> list:
    """The line that says the frames were not ranked under ``--no-time`` (none when no block has frames)."""
    if not framed_blocks(cfg, data):
        return []
    return ["frames ranked: not computed (--no-time; it costs one run with exact sensitivities at "
            "[model.parameters])"]


def frame_ranking_lines(cfg, data, operator, space) -> list:
    """The ranking's lines of every block with frames (none when no block has frames)."""
    from fracid.config import build_parameters, build_specimen
    from fracid.inverse.core.sensitivity import (DirectDifferentiation, ForwardRunError, exact_sensitivity,
                                                 sensitivity_label)
    from fracid.inverse.studies.frame_information import frame_information, rank_frames

    framed = framed_blocks(cfg, data)
    if not framed:
        return []
    params = build_parameters(cfg)
    x = np.array([getattr(params, name) for name in operator.names])
    evaluate, sensitivity = exact_sensitivity(operator)
    if not isinstance(sensitivity, DirectDifferentiation):  # 2 p + 1 runs by differences: not a check's cost
        return [f"frames ranked: not computed (the model has no exact sensitivities: {2 * len(x) + 1} runs by "
                f"central differences; fracid sensitivity gives the information)"]
    start = time.perf_counter()
    try:
        _, S, _ = sensitivity(evaluate, x, None, None)
    except ForwardRunError as error:  # a failed run: the check goes on without the ranking, saying why
        return [f"frames ranked: not computed (the run with sensitivities at [model.parameters] failed: {error})"]
    seconds = time.perf_counter() - start
    width = (np.asarray(space.upper) - np.asarray(space.lower)) / np.sqrt(12.0)
    lines = []
    specimen = build_specimen(cfg)
    for name, a, exp in framed:
        labels, slices = exp.frame_slices(specimen, a)
        inside = np.zeros(data.n_y, dtype=bool)
        for rows in slices:
            inside[rows] = True
        rest = frame_information(S, data.covariance, [np.flatnonzero(~inside)])[0] if (~inside).any() else 0.0
        ranking = rank_frames(frame_information(S, data.covariance, slices), operator.names,
                              rest + np.diag(1.0 / width**2), labels=labels)
        lines.append(f"frames of {name!r} ranked by their information at [model.parameters] ("
                     f"{', '.join(f'{n} = {v:g}' for n, v in zip(operator.names, x))}; one run, "
                     f"{sensitivity_label(sensitivity)}, {seconds:.0f} s; linearised: rank again at a first "
                     f"estimate when these are a guess); the prior: the other data and the bounds")
        lines += ranking.lines()
    return lines


__all__ = ["frame_ranking_lines", "framed_blocks", "skipped_ranking_lines"]
