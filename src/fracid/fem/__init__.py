"""The finite-element model: material laws, formulations, discretisation, dofs and conditions, solver, path following."""
