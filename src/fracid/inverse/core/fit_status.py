"""What a fit is, in words a user can act on, and which parameters the data do not identify.

The status of every local fit begins with one word of :data:`STATUS_ACTIONS` (``"<word>: <details>"``), each
with the action it implies; :func:`status_word` reads it back (from older results too), the CLI summary,
``result.json`` (``status_word``, ``status_action``) and the report show both.

:func:`unidentified` names the parameters the data do not fix: a relative std above :data:`RELATIVE_STD_LIMIT`,
a std near that of the bounds alone (:data:`BOUNDS_STD_FRACTION`) or a correlation above :data:`CORRELATION_LIMIT`
in magnitude, and points to ``fracid study``.
"""

from __future__ import annotations

import numpy as np

CONVERGED = "converged"
VALLEY = "converged along a valley"
STABLE = "stopped but stable"
NOT_CONVERGED = "not converged"
FAILED = "failed"

#: The words of a fit's status, each with what the user should do.
STATUS_ACTIONS = {
    CONVERGED: "the estimate and its std can be used",
    VALLEY: "the data fix a combination of parameters, not each: read the correlation, fix or bound one of them, "
            "or run `fracid study` to map the valley",
    STABLE: "the estimate is usable (its last moves were below half a std) but not converged by the strict "
            "criterion: raise the method's max_iterations (its table in [identify]) to confirm",
    NOT_CONVERGED: "do not use the estimate as it is: it still moves; raise the method's max_iterations, "
                   "narrow the bounds or start elsewhere (`fracid study` checks several starts)",
    FAILED: "there is no usable estimate: read the failed runs' errors in result.json, then check the bounds and "
            "the model's settings",
}
#: Statuses of older results and other methods, read as a word of :data:`STATUS_ACTIONS`.
LEGACY_WORDS = {"stopped": NOT_CONVERGED}

#: A parameter whose std exceeds this fraction of |estimate| is not identified: its 95 % Gaussian interval
#: x +- 1.96 std then runs from below 0.02 x to above 1.98 x, a factor of 100 (at 0.51 it includes 0): the data
#: do not fix even the order of magnitude.
RELATIVE_STD_LIMIT = 0.5
#: Two parameters correlated beyond this |r| are not identified one by one: the std of either with the other
#: known is sqrt(1 - r^2) < 0.14 of its own, so the data fix their combination 7 times better than each.
CORRELATION_LIMIT = 0.99
#: A std above this fraction of a uniform's over the bounds, (upper - lower) / sqrt(12), is the bounds' more than
#: the data's: at 1/sqrt(2) the data add no more precision (1/std^2) than the bounds alone.
BOUNDS_STD_FRACTION = 1 / np.sqrt(2.0)
#: A fit stopped before the strict criterion is "stable" when its last steps moved every parameter by less than
#: this many std: the estimate's remaining drift is inside the uncertainty it reports.
STABLE_STEP = 0.5


def status_word(status: str) -> str:
    """The word of :data:`STATUS_ACTIONS` a status begins with (the longest that matches; a legacy
    ``"stopped: ..."`` reads ``"not converged"``); ``""`` for an empty or unknown status."""
    text = (status or "").strip().lower()
    words = sorted([*STATUS_ACTIONS, *LEGACY_WORDS], key=len, reverse=True)
    for word in words:
        if text == word or text.startswith((f"{word}:", f"{word} (", f"{word};", f"{word},")):
            return LEGACY_WORDS.get(word, word)
    return ""


def status_action(status: str) -> str:
    """What the user should do after a fit of this status (``""`` for an unknown word)."""
    return STATUS_ACTIONS.get(status_word(status), "")


def fit_action(status: str, warned: bool) -> str:
    """:func:`status_action`, qualified for a converged or stable fit when ``warned`` (:func:`unidentified` named
    parameters): the fit converged, but not every parameter is fixed by the data."""
    action = status_action(status)
    if warned and status_word(status) in (CONVERGED, STABLE):
        action += ", except the parameters the data do not identify (see the warning; `fracid study` maps them)"
    return action


