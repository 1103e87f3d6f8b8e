"""Specimens: what a test is (geometry, mesh, supports, loads, measuring points), as a
:class:`~fracid.specimens.description.Description` that every model builds its problem from.

:data:`SPECIMENS` is the registry the configuration's ``[specimen] type`` reads; each class declares
its ``controls`` (the first is the default), the local ``observables`` its damage models record, its
``characteristic_size`` and ``nominal_section`` (size effect).
"""

from fracid.specimens.bar import BarWithWeakZone
from fracid.specimens.beam import NotchedBeam
from fracid.specimens.dogbone import DogBone
from fracid.specimens.strip import TensionStrip
from fracid.specimens.wedge import WedgeSplitting

SPECIMENS = {"notched-beam": NotchedBeam, "dogbone": DogBone, "bar": BarWithWeakZone, "wedge-splitting": WedgeSplitting}

__all__ = ["BarWithWeakZone", "DogBone", "NotchedBeam", "SPECIMENS", "TensionStrip", "WedgeSplitting"]
