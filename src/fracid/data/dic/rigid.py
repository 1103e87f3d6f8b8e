"""The rigid-body motion of the specimen in DIC data: marginalised in the covariance, or estimated.

A specimen settles on its supports and the camera may move: every frame of DIC data carries a rigid motion
(translations t_x, t_y [mm] and a small rotation theta [rad] about the specimen's origin,
u = t + theta (-y, x)) that the model, whose supports are fixed, does not compute. fracid removes it
symmetrically from data and model by giving the three motions of every frame a vague Gaussian prior in the
data covariance,

    C_frame = C_noise + R diag(s^2) R^T,

R (n_frame x 3) the displacement of each mode at the frame's entries (component-major, point fastest: the
order of a field block), s the prior std (:data:`RIGID_STD` [mm] for the translations, the same
displacement at the farthest point for the rotation). The likelihood of data y given a computed field m is
then the one of the residual with the best rigid motion of every frame taken out: as s grows,
r^T C_frame^-1 r tends to min_a (r - R a)^T C_noise^-1 (r - R a) (generalised least squares; Woodbury), and
for motions much smaller than s (settling of a few hundredths of a mm against s = 1 mm) the difference is
(a / s)^2 per mode, a few 1e-4. Nothing is estimated during the identification: the motions are marginalised,
the parameters see only the deformation. The covariance stays low rank plus diagonal (three more columns per
frame), so the cost is unchanged.

:func:`fit_rigid_motion` estimates the motions of a residual afterwards (generalised least squares: the
posterior mean under the prior), for the report's residual maps and the user's check.
"""

from __future__ import annotations

import numpy as np

from fracid.data.covariance_low_rank import LowRankPlusDiagonal
from fracid.data.covariance_matrix import Covariance, Diagonal
from fracid.data.covariance_update import LowRankUpdate

#: prior std of the rigid translations [mm] (and of the rotation's displacement at the farthest point)
RIGID_STD = 1.0


def rigid_modes(points, components) -> np.ndarray:
    """The displacement of the unit rigid motions at the entries of one frame [mm per unit].

    Parameters
    ----------
    points : array_like, shape (n_points, 2)
        Positions [mm] in the specimen frame.
    components : sequence of int
        0 (u_x), 1 (u_y) or both, in the order of the entries (component-major, point fastest).

    Returns
    -------
    ndarray, shape (len(components) * n_points, 3)
        Columns t_x (1 mm), t_y (1 mm), theta (1 rad about the specimen's origin: u_x = -y, u_y = x).
    """
    points = np.asarray(points, float)
    x, y = points[:, 0], points[:, 1]
    one, zero = np.ones_like(x), np.zeros_like(x)
    per_component = {0: np.column_stack([one, zero, -y]), 1: np.column_stack([zero, one, x])}
    return np.vstack([per_component[int(c)] for c in components])


def prior_scales(points, std: float) -> np.ndarray:
    """Prior std of (t_x, t_y, theta): ``std`` [mm], and the rotation moving the farthest point by ``std``."""
    radius = float(np.max(np.hypot(*np.asarray(points, float).T))) if len(points) else 1.0
    return np.array([std, std, std / max(radius, 1e-12)])


def with_rigid_motion(frame_covariance: Covariance, points, components, std: float = RIGID_STD) -> Covariance:
    """The covariance of one frame's entries with its rigid motion marginalised: C + R diag(s^2) R^T.

    Parameters
    ----------
    frame_covariance : Covariance
        The noise covariance of the frame's entries [mm^2] (component-major, point fastest).
    points, components
        As :func:`rigid_modes`.
    std : float
        Prior std of the motions [mm] (:data:`RIGID_STD`): much larger than the motions, small enough to keep
        the Woodbury capacitance well conditioned.

    Returns
    -------
    Covariance
        A :class:`~fracid.data.covariance_low_rank.LowRankPlusDiagonal` whose last columns are the prior's
        (``nuisance``) for a diagonal or low-rank-plus-diagonal C; else a
        :class:`~fracid.data.covariance_update.LowRankUpdate` of C (a sparse correlated C keeps its factor).
        Either way ``noise_diag`` is C's diagonal.
    """
    modes = prior_columns(points, components, std)
    if not isinstance(frame_covariance, (Diagonal, LowRankPlusDiagonal)):
        return LowRankUpdate(frame_covariance, modes)
    low_rank = getattr(frame_covariance, "U", np.zeros((frame_covariance.n, 0)))
    variances = frame_covariance.D.var if hasattr(frame_covariance, "D") else frame_covariance.diag()
    return LowRankPlusDiagonal(np.hstack([low_rank, modes]), variances,
                               nuisance=modes.shape[1] + getattr(frame_covariance, "nuisance", 0))


def prior_columns(points, components, std: float = RIGID_STD) -> np.ndarray:
    """The low-rank columns R diag(s) of the rigid motion's prior at one frame's entries [mm]: the modes of
    :func:`rigid_modes` scaled by :func:`prior_scales`, those the components cannot see (t_y with u_x alone)
    left out."""
    modes = rigid_modes(points, components) * prior_scales(points, std)
    return modes[:, np.any(modes != 0.0, axis=0)]


def fit_rigid_motion(points, components, residual, covariance: Covariance | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The rigid motion of one frame's residual (data minus model), by generalised least squares.

    Parameters
    ----------
    points, components
        As :func:`rigid_modes`.
    residual : array_like, shape (len(components) * n_points,)
        The frame's residual [mm]; NaN entries (missing values) are ignored.
    covariance : Covariance, optional
        The noise covariance of the frame's entries without NaN (identity if None).

    Returns
    -------
    motion : ndarray (3,)
        (t_x [mm], t_y [mm], theta [rad]); a mode the components cannot see (t_y with u_x alone) is 0.
    fitted : ndarray
        The motion's displacement at every entry [mm] (NaN where the residual is).
    """
    modes = rigid_modes(points, components)
    r = np.asarray(residual, float)
    have = np.isfinite(r)
    R, rh = modes[have], r[have]
    W = R if covariance is None else covariance.solve(R)
    seen = np.any(R != 0.0, axis=0)
    motion = np.zeros(3)
    motion[seen] = np.linalg.lstsq(W[:, seen].T @ R[:, seen], W[:, seen].T @ rh, rcond=None)[0]
    fitted = np.where(have, modes @ motion, np.nan)
    return motion, fitted


__all__ = ["RIGID_STD", "fit_rigid_motion", "rigid_modes", "with_rigid_motion"]
