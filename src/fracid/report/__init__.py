"""Output of analysis results (VTK files for ParaView; optional dependencies imported when used)."""

from fracid.report.vtk import bar_mesh, write_result_vtk, write_vtk

__all__ = ["bar_mesh", "write_result_vtk", "write_vtk"]
