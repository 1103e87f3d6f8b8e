"""The covariance of digital-image-correlation (DIC) displacement errors: spatially correlated noise.

DIC measures the displacement of a subset (a square window of ``subset_size`` pixels, here in mm)
around each point; neighbouring points whose subsets overlap share pixels, hence share image noise
and interpolation bias, and their errors are correlated over about a subset size (Wang, Y. Q., Sutton,
M. A., Bruck, H. A., Schreier, H. W., "Quantitative error assessment in pattern matching: effects of
intensity pattern noise, interpolation, strain and image contrast on motion measurements", Strain 45
(2009) 160-178; Sutton, Orteu, Schreier, "Image correlation for shape, motion and deformation
measurements", Springer 2009, ch. 5; the DIC Good Practices Guide, International DIC Society, 2018,
section 5.3: the spatial resolution is of the order of the subset size and the measurements at a step
smaller than the subset are correlated). This module models that correlation, for one displacement
component, as

    C_ij = std^2 [(1 - eta) w(d_ij / R) + eta delta_ij],   w(t) = (1 - t)^4 (4 t + 1) for t < 1, 0 beyond,

d_ij the distance between points i and j [mm], w Wendland's compactly supported function psi_3,1 (positive
definite in two and three dimensions: Wendland, H., "Scattered data approximation", Cambridge University
Press 2005, ch. 9), eta = :data:`NUGGET` the share of the variance independent from point to point (pixel
noise), and the support R = sqrt(14) l with l = subset_size / 2. It stands for the Gaussian
exp(-d^2 / (2 l^2)): the same integral over the plane (2 pi l^2: the number of independent values a field
holds is the same) and within 0.02 of it at every distance (0.61 at half a subset, 0.14 at one), but zero
beyond R = 1.87 subset sizes, so that C is sparse: a frame of 8 000 points on a 1 mm grid with 6 mm subsets
has about 390 neighbours a point, factorised in about a second (:class:`~fracid.data.covariance_sparse.
SparseCovariance`), where the Gaussian's dense form needs 0.5 GB and minutes.

What a DIC code reports, in these keys (docs/dic/README.md, "From the DIC code to the keys"): ``subset_size``
= the subset in pixels times the scale [mm/pixel]; ``std`` = the code's displacement uncertainty (or the std
of the displacements between two images of the unloaded specimen); if the noise's autocorrelation was
measured (two static images), ``subset_size`` = 2 x the lag [mm] at which it falls to exp(-1/2) = 0.61.

:func:`dic_covariance` returns the covariance of one component at a set of points;
:func:`dic_frames_covariance` stacks it over frames and components (independent: each image pair has its
own noise). Units: mm (coordinates, std).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse
from scipy.spatial import cKDTree
from scipy.spatial.distance import cdist

from fracid.data.covariance_matrix import block_diagonal
from fracid.data.covariance_sparse import SparseCovariance

#: share of the variance independent from point to point (the rest correlated over the subset)
NUGGET = 0.05
#: the support of the compactly supported correlation, in correlation lengths l = subset_size / 2
SUPPORT = float(np.sqrt(14.0))
#: nonzeros of the factor per nonzero of the correlation, (low, high): measured (module :func:`factor_estimate`)
FILL_RATIO = (0.8, 3.0)
#: peak memory while building the factor per byte it keeps (measured, :func:`factor_estimate`)
BUILD_PEAK = 2.4


def correlation_length(subset_size: float) -> float:
    """The correlation length l = subset_size / 2 [mm] (see the module docstring)."""
    return 0.5 * float(subset_size)


def support_radius(subset_size: float) -> float:
    """The distance R = sqrt(14) l [mm] beyond which two points' errors are independent."""
    return SUPPORT * correlation_length(subset_size)


def _wendland(t: np.ndarray) -> np.ndarray:
    """psi_3,1(t) = (1 - t)^4 (4 t + 1) on [0, 1], 0 beyond."""
    t = np.clip(t, 0.0, 1.0)
    return (1.0 - t) ** 4 * (4.0 * t + 1.0)


def dic_kernel(points_a, points_b, std: float, subset_size: float) -> np.ndarray:
    """The correlated part std^2 (1 - eta) w(d / R) between two point sets [mm^2], shape (n_a, n_b), dense
    (for small sets and figures; :func:`dic_covariance` never forms it)."""
    d = cdist(np.asarray(points_a, float), np.asarray(points_b, float))
    return std**2 * (1.0 - NUGGET) * _wendland(d / support_radius(subset_size))


