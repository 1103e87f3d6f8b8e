"""Identification of a model's parameters from data, in sub-packages on floors (each imports only those below
it, and :mod:`fracid.settings`, :mod:`fracid.fem`, :mod:`fracid.specimens`, :mod:`fracid.models`,
:mod:`fracid.data`, :mod:`fracid.store` and :mod:`fracid.runtime`; never the report, the configuration or the
command):

:mod:`~fracid.inverse.core` (the forward operator, observations, parameter space, the method's interface and
result, the kinds of stage records) < :mod:`~fracid.inverse.likelihood` (error terms of the data covariance) <
:mod:`~fracid.inverse.methods` (the registered inverse methods and :func:`~fracid.inverse.methods.strategy.identify`)
< :mod:`~fracid.inverse.sampling` (the posterior) < :mod:`~fracid.inverse.studies` (studies and checks built on
the methods' stages).
"""
