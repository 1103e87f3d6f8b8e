"""The finite-element model: material laws, formulations, discretisation, dofs and conditions, solver, path following.

A straight stack: :mod:`~fracid.fem.material` < :mod:`~fracid.fem.mesh` < :mod:`~fracid.fem.formulations` <
:mod:`~fracid.fem.path`. Imports nothing of fracid above it but :mod:`fracid.settings`."""
