"""The covariance of digital-image-correlation (DIC) displacement errors: spatially correlated noise.

DIC measures the displacement of a subset (a square window of ``subset_size`` pixels, here in mm)
around each point; neighbouring points whose subsets overlap share pixels, hence share image noise
and interpolation bias, and their errors are correlated over about a subset size. This module models
that correlation, for one displacement component, by a Gaussian kernel

    C_ij = std^2 exp(-d_ij^2 / (2 l^2)),   l = subset_size / 2,

d_ij the distance between points i and j [mm]. The choice l = subset_size / 2 makes the correlation
fall to exp(-2) ~ 0.14 at one subset size (subsets no longer overlap) and to 0.61 at half a subset
(they share half their pixels), the behaviour reported for the displacement errors of subset-based
DIC (Wang, Y. Q., Sutton, M. A., Bruck, H. A., Schreier, H. W., "Quantitative error assessment in
pattern matching: effects of intensity pattern noise, interpolation, strain and image contrast on
motion measurements", Strain 45 (2009) 160-178; Sutton, Orteu, Schreier, "Image correlation for
shape, motion and deformation measurements", Springer 2009, ch. 5; the DIC Good Practices Guide,
International DIC Society, 2018, section 5.3: the spatial resolution is of the order of the subset
size and the measurements at a step smaller than the subset are correlated).

The dense kernel is n x n; :func:`dic_covariance` returns it as a
:class:`~fracid.data.covariance_low_rank.LowRankPlusDiagonal` (U U^T + diag(d)) from its leading
eigenpairs (exact eigen-decomposition up to :data:`EXACT_LIMIT` points, Nystrom's approximation on
:data:`NYSTROM_LANDMARKS` landmark points beyond), the variance the low-rank part leaves out on the
diagonal, so that the diagonal is std^2 exactly. :func:`dic_frames_covariance` stacks it over frames
and components (independent: each image pair has its own noise). Units: mm (coordinates, std).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
from scipy.spatial.distance import cdist

from fracid.data.covariance_matrix import block_diagonal
from fracid.data.covariance_low_rank import LowRankPlusDiagonal

#: largest number of points whose kernel is decomposed exactly (dense eigh); beyond, Nystrom
EXACT_LIMIT = 2500
#: landmark points of the Nystrom approximation
NYSTROM_LANDMARKS = 1500
#: relative Frobenius error of the low-rank-plus-diagonal form that the default rank allows
FROBENIUS_TOLERANCE = 0.05
#: smallest independent variance kept on the diagonal, relative to std^2 (keeps C positive definite)
DIAGONAL_FLOOR = 1e-3


def correlation_length(subset_size: float) -> float:
    """The kernel's length l = subset_size / 2 [mm] (see the module docstring)."""
    return 0.5 * float(subset_size)


def dic_kernel(points_a, points_b, std: float, subset_size: float) -> np.ndarray:
    """The covariance std^2 exp(-d^2 / (2 l^2)) between two point sets [mm^2], shape (n_a, n_b)."""
    length = correlation_length(subset_size)
    d2 = cdist(np.asarray(points_a, float), np.asarray(points_b, float), "sqeuclidean")
    return std**2 * np.exp(-d2 / (2.0 * length**2))


def _check(points, std, subset_size, rank) -> np.ndarray:
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) == 0:
        raise ValueError(f"points has shape {points.shape}; give (n, 2) coordinates [mm]")
    if not np.all(np.isfinite(points)):
        raise ValueError("points holds NaN or infinite coordinates; give finite coordinates [mm]")
    if not (np.isscalar(std) and np.isfinite(std) and std > 0):
        raise ValueError(f"std = {std!r}; give a finite displacement standard deviation > 0 [mm]")
    if not (np.isscalar(subset_size) and np.isfinite(subset_size) and subset_size > 0):
        raise ValueError(f"subset_size = {subset_size!r}; give the DIC subset size > 0 [mm]")
    if rank is not None and not (isinstance(rank, (int, np.integer)) and 1 <= rank <= len(points)):
        raise ValueError(f"rank = {rank!r}; give None or an integer in [1, {len(points)}] (the number of points)")
    return points


