"""The registry of experiment kinds: the values ``[[experiments]] kind`` accepts, each with its kind object.

A kind is an object meeting :class:`ExperimentKind`. It declares its configuration keys (``keys``; a curve
kind also its data ``column_keys``), reads and checks its own table (``read``, with the checker the
configuration passes in, :class:`TableChecker`: every message names the key and the value), builds the
block's :class:`~fracid.data.experimental.ExperimentalData` (``data``) and its observation kind
(``observation``), names the report view its blocks need (``view``: a name of the report's views, None for a
curve, which the fit figure draws), and, for a kind derived from another, the kind of its source (``source``).
The validated block (what ``read`` returns) says whether it measures a force (``measures_force``).

A new kind is an object and one line here (or ``EXPERIMENTS[name] = kind`` from the user's code:
``tests/test_extension_experiment.py``). The configuration (:mod:`fracid.config`) and the command iterate this
registry and name no kind.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Protocol, runtime_checkable

from fracid.inverse.experiments.curves import ENVELOPE, REPEATS, SINGLE
from fracid.inverse.experiments.derived import FPZ_WIDTH, OPENING
from fracid.inverse.experiments.field import FIELD


class TableChecker(Protocol):
    """The checker a kind reads its table with (:class:`fracid.config.checker.Checker` meets it): each method
    returns the value checked or raises the configuration's error naming the dotted ``key``, the value and
    what is ``allowed`` (the checkers of :mod:`fracid.settings.checks`, the file named)."""

    def fail(self, key: str, value, allowed: str): ...

    def missing(self, key: str, allowed: str): ...

    def warn(self, text: str) -> None: ...

    def table(self, key: str, value, allowed_keys) -> dict: ...

    def number(self, key: str, value, allowed: str = ..., ok=...) -> float: ...

    def integer(self, key: str, value, allowed: str = ..., ok=...) -> int: ...

    def string(self, key: str, value, allowed: str = ...) -> str: ...

    def choice(self, key: str, value, choices) -> str: ...

    def pair(self, key: str, value, allowed: str) -> tuple: ...

    def strings(self, key: str, value, what: str = ...) -> tuple: ...

    def file(self, key: str, value, base: Path) -> Path: ...


@dataclass(frozen=True)
class ReadContext:
    """What a kind's ``read`` needs besides its table.

    Attributes
    ----------
    base : Path
        The configuration file's directory (relative file names are resolved against it).
    specimen : callable
        ``specimen()``: the specimen object of ``[specimen]`` (no per-experiment overrides).
    observables : callable
        ``observables()``: the local observables of the specimen [mm] (a curve's ``quantity`` besides "force").
    overrides : callable
        ``overrides(ck, prefix, raw)``: the block's ``specimen`` overrides ((field, value), ...), checked.
    kinds : tuple of str
        Every registered kind's name (for the messages).
    column_keys : mapping
        Kind name -> the keys of its data columns (a curve block refuses another kind's).
    sources : mapping
        For a derived kind: its source blocks by name, ``name -> [(config, product), ...]`` as read.
    """

    base: Path
    specimen: Callable
    observables: Callable = tuple
    overrides: Callable = lambda ck, prefix, raw: ()
    kinds: tuple = ()
    column_keys: Mapping = field(default_factory=dict)
    sources: Mapping = field(default_factory=dict)


@dataclass(frozen=True)
class BuildContext:
    """What a kind's ``data``, ``observation`` and ``block`` need besides its validated block.

    Attributes
    ----------
    specimen : object
        The block's specimen object (its ``specimen`` overrides applied).
    control : str or None
        The control quantity of the runs (``[specimen] control``).
    check_reach : callable
        ``check_reach(exp, reach)``: refuses a curve whose control reaches ``reach`` [mm] (a control in another
        unit); the configuration's model check.
    source_block : callable
        ``source_block(config)``: the product (``block``) of a source block, for a derived kind.
    """

    specimen: object
    control: str | None = None
    check_reach: Callable = lambda exp, reach: None
    source_block: Callable = lambda config: None


@runtime_checkable
class ExperimentKind(Protocol):
    """An experiment kind (see the module docstring).

    ``name``, ``keys``, ``column_keys``, ``source``, ``view``
        The ``kind`` value; the keys of its table; the keys of its data columns (refused by the other kinds);
        the kind its blocks are derived from (None: from files); the report view of its blocks (None: a curve).
    ``read(ck, index, raw, context) -> (config, product)``
        The validated block ``index`` (a frozen dataclass with ``index``, ``kind``, ``name``, ``role``,
        ``weight``, ``n_points``, ``file``, ``specimen`` overrides, ``quantity`` and ``measures_force``) and
        what the blocks derived from it use (None when none is).
    ``data(config, context) -> ExperimentalData``, ``observation(config, context, name, control)``
        The block's data and its observation kind at the data's ``control`` values [mm]; ``observation``
        raises :class:`~fracid.settings.checks.SettingError` (a key of the block) or ValueError.
    ``block(config, context)``
        Only of a kind another names as its ``source``: the product its derived blocks are computed from
        (:func:`source_block`).
    """

    name: str
    keys: tuple
    column_keys: tuple
    source: str | None
    view: str | None

    def read(self, ck, index: int, raw: dict, context: ReadContext) -> tuple: ...

    def data(self, config, context: BuildContext): ...

    def observation(self, config, context: BuildContext, name: str, control): ...


#: kind name -> kind object, in the order the messages list them
EXPERIMENTS = {kind.name: kind for kind in (REPEATS, ENVELOPE, SINGLE, FIELD, OPENING, FPZ_WIDTH)}

#: the kind whose reader checks a block of an unknown kind (its message lists the known ones)
FALLBACK_KIND = SINGLE.name


def kind_names() -> tuple:
    """The registered kinds' names, in order."""
    return tuple(EXPERIMENTS)


def column_keys() -> dict:
    """Kind name -> the keys of its data columns."""
    return {name: tuple(kind.column_keys) for name, kind in EXPERIMENTS.items()}


def derived_kinds() -> tuple:
    """The names of the kinds derived from another kind's blocks."""
    return tuple(name for name, kind in EXPERIMENTS.items() if kind.source is not None)


def read_experiments(ck, blocks: list, context: ReadContext) -> tuple:
    """The validated blocks in order, each read by its kind (a kind not registered is refused first, naming the
    known ones; a block without ``kind`` is read by :data:`FALLBACK_KIND`'s reader, which names what is missing in
    the order of its keys); the blocks of a derived kind are read last, on the products of their source kind's
    blocks as read.

    Returns
    -------
    tuple
        The blocks' configurations, in the order of ``blocks``.
    """
    context = replace(context, kinds=kind_names(), column_keys=column_keys())
    read, products = {}, {}  # index -> config; kind -> name -> [(config, product), ...]
    for derived in (False, True):
        for i, raw in enumerate(blocks):
            named = raw.get("kind") if isinstance(raw, dict) else None
            if named is not None and named not in EXPERIMENTS:  # the kind decides which keys apply: named first
                ck.choice(f"experiments[{i}].kind", named, kind_names())
            kind = EXPERIMENTS.get(named, EXPERIMENTS[FALLBACK_KIND])
            if (kind.source is not None) != derived:
                continue
            sources = products.get(kind.source, {}) if derived else {}
            config, product = kind.read(ck, i, raw, replace(context, sources=sources))
            read[i] = config
            products.setdefault(kind.name, {}).setdefault(config.name, []).append((config, product))
    return tuple(read[i] for i in range(len(blocks)))


def experiment_kind(config) -> ExperimentKind:
    """The kind of a validated block."""
    return EXPERIMENTS[config.kind]


def source_block(config, context: BuildContext):
    """The product of the block ``config`` (a block some derived block is computed from), by its kind's ``block``."""
    return experiment_kind(config).block(config, context)


__all__ = ["EXPERIMENTS", "FALLBACK_KIND", "BuildContext", "ExperimentKind", "ReadContext", "TableChecker",
           "column_keys", "derived_kinds", "experiment_kind", "kind_names", "read_experiments", "source_block"]
