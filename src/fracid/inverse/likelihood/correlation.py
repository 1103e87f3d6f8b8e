"""Errors correlated along the control: the low-rank modes of a smooth kernel over each data block.

An error term that varies smoothly along a curve (the mesh's error, a model's bias) has the covariance
diag(a) K diag(a) on a block, with K_ij = exp(-(t_i - t_j)^2 / (2 l^2)) over the entries' control values t and
a the term's std per entry. K has a low numerical rank (about the control range / l), so the term is kept as
modes U with U U^T = diag(a) K diag(a) (:func:`block_modes`), added by
:class:`~fracid.data.covariance_update.LowRankUpdate`: no n x n matrix, also for a field of many points per frame
(the points of one frame share the control value, hence the same modes).
"""

from __future__ import annotations

import numpy as np

#: eigenvalues of K below this share of the largest are dropped (K's diagonal is kept to 1e-8)
RANK_TOLERANCE = 1e-10


def kernel_modes(control, length: float) -> np.ndarray:
    """F with F F^T = K, the Gaussian correlation of the values at ``control`` (truncated eigen-decomposition).

    Parameters
    ----------
    control : array_like, shape (n,)
        Control value of every entry of one block [mm] (repeated values share a mode: a field's frame).
    length : float
        Correlation length as a fraction of the block's control range [-] (> 0).

    Returns
    -------
    ndarray, shape (n, r)
        r the numerical rank (1 for a single control value, or a length far above the range).
    """
    t = np.asarray(control, float)
    unique, inverse = np.unique(t, return_inverse=True)
    span = float(unique[-1] - unique[0]) if unique.size > 1 else 1.0
    scaled = (unique[:, None] - unique[None, :]) / (length * (span if span > 0 else 1.0))
    values, vectors = np.linalg.eigh(np.exp(-0.5 * scaled**2))
    keep = values > RANK_TOLERANCE * values[-1]
    return (vectors[:, keep] * np.sqrt(values[keep]))[inverse.ravel()]


def block_modes(amplitude, control, blocks, length: float) -> np.ndarray:
    """Modes U (n, r) of the error term with std ``amplitude`` per entry, correlated along the control within
    each block and independent between blocks: U U^T = diag(a) K_b diag(a) on block b, 0 across blocks.

    Parameters
    ----------
    amplitude : array_like, shape (n,)
        The term's signed amplitude per entry [units of y] (its sign follows the error along the curve).
    control : array_like, shape (n,)
        Control value of every entry [mm].
    blocks : sequence of (name, start, stop)
    length : float
        Correlation length, a fraction of each block's control range [-].
    """
    amplitude, control = np.asarray(amplitude, float), np.asarray(control, float)
    columns = []
    for _, start, stop in blocks:
        modes = kernel_modes(control[start:stop], length) * amplitude[start:stop, None]
        part = np.zeros((amplitude.size, modes.shape[1]))
        part[start:stop] = modes
        columns.append(part)
    return np.hstack(columns) if columns else np.zeros((amplitude.size, 0))


__all__ = ["RANK_TOLERANCE", "block_modes", "kernel_modes"]
