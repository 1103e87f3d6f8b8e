"""Progress bars (tqdm) for long work, shown only on a terminal unless asked for."""

from __future__ import annotations

import sys


def progress_bar(total: float, description: str, enabled: bool | None = None, unit: str = "run"):
    """A tqdm bar on stderr; disabled when ``enabled`` is False, or when None and stderr is not a terminal."""
    from tqdm import tqdm

    if enabled is None:
        enabled = sys.stderr.isatty()
    return tqdm(total=total, desc=description, unit=unit, disable=not enabled, leave=False, dynamic_ncols=True)


def batch_progress(bar):
    """Adapter for :func:`fracid.parallel.run_batch`'s ``progress(done, total)`` callable."""

    def report(done, total):
        bar.total = total
        bar.n = done
        bar.refresh()

    return report
