"""The report's views of the blocks that are not curves, by name: the registry :data:`VIEWS` and the views of a
result's blocks.

An experiment kind names the view of its blocks (``view`` of :mod:`fracid.inverse.experiments.registry`); the
coordinates of a block (its observation's ``coordinates()``) carry that name under ``"view"``, and
:func:`block_views` builds each with the view of that name. A view is a :class:`View`: the function building a
:class:`~fracid.report.block_view.BlockView` (heading, text, table, figures) and the ``quantities`` of the
blocks it shows (a result's ``quantities`` name them when the coordinates are not at hand). A new view is a
function and one line here (or ``VIEWS[name] = View(...)`` from the user's code); the HTML report
(:func:`fracid.report.html.write_report`) and ``fracid identify``'s figures/ then show it with no other change.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fracid.report.block_view import BlockView
from fracid.report.field_figures import field_heading, field_view
from fracid.report.figures import block_control_labels, float_array, result_blocks


@dataclass(frozen=True)
class View:
    """A view of the report.

    Attributes
    ----------
    build : callable
        ``build(name, coordinates, measured, computed, std, control_label) -> BlockView``: the block's view from
        its coordinates (with ``covariance`` [unit^2] or ``std`` of the noise, optionally) and its measured and
        computed values and data std.
    quantities : tuple of str
        The observed quantities of the blocks it shows (an observation kind's ``quantity``).
    heading : str or callable
        The heading of a block of such a quantity whose coordinates are not given (``"... {name}"``, or a
        function of the block's name).
    missing : str
        The text of such a block (``{name}``, ``{n}`` its values, ``{held}``: "not given" or "given for m values").
    """

    build: Callable
    quantities: tuple = ()
    heading: str | Callable = "Block {name}"
    missing: str = "Block {name!r} ({n} values): its coordinates are {held}, so it is not drawn."


#: view name -> :class:`View`; the first is the default of coordinates that name none
VIEWS = {"displacement-field": View(field_view, quantities=("u",), heading=field_heading,
                       missing="Block {name!r} ({n} values) is a displacement field; its point coordinates are {held}, "
                               "so it is not drawn (a field is no curve against the control). fracid identify draws "
                               "its maps.")}


def _quantity_views(result) -> dict:
    """Block name -> the view name of its quantity (the result's ``quantities``), for the blocks some view shows."""
    quantities = list(getattr(result, "quantities", None) or [])
    by_quantity = {q: name for name, view in VIEWS.items() for q in view.quantities}
    return {name: by_quantity[q] for (name, _, _), q in zip(result_blocks(result), quantities) if q in by_quantity}


def view_block_names(result, fields=None) -> set:
    """Names of the blocks that are not curves: those in ``fields`` and those whose quantity a view shows."""
    return set(_quantity_views(result)) | set(fields or {})


def block_views(result, fields=None, control_label: str | None = None) -> list[BlockView]:
    """The views of the result's non-curve blocks, in the order of the blocks.

    Parameters
    ----------
    result : IdentificationResult
    fields : dict of str -> dict, optional
        Per block name, its coordinates (an observation kind's ``coordinates()``, plus ``view``: a key of
        :data:`VIEWS`, by default the view of the block's quantity, and optionally ``covariance`` or ``std``):
        :func:`fracid.config.build_view_coordinates`.
    control_label : str, optional
        The control axis label; by default from the result's ``control_names``.

    A block without coordinates whose quantity a view shows gets a view of text only: the view needs them.
    """
    fields = fields or {}
    blocks = result_blocks(result)
    labels = block_control_labels(result, len(blocks), control_label)
    by_quantity = _quantity_views(result)
    y_exp, std = float_array(result.y_exp, np.nan), float_array(result.std_exp, np.nan)
    y_fit = float_array(result.y_fit, np.nan) if result.y_fit is not None else np.full_like(y_exp, np.nan)
    views = []
    for (name, start, stop), label in zip(blocks, labels):
        info = fields.get(name)
        if info is None and name not in by_quantity:
            continue
        view = VIEWS[(info or {}).get("view") or by_quantity.get(name) or next(iter(VIEWS))]
        if info is None or _entries(info) != stop - start:
            held = "not given" if info is None else f"given for {_entries(info)} values"
            heading = view.heading(name) if callable(view.heading) else view.heading.format(name=name)
            views.append(BlockView(name, heading,
                                   view.missing.format(name=name, n=stop - start, held=held)))
            continue
        views.append(view.build(name, info, y_exp[start:stop], y_fit[start:stop], std[start:stop], label))
    return views


def block_views_and_skipped(result, fields=None, views=None, control_label: str | None = None) -> tuple[list, set]:
    """The views of the non-curve blocks (``views`` when given, else :func:`block_views`) and the names of the
    blocks the curve figure and table leave out (:func:`view_block_names` and the views' blocks)."""
    views = block_views(result, fields, control_label) if views is None else list(views)
    return views, view_block_names(result, fields) | {view.block for view in views}


def _entries(coordinates: dict) -> int:
    """The number of entries the coordinates describe (every observation kind's give ``control``)."""
    return len(np.asarray(coordinates["control"] if "control" in coordinates else coordinates["frame"]))


__all__ = ["VIEWS", "View", "block_views", "block_views_and_skipped", "view_block_names"]
