"""Progress of long work: tqdm bars on a terminal; lines of text when stderr is not one (a log file, a
pipe, a batch job) and the command line asked for them (:func:`progress_lines`).

A line is printed when a stage starts, every :func:`line_interval` seconds while it runs (30 s;
``FRACID_PROGRESS_SECONDS`` changes it) and when it ends: what is done of the total, the failed runs
where known, the time elapsed and left, and the stage's own note (the Kalman filter's estimate so far).
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time

#: the environment variable of the seconds between two progress lines
INTERVAL_VARIABLE = "FRACID_PROGRESS_SECONDS"
DEFAULT_INTERVAL = 30.0

_state = {"lines": False}
_write_lock = threading.Lock()


@contextlib.contextmanager
def progress_lines(enabled: bool = True):
    """Within: progress left to the default (``enabled=None`` of :func:`progress_bar`, ``progress=None``
    of :func:`fracid.runtime.batch.run_batch`) prints lines when stderr is not a terminal."""
    before, _state["lines"] = _state["lines"], bool(enabled)
    try:
        yield
    finally:
        _state["lines"] = before


def is_terminal() -> bool:
    """Whether stderr is a terminal (False when it cannot tell: closed, None, or without ``isatty``)."""
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def lines_wanted(enabled) -> bool:
    """Whether progress asked for with ``enabled`` (None: the default) is to be printed as lines."""
    return enabled is None and _state["lines"] and not is_terminal()


def line_interval() -> float:
    """Seconds between two progress lines: ``FRACID_PROGRESS_SECONDS`` if a number >= 0, else 30."""
    try:
        seconds = float(os.environ.get(INTERVAL_VARIABLE, DEFAULT_INTERVAL))
    except ValueError:
        return DEFAULT_INTERVAL
    return seconds if seconds >= 0 else DEFAULT_INTERVAL


def clock(seconds: float) -> str:
    """``m:ss`` or ``h:mm:ss``."""
    minutes, secs = divmod(int(seconds), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes}:{secs:02d}"


class LineProgress:
    """A stand-in for a tqdm bar that prints ``fracid: <stage>: 12/64 runs, 1 failed, 0:30 elapsed, ~1:10
    left`` on stderr at the start, every :func:`line_interval` seconds and at the end.

    Parameters
    ----------
    total : float
        The amount of work (runs, steps, mm of the control).
    description : str
        The stage's name.
    unit : str
        The unit of ``total``.
    failed : callable, optional
        The number of failed runs so far.
    """

    def __init__(self, total, description, unit="run", failed=None):
        self.total, self.n, self.description, self.unit = total, 0, description, unit
        self.failed, self.postfix, self.start = failed, "", time.perf_counter()
        self.interval, self.last, self.closed = line_interval(), self.start, False
        self._print(f"started, {self._amount(total)}")

    def _amount(self, value) -> str:
        number = f"{value:.4g}" if isinstance(value, float) else str(value)
        plural = "" if self.unit in ("mm",) or value == 1 else "s"
        return f"{number} {self.unit}{plural}"

    def _print(self, text: str) -> None:
        with _write_lock:
            print(f"fracid: {self.description}: {text}", file=sys.stderr, flush=True)

    def _status(self) -> str:
        elapsed = time.perf_counter() - self.start
        done = f"{self.n:.4g}" if isinstance(self.n, float) else str(self.n)
        parts = [f"{done}/{self._amount(self.total)}"]
        if self.failed is not None:
            parts.append(f"{self.failed()} failed")
        parts.append(f"{clock(elapsed)} elapsed")
        if 0 < self.n < (self.total or 0):
            parts.append(f"~{clock(elapsed / self.n * (self.total - self.n))} left")
        return ", ".join(parts) + (f"; {self.postfix}" if self.postfix else "")

    def refresh(self) -> None:
        """Print the status if the interval has passed since the last line."""
        now = time.perf_counter()
        if not self.closed and now - self.last >= self.interval:
            self.last = now
            self._print(self._status())

    def update(self, amount=1) -> None:
        """Add ``amount`` of done work."""
        self.n += amount
        self.refresh()

    def set_postfix_str(self, text: str) -> None:
        """The stage's note (e.g. the current estimate), shown after the counts."""
        self.postfix = text
        self.refresh()

    def close(self) -> None:
        """The last line, with the final counts."""
        if not self.closed:
            self._print("done, " + self._status())
            self.closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def progress_bar(total: float, description: str, enabled: bool | None = None, unit: str = "run"):
    """A tqdm bar on stderr, disabled when ``enabled`` is False, or when None and stderr is not a
    terminal; a :class:`LineProgress` instead when None, stderr is not a terminal and
    :func:`progress_lines` is on."""
    if lines_wanted(enabled):
        return LineProgress(total, description, unit=unit)
    from tqdm import tqdm

    if enabled is None:
        enabled = is_terminal()
    return tqdm(total=total, desc=description, unit=unit, disable=not enabled, leave=False, dynamic_ncols=True)


