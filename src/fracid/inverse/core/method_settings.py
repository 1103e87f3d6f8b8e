"""An inverse method with changed settings, by the settings' own names (:func:`with_settings`).

Every registered method is a frozen dataclass of its settings (:mod:`fracid.inverse.methods.registry`); this
helper knows none of them by name, so the likelihood's terms and the studies use it without importing the
methods.
"""

from __future__ import annotations

import dataclasses


def with_settings(method, **changes):
    """A copy of the inverse method ``method`` (a frozen dataclass) with ``changes`` to its fields or to the
    fields of its settings dataclasses, by their own names: ``with_settings(KnnKalman(), n=16, groups="all")``
    sets ``knn.n`` and ``kalman.groups``. A settings field named ``method`` (the population's design) is
    given through its dataclass (``knn=KnnSettings(method="lhs")``).

    Raises
    ------
    TypeError
        For a name that is none of these (the message lists the known ones).
    """
    if not changes:
        return method
    if not dataclasses.is_dataclass(method) or isinstance(method, type):
        raise TypeError(f"unknown setting(s) {', '.join(sorted(changes))}: the method "
                        f"{getattr(method, 'name', method)!r} has no settings by name; give them to the method")
    fields = {f.name: getattr(method, f.name) for f in dataclasses.fields(method)}
    top = {name: changes.pop(name) for name in list(changes) if name in fields}
    nested = {}
    for part, value in {**fields, **top}.items():
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            names = {f.name for f in dataclasses.fields(value)} - {"method"}
            own = {name: changes.pop(name) for name in list(changes) if name in names}
            if own:
                nested[part] = dataclasses.replace(value, **own)
    if changes:
        known = set(fields) | {f.name for v in fields.values() if dataclasses.is_dataclass(v)
                               for f in dataclasses.fields(v)} - {"method"}
        raise TypeError(f"unknown setting(s) {', '.join(sorted(changes))} of the method {method.name!r}; known: "
                        f"{', '.join(sorted(known))}")
    return dataclasses.replace(method, **{**top, **nested})


__all__ = ["with_settings"]
