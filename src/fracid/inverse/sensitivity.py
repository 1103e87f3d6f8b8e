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
    """
    if executor is None:
        outputs = [evaluate(np.asarray(x, float), needed) for x in points]
    else:
        futures = [executor.submit(evaluate, np.asarray(x, float), needed) for x in points]
        outputs = [f.result() for f in futures]
    return [out if isinstance(out, RunRecord) else RunRecord(np.asarray(x, float), np.asarray(out, float))
            for x, out in zip(points, outputs)]


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