def _eigenpairs(points, std, subset_size, seed) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (decreasing) and eigenvectors of the kernel: exact, or Nystrom on landmarks."""
    n = len(points)
    if n <= EXACT_LIMIT:
        values, vectors = scipy.linalg.eigh(dic_kernel(points, points, std, subset_size))
        return values[::-1], vectors[:, ::-1]
    rng = np.random.default_rng(seed)
    landmarks = points[np.sort(rng.choice(n, NYSTROM_LANDMARKS, replace=False))]
    K_mm = dic_kernel(landmarks, landmarks, std, subset_size)
    K_nm = dic_kernel(points, landmarks, std, subset_size)
    values, vectors = scipy.linalg.eigh(K_mm)
    keep = values > 1e-10 * values[-1]
    F = K_nm @ (vectors[:, keep] / np.sqrt(values[keep]))  # K ~ F F^T (Nystrom)
    s2, W = scipy.linalg.eigh(F.T @ F)  # F F^T = Q diag(s2) Q^T with Q = F W / sqrt(s2)
    s2, W = s2[::-1], W[:, ::-1]
    positive = s2 > 1e-12 * s2[0]
    return s2[positive], F @ (W[:, positive] / np.sqrt(s2[positive]))


def _rank(values: np.ndarray, vectors: np.ndarray, variance: float, tolerance: float) -> int:
    """The fewest modes k whose U U^T, with the rest of the variance on the diagonal, is within
    ``tolerance`` of the kernel in relative Frobenius norm: the error is the off-diagonal part of the
    tail sum_{i > k} lambda_i v_i v_i^T, ``|tail|``^2 - ``|diag tail|``^2, for every k at once."""
    values = np.clip(values, 0.0, None)
    total = np.sum(values**2)
    tail2 = total - np.cumsum(values**2)  # |tail_k|_F^2, k = 1..m
    diag_tail2 = np.zeros_like(values)
    for start in range(0, len(vectors), 1000):  # rows by chunks: (chunk, m) at a time
        kept = np.cumsum(values * vectors[start:start + 1000] ** 2, axis=1)  # variance in the first k modes
        diag_tail2 += np.sum((variance - kept) ** 2, axis=0)
    error = np.sqrt(np.clip(tail2 - diag_tail2, 0.0, None) / total)
    good = np.flatnonzero(error <= tolerance)
    return int(good[0] + 1) if good.size else len(values)


def dic_covariance(points, std: float, subset_size: float, *, rank: int | None = None,
                   seed: int = 0) -> LowRankPlusDiagonal:
    """The covariance of one DIC displacement component at ``points``, low rank plus diagonal.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Subset centres [mm].
    std : float
        Standard deviation of the displacement error at every point [mm] (e.g. 1e-3: 1 micrometre).
    subset_size : float
        DIC subset size [mm] (pixels times the scale); the correlation length is subset_size / 2.
    rank : int, optional
        Modes of the low-rank part; None: the fewest whose form (with the rest of the variance on the
        diagonal) is within :data:`FROBENIUS_TOLERANCE` of the kernel in relative Frobenius norm.
    seed : int
        Seed of the choice of Nystrom landmarks (more than :data:`EXACT_LIMIT` points).

    Returns
    -------
    LowRankPlusDiagonal
        U U^T + diag(d) [mm^2] with diag = std^2 exactly; U holds the leading eigenvectors scaled by
        the square roots of their eigenvalues, d the rest of the variance (at least
        :data:`DIAGONAL_FLOOR` std^2: the modes of a row are scaled down where they would exceed it).

    Raises
    ------
    ValueError
        For malformed points, std or subset_size <= 0, a rank outside [1, n].
    """
    points = _check(points, std, subset_size, rank)
    values, vectors = _eigenpairs(points, std, subset_size, seed)
    tolerance = FROBENIUS_TOLERANCE
    k = min(rank if rank is not None else _rank(values, vectors, std**2, tolerance), len(values))
    U = vectors[:, :k] * np.sqrt(np.clip(values[:k], 0.0, None))
    variance = std**2
    low = np.sum(U**2, axis=1)
    ceiling = (1.0 - DIAGONAL_FLOOR) * variance
    shrink = np.where(low > ceiling, np.sqrt(ceiling / np.maximum(low, 1e-300)), 1.0)
    U = U * shrink[:, None]
    d = variance - np.sum(U**2, axis=1)
    return LowRankPlusDiagonal(U, d, name="DIC covariance")


def dic_frames_covariance(points, std: float, subset_size: float, *, n_frames: int, n_components: int = 2,
                          rank: int | None = None):
    """The covariance of DIC displacements over frames and components, block diagonal (independent).

    Parameters
    ----------
    points, std, subset_size, rank
        As :func:`dic_covariance`.
    n_frames : int
        Frames (image pairs, each with its own noise).
    n_components : int
        Displacement components per frame (2: U then V).

    Returns
    -------
    Covariance
        Blocks ordered frame by frame, within a frame component by component, each block the n points.
    """
    if not (isinstance(n_frames, (int, np.integer)) and n_frames >= 1):
        raise ValueError(f"n_frames = {n_frames!r}; give a positive integer")
    if not (isinstance(n_components, (int, np.integer)) and n_components >= 1):
        raise ValueError(f"n_components = {n_components!r}; give a positive integer")
    block = dic_covariance(points, std, subset_size, rank=rank)
    return block_diagonal([block] * (int(n_frames) * int(n_components)))


__all__ = ["FROBENIUS_TOLERANCE", "DIAGONAL_FLOOR", "EXACT_LIMIT", "NYSTROM_LANDMARKS", "correlation_length",
           "dic_covariance", "dic_frames_covariance", "dic_kernel"]
