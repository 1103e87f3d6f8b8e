"""A resumable batch runner for many forward runs: :func:`run_batch` maps a function over tasks on any
executor of :mod:`fracid.runtime.executors`; with a :class:`~fracid.store.runs.RunStore` it skips tasks already stored
and stores every run as soon as it finishes, so a study killed at any moment resumes where it stopped,
losing only runs in flight.

Workers compute, the parent stores: the function runs in the workers and returns a record (a dict);
only the process that called :func:`run_batch` writes to the store.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import pickle
import sys
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from fracid.runtime.stops import raise_if_stopped
from fracid.runtime.executors import SerialExecutor, is_dask, is_executor, make_executor
from fracid.runtime.progress import batch_lines, clock, is_terminal, lines_wanted
from fracid.store.records import decode_record, encode_record

__all__ = ["BatchStats", "run_batch"]


@dataclass
class BatchStats:
    """Counters of one :func:`run_batch` call, filled in as it goes.

    Attributes
    ----------
    total : int
        Number of tasks.
    computed : int
        Runs executed by this call (tasks sharing a key count once).
    reused : int
        Tasks whose record was loaded from the store.
    failed : int
        Records with status ``"failed"`` among those returned (computed or reused).
    seconds : float
        Wall-clock time of the call [s].
    compute_seconds : float
        Sum of the workers' times of the computed runs [s]; ``compute_seconds / seconds`` is the
        effective parallelism.
    """

    total: int = 0
    computed: int = 0
    reused: int = 0
    failed: int = 0
    seconds: float = 0.0
    compute_seconds: float = 0.0
    _start: float = field(default=0.0, init=False, repr=False, compare=False)

    def _reset(self, total: int) -> None:
        self.total, self.computed, self.reused, self.failed = total, 0, 0, 0
        self.seconds = self.compute_seconds = 0.0
        self._start = time.perf_counter()

    def _tick(self) -> None:
        self.seconds = time.perf_counter() - self._start


def run_batch(function: Callable[[object], dict], tasks: Sequence, *, executor, store=None,
              keys: Sequence[str] | None = None, study: str = "", progress=None, stats: BatchStats | None = None,
              retry_failed: bool = False) -> list[dict]:
    """Run ``function(task)`` for every task on ``executor``; records in task order.

    Parameters
    ----------
    function : callable
        ``function(task) -> dict``, picklable (a module-level function) for process pools. An
        exception it raises does not stop the batch: the task's record becomes
        ``{"status": "failed", "error": "<type>: <message>", "traceback": "..."}``. Records it returns
        get ``"status": "ok"`` unless they carry a status of their own.
    tasks : sequence
        Picklable arguments, one per run.
    executor
        From :func:`~fracid.runtime.executors.make_executor` (a SerialExecutor, a process pool, a dask Client) or any executor
        with ``submit``; anything else (e.g. ``2`` or ``"serial"``) is passed to :func:`make_executor`
        and the executor made is shut down at the end.
    store : RunStore, optional
        With ``keys``: tasks whose key is stored are not run, their record is loaded; every finished
        run is stored at once by this (the parent) process, failed runs included.
    keys : sequence of str, optional
        One key per task (see :func:`fracid.store.runs.key_for`). Tasks with equal keys run once and share
        their record.
    study : str
        Label stored with the runs.
    progress : None, bool or callable
        ``None``: a one-line progress report on stderr if stderr is a terminal (else lines of text within
        :func:`fracid.runtime.progress.progress_lines`, as the command line does); ``False``: none;
        ``True``: the report on stderr in any case; a callable: called as ``progress(done, total)``.
    stats : BatchStats, optional
        Filled in (overwritten) with the counters of this call.
    retry_failed : bool
        Run again the tasks stored with status ``"failed"`` instead of reusing their record.

    Returns
    -------
    list of dict
        One record per task, in the order of ``tasks``. With a store, fresh records are returned as
        stored and read back, so a rerun returns equal records.

    Raises
    ------
    ValueError
        For ``store`` without ``keys`` (or the reverse), a key count that is not the task count,
        or a read-only store.
    Exception
        When the executor itself fails (a worker killed, an unpicklable task): runs finished until
        then are stored; a note on the exception says so. Run the batch again to resume.

    Notes
    -----
    Each run is stored as soon as it finishes, whatever the order (see :func:`_completed`): a kill
    loses only the runs in flight, not those finished behind a slow one.
    """
    tasks = list(tasks)
    keys = _check_store_and_keys(tasks, store, keys)
    stats = stats if stats is not None else BatchStats()
    stats._reset(len(tasks))
    report = _progress_reporter(progress, stats)
    records: list = [None] * len(tasks)

    groups = _reuse_stored(records, store, keys, retry_failed, stats)
    report(stats.reused, len(tasks))
    _check_picklable(function, executor)
    calls = [(group, (function, tasks[group[0]], store is not None)) for group in groups]
    _run_and_keep(executor, calls, records, _Destination(store, keys, study), stats, report)
    return records


@dataclass(frozen=True)
class _Destination:
    """Where :func:`run_batch` keeps finished runs: the store (None: nowhere), the tasks' keys, the study."""

    store: object
    keys: list | None
    study: str

    def keep(self, payload, status: str, seconds: float, group: list[int]) -> dict:
        """Store a finished run (parent side) and return its record."""
        if self.store is None:
            return payload
        self.store.put(self.keys[group[0]], payload, status=status, seconds=seconds, study=self.study)
        return decode_record(payload)


