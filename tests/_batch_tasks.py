"""Cheap picklable task functions for tests/test_parallel.py, and a batch to run in a child process.

Child-process use (the kill test)::

    python -c "import _batch_tasks; _batch_tasks.main()" STORE N_TASKS WORKERS CALLS_DIR SLEEP
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from fracid.runtime.batch import run_batch
from fracid.runtime.executors import make_executor
from fracid.store.runs import RunStore, key_for

NONDETERMINISTIC = ("pid", "time")


def make_tasks(n: int, sleep: float = 0.0, calls_dir: str | None = None) -> list[dict]:
    """Tasks 0..n-1; each sleeps ``sleep`` s and, with ``calls_dir``, logs its call there."""
    return [{"i": i, "sleep": sleep, "calls_dir": calls_dir} for i in range(n)]


def task_keys(tasks) -> list[str]:
    """Store keys: only the task number determines the result."""
    return [key_for(test="batch", i=task["i"]) for task in tasks]


def fails(i: int) -> bool:
    return i % 7 == 3


def compute(task: dict) -> dict:
    """A deterministic record of ``task["i"]`` (plus pid and time); raises for every 7th task."""
    i = task["i"]
    if task.get("calls_dir"):
        with open(os.path.join(task["calls_dir"], f"{i}.calls"), "a") as log:
            log.write(f"{os.getpid()}\n")
    time.sleep(task.get("sleep", 0.0))
    if fails(i):
        raise ValueError(f"task {i} fails on purpose")
    x = np.linspace(0.0, 1.0, 50) * (i + 1)
    return {
        "i": i,
        "value": float(np.sin(x).sum()),
        "curve": np.sin(x),
        "counts": np.arange(i % 5, dtype=np.int64),
        "grid": np.outer(np.arange(3), np.arange(4)) * i,
        "nested": {"square": i * i, "label": f"task {i}"},
        "pid": os.getpid(),
        "time": time.time(),
    }


def deterministic(record: dict) -> dict:
    """``record`` without the fields that change from run to run."""
    return {name: value for name, value in record.items() if name not in NONDETERMINISTIC}


def busy(task: dict) -> dict:
    """CPU-bound: ``task["n"]`` iterations of pure-Python arithmetic."""
    total = 0
    for k in range(task["n"]):
        total = (total + k * k) % 1_000_003
    return {"total": total}


def thread_environment(_task) -> dict:
    """The BLAS/OpenMP thread variables a worker sees."""
    from fracid.runtime.executors import THREAD_VARIABLES

    return {name: os.environ.get(name) for name in THREAD_VARIABLES}


def main(argv=None) -> None:
    """Run a batch of ``compute`` into a store (for the kill test)."""
    store_path, n, workers, calls_dir, sleep = argv if argv is not None else sys.argv[1:]
    tasks = make_tasks(int(n), float(sleep), calls_dir)
    with RunStore(store_path) as store, make_executor(int(workers)) as executor:
        run_batch(compute, tasks, executor=executor, store=store, keys=task_keys(tasks), progress=False)
