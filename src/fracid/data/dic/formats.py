"""The layouts of DIC codes' exports that fracid reads by name: columns, unit and the rule for failed points.

A field block names its export's layout with ``format``; its columns become the defaults of the column keys
(``x``, ``y``, ``u``, ``v``, ``sigma``), which the configuration may still override, its unit the default of
``coordinate_unit``. Only layouts documented by their makers are here, each with its source; any other export
(VIC-2D/3D, GOM/ZEISS Correlate, MatchID, muDIC, Ncorr saved to CSV...) is read through the generic layout
with its columns named in the configuration (docs/dic/README.md, "Formats": muDIC pickles its objects, which
fracid does not load; Ncorr saves MATLAB v7.3 files, HDF5 that scipy.io cannot read).

- ``generic``: fracid's own CSV point clouds (``X, Y, U, V``, optional sigma and quality columns named by the
  keys), in the unit the configuration gives.
- ``dice``: the solution files of DICe, the Digital Image Correlation Engine (Sandia National Laboratories;
  github.com/dicengine/dice, commit 5ebcdfaf, ``src/core/DICe_Schema.cpp``: ``Output_Spec::write_header``
  writes ``SUBSET_ID`` then the field names, ``write_frame`` every value as ``%4.4E``, the delimiter the
  user's (a comma in the GUI's exports); ``Schema::record_failed_step`` sets ``SIGMA`` (and GAMMA, BETA) to -1
  for a subset whose correlation failed, its ``STATUS_FLAG`` the reason: ``src/base/DICe.h`` ``enum
  Status_Flag``). Coordinates and displacements in pixels (the image's), ``SIGMA`` the predicted displacement
  std in pixels. An optional block of ``***`` information lines above the header is skipped. A subset with
  SIGMA < 0 is a failed one: its values are dropped at that frame and counted in a note.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["FORMATS", "DicFormat"]


@dataclass(frozen=True)
class DicFormat:
    """A DIC code's export layout.

    Attributes
    ----------
    name : str
        The ``format`` key's value.
    columns : dict
        Default column names of "x", "y", "u", "v", "sigma" (None: none).
    unit : str or None
        The unit the code writes ("px" or "mm"); None: the configuration's ``coordinate_unit``.
    failed_sigma : bool
        A negative sigma marks a failed point (dropped and counted) rather than an error.
    source : str
        Where the layout is documented.
    """

    name: str
    columns: dict
    unit: str | None
    failed_sigma: bool
    source: str


FORMATS = {
    "generic": DicFormat("generic", {"x": "X", "y": "Y", "u": "U", "v": "V", "sigma": None}, None, False,
                         "fracid's CSV point clouds (docs/dic/README.md)"),
    "dice": DicFormat("dice", {"x": "COORDINATE_X", "y": "COORDINATE_Y", "u": "DISPLACEMENT_X",
                               "v": "DISPLACEMENT_Y", "sigma": "SIGMA"}, "px", True,
                      "DICe solution files (github.com/dicengine/dice 5ebcdfaf: src/core/DICe_Schema.cpp "
                      "Output_Spec, Schema::record_failed_step; src/base/DICe.h Status_Flag)"),
}
