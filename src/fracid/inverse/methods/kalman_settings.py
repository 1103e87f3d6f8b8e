"""The settings of the Kalman filter stage (:class:`KalmanSettings`) and their table ``[identify.kalman]`` of the
configuration: :func:`kalman_from_table` checks it, :func:`named_groups` resolves a named observation
sequence."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.inverse.methods.kalman_status import DEFAULT_MAX_STARTS
from fracid.settings import checks as settings
from fracid.settings.keys import FROM_CLASS, Key, Said, described


#: Kalman steps per pass when [identify.kalman] groups is not given. A step costs one run (with exact
#: sensitivities) up to its observations: a few steps are as informative as one per observation and cost less
DEFAULT_GROUPS = 4


@dataclass(frozen=True)
class KalmanSettings:
    """The Kalman filter (:func:`~fracid.inverse.methods.kalman.kalman_filter`).

    Attributes
    ----------
    groups : None, sequence of index arrays, "blocks" or "all"
        The observation sequence: one observation per step (None), the given index arrays, one
        step per data block (``"blocks"``) or one step with every observation (``"all"``: the batch
        filter).
    max_iterations : int
        Global iterations (passes over the observations) at most.
    tol : float
        Convergence: no parameter moves by more than ``tol`` of its standard deviation [-].
    restart : {"linearize", "prior-mean"}
        How a global iteration starts again (see :func:`~fracid.inverse.methods.kalman.kalman_filter`).
    max_starts : int
        Starts of the filter at most: when it ends at a poor point from the KNN prior, it starts again
        from the next-best population points (:func:`~fracid.inverse.methods.kalman_status.restarted`). Not part
        of :meth:`options` (the filters of the study's checks start once).
    """

    groups: object = None
    max_iterations: int = 10
    tol: float = 0.01
    restart: str = "linearize"
    max_starts: int = DEFAULT_MAX_STARTS

    def options(self, n_y: int, blocks=()) -> dict:
        """Keyword arguments of :func:`~fracid.inverse.methods.kalman.kalman_filter` for ``n_y`` observations in
        ``blocks`` (``(name, start, stop)``; a named ``groups`` is resolved with them)."""
        return {"groups": named_groups(self.groups, n_y, blocks), "max_iterations": self.max_iterations,
                "tol": self.tol, "restart": self.restart}


#: the values of ``[identify.kalman] restart``, and the table's keys, described (their meanings are
#: :class:`KalmanSettings`'s but that of groups, which the configuration gives as a count)
RESTARTS = ("linearize", "prior-mean")
KALMAN_KEY_DOCS = described({
    "groups": Key(Said(f"{DEFAULT_GROUPS} (n_y if fewer)"), "", "integer, 1 <= groups <= n_y (the total n_points)",
                  "Consecutive observation groups: the filter's steps per pass (one run each with exact "
                  "sensitivities)."),
    "max_iterations": Key(FROM_CLASS, "", "integer >= 1"),
    "tol": Key(FROM_CLASS, "standard deviations", "> 0"),
    "restart": Key(FROM_CLASS, "", " | ".join(f'"{r}"' for r in RESTARTS)),
    "max_starts": Key(FROM_CLASS, "", "integer >= 1"),
}, KalmanSettings)
KALMAN_KEYS = tuple(KALMAN_KEY_DOCS)


def kalman_from_table(raw, n_y: int | None) -> KalmanSettings:
    """The :class:`KalmanSettings` of the table ``[identify.kalman]`` (``raw``, a dict; empty: the defaults),
    ``groups`` still a count (or None): ``1 <= groups <= n_y`` (the total data values, when known).

    Raises
    ------
    fracid.settings.checks.SettingError
        Naming ``kalman.<key>``, the value and what is allowed.
    """
    raw = settings.table("kalman", raw, KALMAN_KEYS)
    groups = None
    if "groups" in raw:
        top = n_y if n_y else None
        allowed = (f"must be an integer with 1 <= groups <= n_y = {top} (the total n_points of the experiments)"
                   if top else "must be an integer >= 1")
        groups = settings.integer("kalman.groups", raw["groups"], allowed, lambda v: v >= 1 and (top is None or v <= top))
    return KalmanSettings(
        groups=groups,
        max_iterations=settings.integer("kalman.max_iterations", raw.get("max_iterations", 10),
                                        "must be an integer >= 1", lambda v: v >= 1),
        tol=settings.number("kalman.tol", raw.get("tol", 0.01), "must be a number > 0 [standard deviations]",
                            lambda v: v > 0),
        restart=settings.choice("kalman.restart", raw.get("restart", "linearize"), RESTARTS),
        max_starts=settings.integer("kalman.max_starts", raw.get("max_starts", DEFAULT_MAX_STARTS),
                                    "must be an integer >= 1 (starts of the filter in all)", lambda v: v >= 1))


def named_groups(groups, n_y: int, blocks=()):
    """``groups`` as index arrays: ``"all"`` is one group of the ``n_y`` observations, ``"blocks"`` one per
    data block ``(name, start, stop)``; anything else is returned as it is."""
    if not isinstance(groups, str):
        return groups
    if groups == "all":
        return [np.arange(n_y)]
    if groups == "blocks":
        return [np.arange(start, stop) for _, start, stop in blocks or [("all", 0, n_y)]]
    raise ValueError(f"groups = {groups!r}; give index arrays, None, 'blocks' or 'all'")


__all__ = ["DEFAULT_GROUPS", "KALMAN_KEYS", "KALMAN_KEY_DOCS", "RESTARTS", "KalmanSettings", "kalman_from_table", "named_groups"]
