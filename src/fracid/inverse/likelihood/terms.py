"""The error terms applied to an identification: the measurement covariance widened by the mesh's discretisation
error and the model's own error, and the identification run again with it (to a fixed point).

:func:`identify_with_terms` runs the method with the data covariance C_exp (the measurement scatter alone), then
per loop: the discretisation error at the estimate (:mod:`~fracid.inverse.likelihood.discretisation`; once, or
at every loop when its ``iterations`` ask), sigma_m at the estimate
(:mod:`~fracid.inverse.likelihood.model_error`), and the method again with the widened covariance, its local
fit started from the last estimate (a KNN-started method's ``start``: the search and restarts of the first
identification, on the measurement's misfit, are not undone by a term that widens the covariance at a poor
point; restarts stay judged on the measurement's misfit). The loops stop when the estimate moves less than :data:`FIXED_POINT_TOL` of its std. The re-identifications reuse the stored
runs (the population is the same points; a temporary run store when none is given). With a term correlated along
the curves a Kalman filter assimilates one data block per step (its steps assume no correlation between them).

The result is the last identification's (its estimate and covariance with the terms), with the measurement std
as ``std_exp`` and the terms in ``error_terms`` (:func:`~fracid.inverse.likelihood.record.terms_record`).
"""

from __future__ import annotations

import contextlib
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fracid.data.covariance_matrix import as_covariance
from fracid.inverse.core.method import observed_fields
from fracid.inverse.core.method_settings import with_settings
from fracid.inverse.core.runs import StoredOperator
from fracid.inverse.core.sensitivity import exact_sensitivity
from fracid.inverse.likelihood.discretisation import discretisation_error
from fracid.inverse.likelihood.model_error import error_groups, estimate_sigma
from fracid.inverse.likelihood.record import terms_record, widened
from fracid.inverse.likelihood.settings import (FIXED_POINT_TOL, DiscretisationError, ModelError, as_discretisation,
                                                as_model_error)


@dataclass(frozen=True)
class ErrorTerms:
    """The error terms added to the data covariance (None: not added).

    Attributes
    ----------
    discretisation : DiscretisationError or None
    model_error : ModelError or None
    """

    discretisation: DiscretisationError | None = None
    model_error: ModelError | None = None

    @classmethod
    def of(cls, discretisation_error=None, model_error=None) -> "ErrorTerms | None":
        """The terms of the API's arguments (words or settings objects); None when both are off."""
        terms = cls(as_discretisation(discretisation_error), as_model_error(model_error))
        return terms if terms.discretisation or terms.model_error else None

    @property
    def loops(self) -> int:
        """Identifications with the terms at most."""
        return max(getattr(self.discretisation, "iterations", 1), getattr(self.model_error, "iterations", 1))

    @property
    def correlated(self) -> bool:
        """Whether a term correlates the values along a curve (the mesh's error, a model bias)."""
        return self.discretisation is not None or getattr(self.model_error, "kind", "") == "bias"


@dataclass(frozen=True)
class Problem:
    """What the terms are computed on: the operator, the data, their blocks, controls and quantities."""

    operator: object
    y_exp: np.ndarray
    C_exp: object
    space: object
    blocks: list
    control: np.ndarray
    quantities: list

    @classmethod
    def of(cls, operator, y_exp, C_exp, space, blocks=()) -> "Problem":
        """The problem with the operator's blocks and controls where ``blocks`` are not given."""
        y_exp = np.asarray(y_exp, float)
        fields = observed_fields(operator, y_exp.size)
        if not blocks:
            kinds = getattr(operator, "observations", None)
            blocks = ([(k.name, s.start, s.stop) for k, s in zip(kinds, operator.slices())] if fields else
                      [("all", 0, y_exp.size)])
        control = fields.get("control", np.arange(y_exp.size, dtype=float))
        return cls(operator, y_exp, as_covariance(C_exp, y_exp.size, name="C_exp"), space,
                   [tuple(b) for b in blocks], np.asarray(control, float), list(fields.get("quantities", [])))


def identify_with_terms(method, problem: Problem, terms: ErrorTerms, *, executor=None, store=None, progress=None,
                        retry_failed=False, notes=()):
    """Identify with ``method``, then with the data covariance widened by ``terms`` (module docstring).

    Returns
    -------
    MethodResult
        The last identification's result, with ``error_terms`` (per block: measurement, discretisation and
        model-error std; the settings, loops and runs) and ``std_exp`` the measurement std.

    Raises
    ------
    ForwardRunError
        When a run the terms need fails (a refined mesh's).
    """
    with contextlib.ExitStack() as stack:
        store = store if store is not None else _temporary_store(stack)
        options = dict(executor=executor, store=store, progress=progress, retry_failed=retry_failed,
                       blocks=problem.blocks, notes=list(notes))

        def fit(inverse, C):
            return inverse(problem.operator, problem.y_exp, C, problem.space, **options)

        first = fit(method, problem.C_exp)
        return with_error_terms(method, fit, problem, terms, first, store=store, executor=executor,
                                retry_failed=retry_failed)


