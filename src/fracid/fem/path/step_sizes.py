"""The adaptive step sizes of an incremental analysis: the sequence of control increments [mm] that
:func:`~fracid.fem.path.path_following.follow_path` tries, by the rule of its
:class:`~fracid.fem.path.path_following.StepOptions`: cut after a failure, grown after an easy step, a jump
to just below damage onset while the response is linear, landing on the checkpoints.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # the options are the path's; this module only reads them
    from fracid.fem.path.path_following import StepOptions

__all__ = ["StepSizes", "check_steps"]


def check_steps(steps: StepOptions, target: float) -> None:
    """Raise a ValueError unless the bounds of ``steps`` are positive and not above ``target`` [mm] and its
    grow and shrink factors grow and shrink."""
    for name in ("initial", "maximum", "minimum"):
        value = getattr(steps, name)
        if value is not None and not (math.isfinite(value) and 0 < value <= target):
            raise ValueError(f"step {name} = {value!r} [mm]; it must be positive and not above the target {target}")
    if not (steps.grow >= 1.0 and 0.0 < steps.shrink < 1.0):
        raise ValueError(f"step grow = {steps.grow}, shrink = {steps.shrink}: need grow >= 1 and 0 < shrink < 1")


class StepSizes:
    """The adaptive sequence of increments of :class:`~fracid.fem.path.path_following.StepOptions`: cut after a failure, grown after an easy
    step, jumping to damage onset while the response is linear."""

    def __init__(self, steps: StepOptions, target: float, checkpoints):
        self.steps, self.target = steps, target
        self.base = steps.initial  # reference increment; set from the onset of damage when not given
        self.step = self.base if self.base is not None else 1e-3 * target  # elastic probe
        self.first_step = self.step
        self.marks = np.sort(np.asarray([] if checkpoints is None else checkpoints, dtype=float))
        self.elastic = True

    def increment(self, tau: float) -> float:
        """The next increment from ``tau``: the current step, ending at the target or the next checkpoint."""
        increment = min(self.step, self.target - tau)
        ahead = self.marks[self.marks > tau * (1.0 + 1e-12) + 1e-15]
        if ahead.size and ahead[0] < tau + increment:
            increment = ahead[0] - tau
        return increment

    def cut(self, increment: float) -> bool:
        """Shrink the step after ``increment`` failed; whether it fell below the minimum step."""
        steps = self.steps
        self.step = increment * steps.shrink
        minimum = steps.minimum if steps.minimum is not None else 1e-4 * (self.base or self.first_step)
        return self.step < minimum

    def advance(self, tau: float, increment: float, iterations: int, onset_ratio: float) -> None:
        """Set the next step after ``increment`` converged at ``tau`` in ``iterations`` Newton iterations.

        Parameters
        ----------
        tau : float
            The control reached [mm].
        increment : float
            The increment that converged [mm].
        iterations : int
        onset_ratio : float
            The problem's ``onset_ratio`` of the converged history: in (0, 1) while no point has damaged.
        """
        steps = self.steps
        if self.elastic and 0.0 < onset_ratio < 1.0 and steps.jump_to_onset:
            # linear response so far: jump to just below damage onset
            tau_onset = tau / onset_ratio
            self.base = self.base if self.base is not None else tau_onset / 20.0
            # land half a small step below onset, so the next step clearly crosses it
            # (landing on it exactly would leave the crossing to rounding)
            self.step = max(tau_onset - 0.5 * self.base * steps.onset_fraction - tau, self.base * steps.onset_fraction)
            return
        self.base = self.base if self.base is not None else increment
        if self.elastic:  # this step crossed damage onset: go on with small steps, growing again
            self.elastic = False
            self.step = self.base * steps.onset_fraction
            return
        maximum = steps.maximum if steps.maximum is not None else steps.max_factor * self.base
        self.step = min(increment * steps.grow if iterations <= steps.easy_iterations else increment, maximum)
