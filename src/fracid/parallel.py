"""Executors and a resumable batch runner for many forward runs.

:func:`make_executor` gives a ``concurrent.futures``-style executor: in-process (:class:`SerialExecutor`),
a process pool, or a ``dask.distributed`` client. :func:`run_batch` maps a function over tasks on any of
them; with a :class:`~fracid.store.RunStore` it skips tasks already stored and stores every run as soon
as it finishes, so a study killed at any moment resumes where it stopped, losing only runs in flight.

Workers compute, the parent stores: the function runs in the workers and returns a record (a dict);
only the process that called :func:`run_batch` writes to the store.

Process pools use the ``"spawn"`` start method. ``fork`` copies the parent at an arbitrary moment:
locks held by BLAS/OpenMP thread pools (a known source of deadlocks in the child) and open SQLite
connections (which SQLite forbids carrying across a fork). ``forkserver`` would avoid this too, but
exists on POSIX only; ``spawn`` works everywhere and its start-up cost (a fresh interpreter importing
numpy and scipy, well under a second) is paid once per worker, not per task. As with any spawn pool,
a script that starts one must guard its entry point with ``if __name__ == "__main__":``.

Our solver is single-threaded and parallelism comes from the workers, so BLAS/OpenMP threads only
contend for the cores: the workers start with ``OPENBLAS_NUM_THREADS``, ``MKL_NUM_THREADS``,
``OMP_NUM_THREADS`` (and their vecLib/numexpr siblings) set to 1 -- in their environment before the
interpreter starts (OpenBLAS reads it when numpy is first imported), and again by the pool initializer
(for libraries loaded later, such as MKL through pypardiso). The parent's environment is left as it was.
Dask's nanny sets the same variables in its workers by default.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import multiprocessing.context
import os
import pickle
import sys
import threading
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from fracid.progress import _is_terminal, clock
from fracid.store import decode_record, encode_record

__all__ = ["BatchStats", "SerialExecutor", "executor_session", "make_executor", "run_batch"]

THREAD_VARIABLES = (
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "OMP_NUM_THREADS",
    "VECLIB_MAXIMUM_THREADS",
    "NUMEXPR_NUM_THREADS",
)

_DASK_HINT = "pip install 'fracid[dask]'"


# ----------------------------------------------------------------------------------------------
# executors


class SerialExecutor(cf.Executor):
    """Runs each submitted call at once, in the calling process; returns completed futures.

    For debugging (breakpoints and tracebacks work) and for machines with one core.
    """

    def __init__(self):
        self._shutdown = False

    def submit(self, fn, /, *args, **kwargs) -> cf.Future:
        """Call ``fn(*args, **kwargs)`` now; the future holds its result or its exception."""
        if self._shutdown:
            raise RuntimeError("cannot submit to a SerialExecutor after shutdown")
        future = cf.Future()
        future.set_running_or_notify_cancel()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # noqa: BLE001 -- delivered through the future, as in a pool
            future.set_exception(exc)
        return future

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        """Refuse further submissions (nothing is ever pending)."""
        self._shutdown = True

    def __repr__(self) -> str:
        return "SerialExecutor()"


def executor_width(executor) -> int:
    """How many tasks ``executor`` runs at once: its workers (1 for None or a serial executor)."""
    if executor is None or isinstance(executor, SerialExecutor):
        return 1
    if _is_dask(executor):
        return max(1, sum(executor.nthreads().values()))
    return max(1, int(getattr(executor, "_max_workers", 1)))


def concurrently(function, items, executor) -> list:
    """``[function(item) for item in items]``, as many at once as ``executor`` has workers.

    For independent sequential procedures whose steps are forward runs on ``executor`` (the filters
    of a multi-start check or of noisy replicates): each runs in a thread of this process and
    submits its runs to the executor, so the workers stay busy although every procedure waits for
    its own run. Results in the order of ``items``; an exception of ``function`` propagates.
    """
    items = list(items)
    width = min(executor_width(executor), len(items))
    if width <= 1:
        return [function(item) for item in items]
    with cf.ThreadPoolExecutor(width, thread_name_prefix="fracid-concurrent") as threads:
        return list(threads.map(function, items))


def make_executor(workers=None, scheduler: str | None = None):
    """An executor for :func:`run_batch`.

    Parameters
    ----------
    workers : int, "serial", Executor or None
        ``None``: a process pool with one worker per available core; ``1`` or ``"serial"``: a
        :class:`SerialExecutor`; ``n >= 2``: a process pool of ``n`` workers; an executor (anything
        with a ``submit`` method, e.g. a ``dask.distributed.Client``) is returned unchanged.
    scheduler : str, optional
        Address of a dask scheduler (``"tcp://host:8786"``): returns ``dask.distributed.Client(scheduler)``.
        Needs the dask extra (``pip install 'fracid[dask]'``). Give either ``workers`` or ``scheduler``.

    Returns
    -------
    Executor
        Use it as a context manager (or call ``shutdown()``/``close()``) to release the workers.

    Raises
    ------
    ValueError
        For an invalid ``workers`` or when both ``workers`` and ``scheduler`` are given.
    ImportError
        For ``scheduler`` without dask.distributed installed.
    """
    if scheduler is not None:
        if workers is not None:
            raise ValueError(f"give either workers={workers!r} or scheduler={scheduler!r}, not both")
        return _dask_client(scheduler)
    if _is_executor(workers):
        return workers
    if workers == "serial":
        return SerialExecutor()
    n = available_cores() if workers is None else _check_workers(workers)
    if n == 1:
        return SerialExecutor()
    return cf.ProcessPoolExecutor(max_workers=n, mp_context=_SingleThreadSpawnContext(), initializer=_init_worker)


@contextlib.contextmanager
def executor_session(workers=None, scheduler: str | None = None):
    """:func:`make_executor` as a context that stops at once when interrupted.

    A process pool used as a plain context manager waits for its running tasks at exit, so Ctrl-C
    would wait for every forward run in flight (minutes on a fine mesh). Here an exception (Ctrl-C
    included) terminates the workers at once: the runs in flight are lost, those finished are already
    stored. Workers ignore SIGINT (the terminal sends it to the whole process group) and leave the
    decision to the parent. A dask client is closed, never its cluster.
    """
    executor = make_executor(workers, scheduler)
    try:
        yield executor
    except BaseException:
        _stop_now(executor)
        raise
    _close(executor, wait=True)


def _stop_now(executor) -> None:
    if isinstance(executor, cf.ProcessPoolExecutor):
        for process in list((getattr(executor, "_processes", None) or {}).values()):
            process.terminate()
    _close(executor, wait=False)


def _close(executor, wait: bool) -> None:
    if _is_dask(executor):
        executor.close()
    else:
        executor.shutdown(wait=wait, cancel_futures=not wait)


def _init_worker() -> None:
    """Pool initializer: one BLAS thread, and SIGINT ignored (the parent stops the workers)."""
    import signal

    limit_threads()
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity where the OS reports it)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def limit_threads() -> None:
    """Pool initializer: one BLAS/OpenMP thread in this process (env, and threadpoolctl if present)."""
    for name in THREAD_VARIABLES:
        os.environ[name] = "1"
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return
    threadpool_limits(1)


def _check_workers(workers) -> int:
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be a positive int, 'serial', None or an executor, got {workers!r}")
    return workers


def _is_executor(obj) -> bool:
    return isinstance(obj, cf.Executor) or callable(getattr(obj, "submit", None))


def _dask_client(scheduler):
    if _is_executor(scheduler):
        return scheduler
    try:
        from dask.distributed import Client
    except ImportError as exc:
        raise ImportError(f"scheduler={scheduler!r} needs dask.distributed: {_DASK_HINT}") from exc
    return Client(scheduler)


def _is_dask(executor) -> bool:
    return type(executor).__module__.split(".")[0] == "distributed"


_ENV_LOCK = threading.Lock()


@contextlib.contextmanager
def _single_thread_environment():
    """Set the thread variables to 1 in os.environ for the duration (a child inherits them)."""
    with _ENV_LOCK:
        saved = {name: os.environ.get(name) for name in THREAD_VARIABLES}
        os.environ.update({name: "1" for name in THREAD_VARIABLES})
        try:
            yield
        finally:
            for name, value in saved.items():
                if value is None:
                    os.environ.pop(name, None)
                else:
                    os.environ[name] = value


class _SingleThreadSpawnProcess(multiprocessing.context.SpawnProcess):
    """A spawned process whose interpreter starts with one BLAS/OpenMP thread."""

    @staticmethod
    def _Popen(process_obj):
        with _single_thread_environment():
            return multiprocessing.context.SpawnProcess._Popen(process_obj)




class _SingleThreadSpawnContext(multiprocessing.context.SpawnContext):
    """The spawn context, with :class:`_SingleThreadSpawnProcess` processes.

    ProcessPoolExecutor starts its workers on demand (at submit, or to replace a dead one), so the
    environment is set around each start rather than once around the pool's creation.
    """

    Process = _SingleThreadSpawnProcess


# ----------------------------------------------------------------------------------------------
# batch runner


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


def run_batch(
    function: Callable[[object], dict],
    tasks: Sequence,
    *,
    executor,
    store=None,
    keys: Sequence[str] | None = None,
    study: str = "",
    progress=None,
    stats: BatchStats | None = None,
    retry_failed: bool = False,
) -> list[dict]:
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
        From :func:`make_executor` (a SerialExecutor, a process pool, a dask Client) or any executor
        with ``submit``; anything else (e.g. ``2`` or ``"serial"``) is passed to :func:`make_executor`
        and the executor made is shut down at the end.
    store : RunStore, optional
        With ``keys``: tasks whose key is stored are not run, their record is loaded; every finished
        run is stored at once by this (the parent) process, failed runs included.
    keys : sequence of str, optional
        One key per task (see :func:`fracid.store.key_for`). Tasks with equal keys run once and share
        their record.
    study : str
        Label stored with the runs.
    progress : None, bool or callable
        ``None``: a one-line progress report on stderr if stderr is a terminal (else lines of text within
        :func:`fracid.progress.progress_lines`, as the command line does); ``False``: none;
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
    Finished runs are collected with ``as_completed`` (``concurrent.futures.as_completed`` for
    standard futures, ``dask.distributed.as_completed`` for dask ones) rather than in submission
    order, so that each is stored as soon as it finishes, whatever the order: a kill loses only the
    runs in flight, not those finished behind a slow one. With a :class:`SerialExecutor` each run is
    stored before the next starts. Executors whose futures are of another kind are waited on in
    submission order.
    """
    tasks = list(tasks)
    keys = _check_store_and_keys(tasks, store, keys)
    stats = stats if stats is not None else BatchStats()
    stats._reset(len(tasks))
    report = _progress_reporter(progress, stats)
    records: list = [None] * len(tasks)

    groups = _reuse_stored(records, store, keys, retry_failed, stats)
    done = stats.reused
    report(done, len(tasks))
    _check_picklable(function, executor)
    owned = not _is_executor(executor)
    pool = make_executor(executor) if owned else executor
    encode = store is not None
    calls = [(group, (function, tasks[group[0]], encode)) for group in groups]
    failed_run = True
    try:
        with contextlib.closing(_completed(pool, calls)) as completed:
            for group, (payload, status, seconds) in completed:
                record = _keep(payload, status, seconds, group, store, keys, study)
                for index in group:
                    records[index] = record
                done += len(group)
                _count(stats, record, seconds, len(group))
                report(done, len(tasks))
        failed_run = False
    except BaseException as exc:
        _note_interrupted(exc, stats, store)
        raise
    finally:
        if owned:
            pool.shutdown(wait=not failed_run, cancel_futures=True)
        stats._tick()
    return records


