"""Identification with an inverse method: :func:`identify` and :func:`identify_data`.

The methods live in their own modules and are registered in :data:`fracid.inverse.methods.METHODS`:
:class:`~fracid.inverse.knn_kalman.KnnKalman` (the default: KNN population search, then the Kalman
filter, docs/theory.md, sections 4.2 to 4.4) and :class:`~fracid.inverse.knn_gauss_newton.KnnGaussNewton`;
they are importable from here too.
"""

from __future__ import annotations

import time
from dataclasses import fields

from fracid.inverse.kalman_status import DEFAULT_MAX_STARTS
from fracid.inverse.knn_gauss_newton import GaussNewtonResult, KnnGaussNewton
from fracid.inverse.knn_kalman import (IdentificationResult, KalmanSettings, KnnKalman, KnnSettings, kalman_progress,
                                       knn_output, knn_record, named_groups, refine)
from fracid.inverse.method import InverseMethod, MethodResult, check_problem
from fracid.inverse.space import ParameterSpace


#: the keywords of :func:`identify` that build the default method, with their defaults
_DEFAULT_METHOD_KEYWORDS = {**{f.name: f.default for f in fields(KnnSettings)},
                            **{f.name: f.default for f in fields(KalmanSettings)}}


def identify(operator, y_exp, C_exp, space: ParameterSpace, *, method: InverseMethod | str | None = None, n=64,
             seed=0, k=5, groups=None, max_iterations=10, tol=0.01, restart="linearize", max_starts=DEFAULT_MAX_STARTS,
             executor=None, store=None, blocks=(), notes=(), progress=None, retry_failed=False) -> MethodResult:
    """Identify the parameters of ``space`` from the data with an inverse method (by default KNN over a
    population for a global overview and the prior, then the Kalman filter to refine).

    Parameters
    ----------
    operator : ForwardOperator
    y_exp, C_exp : ndarray
        Measured data and covariance (e.g. from :mod:`fracid.data`).
    space : ParameterSpace
        Bounds of the estimates (:func:`~fracid.inverse.method.identification_bounds`) and, for the
        default method, of the population.
    method : InverseMethod, str or None
        The inverse method (:class:`~fracid.inverse.method.InverseMethod`). None or a str: the default,
        :class:`KnnKalman` with the settings below; the str is then the design of its population
        (``"sobol"`` when None, ``"lhs"``, ``"grid"``).
    n, seed, k
        KNN population and neighbours of the default method (:class:`KnnSettings`).
    groups, max_iterations, tol, restart, max_starts
        Kalman filter settings of the default method (:class:`KalmanSettings`); ``groups`` may be
        ``"blocks"`` or ``"all"``.
    executor, store
        Parallel execution and the persistent run store.
    progress : None, bool
        Progress bars (None: on a terminal).
    retry_failed : bool
        Run again the runs stored as failed.

    Returns
    -------
    MethodResult
        An :class:`IdentificationResult` for the default method; ``runs["wall_seconds"]`` is the wall
        time of the call [s].

    Raises
    ------
    AllRunsFailed
        Default method: when fewer than k population runs succeeded. A failed run of the Kalman stage
        never raises: see :func:`refine`.
    TypeError, ValueError
        Before any forward run, for arguments that do not fit together
        (:func:`~fracid.inverse.method.check_problem`: the shapes of ``y_exp`` and ``C_exp`` against the
        operator's outputs, the space's names against the operator's), and when ``method`` is an inverse
        method and settings of the default method are given too.
    """
    start = time.perf_counter()
    y_exp, C_exp = check_problem(operator, y_exp, C_exp, space)
    if not (method is None or isinstance(method, str) or callable(method)):
        raise TypeError(f"method is a {type(method).__name__}; give an InverseMethod (e.g. KnnKalman()), a population "
                        "design ('sobol', 'lhs', 'grid') or None")
    given = {"n": n, "seed": seed, "k": k, "groups": groups, "max_iterations": max_iterations, "tol": tol,
             "restart": restart, "max_starts": max_starts}
    if method is None or isinstance(method, str):
        design = {} if method is None else {"method": method}
        method = KnnKalman(KnnSettings(n=n, seed=seed, k=k, **design),
                           KalmanSettings(groups=groups, max_iterations=max_iterations, tol=tol, restart=restart,
                                          max_starts=max_starts))
    else:
        changed = [name for name, value in given.items() if not _is_default(value, _DEFAULT_METHOD_KEYWORDS[name])]
        if changed:
            raise ValueError(f"{', '.join(changed)}: settings of the default method (KNN -> Kalman filter), "
                             f"not of the method {getattr(method, 'name', method)!r} given; give them to the method")
    result = method(operator, y_exp, C_exp, space, executor=executor, store=store, progress=progress,
                    retry_failed=retry_failed, blocks=blocks, notes=notes)
    result.runs["wall_seconds"] = time.perf_counter() - start
    return result


def _is_default(value, default) -> bool:
    if value is default:
        return True
    return isinstance(value, (int, float, str)) and type(value) is type(default) and value == default


def identify_data(operator, data, space: ParameterSpace, **settings) -> MethodResult:
    """:func:`identify` with measured data from :mod:`fracid.data` (its blocks and notes are kept).

    ``data`` is an :class:`~fracid.data.ExperimentalData`; its blocks must line up with the
    operator's observations (same number of values, in order).
    """
    if not all(hasattr(data, attr) for attr in ("y", "covariance", "blocks", "notes")):
        raise TypeError(f"data is a {type(data).__name__}; give fracid.data.ExperimentalData (e.g. from "
                        "fracid.data.with_std), or call identify(operator, y_exp, C_exp, space)")
    if data.y.size != operator.n_outputs:
        raise ValueError(f"the data hold {data.y.size} values but the observations compute {operator.n_outputs}")
    for block, part in zip(data.blocks, operator.slices()):
        name, start, stop = block
        if (start, stop) != (part.start, part.stop):
            raise ValueError(f"data block {name!r} spans [{start}, {stop}) but its observation spans [{part.start}, {part.stop})")
    return identify(operator, data.y, data.covariance, space, blocks=list(data.blocks), notes=list(data.notes), **settings)


__all__ = ["GaussNewtonResult", "IdentificationResult", "KalmanSettings", "KnnGaussNewton", "KnnKalman", "KnnSettings",
           "identify", "identify_data", "kalman_progress", "knn_output", "knn_record", "named_groups", "refine"]
