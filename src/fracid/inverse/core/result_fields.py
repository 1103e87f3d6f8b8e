"""The fields of a method's result that follow from the problem and the estimate, not from the method:
the bounds the estimate is kept in, the parameters on a bound, the observed controls and quantities, and the
run's own curves at the estimate (:class:`~fracid.inverse.core.method.MethodResult` re-exports them)."""

from __future__ import annotations

import numpy as np

from fracid.data.covariance_matrix import as_covariance


def identification_bounds(operator, space) -> tuple[np.ndarray, np.ndarray]:
    """The box an estimate is kept in: the space's bounds within the parameters' valid ranges."""
    lower, upper = operator.valid_bounds()
    return np.maximum(space.lower, lower), np.minimum(space.upper, upper)


def at_bounds(names, x, bounds) -> list[str]:
    """Names of the parameters whose value lies on a bound (within 1e-9 of the bounds' span)."""
    lower, upper = bounds
    span = np.where(np.isfinite(upper - lower), upper - lower, 1.0)
    return [n for n, v, lo, hi, w in zip(names, x, lower, upper, span) if min(v - lo, hi - v) <= 1e-9 * w]


def result_fields(operator, space, x, y_exp, C_exp, *, blocks=(), notes=()) -> dict:
    """The fields of a :class:`MethodResult` that follow from the problem and the estimate ``x``:
    ``names``, ``y_exp``, ``std_exp``, ``blocks``, ``notes``, ``units``, ``bounds``
    (:func:`identification_bounds`) and ``at_bound``.

    A method adds ``x``, ``C``, ``y_fit``, its status and its stages:
    ``MethodResult(x=x, C=C, y_fit=y_fit, ..., **result_fields(...))``.
    """
    lower, upper = identification_bounds(operator, space)
    return {"names": list(space.names), "y_exp": np.asarray(y_exp, float),
            "std_exp": as_covariance(C_exp, name="C_exp").std(), "blocks": list(blocks), "notes": list(notes),
            "units": dict(operator.units), "bounds": (lower.tolist(), upper.tolist()),
            "at_bound": at_bounds(space.names, np.asarray(x, float), (lower, upper)),
            **observed_fields(operator, np.size(y_exp))}


def estimate_curves(evaluate, x) -> list:
    """The run's own curves at the estimate ``x`` (:attr:`MethodResult.curves`): ``evaluate(x)``'s
    ``RunRecord.curves``. A method's last run is at its estimate: through a
    :class:`~fracid.inverse.core.runs.StoredOperator` that run is remembered (or stored) and costs nothing
    here; a plain operator runs once more. Empty when ``x`` is not finite or the run fails."""
    x = np.asarray(x, float)
    if not np.all(np.isfinite(x)):
        return []
    record = evaluate(x)
    return list(getattr(record, "curves", None) or []) if record.ok else []


def observed_fields(operator, n: int) -> dict:
    """``control`` [mm], ``control_names`` and ``quantities`` of a result, from the operator's
    observations (:class:`~fracid.inverse.core.forward_operator.Observation`); empty when it has none or
    they do not hold ``n`` values."""
    observations = list(getattr(operator, "observations", None) or [])
    if not observations or sum(o.size for o in observations) != n:
        return {}
    return {"control": np.concatenate([np.asarray(o.controls, float) for o in observations]),
            "control_names": [str(o.control or getattr(o.specimen, "default_control", "") or "") for o in observations],
            "quantities": [str(getattr(o, "quantity", o.name)) for o in observations]}
