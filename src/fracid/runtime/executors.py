"""Executors for many forward runs.

:func:`make_executor` gives a ``concurrent.futures``-style executor: in-process (:class:`SerialExecutor`),
a process pool, or a ``dask.distributed`` client. :func:`fracid.runtime.batch.run_batch` maps a function over
tasks on any of them, resumably.

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
import threading

__all__ = ["SerialExecutor", "executor_session", "make_executor"]

THREAD_VARIABLES = (
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "OMP_NUM_THREADS",
    "VECLIB_MAXIMUM_THREADS",
    "NUMEXPR_NUM_THREADS",
)

_DASK_HINT = "pip install 'fracid[dask]'"


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
    if is_dask(executor):
        return max(1, sum(executor.nthreads().values()))
    return max(1, int(getattr(executor, "_max_workers", 1)))


def concurrently(function, items, executor, progress=None) -> list:
    """``[function(item) for item in items]``, as many at once as ``executor`` has workers.

    For independent sequential procedures whose steps are forward runs on ``executor`` (the filters
    of a multi-start check or of noisy replicates): each runs in a thread of this process and
    submits its runs to the executor, so the workers stay busy although every procedure waits for
    its own run. Results in the order of ``items``; an exception of ``function`` propagates.
    ``progress(done, total)``, when given, is called after each procedure ends.
    """
    items = list(items)
    done = []

    def counted(item):
        result = function(item)
        done.append(item)
        if progress is not None:
            progress(len(done), len(items))
        return result

    width = min(executor_width(executor), len(items))
    if width <= 1:
        return [counted(item) for item in items]
    with cf.ThreadPoolExecutor(width, thread_name_prefix="fracid-concurrent") as threads:
        return list(threads.map(counted, items))


def make_executor(workers=None, scheduler: str | None = None):
    """An executor for :func:`fracid.runtime.batch.run_batch`.

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
    if is_executor(workers):
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
    if is_dask(executor):
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


def is_executor(obj) -> bool:
    """Whether ``obj`` is an executor: a ``concurrent.futures.Executor`` or anything with ``submit``."""
    return isinstance(obj, cf.Executor) or callable(getattr(obj, "submit", None))


def _dask_client(scheduler):
    if is_executor(scheduler):
        return scheduler
    try:
        from dask.distributed import Client
    except ImportError as exc:
        raise ImportError(f"scheduler={scheduler!r} needs dask.distributed: {_DASK_HINT}") from exc
    return Client(scheduler)


def is_dask(executor) -> bool:
    """Whether ``executor`` is a ``dask.distributed`` client."""
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