def stable_step(points, C) -> float:
    """The largest move of a parameter between successive ``points`` (the last two and three), in std of C."""
    points = [np.asarray(p, float) for p in points][-3:]
    std = np.sqrt(np.maximum(np.diag(np.asarray(C, float)), np.finfo(float).tiny))
    steps = [np.max(np.abs(b - a) / std) for a, b in zip(points, points[1:])]
    return float(max(steps)) if steps else float("inf")


def measurement_part(C):
    """The measurement-only covariance a covariance widened by error terms carries (:func:`with_measurement`), or
    ``C`` itself: what a poor fit is judged on."""
    measurement = getattr(C, "measurement", None)
    return C if measurement is None else measurement


def with_measurement(C, measurement):
    """``C`` (a widened covariance object) carrying ``measurement``, the data's scatter alone, for
    :func:`measurement_part`; ``C`` unchanged when it is ``measurement``."""
    if C is not measurement:
        C.measurement = measurement_part(measurement)
    return C


def unidentified(names, x, C, bounds=None) -> list[str]:
    """Warnings naming the parameters the data do not identify (module docstring); empty when every parameter is.

    Parameters
    ----------
    names : sequence of str
    x : array_like
        The estimate (units of the parameters).
    C : array_like
        Its covariance (squared units).
    bounds : (lower, upper) or None
        The box of the estimate: a std above :data:`BOUNDS_STD_FRACTION` of a uniform's over it is the bounds'.
    """
    x, C = np.asarray(x, float), np.asarray(C, float)
    std = np.sqrt(np.maximum(np.diag(C), 0.0))
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(std))):
        return []
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.where(x != 0, std / np.abs(x), np.inf)
    prior = _bounds_std(bounds, x.size)
    reasons = {}
    for i in range(x.size):
        if std[i] > 0 and relative[i] > RELATIVE_STD_LIMIT:
            reasons[i] = f"std {100 * relative[i]:.3g} % of the estimate"
        elif std[i] > BOUNDS_STD_FRACTION * prior[i]:
            reasons[i] = f"std {std[i] / prior[i]:.2g} times that of the bounds alone, a uniform over them"
    out = []
    if reasons:
        listed = "; ".join(f"{names[i]} = {x[i]:.3g} +- {std[i]:.2g} ({why})" for i, why in reasons.items())
        out.append(f"not identified by the data: {listed}. Above {100 * RELATIVE_STD_LIMIT:g} % the 95 % interval "
                   "spans more than a factor of 100. Fix the parameter, give data that sense it, or run `fracid "
                   "study` to see what the data determine")
    pairs = correlated_pairs(C)
    if pairs:
        listed = "; ".join(f"{names[i]} and {names[j]} (r = {r:+.4f})" for i, j, r in pairs)
        out.append(f"not identified one by one: {listed} are correlated beyond |r| = {CORRELATION_LIMIT:g}, so the "
                   "data fix their combination, not each; their std are the valley's length. Fix one of them or run "
                   "`fracid study` to map the valley")
    return out


def _bounds_std(bounds, p) -> np.ndarray:
    """The std of a uniform over each parameter's bounds, (upper - lower) / sqrt(12); inf where not known."""
    try:
        lower, upper = (np.asarray(b, float) for b in bounds)
        if lower.shape == upper.shape == (p,) and np.all(np.isfinite(upper - lower)):
            return (upper - lower) / np.sqrt(12.0)
    except (TypeError, ValueError):
        pass
    return np.full(p, np.inf)


def correlated_pairs(C) -> list[tuple]:
    """(i, j, r) of every pair with ``|r|`` above :data:`CORRELATION_LIMIT`."""
    C = np.asarray(C, float)
    std = np.sqrt(np.maximum(np.diag(C), np.finfo(float).tiny))
    r = C / np.outer(std, std)
    p = C.shape[0]
    return [(i, j, float(r[i, j])) for i in range(p) for j in range(i + 1, p) if abs(r[i, j]) > CORRELATION_LIMIT]


__all__ = ["BOUNDS_STD_FRACTION", "CONVERGED", "CORRELATION_LIMIT", "FAILED", "NOT_CONVERGED", "RELATIVE_STD_LIMIT", "STABLE", "STABLE_STEP",
           "STATUS_ACTIONS", "VALLEY", "correlated_pairs", "fit_action", "measurement_part", "stable_step", "status_action", "status_word",
           "unidentified", "with_measurement"]
