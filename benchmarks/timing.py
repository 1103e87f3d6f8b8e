"""Timing helpers shared by the benchmark scripts."""

from __future__ import annotations

import time


class Timed:
    """Replaces ``module.name`` by a wrapper that sums its wall time [s] and its calls, inside a ``with`` block
    (the callers look the function up in its module at every call)."""

    def __init__(self, module, name):
        self.module, self.name, self.fn = module, name, getattr(module, name)
        self.seconds, self.calls = 0.0, 0

    def __call__(self, *args, **kwargs):
        t0 = time.perf_counter()
        try:
            return self.fn(*args, **kwargs)
        finally:
            self.seconds += time.perf_counter() - t0
            self.calls += 1

    def __enter__(self):
        setattr(self.module, self.name, self)
        return self

    def __exit__(self, *exc):
        setattr(self.module, self.name, self.fn)
