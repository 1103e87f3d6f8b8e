"""Specimens: what a test is (geometry, mesh, supports, loads, measuring points), as a
:class:`~fracid.specimens.description.Description` that every model builds its problem from.

:data:`SPECIMENS` is the registry the configuration's ``[specimen] type`` reads; each class declares
what :class:`~fracid.specimens.protocol.Specimen` asks (its control names, the first the default,
the local ``observables`` its damage models record, its defaults, the field a size-effect series
scales, the limits of its mesh and its refined mesh, ``refined(factor)``); a size-effect specimen also has ``characteristic_size`` and
``nominal_section``. Every specimen is registered alike: the built-in geometries, the tension strip
and the user's own mesh (``"mesh"``, read from a Gmsh file). A specimen declares the control that follows a
snap-back (``snap_back_control``) and, when its ``[specimen]`` table is not its dataclass fields, the reader of
that table (``config_section``, a :class:`~fracid.specimens.protocol.SpecimenSection`).

The package may import :mod:`fracid.fem` and :mod:`fracid.settings` only (floor 1).
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

def snap_back_control(control: str, functionals) -> str | None:
    """The control to use instead of ``control`` when the curve snaps back under it, or None.

    Parameters
    ----------
    control : str
        The control the analysis failed under.
    functionals : iterable of str
        The functionals of the failed problem: the specimen is the registered one (:data:`SPECIMENS`) whose
        controls are all among them and include ``control``, and its declared ``snap_back_control`` the answer
        (None for a specimen that declares none, e.g. one's own mesh, or when ``control`` is already the one
        that follows snap-back).
    """
    names = set(functionals)
    for kind in SPECIMENS.values():
        indirect = kind.snap_back_control
        if indirect is not None and control in kind.controls and set(kind.controls) <= names and indirect != control:
            return indirect
    return None


__all__ = ["BarWithWeakZone", "DogBone", "MeshSpecimen", "NotchedBeam", "Specimen", "SPECIMENS",
           "TensionStrip", "WedgeSplitting", "snap_back_control"]
