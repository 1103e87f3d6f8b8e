"""The discretisation: elements and their shape functions, the mesh's scalar spaces, the dof map of the
displacement and the named scalar fields, assembly, the probe operator (shape functions at points) and level
sets.

May import :mod:`fracid.fem.material`; never the formulations or the path.
"""
