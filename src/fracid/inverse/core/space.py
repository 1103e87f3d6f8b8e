"""The parameter space of an identification: names, bounds and scale of the identified parameters, and
the map between their values and the unit cube (shared by every inverse method, the population designs
and the posterior sampler)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ParameterSpace:
    """Names, bounds and scale of the identified parameters.

    Parameters
    ----------
    names : sequence of str
    lower, upper : array_like
        Bounds, in the parameters' units.
    log : sequence of bool, optional
        Per parameter: sample uniformly in log(x) instead of x (for ranges over decades).
    """

    names: tuple
    lower: np.ndarray
    upper: np.ndarray
    log: tuple = ()

    def __post_init__(self):
        names = tuple(self.names)
        lower, upper = np.asarray(self.lower, float), np.asarray(self.upper, float)
        log = tuple(self.log) if self.log else (False,) * len(names)
        if not (lower.shape == upper.shape == (len(names),) and len(log) == len(names)):
            raise ValueError("names, lower, upper and log must have one entry per parameter")
        for name, lo, hi, lg in zip(names, lower, upper, log):
            if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
                raise ValueError(f"bounds of {name!r}: lower = {lo} must be below upper = {hi}")
            if lg and lo <= 0:
                raise ValueError(f"bounds of {name!r}: log scale needs a positive lower bound, got {lo}")
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "lower", lower)
        object.__setattr__(self, "upper", upper)
        object.__setattr__(self, "log", log)

    def from_unit(self, u: np.ndarray) -> np.ndarray:
        """Map points of the unit cube to parameter values."""
        u = np.atleast_2d(u)
        lo, hi = _safe_log(self.lower), _safe_log(self.upper)
        return np.where(np.array(self.log), np.exp(lo + u * (hi - lo)), self.lower + u * (self.upper - self.lower))

    def to_unit(self, x: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`from_unit`."""
        x = np.atleast_2d(x)
        log = np.array(self.log)
        lo, hi = _safe_log(self.lower), _safe_log(self.upper)
        log_span = np.where(log, hi - lo, 1.0)  # the log branch is evaluated for linear entries too
        return np.where(log, (_safe_log(x) - lo) / log_span, (x - self.lower) / (self.upper - self.lower))


def _safe_log(v):
    """log where v > 0 (log-scale parameters have positive bounds), 0 elsewhere (linear ones, unused)."""
    return np.log(np.where(v > 0, v, 1.0))
