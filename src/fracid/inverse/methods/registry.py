"""The registry of inverse methods: the names ``[identify] method`` accepts, each with its class.

Every class is a frozen dataclass of its settings (``KnnKalman(knn=KnnSettings(...),
kalman=KalmanSettings(...))``, ``KnnGaussNewton(knn=KnnSettings(...), max_iterations=..., tol=...)``)
with a ``name`` that is its key here and the ``stages`` it runs (stage name -> label, the keys of its
counters and records in the result, the report's sections). A method meets
:class:`~fracid.inverse.core.method.InverseMethod` (``fracid identify``); one that also meets
:class:`StudyMethod` runs every check of ``fracid study`` through its own stages.

A new method is a class and one line here (or ``METHODS[name] = cls`` from the user's code). Its settings
come from the configuration's tables ``[identify.<table>]`` that it declares in ``config_tables`` (without it:
the table of its name, ``[identify.<name>]``), with their keys described in ``config_keys`` (table -> key ->
:class:`~fracid.settings.keys.Key`, read by the configuration reference: :func:`table_keys`), read and checked by its ``from_config(tables, context)`` class
method (:func:`method_from_tables`; the checkers and their :class:`~fracid.settings.checks.SettingError`
are in :mod:`fracid.settings.checks`); ``config_template(tables)`` writes them for ``fracid init``. The
configuration knows no method: it allows every table a registered method declares (:func:`known_tables`) and
warns of one the chosen method does not read (:func:`table_readers`).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from fracid.inverse.methods.knn_gauss_newton import KnnGaussNewton
from fracid.inverse.methods.knn_kalman import KnnKalman


@runtime_checkable
class StudyMethod(Protocol):
    """What :func:`~fracid.inverse.studies.study.run_study` asks of a method besides calling it.

    ``search(operator, y_exp, C_exp, space, *, executor, store, progress, stats, retry_failed)``
        The global stage: a :class:`~fracid.inverse.methods.knn.KnnResult` (population, ranking, prior x0 and
        C0); the study's objective maps, valley and multi-start points come from it.
    ``refine(operator, y_exp, C_exp, overview, *, C0, executor, blocks, notes, progress)``
        The local stage from the overview's prior (covariance ``C0`` when given): the
        :class:`~fracid.inverse.core.method.MethodResult` of the identification.
    ``fit_from(evaluate, y_exp, C_exp, x0, C0, *, bounds, executor, blocks)``
        The local stage alone from a prior (x0, C0): a fit with ``x``, ``std``, ``y``, ``failed`` and
        ``status``, for the multi-start check and the noisy replicates.
    """

    name: str
    stages: dict

    def search(self, operator, y_exp, C_exp, space, **options): ...

    def refine(self, operator, y_exp, C_exp, overview, **options): ...

    def fit_from(self, evaluate, y_exp, C_exp, x0, C0, **options): ...


#: inverse method name -> its class; the first is the default
METHODS = {KnnKalman.name: KnnKalman, KnnGaussNewton.name: KnnGaussNewton}

#: the default inverse method's name
DEFAULT_METHOD = KnnKalman.name


def config_tables(cls) -> tuple:
    """The ``[identify.<table>]`` tables the method class ``cls`` reads: its ``config_tables``, else the table
    of its name (``(cls.name,)``)."""
    return tuple(getattr(cls, "config_tables", None) or (cls.name,))


def known_tables() -> tuple:
    """Every table a registered method reads, each once, in the order of :data:`METHODS`."""
    return tuple(dict.fromkeys(table for cls in METHODS.values() for table in config_tables(cls)))


def table_keys(table: str) -> dict:
    """The keys of the table ``[identify.<table>]``, described (key -> :class:`~fracid.settings.keys.Key`): those
    the first registered method that reads it declares in its ``config_keys`` (table -> keys); empty when none
    does."""
    for name in table_readers(table):
        keys = (getattr(METHODS[name], "config_keys", None) or {}).get(table)
        if keys:
            return dict(keys)
    return {}


def table_readers(table: str) -> tuple:
    """The names of the registered methods that read the table ``table``."""
    return tuple(name for name, cls in METHODS.items() if table in config_tables(cls))


def method_from_tables(cls, given: dict, context):
    """The method ``cls`` with the settings of the tables ``given`` (table name -> the table as read; those it
    does not read are left out, those absent are empty): ``cls.from_config(tables, context)``; a class without
    ``from_config`` is built with its defaults and takes no table.

    Parameters
    ----------
    cls : type
        An inverse method class.
    given : dict
        The ``[identify.<table>]`` tables given, by name.
    context : fracid.settings.checks.SettingsContext
        The data's size ``n_y`` and the identified ``parameters``.

    Raises
    ------
    fracid.settings.checks.SettingError
        A setting refused by the method, named relative to ``[identify]``.
    ValueError, TypeError
        Another refusal of the method; settings given to a method that takes none.
    """
    tables = {table: given.get(table, {}) for table in config_tables(cls)}
    from_config = getattr(cls, "from_config", None)  # an optional hook of the method
    if from_config is not None:
        return from_config(tables, context)
    if any(tables.values()):
        raise ValueError(f"the method {cls.name!r} takes no settings from the configuration")
    return cls()


def method_stages(name: str) -> dict:
    """The stages (name -> label) of the registered method ``name``; empty for an unknown name."""
    cls = METHODS.get(name)
    return dict(getattr(cls, "stages", None) or {})


__all__ = ["DEFAULT_METHOD", "METHODS", "StudyMethod", "config_tables", "known_tables",
           "method_from_tables", "method_stages", "table_keys", "table_readers"]
