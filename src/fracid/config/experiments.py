"""Validation of the ``[[experiments]]`` blocks: each read and checked by its kind
(:data:`fracid.inverse.experiments.registry.EXPERIMENTS`), with this file's checker and what the kinds need of
the rest of the configuration (the specimen, its observables and the per-experiment overrides of
``[specimen]``)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from fracid.config.checker import Checker
from fracid.config.registry import specimen_class, specimen_observables
from fracid.config.schema import SpecimenConfig
from fracid.config.sections import check_specimen, check_specimen_size, specimen_options
from fracid.inverse.experiments.registry import ReadContext, read_experiments as read_blocks


def _overrides(ck: Checker, prefix: str, raw: dict, specimen: SpecimenConfig) -> tuple:
    """The block's ``specimen`` overrides ((field, value), ...), checked with the rest of ``[specimen]``."""
    cls = specimen_class(specimen.type)
    if "specimen" in raw and cls.config_section is not None:
        ck.fail(f"{prefix}.specimen", raw["specimen"], f"a {specimen.type} specimen (read by its own [specimen] "
                "section) takes no per-experiment overrides yet; run the experiments of different specimens from "
                "configurations of their own")
    if "specimen" not in raw:
        return ()
    fields = [f.name for f in dataclasses.fields(cls)]
    given = specimen_options(ck, f"{prefix}.specimen", ck.table(f"{prefix}.specimen", raw["specimen"], fields), cls)
    check_specimen(ck, f"{prefix}.specimen", specimen.type, cls, {**dict(specimen.options), **given}, given)
    check_specimen_size(ck, f"{prefix}.specimen", specimen.type, cls, {**dict(specimen.options), **given}, given)
    return tuple(given.items())


def read_experiments(ck: Checker, raw, base: Path, specimen: SpecimenConfig, needed: bool) -> tuple:
    """The validated ``[[experiments]]`` blocks in order, each by its kind (the blocks derived from another
    kind's checked last, on those blocks as read: :func:`fracid.inverse.experiments.registry.read_experiments`)."""
    if raw is None:
        if needed:
            ck.missing("experiments", "one or more [[experiments]] blocks (data files) for identification")
        return ()
    if not isinstance(raw, list) or not raw:
        ck.fail("experiments", raw, "must be one or more [[experiments]] tables")
    context = ReadContext(base=base, specimen=lambda: specimen_class(specimen.type)(**dict(specimen.options)),
                          observables=lambda: specimen_observables(specimen),
                          overrides=lambda ck_, prefix, block: _overrides(ck_, prefix, block, specimen))
    return read_blocks(ck, raw, context)
