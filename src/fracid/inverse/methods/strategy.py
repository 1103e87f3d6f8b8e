"""Identification with an inverse method: :func:`identify` and :func:`identify_data`.

The methods live in their own modules and are registered in :data:`fracid.inverse.methods.registry.METHODS`:
:class:`~fracid.inverse.methods.knn_kalman.KnnKalman` (the default: KNN population search, then the Kalman
filter, docs/theory.md, sections 4.2 to 4.4) and :class:`~fracid.inverse.methods.knn_gauss_newton.KnnGaussNewton`.
"""

from __future__ import annotations

import time

from fracid.inverse.core.method import InverseMethod, MethodResult, check_problem
from fracid.inverse.core.method_settings import with_settings
from fracid.inverse.methods.registry import DEFAULT_METHOD, METHODS
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.likelihood.terms import ErrorTerms, Problem, identify_with_terms


def identify(operator, y_exp, C_exp, space: ParameterSpace, *, method: InverseMethod | str | None = None,
             executor=None, store=None, blocks=(), notes=(), progress=None, retry_failed=False,
             discretisation_error=None, model_error=None, **settings) -> MethodResult:
    """Identify the parameters of ``space`` from the data with an inverse method (by default KNN over a
    population for a global overview and the prior, then the Kalman filter to refine).

    Parameters
    ----------
    operator : ForwardOperator
    y_exp, C_exp : ndarray or covariance
        Measured data and covariance (e.g. from :mod:`fracid.data`).
    space : ParameterSpace
        Bounds of the estimates (:func:`~fracid.inverse.core.method.identification_bounds`) and, for the
        KNN-started methods, of the population.
    method : InverseMethod, str or None
        The inverse method (:class:`~fracid.inverse.core.method.InverseMethod`), or the name of a registered one
        (:data:`~fracid.inverse.methods.registry.METHODS`, its default settings); None: ``"knn-kalman"``.
    executor, store
        Parallel execution and the persistent run store.
    progress : None, bool
        Progress bars (None: on a terminal).
    retry_failed : bool
        Run again the runs stored as failed.
    discretisation_error : None, "off", "richardson" or DiscretisationError
        Add the mesh's discretisation error at the estimate to the data covariance (Richardson extrapolation
        from a refined mesh, :mod:`fracid.inverse.likelihood.discretisation`) and identify again.
    model_error : None, "off", "variance", "bias" or ModelError
        Identify the model's own error (a std per data block, :mod:`fracid.inverse.likelihood.model_error`)
        with the parameters, to a fixed point. With either term the result's ``error_terms`` reports them
        (:mod:`fracid.inverse.likelihood.terms`); the re-identifications reuse the stored runs.
    **settings
        Settings of the method by their own names (:func:`~fracid.inverse.core.method_settings.with_settings`), e.g.
        ``n=16, k=3`` of its KNN population, ``groups="all", max_iterations=8`` of its Kalman filter.

    Returns
    -------
    MethodResult
        The method's result (:class:`~fracid.inverse.methods.knn_kalman.IdentificationResult` for the default); ``runs["wall_seconds"]`` is the
        wall time of the call [s].

    Raises
    ------
    AllRunsFailed
        KNN-started methods: when fewer than k population runs succeeded. A failed run of their local stage
        never raises (:meth:`~fracid.inverse.methods.knn_started.KnnStarted.refine`).
    TypeError, ValueError
        Before any forward run, for arguments that do not fit together
        (:func:`~fracid.inverse.core.method.check_problem`: the shapes of ``y_exp`` and ``C_exp`` against the
        operator's outputs, the space's names against the operator's), an unknown method name and settings
        the method does not have.
    """
    start = time.perf_counter()
    y_exp, C_exp = check_problem(operator, y_exp, C_exp, space)
    method = with_settings(_method(method), **settings)
    terms = ErrorTerms.of(discretisation_error, model_error)
    if terms is not None:
        result = identify_with_terms(method, Problem.of(operator, y_exp, C_exp, space, blocks), terms,
                                     executor=executor, store=store, progress=progress, retry_failed=retry_failed,
                                     notes=notes)
    else:
        result = method(operator, y_exp, C_exp, space, executor=executor, store=store, progress=progress,
                        retry_failed=retry_failed, blocks=blocks, notes=notes)
    result.runs["wall_seconds"] = time.perf_counter() - start
    return result


def _method(method):
    """The inverse method ``method`` names (a key of METHODS; None: the default) or is."""
    if method is None or isinstance(method, str):
        name = DEFAULT_METHOD if method is None else method
        if name not in METHODS:
            raise ValueError(f"method = {method!r}: not a registered inverse method; choose one of "
                             f"{', '.join(map(repr, METHODS))} or give an InverseMethod object")
        return METHODS[name]()
    if not callable(method):
        raise TypeError(f"method is a {type(method).__name__}; give an InverseMethod (e.g. KnnKalman()), the name "
                        f"of a registered one ({', '.join(map(repr, METHODS))}) or None")
    return method


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


__all__ = ["identify", "identify_data"]