def _check_store_and_keys(tasks, store, keys):
    if store is None and keys is None:
        return None
    if store is None:
        raise ValueError("keys= needs store= (a fracid.store.RunStore) to look the runs up in")
    if keys is None:
        raise ValueError("store= needs keys=, one per task (see fracid.store.key_for)")
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


def _keep(payload, status, seconds, group, store, keys, study) -> dict:
    """Store a finished run (parent side) and return its record."""
    if store is None:
        return payload
    store.put(keys[group[0]], payload, status=status, seconds=seconds, study=study)
    return decode_record(payload)


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
    if in_process or (_is_executor(executor) and not isinstance(executor, cf.ProcessPoolExecutor)):
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
    """Yield ``(group, result)`` as the calls finish; cancel what is left if stopped early."""
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
    if _is_dask(executor):
        return executor.submit(fn, *args, pure=False)  # a rerun must run, not hit dask's cache
    return executor.submit(fn, *args)


def _as_completed(executor, futures):
    if all(isinstance(f, cf.Future) for f in futures):
        return cf.as_completed(futures)
    if _is_dask(executor):
        from dask.distributed import as_completed

        return as_completed(futures)
    return iter(futures)


# -- progress --------------------------------------------------------------------------------------


def _progress_reporter(progress, stats: BatchStats | None = None) -> Callable[[int, int], None]:
    from fracid.progress import batch_lines, lines_wanted

    if lines_wanted(progress):  # stderr is not a terminal and the command line asked for lines
        return batch_lines("forward runs", failed=(lambda: stats.failed) if stats is not None else None)
    if progress is None:
        progress = _is_terminal()
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