def with_error_terms(method, fit, problem: Problem, terms: ErrorTerms, first, *, store=None, executor=None,
                     retry_failed=False):
    """The loops of :func:`identify_with_terms` from the identification ``first`` (with C_exp).

    Parameters
    ----------
    method : InverseMethod
        The method of ``first``; with a term correlated along the curves, a Kalman filter refits with one data block
        per step.
    fit : callable(method, C) -> MethodResult
        Identifies with ``method`` and the data covariance ``C`` (e.g. a study's refinement from its population).
    problem : Problem
    terms : ErrorTerms
    first : MethodResult
        The identification with C_exp alone.
    store, executor, retry_failed
        Where the runs of the refined meshes and of the sensitivities at the estimates go.

    Returns
    -------
    MethodResult
        As :func:`identify_with_terms`.
    """
    if not _finite(first):  # no estimate to compute the terms at: the failure's status stands
        first.notes = list(first.notes) + ["error terms not computed: the identification gave no finite estimate"]
        return first
    refit = _by_blocks(method) if terms.correlated else method
    options = {"store": store, "executor": executor, "retry_failed": retry_failed}
    result, loops, disc, computed = _loops(lambda C, x: fit(_started(refit, x), C), problem, terms, first, options)
    result.error_terms = terms_record(problem, terms, first, result, loops, disc, computed)
    result.std_exp = problem.C_exp.std()
    result.notes = list(result.notes) + result.error_terms["notes"]
    return result


def _loops(refit, problem, terms, first, options):
    """The fixed-point loops; returns (last result, the loops' records, the last discretisation term, runs computed)."""
    groups = None if terms.model_error is None else error_groups(
        terms.model_error, problem.blocks, problem.quantities, problem.y_exp, problem.control)
    state, disc, loops, computed = first, None, [], 0
    for loop in range(terms.loops):
        if terms.discretisation is not None and (disc is None or loop < terms.discretisation.iterations):
            disc = discretisation_error(problem.operator, state.x, terms.discretisation, problem.blocks, **options)
            computed += disc.computed
        base, _ = widened(problem.C_exp, problem.blocks, problem.control, error=None if disc is None else disc.error,
                          length=getattr(terms.discretisation, "correlation_length", None))
        sigma = None if groups is None else _sigma(problem, state.x, base, groups, terms.model_error, options)
        _, C = widened(base, problem.blocks, problem.control, sigma=sigma, groups=groups)
        new = refit(C, state.x)
        computed += _computed(new)
        moved = float(np.max(np.abs(np.asarray(new.x) - np.asarray(state.x)) / np.asarray(new.std)))
        loops.append({"loop": loop + 1, "x": np.asarray(new.x).tolist(), "std": np.asarray(new.std).tolist(),
                      "sigma": None if sigma is None else sigma.tolist(), "moved_std": moved,
                      "groups": None if groups is None else groups.names})
        state = new
        if moved <= FIXED_POINT_TOL or not _finite(new):  # converged, or no estimate to compute the terms at
            break
    return state, loops, disc, computed


def _finite(result) -> bool:
    return bool(np.all(np.isfinite(result.x)) and np.all(np.isfinite(result.std)))


def _sigma(problem, x, base, groups, settings, options) -> np.ndarray:
    """sigma_m per group at the estimate x (the run there, with its sensitivities, from the store)."""
    evaluate, sensitivity = exact_sensitivity(StoredOperator(problem.operator, options["store"],
                                                             retry_failed=options["retry_failed"]))
    y, J, _ = sensitivity(evaluate, np.asarray(x, float), None, options["executor"])
    span = np.asarray(problem.space.upper, float) - np.asarray(problem.space.lower, float)
    precision = np.diag(12.0 / span**2)  # the uniform prior over the bounds
    return estimate_sigma(problem.y_exp - np.asarray(y, float), np.asarray(J, float), base, groups, precision, settings)


def _started(method, x):
    """``method`` whose local fit starts from x, the last estimate (when it has such a setting): the search for the
    minimum was done with the measurement covariance, and a model error fitted at a poor point would widen the
    covariance there and hide it (its restarts are still judged on the measurement's misfit)."""
    try:
        return with_settings(method, start=tuple(float(v) for v in x))
    except TypeError:  # no start of its own: the method searches again
        return method


def _by_blocks(method):
    """``method`` with a Kalman filter that assimilates one data block per step (when it has such a setting)."""
    try:
        return with_settings(method, groups="blocks")
    except TypeError:  # no observation groups: it sees the whole covariance at once
        return method


def _computed(result) -> int:
    """Forward runs a result's stages computed (not loaded from the store)."""
    return int(sum(v for k, v in (result.runs or {}).items() if k.endswith("_computed")))


def _temporary_store(stack):
    """A run store in a temporary directory, removed when ``stack`` closes (the re-identifications reuse its runs)."""
    from fracid.store.runs import RunStore

    directory = stack.enter_context(tempfile.TemporaryDirectory(prefix="fracid-terms-"))
    return stack.enter_context(RunStore(Path(directory) / "runs.sqlite"))


__all__ = ["FIXED_POINT_TOL", "ErrorTerms", "Problem", "identify_with_terms", "with_error_terms"]
