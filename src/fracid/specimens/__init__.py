"""Specimens: what a test is (geometry, mesh, supports, loads, measuring points), as a
:class:`~fracid.specimens.description.Description` that every model builds its problem from.

:data:`SPECIMENS` is the registry the configuration's ``[specimen] type`` reads; each class declares
what :class:`~fracid.specimens.protocol.Specimen` asks (its control names, the first the default,
the local ``observables`` its damage models record, its defaults, the field a size-effect series
scales and the limits of its mesh); a size-effect specimen also has ``characteristic_size`` and
``nominal_section``. Every specimen is registered alike: the built-in geometries, the tension strip
and the user's own mesh (``"mesh"``, read from a Gmsh file).
"""

from fracid.specimens.bar import BarWithWeakZone
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.dogbone import DogBone
from fracid.specimens.mesh import MeshSpecimen
from fracid.specimens.protocol import Specimen
from fracid.specimens.strip import TensionStrip
from fracid.specimens.wedge import WedgeSplitting

SPECIMENS = {"notched-beam": NotchedBeam, "dogbone": DogBone, "bar": BarWithWeakZone, "wedge-splitting": WedgeSplitting,
             "strip": TensionStrip, "mesh": MeshSpecimen}

#: the control of each specimen that grows through a snap-back (an opening across the crack)
SNAP_BACK_CONTROLS = {NotchedBeam: "cmod", BarWithWeakZone: "weak_zone_elongation", DogBone: "elongation",
                      TensionStrip: "band_opening", WedgeSplitting: "cmod"}


def snap_back_control(control: str, functionals) -> str | None:
    """The control to use instead of ``control`` when the curve snaps back under it, or None.

    Parameters
    ----------
    control : str
        The control the analysis failed under.
    functionals : iterable of str
        The functionals of the failed problem: the specimen is the one whose controls are all among
        them and include ``control`` (None for a specimen of one's own mesh, or when ``control`` is
        already the one that follows snap-back).
    """
    names = set(functionals)
    for kind, indirect in SNAP_BACK_CONTROLS.items():
        if control in kind.controls and set(kind.controls) <= names and indirect != control:
            return indirect
    return None


__all__ = ["BarWithWeakZone", "DogBone", "MeshSpecimen", "NotchedBeam", "Specimen", "SNAP_BACK_CONTROLS", "SPECIMENS",
           "TensionStrip", "WedgeSplitting", "snap_back_control"]
