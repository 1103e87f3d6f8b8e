"""The registry of inverse methods: the names ``[identify] method`` accepts, each with its
:class:`~fracid.inverse.method.InverseMethod` class.

Every class is a frozen dataclass of its settings (``KnnKalman(knn=KnnSettings(...),
kalman=KalmanSettings(...))``, ``KnnGaussNewton(knn=KnnSettings(...), max_iterations=..., tol=...)``)
with a ``name`` that is its key here; :func:`fracid.config.build_method` builds the configured one.
"""

from __future__ import annotations

from fracid.inverse.strategy import KnnGaussNewton, KnnKalman

#: inverse method name -> its class; the first is the default
METHODS = {KnnKalman.name: KnnKalman, KnnGaussNewton.name: KnnGaussNewton}

__all__ = ["METHODS", "KnnGaussNewton", "KnnKalman"]