def _check(points, std, subset_size) -> np.ndarray:
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) == 0:
        raise ValueError(f"points has shape {points.shape}; give (n, 2) coordinates [mm]")
    if not np.all(np.isfinite(points)):
        raise ValueError("points holds NaN or infinite coordinates; give finite coordinates [mm]")
    if not (np.isscalar(std) and np.isfinite(std) and std > 0):
        raise ValueError(f"std = {std!r}; give a finite displacement standard deviation > 0 [mm]")
    if not (np.isscalar(subset_size) and np.isfinite(subset_size) and subset_size > 0):
        raise ValueError(f"subset_size = {subset_size!r}; give the DIC subset size > 0 [mm]")
    return points


def dic_correlation(points, subset_size: float):
    """The sparse correlation matrix (1 - eta) w(d / R) + eta I of the points (CSC, unit diagonal)."""
    points = np.asarray(points, float)
    tree = cKDTree(points)
    pairs = tree.sparse_distance_matrix(tree, support_radius(subset_size), output_type="coo_matrix")
    off = pairs.row != pairs.col
    values = (1.0 - NUGGET) * _wendland(pairs.data[off] / support_radius(subset_size))
    n = len(points)
    K = scipy.sparse.coo_matrix((values, (pairs.row[off], pairs.col[off])), shape=(n, n))
    return (K + scipy.sparse.identity(n)).tocsc()


def factor_estimate(points, subset_size: float, sample: int = 200) -> dict:
    """What the sparse factor of :func:`dic_covariance` at ``points`` will take, before building it.

    Counts the neighbours within the support of up to ``sample`` points (a KD-tree query), hence the
    correlation's nonzeros; the factor's L holds 0.8 to 3 times as many (measured on grids of 900 to 32 000
    points, 6 mm subsets: the ratio grows with the number of points), 36 bytes each (SuperLU's L and U and a
    row-major copy of L), and the correlation 12 bytes per nonzero; the peak while building is about
    :data:`BUILD_PEAK` times what is kept (the pairs' distances and SuperLU's workspace: 3.3 GB resident for a
    1.4 GB factor at 32 000 points).

    Returns
    -------
    dict
        ``neighbours`` (mean per point), ``nonzeros`` (of the correlation), ``bytes`` (low, high) [B] kept,
        ``peak`` (low, high) [B] while building.
    """
    points = np.asarray(points, float)
    rng = np.random.default_rng(0)
    chosen = points if len(points) <= sample else points[rng.choice(len(points), sample, replace=False)]
    counts = cKDTree(points).query_ball_point(chosen, support_radius(subset_size), return_length=True)
    nonzeros = float(np.mean(counts)) * len(points)
    kept = tuple(12.0 * nonzeros + 36.0 * ratio * nonzeros for ratio in FILL_RATIO)
    return {"neighbours": float(np.mean(counts)) - 1.0, "nonzeros": nonzeros,
            "bytes": kept, "peak": tuple(BUILD_PEAK * b for b in kept)}


def dic_covariance(points, std: float, subset_size: float) -> SparseCovariance:
    """The covariance of one DIC displacement component at ``points``, sparse.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Subset centres [mm].
    std : float
        Standard deviation of the displacement error at every point [mm] (e.g. 1e-3: 1 micrometre).
    subset_size : float
        DIC subset size [mm] (pixels times the scale); the correlation length is subset_size / 2.

    Returns
    -------
    SparseCovariance
        std^2 [(1 - eta) w(d / R) + eta I] [mm^2] (module docstring), diagonal std^2 exactly. Two points at
        the same place (distance 0) are taken as one correlated pair, not as the same point.

    Raises
    ------
    ValueError
        For malformed points, std or subset_size <= 0.
    """
    points = _check(points, std, subset_size)
    return SparseCovariance(dic_correlation(points, subset_size), np.full(len(points), float(std)),
                            name="DIC covariance")


def dic_frames_covariance(points, std: float, subset_size: float, *, n_frames: int, n_components: int = 2):
    """The covariance of DIC displacements over frames and components, block diagonal (independent).

    Parameters
    ----------
    points, std, subset_size
        As :func:`dic_covariance`.
    n_frames : int
        Frames (image pairs, each with its own noise).
    n_components : int
        Displacement components per frame (2: U then V).

    Returns
    -------
    Covariance
        Blocks ordered frame by frame, within a frame component by component, each block the n points (one
        factorisation shared by all blocks).
    """
    if not (isinstance(n_frames, (int, np.integer)) and n_frames >= 1):
        raise ValueError(f"n_frames = {n_frames!r}; give a positive integer")
    if not (isinstance(n_components, (int, np.integer)) and n_components >= 1):
        raise ValueError(f"n_components = {n_components!r}; give a positive integer")
    block = dic_covariance(points, std, subset_size)
    return block_diagonal([block] * (int(n_frames) * int(n_components)))


__all__ = ["NUGGET", "SUPPORT", "correlation_length", "dic_correlation", "dic_covariance", "dic_frames_covariance",
           "dic_kernel", "factor_estimate", "support_radius"]
