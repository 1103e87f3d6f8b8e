"""Twin experiments: synthetic data from known parameters, to be identified back.

The data are computed by the same forward operator that identifies them, plus Gaussian noise of a
stated standard deviation per block, so the identification's error and its reported uncertainty
can be compared with the truth.
"""

from __future__ import annotations

import numpy as np

from fracid.data import ExperimentalData


def synthetic_data(operator, x_true, std, *, seed: int | None = 0) -> ExperimentalData:
    """Data computed at ``x_true`` with noise, one block per observation of the operator.

    Parameters
    ----------
    operator : ForwardOperator
    x_true : array_like
        The known parameters.
    std : dict of str -> float, or float
        Per block name: the noise standard deviation. A value in (0, 1) with the key suffixed
        ``":relative"`` (e.g. ``{"global:relative": 0.02}``) is relative to the block's largest |y|;
        a plain float applies to every block as relative.
    seed : int or None
        Seed of the noise; None gives noise-free data (with the stated covariance).

    Raises
    ------
    RuntimeError
        If the forward run at ``x_true`` fails.
    """
    record = operator(np.asarray(x_true, float))
    if not record.ok:
        raise RuntimeError(f"the twin's forward run at {list(x_true)} failed: {record.error}")
    y = record.y
    s = np.empty_like(y)
    blocks, notes = [], []
    for obs, part in zip(operator.observations, operator.slices()):
        block_std = _block_std(std, obs.name, y[part])
        s[part] = block_std
        blocks.append((obs.name, part.start, part.stop))
        notes.append(f"twin experiment: block {obs.name!r} computed at {dict(zip(operator.names, np.ravel(x_true)))}, "
                     f"noise std {block_std:.4g}" + ("" if seed is not None else " (not added)"))
    noisy = y if seed is None else y + np.random.default_rng(seed).standard_normal(y.size) * s
    control = np.concatenate([obs.control_points for obs in operator.observations])
    return ExperimentalData(control, noisy, np.diag(s**2), tuple(blocks), tuple(notes))


def _block_std(std, name, values) -> float:
    if isinstance(std, (int, float)):
        return float(std) * float(np.max(np.abs(values)))
    if f"{name}:relative" in std:
        return float(std[f"{name}:relative"]) * float(np.max(np.abs(values)))
    if name in std:
        return float(std[name])
    raise KeyError(f"no noise level for block {name!r}: give std[{name!r}] (absolute) or "
                   f"std['{name}:relative'] (fraction of its largest value)")
