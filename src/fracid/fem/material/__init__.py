"""The material at a point: pure functions over arrays of all quadrature points. Elasticity, equivalent
strains, damage and its softening laws (:mod:`~fracid.fem.material.laws`), the traction-separation laws
(:mod:`~fracid.fem.material.tsl`), the cohesive crack's and the crack band's functions, the PF-CZM's
functions and its exact 1D law, and the parameter classes composed from ranged parts
(:mod:`~fracid.fem.material.ranges`).

The lowest floor of :mod:`fracid.fem`: imports only :mod:`fracid.settings`.
"""
