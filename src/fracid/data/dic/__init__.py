"""Readers of digital image correlation (DIC) data: per-frame CSV point clouds with a frame table, VTU/VTK
point data, and the camera frame placed on the specimen.

>>> from fracid.data.dic import CameraPlacement
>>> CameraPlacement(scale=0.05).to_specimen([[100.0, 20.0]]).tolist()
[[5.0, 1.0]]

Part of :mod:`fracid.data`: may import what it may (settings, fem, specimens).
"""

from fracid.data.dic.csv_frames import read_dic_frames
from fracid.data.dic.data import DicData
from fracid.data.dic.derived import DerivedBlock, frame_rigid_motions, opening_profile, process_zone_width
from fracid.data.dic.field import FieldBlock, field_block
from fracid.data.dic.placement import CameraPlacement, fit_placement
from fracid.data.dic.vtk_frames import read_dic_vtk

__all__ = ["CameraPlacement", "DerivedBlock", "DicData", "FieldBlock", "field_block", "fit_placement", "frame_rigid_motions",
           "opening_profile", "process_zone_width", "read_dic_frames", "read_dic_vtk"]