def _run_and_keep(executor, calls, records: list, destination: _Destination, stats: BatchStats, report) -> None:
    """Run ``calls`` on ``executor`` and keep each run as it finishes, filling ``records`` and ``stats``.

    An ``executor`` that is not one (a worker count, ``"serial"``) is made here and shut down at the
    end: at once, its pending runs cancelled, when the batch stops on an exception.
    """
    owned = not is_executor(executor)
    pool = make_executor(executor) if owned else executor
    done = stats.reused
    failed_run = True
    try:
        with contextlib.closing(_completed(pool, calls)) as completed:
            for group, (payload, status, seconds) in completed:
                record = destination.keep(payload, status, seconds, group)
                raise_if_stopped()
                for index in group:
                    records[index] = record
                done += len(group)
                _count(stats, record, seconds, len(group))
                report(done, len(records))
        failed_run = False
    except BaseException as exc:
        _note_interrupted(exc, stats, destination.store)
        raise
    finally:
        if owned:
            pool.shutdown(wait=not failed_run, cancel_futures=True)
        stats._tick()


def _check_store_and_keys(tasks, store, keys):
    if store is None and keys is None:
        return None
    if store is None:
        raise ValueError("keys= needs store= (a fracid.store.runs.RunStore) to look the runs up in")
    if keys is None:
        raise ValueError("store= needs keys=, one per task (see fracid.store.runs.key_for)")
    keys = list(keys)
    if len(keys) != len(tasks):
        raise ValueError(f"got {len(keys)} keys for {len(tasks)} tasks; give one key per task")
    if getattr(store, "readonly", False):
        raise ValueError(f"{store!r} is read-only; run_batch stores every finished run")
    return keys


def _reuse_stored(records, store, keys, retry_failed, stats) -> list[list[int]]:
    """Fill ``records`` from the store; the groups of task indices left to run (one run per group)."""
    if store is None:
        return [[index] for index in range(len(records))]
    statuses = store.statuses(keys)
    reusable = {key for key, status in statuses.items() if not (retry_failed and status == "failed")}
    stored = store.get_many(reusable)
    groups: dict[str, list[int]] = {}
    for index, key in enumerate(keys):
        if key in stored:
            records[index] = stored[key]
            stats.reused += 1
            stats.failed += records[index].get("status") == "failed"
        else:
            groups.setdefault(key, []).append(index)
    return list(groups.values())


def _count(stats: BatchStats, record: dict, seconds: float, n_tasks: int) -> None:
    stats.computed += 1
    stats.compute_seconds += seconds
    stats.failed += n_tasks * (record.get("status") == "failed")
    stats._tick()


def _note_interrupted(exc: BaseException, stats: BatchStats, store) -> None:
    where = "stored" if store is not None else "finished (not stored: no store given)"
    exc.add_note(
        f"run_batch stopped after {stats.computed} runs {where} and {stats.reused} reused, "
        f"of {stats.total} tasks" + ("; run it again to resume" if store is not None else "")
    )