def batch_lines(description: str = "forward runs", failed=None):
    """A ``progress(done, total)`` callable for :func:`fracid.runtime.batch.run_batch` printing lines; it
    closes (its last line) when ``done`` reaches ``total``."""
    line = None

    def report(done, total):
        nonlocal line
        if line is None:
            line = LineProgress(total, description, failed=failed)
        line.total, line.n = total, done
        if done >= total:
            line.close()
        else:
            line.refresh()

    return report


def batch_progress(bar):
    """Adapter for :func:`fracid.runtime.batch.run_batch`'s ``progress(done, total)`` callable."""

    def report(done, total):
        bar.total = total
        bar.n = done
        bar.refresh()

    return report


class StageLines:
    """The stage of each of several jobs that run side by side (the models of ``fracid compare``), and a line per
    job still running every :func:`line_interval` seconds, so that minutes of work never pass in silence.

    Use :meth:`log` as the jobs' ``log(text)``: a line ``"<label>: <text>"`` is written at once and sets the label's
    stage; a text starting with one of ``ends`` (``"done"``, ``"failed"``) ends the label's job. Within ``with``, a
    thread writes ``"<label>: 1:30 elapsed, <stage>"`` for every job still running each interval (the time since
    the job's first line; since the start while it waits for a worker).

    Parameters
    ----------
    labels : sequence of str
        The jobs' labels (the lines' prefixes).
    write : callable
        ``write(text)``: prints a line (stdout unless ``--quiet``, in ``fracid compare``).
    ends : tuple of str
        The starts of a text that ends a job.
    """

    def __init__(self, labels, write, ends=("done", "failed")):
        self.write, self.ends, self.started = write, tuple(ends), time.perf_counter()
        self.stages = {label: "waiting for a worker" for label in labels}
        self.since = dict.fromkeys(self.stages, self.started)  # a job's first line, or the start while it waits
        self.running = set(self.stages)
        self._stop, self._thread, self._lock = threading.Event(), None, threading.Lock()

    def log(self, text: str) -> None:
        """Write ``text`` and, when it starts with a known label, record the label's stage."""
        label, _, rest = str(text).partition(": ")
        with self._lock:
            if label in self.stages:
                if self.stages[label] == "waiting for a worker":
                    self.since[label] = time.perf_counter()
                self.stages[label] = rest
                if rest.startswith(self.ends):
                    self.running.discard(label)
        self.write(text)

    def status(self) -> list[str]:
        """A line per job still running: its label, the time since its first line (since the start while it
        waits), its last stage."""
        now = time.perf_counter()
        with self._lock:
            return [f"{label}: {clock(now - self.since[label])} elapsed, {stage}"
                    for label, stage in self.stages.items() if label in self.running]

    def _beat(self, interval: float) -> None:
        while not self._stop.wait(interval):
            for line in self.status():
                self.write(line)

    def __enter__(self):
        interval = max(line_interval(), 0.05)
        self._thread = threading.Thread(target=self._beat, args=(interval,), name="fracid-stage-lines", daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        return False
