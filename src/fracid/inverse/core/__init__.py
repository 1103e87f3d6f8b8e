"""What every inverse method and study builds on: the forward operator and its observations, the parameter
space, the misfit, sensitivities, stored runs, the method's interface and result (:mod:`~fracid.inverse.core.method`)
with the kinds of record its stages leave (:mod:`~fracid.inverse.core.stage_records`), and the plans of their runs.

The lowest floor of :mod:`fracid.inverse`: imports no other sub-package of it.
"""
