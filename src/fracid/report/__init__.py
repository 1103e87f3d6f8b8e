"""Output of analysis results (VTK files for ParaView, the HTML report of an identification;
optional dependencies imported when used).

The report draws a method's stages by the kind of record each leaves (:mod:`~fracid.report.stages`,
:mod:`~fracid.report.stage_figures`) and a data block by the view its experiment kind names
(:mod:`~fracid.report.views`), so it names no method, stage or kind. May import every package below it
(settings, fem, specimens, models, data, store, runtime, inverse); never the configuration or the command.
"""

from fracid.report.html import fit_metrics, write_report
from fracid.report.vtk import write_result_vtk, write_vtk

__all__ = ["fit_metrics", "write_report", "write_result_vtk", "write_vtk"]
