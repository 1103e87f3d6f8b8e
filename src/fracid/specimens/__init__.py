"""Specimens: geometry, mesh, boundary conditions, load and observables."""

from fracid.specimens.bar import BarWithWeakZone

__all__ = ["BarWithWeakZone"]
