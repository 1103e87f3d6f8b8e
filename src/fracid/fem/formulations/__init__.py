"""The boundary-value problems: the :class:`~fracid.fem.formulations.protocol.Problem` protocol (its history
declared by the formulation), gradient, local and integral damage, the crack band, the cohesive interface,
the PF-CZM, their weak forms and parameter sensitivities, and the process-zone width.

May import :mod:`fracid.fem.material` and :mod:`fracid.fem.mesh`; never the path.
"""
