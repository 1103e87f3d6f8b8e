"""The nonlinear solution: Newton on the bordered system, path following by indirect (arc-length) control
to :class:`~fracid.fem.path.path_following.PathResult`, the recorder, direct differentiation of the path
(:mod:`~fracid.fem.path.ddm`) and the linear solvers (SciPy, PARDISO).

The top floor of :mod:`fracid.fem`: may import the material, the mesh and the formulations.
"""
