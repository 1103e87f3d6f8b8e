"""Output of analysis results (VTK files for ParaView, the HTML report of an identification;
optional dependencies imported when used)."""

from fracid.report.html import fit_metrics, write_report
from fracid.report.vtk import write_result_vtk, write_vtk

__all__ = ["fit_metrics", "write_report", "write_result_vtk", "write_vtk"]
