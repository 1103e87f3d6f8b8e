"""The likelihood's error terms beyond the measurement scatter (issue 28): the mesh's discretisation error and the
model's own error, added to the data covariance of an identification and of its posterior.

One module per concept: :mod:`~fracid.inverse.likelihood.settings` (the settings and their ``[identify]`` keys),
:mod:`~fracid.inverse.likelihood.correlation` (errors correlated along the control: low-rank kernel modes),
:mod:`~fracid.inverse.likelihood.discretisation` (Richardson extrapolation from refined meshes at the estimate),
:mod:`~fracid.inverse.likelihood.model_error` (sigma_m identified with the parameters),
:mod:`~fracid.inverse.likelihood.marginal` (sigma_m integrated out per posterior draw),
:mod:`~fracid.inverse.likelihood.terms` (the identification with the terms, to a fixed point) and
:mod:`~fracid.inverse.likelihood.record` (what a result keeps of them, and the covariances rebuilt from it).
The covariance objects are :mod:`fracid.data.covariance_update`'s.

>>> from fracid.inverse.methods.strategy import identify_data
>>> result = identify_data(operator, data, space, discretisation_error="richardson",
...                        model_error="variance")                      # doctest: +SKIP
>>> result.error_terms["blocks"]                                       # doctest: +SKIP

May import :mod:`fracid.inverse.core` (and the data's covariance objects); never the methods, the sampling or the
studies (the method it re-identifies with is given to it).
"""
