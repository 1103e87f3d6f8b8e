"""One Kalman update of the parameters by a group of observations: the gain form for few observations, the
information (normal-equation) form for many (docs/theory.md, section 4.3).

Both give the same Gaussian posterior of a linear observation y = S x + e, e ~ N(0, R):

* gain form (:func:`kalman_update`): K = C S^T (S C S^T + R)^-1, an m x m solve;
* information form (:func:`information_update`): C_new = (C^-1 + S^T R^-1 S)^-1 and
  x_new = x + C_new S^T R^-1 (innovation), a p x p solve, with R used only through its whitening
  (:class:`~fracid.data.covariance_matrix.Covariance`): O(m p^2) for a diagonal R, never m x m.

:func:`assimilate` takes the gain form for a group of at most p observations (the filter's results
unchanged from the step-by-step form) and the information form above.
"""

from __future__ import annotations

import numpy as np

from fracid.data.covariance_matrix import Covariance, as_covariance


def kalman_update(x, C, S, innovation, R):
    """One Kalman update in Joseph form.

    Parameters
    ----------
    x : ndarray, shape (p,)
        Prior mean [units of the parameters].
    C : ndarray, shape (p, p)
        Prior covariance.
    S : ndarray, shape (m, p)
        Sensitivity of the m observations to x.
    innovation : ndarray, shape (m,)
        Measured minus computed observations [units of y].
    R : ndarray, shape (m, m), or Covariance
        Covariance of the measurement errors [units of y squared] (its dense form is used: m small).

    Returns
    -------
    x_new, C_new, K : ndarray
        Posterior mean and covariance, and the gain. The Joseph form
        (I - K S) C (I - K S)^T + K R K^T keeps C symmetric positive definite under round-off.
    """
    R = R.dense() if isinstance(R, Covariance) else R
    A = S @ C @ S.T + R
    K = np.linalg.solve(A, S @ C).T  # C S^T A^-1 (A symmetric)
    I_KS = np.eye(x.size) - K @ S
    C_new = I_KS @ C @ I_KS.T + K @ R @ K.T
    return x + K @ innovation, 0.5 * (C_new + C_new.T), K


def information_update(x, C, S, innovation, R):
    """The same update in information form: C_new = (C^-1 + S^T R^-1 S)^-1, x_new = x + C_new S^T R^-1 innovation.

    Solved in standardised parameters (x_j / sqrt(C_jj)) so that parameters of unlike scales (E ~ 1e4 MPa,
    kappa ~ 1e-4) do not spoil the p x p inverse.

    Parameters
    ----------
    x, C, S, innovation
        As :func:`kalman_update`.
    R : Covariance or array_like
        Covariance of the m measurement errors [units of y squared]; only its whitening is used.

    Returns
    -------
    x_new, C_new, K : ndarray
        Posterior mean and covariance, and the gain K = C_new S^T R^-1 (p x m).
    """
    R = as_covariance(R, np.size(innovation), name="R")
    s = np.sqrt(np.diag(C))
    W = R.whiten(S * s[None, :])  # R^-1/2 S diag(s), m x p
    precision = np.linalg.inv(C / np.outer(s, s)) + W.T @ W
    C_std = np.linalg.inv(0.5 * (precision + precision.T))
    C_std = 0.5 * (C_std + C_std.T)
    x_new = x + s * (C_std @ (W.T @ R.whiten(innovation)))
    K = s[:, None] * (C_std @ (R.solve(S) * s[None, :]).T)
    return x_new, C_std * np.outer(s, s), K


def assimilate(x, C, S, innovation, R):
    """:func:`kalman_update` for a group of at most p = len(x) observations, :func:`information_update` above."""
    if np.size(innovation) <= np.size(x):
        return kalman_update(x, C, S, innovation, R)
    return information_update(x, C, S, innovation, R)


__all__ = ["assimilate", "information_update", "kalman_update"]
