"""The check of an identification's arguments before any forward run: operator, data, covariance and space.

:func:`check_problem` is what every inverse method calls first (re-exported by
:mod:`fracid.inverse.core.method`); it returns the data covariance as a
:class:`~fracid.data.covariance_matrix.Covariance`, so that nothing downstream forms an n x n matrix
when it is diagonal, low-rank or block diagonal.
"""

from __future__ import annotations

import numpy as np

from fracid.data.covariance_matrix import Covariance, as_covariance


def _float_array(name: str, value) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name} is a {type(value).__name__} that is not an array of numbers") from None
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} holds {int(np.sum(~np.isfinite(array)))} NaN or infinite values; every entry "
                         "must be a finite number")
    return array


def _check_space(operator, space) -> None:
    if not all(hasattr(space, attr) for attr in ("names", "lower", "upper", "log")):
        raise TypeError(f"space is a {type(space).__name__}; give a fracid.inverse.core.space.ParameterSpace(names, lower, "
                        "upper): the identified parameters and their bounds")
    names = getattr(operator, "names", None)
    if names is not None and tuple(space.names) != tuple(names):
        raise ValueError(f"the space's parameters {list(space.names)} are not the operator's identified parameters "
                         f"{list(names)}: give the same names in the same order")


def check_problem(operator, y_exp, C_exp, space) -> tuple[np.ndarray, np.ndarray]:
    """Check the arguments of an identification before any forward run.

    Parameters
    ----------
    operator : ForwardOperator or callable
        Its ``n_outputs`` (when it has one) sets the size of y; its ``names`` (when it has them) must
        be the space's.
    y_exp : array_like
        Measured values, shape (n,) [units of y].
    C_exp : array_like or Covariance
        Their covariance [units of y squared]: an (n, n) symmetric positive definite array or a
        :class:`~fracid.data.covariance_matrix.Covariance` of n values.
    space : ParameterSpace

    Returns
    -------
    y_exp : ndarray
        As a float array.
    C_exp : Covariance
        A :class:`~fracid.data.covariance_matrix.Diagonal` when the array is diagonal (no n x n matrix
        downstream), else as given or :class:`~fracid.data.covariance_matrix.Dense`; it reads as an array
        (``np.asarray(C_exp)``) while n is small.

    Raises
    ------
    TypeError
        An operator that is not callable, a space that is not a ParameterSpace, values that are not numbers.
    ValueError
        Shapes that do not match the operator's outputs, non-finite values, a covariance that is not
        symmetric positive definite, parameter names that differ from the operator's.
    """
    if not callable(operator):
        raise TypeError(f"operator is a {type(operator).__name__}; give a ForwardOperator "
                        "(fracid.inverse.core.forward_operator) or a callable x -> run record")
    _check_space(operator, space)
    y = _float_array("y_exp", y_exp)
    n = int(getattr(operator, "n_outputs", y.size))
    if y.shape != (n,):
        raise ValueError(f"y_exp has shape {y.shape}, but the operator computes {n} values: give a vector of {n} "
                         "measured values, in the order of its observations")
    return y, _check_covariance(C_exp, n)


def _check_covariance(C_exp, n: int) -> Covariance:
    """C_exp as a :class:`~fracid.data.covariance_matrix.Covariance` of n values: a covariance object, or an
    (n, n) array (a 1-D array is refused: standard deviations and variances are too easily confused)."""
    if not isinstance(C_exp, Covariance):
        C = _float_array("C_exp", C_exp)
        if C.shape != (n, n):
            raise ValueError(f"C_exp has shape {C.shape}, but the covariance of {n} measured values has shape "
                             f"({n}, {n}) (from standard deviations: np.diag(std**2), or for many values "
                             "fracid.data.covariance_matrix.Diagonal(std**2))")
        C_exp = C
    return as_covariance(C_exp, n, name="C_exp")


__all__ = ["check_problem"]
