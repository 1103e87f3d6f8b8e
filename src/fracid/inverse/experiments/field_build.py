"""The field block of a configuration's ``[[experiments]] kind = "field"``, built once per process.

:func:`placed_field_block` reads the frames (:func:`fracid.data.dic.read_dic_frames`, the block's format, columns,
unit and placement), synchronises them with the machine log when there is one
(:mod:`fracid.inverse.experiments.field_log`), locates the points on the specimen's mesh (the few outside dropped:
:mod:`fracid.inverse.experiments.field_on_mesh`), keeps the region away from the crack and builds the block
(:func:`fracid.data.dic.field_block`); :func:`field_synchronisation` gives the synchronised frames of the same
build (:mod:`fracid.inverse.experiments.built_once`).
"""

from __future__ import annotations

from dataclasses import replace

from fracid.data.dic.formats import FORMATS
from fracid.inverse.experiments.built_once import built_once
from fracid.inverse.experiments.crack_region import away_from_crack
from fracid.inverse.experiments.field_log import frame_table_columns, synchronise_frames


def placed_field_block(exp, specimen) -> tuple:
    """(the field block, its warnings): its points located on the specimen's mesh (the few outside dropped,
    :func:`~fracid.inverse.experiments.field_on_mesh.points_on_mesh`), its frames without a value dropped; built
    once per process for the same configuration, specimen and files
    (:func:`~fracid.inverse.experiments.built_once.built_once`)."""
    return built_once(replace(exp, n_points=0), specimen, _build_placed_field_block)[:2]


def field_synchronisation(exp, specimen):
    """The frames synchronised with the machine log (:class:`~fracid.data.dic.synchronise.SynchronisedFrames`) of
    the block built once, or None without a log."""
    return built_once(replace(exp, n_points=0), specimen, _build_placed_field_block)[2]


def _build_placed_field_block(exp, specimen) -> tuple:
    from fracid.data.dic import field_block as block_of, read_dic_frames
    from fracid.inverse.experiments.field_on_mesh import points_on_mesh

    dic = read_dic_frames(exp.file, **dict(exp.columns), min_quality=exp.min_quality,
                          coordinate_unit=exp.coordinate_unit,
                          load_columns=frame_table_columns(exp.log, exp.control_column),
                          placement=exp.placement, file_column=exp.file_column, delimiter=exp.delimiter,
                          decimal=exp.decimal, failed_sigma=FORMATS[exp.format].failed_sigma)
    sync_warnings, synced = [], None
    if exp.log is not None:
        dic, synced = synchronise_frames(dic, exp.log, exp.frames)
        sync_warnings = [note.removeprefix("WARNING: ") for note in synced.times.notes if note.startswith("WARNING: ")]
    inside, dropped = points_on_mesh(specimen, dic.points, exp.placement)
    away = away_from_crack(specimen, exp.exclude_near)
    region = inside if away is None else (lambda points: inside & away(points))
    block = block_of(dic, exp.frames, exp.components, control=exp.control_column, std=exp.std,
                     subset_size=exp.subset_size, rigid_std=exp.rigid_std, region=region,
                     point_spacing=exp.point_spacing, name=exp.name)
    notes = [note.removeprefix("WARNING: ") for note in block.data.notes if note.startswith("WARNING: field ")]
    return block, [*([dropped] if dropped else []), *sync_warnings, *notes], synced


__all__ = ["field_synchronisation", "placed_field_block"]
