"""The posterior's likelihood with the model error's std integrated out, per draw, on a 1-D quadrature.

For a draw x with residual r = y(x) - y_exp, the likelihood with sigma_m of group g unknown is

    p(r_g | x) = integral N(r_g; 0, C_g + sigma^2 B_g) p(sigma) d sigma,

computed by the trapezoidal rule in log sigma, weighted by the prior
(:func:`~fracid.inverse.likelihood.model_error.log_prior`): no forward run beyond the draw's own. The likelihood
of n_g values is flat in log sigma well below the measurement std and about Gaussian around its peak, of width
1 / sqrt(2 n_g): the points (:func:`quadrature_grid`) cover the bounds coarsely and, around the identified sigma
(e^-W .. e^W times it, W = 1 + 8 / sqrt(2 n_g)), at half that width (the rule's error is then negligible). The groups are independent (stacked data blocks are), so the likelihood is the product
over the groups. The values are relative to the likelihood under C alone (the normalisation
-1/2 log det(2 pi C) of the base is the sampler's), so the posterior's evidence keeps its meaning. The
posterior of sigma is the weighted mean over the draws of each draw's posterior on the grid (:meth:`summary`).
"""

from __future__ import annotations

import numpy as np
from scipy.special import logsumexp

from fracid.inverse.likelihood.model_error import GRID_POINTS, ErrorGroups, log_prior, with_model_error

#: the most points of a quadrature in log sigma (a group of very many values is then integrated more coarsely)
MAX_POINTS = 401


def _spaced(lower: float, upper: float, step: float) -> np.ndarray:
    """Points from ``lower`` to ``upper`` about ``step`` apart, at least GRID_POINTS and at most MAX_POINTS."""
    return np.linspace(lower, upper, int(np.clip(np.ceil((upper - lower) / step) + 1, GRID_POINTS, MAX_POINTS)))


def quadrature_grid(bounds, n: int, centre: float | None = None) -> np.ndarray:
    """Points in log sigma for a group of ``n`` values (module docstring) over ``bounds`` [units of y], finer
    around ``centre`` (the identified sigma) when given; increasing sigma values."""
    lower, upper = np.log(np.asarray(bounds, float))
    step = 0.5 / np.sqrt(2.0 * max(n, 1))
    if centre is None:
        return np.exp(_spaced(lower, upper, step))
    reach = 1.0 + 16.0 * step
    near = _spaced(max(lower, np.log(centre) - reach), min(upper, np.log(centre) + reach), step)
    return np.exp(np.union1d(np.linspace(lower, upper, GRID_POINTS), near))


class MarginalLikelihood:
    """log-likelihood of draws with sigma_m marginalised (module docstring).

    Parameters
    ----------
    base : Covariance
        C: the measurement covariance (with the mesh's error when added) [units of y squared].
    groups : ErrorGroups
        The groups of blocks sharing one sigma_m.
    settings : ModelError
        Its prior and bounds.
    centre : sequence of float, optional
        The identified sigma_m per group [units of y]: the quadrature then spans the region around it.
    """

    def __init__(self, base, groups: ErrorGroups, settings, centre=None):
        self.groups, self.settings = groups, settings
        self.grids, self.log_weights, self.covariances = [], [], []
        for g, (index, scale, modes) in enumerate(zip(groups.indices, groups.scales, groups.modes)):
            bounds = np.asarray(settings.bounds, float) * scale
            grid = quadrature_grid(bounds, index.size, None if centre is None else centre[g])
            self.grids.append(grid)
            self.log_weights.append(_log_trapezoid(grid, scale, settings) - _log_trapezoid(
                np.exp(np.linspace(*np.log(bounds), MAX_POINTS)), scale, settings, total=True))
            part = base.take(index)
            one = ErrorGroups([""], [[]], [np.arange(index.size)], np.array([scale]),
                              [None if modes is None else modes[index]])
            reference = part.logdet()
            self.covariances.append([(with_model_error(part, [s], one), reference) for s in grid])

    def _group_terms(self, residuals, g) -> np.ndarray:
        """log prior weight + log N(r_g; 0, C_g(sigma)) - log N(r_g; 0, C_g), shape (draws, grid)."""
        R = residuals[:, self.groups.indices[g]].T
        columns = [-0.5 * (C.quadratic(R) + C.logdet() - reference) for C, reference in self.covariances[g]]
        return np.column_stack(columns) + self.log_weights[g][None, :]

    def __call__(self, residuals) -> np.ndarray:
        """The log-likelihood of every draw, relative to the base's normalisation.

        Parameters
        ----------
        residuals : ndarray, shape (draws, n)
            y(x_i) - y_exp of every draw (finite rows).
        """
        residuals = np.atleast_2d(np.asarray(residuals, float))
        return sum(logsumexp(self._group_terms(residuals, g), axis=1) for g in range(len(self.grids)))

    def summary(self, residuals, weights) -> list[dict]:
        """The posterior of sigma_m per group from weighted draws: ``group``, ``blocks``, ``mean``, ``median``,
        ``interval_90`` [units of y], the ``grid`` and its ``probability``."""
        residuals = np.atleast_2d(np.asarray(residuals, float))
        weights = np.asarray(weights, float)
        ok = weights > 0
        out = []
        for g, grid in enumerate(self.grids):
            terms = self._group_terms(residuals[ok], g)
            per_draw = np.exp(terms - logsumexp(terms, axis=1, keepdims=True))
            probability = weights[ok] @ per_draw / np.sum(weights[ok])
            cdf = np.cumsum(probability)
            low, median, high = (float(np.interp(q, cdf, grid)) for q in (0.05, 0.5, 0.95))
            out.append({"group": self.groups.names[g], "blocks": list(self.groups.blocks[g]),
                        "mean": float(probability @ grid), "median": median, "interval_90": [low, high],
                        "grid": grid.tolist(), "probability": probability.tolist()})
        return out


def _log_trapezoid(grid, scale, settings, total=False):
    """log of the trapezoidal rule's weights in log sigma times the prior's density on ``grid`` (increasing);
    ``total``: the log of their sum (the prior's mass over the grid's range: its normalisation)."""
    u = np.log(grid)
    weights = 0.5 * (np.diff(u, prepend=u[0]) + np.diff(u, append=u[-1]))
    terms = log_prior(grid, scale, settings) + np.log(weights)
    return logsumexp(terms) if total else terms


__all__ = ["MAX_POINTS", "MarginalLikelihood", "quadrature_grid"]
