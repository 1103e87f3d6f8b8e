"""Sensitivities of the forward operator, behind one small interface.

A sensitivity method is a callable ``(evaluate, x, needed, executor) -> (y, S, records)``: the outputs
at x, the matrix S = d y / d x (n_outputs x n_parameters) and the runs it made. The Kalman filter only
sees this interface, so a cheaper method (a direct differentiation of the finite-element model) can
replace the central differences without touching the filter.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.inverse.forward_operator import RunRecord


class ForwardRunError(RuntimeError):
    """A forward run the method cannot do without (its own point) failed."""


def evaluate_points(evaluate, points, needed=None, executor=None) -> list[RunRecord]:
    """Evaluate ``evaluate(x, needed)`` at every point, in parallel when an executor is given.

    Plain arrays returned by ``evaluate`` (analytic test models) are wrapped in a :class:`RunRecord`.
    An ``evaluate`` with an ``evaluate_many(points, needed, executor)`` method (a run store or a
    memory of runs, see :class:`Memoized` and :class:`fracid.inverse.runs.StoredOperator`) is
    asked through it, so that runs already made are not made again.
    """
    if hasattr(evaluate, "evaluate_many"):
        return evaluate.evaluate_many(points, needed, executor)
    if executor is None:
        outputs = [evaluate(np.asarray(x, float), needed) for x in points]
    else:
        futures = [executor.submit(evaluate, np.asarray(x, float), needed) for x in points]
        outputs = [f.result() for f in futures]
    return [out if isinstance(out, RunRecord) else RunRecord(np.asarray(x, float), np.asarray(out, float))
            for x, out in zip(points, outputs)]


class Memoized:
    """``evaluate`` that remembers its runs in this process: a point asked again is not run again.

    The Kalman filter asks for the run at its own point before the perturbed ones (to see whether
    it succeeds and lowers the objective), then the sensitivity method asks for it again.
    """

    def __init__(self, evaluate):
        self.evaluate = evaluate
        self.memory: dict = {}

    def __call__(self, x, needed=None):
        return self.evaluate_many([x], needed, None)[0]

    def evaluate_many(self, points, needed=None, executor=None) -> list[RunRecord]:
        keys = [(np.asarray(x, float).tobytes(), needed) for x in points]
        missing = {key: x for key, x in zip(keys, points) if key not in self.memory}
        fresh = evaluate_points(self.evaluate, list(missing.values()), needed, executor)
        self.memory.update(zip(missing, fresh))
        return [self.memory[key] for key in keys]


def memoized(evaluate):
    """``evaluate`` itself if it already avoids repeated runs (has ``evaluate_many``), else :class:`Memoized`."""
    return evaluate if hasattr(evaluate, "evaluate_many") else Memoized(evaluate)


@dataclass(frozen=True)
class CentralDifferences:
    """S_j = (h(x + dx_j) - h(x - dx_j)) / (2 dx_j), dx_j = relative_step * max(|x_j|, floor_j).

    The 2 p + 1 runs go to the executor together. A failed perturbed run falls back to the
    one-sided difference with the other side; a failed central run raises :class:`ForwardRunError`.
    """

    relative_step: float = 1e-2

    def __call__(self, evaluate, x, needed=None, executor=None):
        x = np.asarray(x, dtype=float)
        p = x.size
        dx = self.relative_step * np.where(np.abs(x) > 0, np.abs(x), 1.0)
        points = [x] + [x + s * dx[j] * np.eye(p)[j] for j in range(p) for s in (1.0, -1.0)]
        records = evaluate_points(evaluate, points, needed, executor)
        centre = records[0]
        if not centre.ok:
            raise ForwardRunError(f"the forward run at x = {x.tolist()} failed: {centre.error}")
        S = np.empty((centre.y.size, p))
        for j in range(p):
            plus, minus = records[1 + 2 * j], records[2 + 2 * j]
            if plus.ok and minus.ok:
                S[:, j] = (plus.y - minus.y) / (2 * dx[j])
            elif plus.ok or minus.ok:
                side, sign = (plus, 1.0) if plus.ok else (minus, -1.0)
                S[:, j] = sign * (side.y - centre.y) / dx[j]
            else:
                raise ForwardRunError(f"both perturbed runs of parameter {j} failed at x = {x.tolist()}: {plus.error}")
        return centre.y, S, records
