"""The registry of inverse methods: the names ``[identify] method`` accepts, each with its class.

Every class is a frozen dataclass of its settings (``KnnKalman(knn=KnnSettings(...),
kalman=KalmanSettings(...))``, ``KnnGaussNewton(knn=KnnSettings(...), max_iterations=..., tol=...)``)
with a ``name`` that is its key here and the ``stages`` it runs (stage name -> label, the keys of its
counters and records in the result, the report's sections). A method meets
:class:`~fracid.inverse.method.InverseMethod` (``fracid identify``); one that also meets
:class:`StudyMethod` runs every check of ``fracid study`` through its own stages.

A new method is a class and one line here (or ``METHODS[name] = cls`` from the user's code); its
settings come from ``[identify.<name>]`` of the configuration through its ``from_config`` class method
(see :func:`fracid.config.build_method`).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from fracid.inverse.knn_gauss_newton import KnnGaussNewton
from fracid.inverse.knn_kalman import KnnKalman


@runtime_checkable
class StudyMethod(Protocol):
    """What :func:`~fracid.inverse.study.run_study` asks of a method besides calling it.

    ``search(operator, y_exp, C_exp, space, *, executor, store, progress, stats, retry_failed)``
        The global stage: a :class:`~fracid.inverse.knn.KnnResult` (population, ranking, prior x0 and
        C0); the study's objective maps, valley and multi-start points come from it.
    ``refine(operator, y_exp, C_exp, overview, *, C0, executor, blocks, notes, progress)``
        The local stage from the overview's prior (covariance ``C0`` when given): the
        :class:`~fracid.inverse.method.MethodResult` of the identification.
    ``fit_from(evaluate, y_exp, C_exp, x0, C0, *, bounds, executor, blocks)``
        The local stage alone from a prior (x0, C0): a fit with ``x``, ``std``, ``y``, ``failed`` and
        ``status``, for the multi-start check and the noisy replicates.
    """

    name: str
    stages: dict

    def search(self, operator, y_exp, C_exp, space, **options): ...

    def refine(self, operator, y_exp, C_exp, overview, **options): ...

    def fit_from(self, evaluate, y_exp, C_exp, x0, C0, **options): ...


#: inverse method name -> its class; the first is the default
METHODS = {KnnKalman.name: KnnKalman, KnnGaussNewton.name: KnnGaussNewton}

#: the default inverse method's name
DEFAULT_METHOD = KnnKalman.name


def method_stages(name: str) -> dict:
    """The stages (name -> label) of the registered method ``name``; empty for an unknown name."""
    cls = METHODS.get(name)
    return dict(getattr(cls, "stages", None) or {})


__all__ = ["DEFAULT_METHOD", "METHODS", "KnnGaussNewton", "KnnKalman", "StudyMethod", "method_stages"]
