"""What an inverse method's stages will cost, said before the work starts: a :class:`StagePlan` per
stage (``method.plan(operator, n_y, n_parameters)``), printed by ``fracid identify`` and ``fracid check``.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class StagePlan:
    """The forward runs of one stage of an inverse method.

    Attributes
    ----------
    stage, label : str
        The stage's name and its label in text (``"kalman"``, ``"Kalman filter"``).
    runs : int
        Forward runs at most (without backtracking over failed or worse points).
    side_by_side : bool
        Whether the runs are independent (they run in parallel on the workers) or one after another.
    full_runs : float
        The runs in full-curve equivalents (a run that stops early at the data it needs costs less).
    text : str
        How the count comes about, in words.
    keys : str
        The settings that set the count, as the configuration names them (``"[identify.knn] n"``).
    exact : bool
        Whether its runs carry exact sensitivities (a run then costs more than a plain one).
    """

    stage: str
    label: str
    runs: int
    side_by_side: bool
    full_runs: float
    text: str
    keys: str = ""
    exact: bool = False

    def line(self) -> str:
        """``"stage <label>: <text> (<keys>)"``."""
        return f"stage {self.label}: {self.text}" + (f" ({self.keys})" if self.keys else "")


def plural(count, noun: str) -> str:
    """``"1 run"``, ``"2 runs"``."""
    return f"{count} {noun}{'' if count == 1 else 's'}"


def runs_per_linearisation(operator, p: int) -> tuple[int, str]:
    """Forward runs of one linearisation at a point: 1 when the model differentiates its runs exactly
    (:func:`~fracid.inverse.core.sensitivity.exact_sensitivity`), else the run and 2 per parameter (central
    differences); and the words for it."""
    from fracid.inverse.core.sensitivity import DirectDifferentiation, exact_sensitivity

    if operator is not None and isinstance(exact_sensitivity(operator)[1], DirectDifferentiation):
        return 1, "the run with its exact sensitivities"
    return 2 * p + 1, "the run and 2 per parameter: central differences"


__all__ = ["StagePlan", "plural", "runs_per_linearisation"]