def _check_picklable(function, executor) -> None:
    """A process pool (or a worker count that makes one) needs a function pickle can send."""
    in_process = executor in (1, "serial") or isinstance(executor, SerialExecutor)
    if in_process or (is_executor(executor) and not isinstance(executor, cf.ProcessPoolExecutor)):
        return
    try:
        pickle.dumps(function)
    except Exception as exc:
        raise TypeError(
            f"function {function!r} cannot be sent to worker processes ({exc}); "
            "use a module-level function, or functools.partial of one"
        ) from exc


# -- worker side ---------------------------------------------------------------------------------


def _run_one(function, task, encode: bool):
    """Worker side: ``(record or its encoded bytes, status, seconds)``; exceptions become records."""
    start = time.perf_counter()
    try:
        record = _as_record(function(task), function)
    except Exception as exc:  # noqa: BLE001 -- a failed run is a record, the batch goes on
        record = _failure(exc)
    seconds = time.perf_counter() - start
    if not encode:
        return record, str(record["status"]), seconds
    try:
        payload = encode_record(record)
    except (TypeError, ValueError) as exc:
        record = _failure(exc, prefix="record cannot be stored: ")
        payload = encode_record(record)
    return payload, str(record["status"]), seconds


def _as_record(result, function) -> dict:
    if not isinstance(result, dict):
        name = getattr(function, "__qualname__", repr(function))
        raise TypeError(f"{name} returned {type(result).__name__}, expected a dict record")
    record = dict(result)
    record.setdefault("status", "ok")
    return record


def _failure(exc: BaseException, prefix: str = "") -> dict:
    return {
        "status": "failed",
        "error": f"{prefix}{type(exc).__name__}: {exc}",
        "traceback": "".join(traceback.format_exception(exc)),
    }


# -- collecting futures --------------------------------------------------------------------------


def _completed(executor, calls):
    """Yield ``(group, result)`` as the calls finish; cancel what is left if stopped early.

    Finished runs are collected with ``as_completed`` (``concurrent.futures.as_completed`` for
    standard futures, ``dask.distributed.as_completed`` for dask ones) rather than in submission
    order, so that each is stored as soon as it finishes, whatever the order: a kill loses only the
    runs in flight, not those finished behind a slow one. With a :class:`SerialExecutor` each run is
    stored before the next starts. Executors whose futures are of another kind are waited on in
    submission order.
    """
    if isinstance(executor, SerialExecutor):
        for group, args in calls:
            yield group, executor.submit(_run_one, *args).result()
        return
    futures = {}
    try:
        for group, args in calls:
            futures[_submit(executor, _run_one, *args)] = group
        for future in _as_completed(executor, list(futures)):
            yield futures[future], future.result()
    finally:
        for future in futures:
            future.cancel()


def _submit(executor, fn, *args):
    if is_dask(executor):
        return executor.submit(fn, *args, pure=False)  # a rerun must run, not hit dask's cache
    return executor.submit(fn, *args)


def _as_completed(executor, futures):
    if all(isinstance(f, cf.Future) for f in futures):
        return cf.as_completed(futures)
    if is_dask(executor):
        from dask.distributed import as_completed

        return as_completed(futures)
    return iter(futures)


# -- progress --------------------------------------------------------------------------------------


def _progress_reporter(progress, stats: BatchStats | None = None) -> Callable[[int, int], None]:
    if lines_wanted(progress):  # stderr is not a terminal and the command line asked for lines
        return batch_lines("forward runs", failed=(lambda: stats.failed) if stats is not None else None)
    if progress is None:
        progress = is_terminal()
    if progress is True:
        return _TextProgress(sys.stderr)
    if progress is False:
        return lambda done, total: None
    if callable(progress):
        return progress
    raise TypeError(f"progress must be None, True, False or a callable(done, total), got {progress!r}")


class _TextProgress:
    """``runs 37/120 (31 %), 0:42 elapsed, ~1:34 left`` on one line, rewritten in place."""

    def __init__(self, stream):
        self.stream = stream
        self.start = time.perf_counter()
        self.first = None

    def __call__(self, done: int, total: int) -> None:
        if self.first is None:
            self.first = done
        elapsed = time.perf_counter() - self.start
        line = f"runs {done}/{total} ({100 * done // max(total, 1)} %), {clock(elapsed)} elapsed"
        if self.first < done < total:
            line += f", ~{clock(elapsed / (done - self.first) * (total - done))} left"
        self.stream.write("\r" + line.ljust(60) + ("\n" if done >= total else ""))
        self.stream.flush()
