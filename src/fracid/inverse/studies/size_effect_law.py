"""Bazant's size effect law and its fit to nominal strengths.

Bazant's size effect law (SEL) for geometrically similar specimens of size D,

    sigma_N = B f_t / sqrt(1 + D / D0),

goes from the strength criterion (sigma_N = B f_t, small D) to linear elastic fracture mechanics
(sigma_N ~ D^(-1/2), large D); the transitional size D0 marks the change. :func:`bazant_law` evaluates
it and :func:`fit_size_effect` fits (B f_t, D0) to nominal strengths (:class:`SizeEffectFit`). The
forward runs that give the strengths are in :mod:`fracid.inverse.studies.size_effect`.

Units: sizes D and D0 [mm], nominal strengths and B f_t [MPa].
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

__all__ = ["SizeEffectFit", "bazant_law", "fit_size_effect"]

# fewest distinct sizes a fit accepts: two parameters plus one size to test the shape of the law
_MIN_SIZES = 3


def bazant_law(D, B_ft, D0):
    """Bazant's size effect law, sigma_N = B_ft / sqrt(1 + D / D0).

    Parameters
    ----------
    D : float or array_like
        Specimen size [mm], D >= 0.
    B_ft : float
        Nominal strength of a vanishingly small specimen (the strength criterion) [MPa].
    D0 : float
        Transitional size, where the strength and LEFM asymptotes cross [mm], D0 > 0.

    Returns
    -------
    float or ndarray
        Nominal strength sigma_N [MPa], of the shape of ``D``.

    Examples
    --------
    >>> float(bazant_law(300.0, 4.0, 100.0))
    2.0
    """
    return B_ft / np.sqrt(1.0 + np.asarray(D, dtype=float) / D0)


def _law_jacobian(D: np.ndarray, B_ft: float, D0: float) -> np.ndarray:
    """d sigma_N / d (B_ft, D0) at every size: shape (n, 2), units [-] and [MPa/mm]."""
    ratio = 1.0 + D / D0
    return np.column_stack([ratio ** -0.5, 0.5 * B_ft * D / D0**2 * ratio ** -1.5])


@dataclass(frozen=True)
class SizeEffectFit:
    """Parameters of Bazant's size effect law fitted to nominal strengths.

    Attributes
    ----------
    B_ft : float
        Strength-criterion asymptote B f_t [MPa].
    D0 : float
        Transitional size [mm].
    covariance : ndarray (2, 2)
        Covariance of (B_ft, D0) [MPa^2, MPa mm, mm^2]; inf everywhere when the data do not
        determine both parameters (e.g. no size effect at all).
    residual_rms : float
        Root mean square of the misfit sigma_N(fit) - sigma_N(data) [MPa].
    """

    B_ft: float
    D0: float
    covariance: np.ndarray = field(compare=False)
    residual_rms: float = 0.0

    def __post_init__(self):
        covariance = np.array(self.covariance, dtype=float).reshape(2, 2)
        covariance.setflags(write=False)  # the dataclass is frozen: so is its matrix
        object.__setattr__(self, "covariance", covariance)

    @property
    def std(self) -> np.ndarray:
        """Standard deviations of (B_ft [MPa], D0 [mm])."""
        return np.sqrt(np.diag(self.covariance))

    def predict(self, D):
        """Nominal strength [MPa] at sizes ``D`` [mm] by the fitted law."""
        return bazant_law(D, self.B_ft, self.D0)

    def as_dict(self) -> dict:
        """Plain-Python form (for JSON): parameters, their standard deviations, covariance, misfit."""
        std_B, std_D0 = self.std
        return {
            "B_ft": float(self.B_ft),
            "D0": float(self.D0),
            "std_B_ft": float(std_B),
            "std_D0": float(std_D0),
            "covariance": self.covariance.tolist(),
            "residual_rms": float(self.residual_rms),
        }


def fit_size_effect(D, sigma_N, std=None) -> SizeEffectFit:
    """Fit Bazant's size effect law to nominal strengths by weighted nonlinear least squares.

    Minimises sum(((bazant_law(D_i) - sigma_i) / std_i)^2). The start is Bazant's linear
    regression Y = 1 / sigma_N^2 = A D + C (B_ft = 1 / sqrt(C), D0 = C / A), then
    :func:`scipy.optimize.least_squares` refines it in log(B_ft), log(D0), which keeps both positive.

    Parameters
    ----------
    D : array_like
        Specimen sizes [mm], positive, at least 3 distinct values (replicates are allowed).
    sigma_N : array_like
        Nominal strengths [MPa], positive, one per entry of ``D``.
    std : float or array_like, optional
        Standard deviation of each ``sigma_N`` [MPa], positive. Given: the covariance is absolute
        (as ``curve_fit(absolute_sigma=True)``). None: equal weights, and the covariance is scaled
        by the residual variance sum(r^2) / (n - 2) (as ``curve_fit(absolute_sigma=False)``).

    Returns
    -------
    SizeEffectFit

    Raises
    ------
    ValueError
        Mismatched lengths, values that are not positive finite numbers, fewer than 3 sizes.
    RuntimeError
        When the least-squares solver does not converge.
    """
    D, sigma, weights = _checked_data(D, sigma_N, std)
    start = np.log(_linear_start(D, sigma, weights))

    def residuals(log_p):
        return weights * (bazant_law(D, *np.exp(log_p)) - sigma)

    def jacobian(log_p):
        p = np.exp(log_p)
        return weights[:, None] * _law_jacobian(D, *p) * p  # chain rule: d/d log p = p d/dp

    solution = least_squares(residuals, start, jac=jacobian, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    if not solution.success:
        raise RuntimeError(f"the size-effect fit did not converge: {solution.message}")
    B_ft, D0 = np.exp(solution.x)
    r = residuals(solution.x)
    covariance = _covariance(weights[:, None] * _law_jacobian(D, B_ft, D0))
    if std is None and np.isfinite(covariance).all():  # inf stays inf, even for a zero misfit
        covariance = covariance * (r @ r) / (D.size - 2)
    misfit = r / weights  # [MPa]
    return SizeEffectFit(float(B_ft), float(D0), covariance, float(np.sqrt(np.mean(misfit**2))))


def _checked_data(D, sigma_N, std):
    """(D, sigma_N, weights 1/std) as float arrays, or a ValueError naming the faulty argument."""
    D = _positive_vector("D", D, "mm")
    sigma = _positive_vector("sigma_N", sigma_N, "MPa")
    if sigma.size != D.size:
        raise ValueError(f"sigma_N has {sigma.size} values but D has {D.size}; give one strength per size")
    if std is None:
        weights = np.ones_like(D)
    else:
        std = _positive_vector("std", np.broadcast_to(std, D.shape) if np.ndim(std) == 0 else std, "MPa")
        if std.size != D.size:
            raise ValueError(f"std has {std.size} values but D has {D.size}; give one standard deviation per size")
        weights = 1.0 / std
    distinct = np.unique(D)
    if distinct.size < _MIN_SIZES:
        raise ValueError(f"D = {D.tolist()} holds {distinct.size} distinct size(s); fitting the size effect law "
                         f"needs at least {_MIN_SIZES}")
    return D, sigma, weights


def _positive_vector(name: str, values, unit: str) -> np.ndarray:
    """1-D float array of positive finite numbers, or a ValueError with the first bad value."""
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {values!r} is not an array of numbers [{unit}]") from None
    if array.ndim != 1:
        raise ValueError(f"{name} has shape {array.shape}; it must be a 1-D array [{unit}]")
    bad = np.flatnonzero(~(np.isfinite(array) & (array > 0)))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"{name}[{i}] = {float(array[i])!r}; every value must be a positive finite number [{unit}]")
    return array


def _linear_start(D: np.ndarray, sigma: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """(B_ft, D0) from Bazant's regression Y = 1 / sigma^2 = A D + C, weighted like the fit.

    std(Y) = 2 std(sigma) / sigma^3, so the weights of the line are weights * sigma^3 / 2. Data
    that the law cannot follow give A <= 0 (no decrease with size) or C <= 0 (steeper than LEFM):
    the start then sits near the asymptote the data point to, and the nonlinear fit goes on from it.
    """
    A, C = np.polyfit(D, sigma**-2.0, 1, w=weights * sigma**3 / 2)
    if A <= 0:  # strength criterion: D0 far above the sizes
        D0 = 100.0 * D.max()
        return np.array([float(np.median(sigma * np.sqrt(1.0 + D / D0))), D0])
    if C <= 0:  # LEFM: D0 far below the sizes, sigma ~ B_ft sqrt(D0 / D), so A = 1 / (B_ft^2 D0)
        D0 = D.min() / 100.0
        return np.array([1.0 / np.sqrt(A * D0), D0])
    return np.array([1.0 / np.sqrt(C), C / A])


def _covariance(J: np.ndarray) -> np.ndarray:
    """(J^T J)^-1 of a weighted Jacobian; inf where J is rank-deficient (as curve_fit does)."""
    _, s, VT = np.linalg.svd(J, full_matrices=False)
    if s[-1] <= np.finfo(float).eps * max(J.shape) * s[0]:
        return np.full((2, 2), np.inf)
    return (VT.T / s**2) @ VT
