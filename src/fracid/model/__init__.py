"""The forward model: material laws, elements, assembly, linear and nonlinear solvers."""
