"""The kinds of ``[[experiments]]`` blocks (``kind = "..."``) and their registry.

Each kind lives in its own module and declares what the outer ring needs: its configuration keys, the reading
and checking of its own table (with a checker object passed in, :class:`~fracid.inverse.experiments.registry.
TableChecker`, built on :mod:`fracid.settings.checks`), its :class:`~fracid.data.experimental.ExperimentalData`,
its observation kind (:mod:`fracid.inverse.core.observations`), the report view its blocks need (by name),
whether it measures a force, and for a derived kind the kind of its source. :mod:`fracid.config` and the
command iterate :data:`~fracid.inverse.experiments.registry.EXPERIMENTS` and name no kind.

Modules: :mod:`~fracid.inverse.experiments.vocabulary` (units, separators, roles),
:mod:`~fracid.inverse.experiments.curve_table` and :mod:`~fracid.inverse.experiments.curves` (the force and
local curves: "repeats", "envelope", "single"), :mod:`~fracid.inverse.experiments.crack_region` and
:mod:`~fracid.inverse.experiments.field` (a DIC displacement field: "field"),
:mod:`~fracid.inverse.experiments.derived` (local data derived from a field: "opening", "fpz-width"),
:mod:`~fracid.inverse.experiments.registry` (the protocol, the contexts and :data:`EXPERIMENTS`).

May import: :mod:`fracid.settings`, :mod:`fracid.specimens`, :mod:`fracid.models`, :mod:`fracid.data` and
:mod:`fracid.inverse.core`; nothing of the other inverse packages, nor of report, config or cli.
"""
