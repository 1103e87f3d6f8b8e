"""The inverse methods: the registry (:mod:`~fracid.inverse.methods.registry`, ``METHODS``), the KNN-started
methods (:mod:`~fracid.inverse.methods.knn_started` and its variants), their building blocks (KNN search, Kalman
filter, Gauss-Newton) and :func:`~fracid.inverse.methods.strategy.identify`.

May import :mod:`fracid.inverse.core` and :mod:`fracid.inverse.likelihood`; never the sampling or the studies.
"""
