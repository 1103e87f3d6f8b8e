"""Executors and run_batch: serial = process pool = dask, failures recorded, resume after a real SIGKILL."""

import concurrent.futures as cf
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import _batch_tasks as bt
import numpy as np
import pytest

from fracid.runtime.batch import BatchStats, run_batch
from fracid.runtime.executors import (
    THREAD_VARIABLES,
    SerialExecutor,
    make_executor,
)
from fracid.store.runs import RunStore

TESTS = str(Path(__file__).resolve().parent)
PARENT_ENVIRONMENT = {name: os.environ.get(name) for name in THREAD_VARIABLES}
N_FAILED = sum(bt.fails(i) for i in range(24))


def assert_records_equal(got, expected):
    assert len(got) == len(expected)
    for a, b in zip(got, expected):
        a, b = bt.deterministic(a), bt.deterministic(b)
        assert a.keys() == b.keys()
        for name in a:
            if isinstance(a[name], np.ndarray):
                assert a[name].dtype == b[name].dtype and np.array_equal(a[name], b[name]), name
            else:
                assert a[name] == b[name], name


@pytest.fixture(scope="module")
def pool():
    with make_executor(2) as executor:
        yield executor


@pytest.fixture(scope="module")
def serial_records():
    return run_batch(bt.compute, bt.make_tasks(24), executor=SerialExecutor(), progress=False)


# -- executors ---------------------------------------------------------------------------------------


def test_make_executor_kinds():
    assert isinstance(make_executor(1), SerialExecutor) and isinstance(make_executor("serial"), SerialExecutor)
    existing = cf.ThreadPoolExecutor(1)
    assert make_executor(existing) is existing
    existing.shutdown()
    with make_executor(2) as executor:
        assert isinstance(executor, cf.ProcessPoolExecutor) and executor._max_workers == 2
    for bad in (0, -2, 1.5, "fast", True):
        with pytest.raises(ValueError, match="workers"):
            make_executor(bad)
    with pytest.raises(ValueError, match="not both"):
        make_executor(2, scheduler="tcp://localhost:8786")


def test_scheduler_without_dask_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    with pytest.raises(ImportError, match=r"pip install 'fracid\[dask\]'"):
        make_executor(scheduler="tcp://localhost:8786")


def test_serial_executor_returns_completed_futures():
    with SerialExecutor() as executor:
        assert executor.submit(pow, 2, 10).result() == 1024
        failed = executor.submit(int, "x")
        assert failed.done() and isinstance(failed.exception(), ValueError)
    with pytest.raises(RuntimeError, match="shutdown"):
        executor.submit(pow, 2, 3)


def test_pool_workers_start_with_one_blas_thread(pool):
    environment = pool.submit(bt.thread_environment, None).result()
    assert environment == {name: "1" for name in THREAD_VARIABLES}
    if os.path.exists("/proc/self/environ"):  # the environment the worker's interpreter started with
        pid = pool.submit(os.getpid).result()
        start = Path(f"/proc/{pid}/environ").read_bytes().split(b"\0")
        assert b"OPENBLAS_NUM_THREADS=1" in start and b"OMP_NUM_THREADS=1" in start
    assert {name: os.environ.get(name) for name in THREAD_VARIABLES} == PARENT_ENVIRONMENT  # untouched


# -- run_batch ---------------------------------------------------------------------------------------


def test_serial_and_pool_give_the_same_records_in_order(pool, serial_records):
    stats = BatchStats()
    records = run_batch(bt.compute, bt.make_tasks(24, sleep=0.01), executor=pool, stats=stats, progress=False)
    assert_records_equal(records, serial_records)
    assert [r.get("i") for r in records if r["status"] == "ok"] == [i for i in range(24) if not bt.fails(i)]
    assert {r["pid"] for r in records if r["status"] == "ok"} != {os.getpid()}
    failed = [r for r in records if r["status"] == "failed"]
    assert len(failed) == stats.failed == N_FAILED > 0
    assert failed[0]["error"] == "ValueError: task 3 fails on purpose"
    assert "fails on purpose" in failed[0]["traceback"]
    assert (stats.computed, stats.reused, stats.total) == (24, 0, 24)


def test_bad_returns_become_failed_records(tmp_path):
    tasks = [{"n": 10}, "not a dict"]
    records = run_batch(bt.busy, tasks, executor="serial", progress=False)
    assert records[0] == {"total": 285, "status": "ok"}
    assert records[1]["status"] == "failed" and records[1]["error"].startswith("TypeError")
    with RunStore(tmp_path / "s.sqlite") as store:
        records = run_batch(repr_record, [1], executor="serial", store=store, keys=["k"], progress=False)
        assert records[0]["status"] == "failed" and "cannot be stored" in records[0]["error"]
        assert store.get("k") == records[0]


def repr_record(task):
    return {"value": {1, 2}}  # a set: not storable


def test_store_reuse_retry_and_progress(tmp_path, serial_records):
    tasks = bt.make_tasks(24)
    keys = bt.task_keys(tasks)
    calls = []
    with RunStore(tmp_path / "s.sqlite") as store:
        first = run_batch(bt.compute, tasks[:10], executor="serial", store=store, keys=keys[:10], progress=False)
        stats = BatchStats()
        records = run_batch(
            bt.compute, tasks, executor="serial", store=store, keys=keys, study="demo", stats=stats,
            progress=lambda done, total: calls.append((done, total)),
        )
        assert (stats.reused, stats.computed) == (10, 14)
        assert [r.get("time") for r in records[:10]] == [r.get("time") for r in first]  # loaded, not rerun
        assert_records_equal(records, serial_records)
        assert calls[0] == (10, 24) and calls[-1] == (24, 24) and len(calls) == 15
        assert len(store) == 24 and len(store.keys("demo")) == 14
        assert store.info(keys[3])["status"] == "failed"

        run_batch(bt.compute, tasks, executor="serial", store=store, keys=keys, stats=stats, progress=False)
        assert (stats.reused, stats.computed) == (24, 0)
        run_batch(
            bt.compute, tasks, executor="serial", store=store, keys=keys, stats=stats, retry_failed=True, progress=False
        )
        assert (stats.reused, stats.computed, stats.failed) == (24 - N_FAILED, N_FAILED, N_FAILED)


def test_equal_keys_run_once(tmp_path):
    tasks = bt.make_tasks(3)
    keys = ["a", "b", "a"]
    with RunStore(tmp_path / "s.sqlite") as store:
        stats = BatchStats()
        records = run_batch(bt.compute, tasks, executor="serial", store=store, keys=keys, stats=stats, progress=False)
    assert stats.computed == 2 and records[2] is records[0] and records[0]["i"] == 0


def test_text_progress_on_request(capsys):
    run_batch(bt.compute, bt.make_tasks(3), executor="serial", progress=True)
    err = capsys.readouterr().err
    assert "runs 3/3 (100 %)" in err and err.endswith("\n")
    run_batch(bt.compute, bt.make_tasks(3), executor="serial")  # stderr is not a terminal: silent
    assert capsys.readouterr().err == ""


def test_argument_errors(tmp_path):
    tasks = bt.make_tasks(2)
    with pytest.raises(ValueError, match="needs keys"):
        run_batch(bt.compute, tasks, executor="serial", store=RunStore(tmp_path / "a.sqlite"))
    with pytest.raises(ValueError, match="needs store"):
        run_batch(bt.compute, tasks, executor="serial", keys=["a", "b"])
    with pytest.raises(ValueError, match="1 keys for 2 tasks"):
        run_batch(bt.compute, tasks, executor="serial", store=RunStore(tmp_path / "b.sqlite"), keys=["a"])
    with pytest.raises(TypeError, match="module-level function"):
        run_batch(lambda task: {}, tasks, executor=2)
    with pytest.raises(TypeError, match="progress"):
        run_batch(bt.compute, tasks, executor="serial", progress="yes")


# -- resume after a real kill --------------------------------------------------------------------------

CHILD = "import sys; sys.path.insert(0, sys.argv[1]); import _batch_tasks; _batch_tasks.main(sys.argv[2:])"


def run_child_and_kill(store_path, calls_dir, n_tasks, at_least):
    """Start the batch in a new session, SIGKILL its whole process group once ``at_least`` rows are stored."""
    args = [sys.executable, "-c", CHILD, TESTS, str(store_path), str(n_tasks), "2", str(calls_dir), "0.05"]
    child = subprocess.Popen(args, start_new_session=True, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and child.poll() is None:
            if store_path.exists() and _rows(store_path) >= at_least:
                break
            time.sleep(0.02)
        assert child.poll() is None, f"the batch ended before the kill: {child.stderr.read().decode()}"
        os.killpg(child.pid, signal.SIGKILL)  # the parent and its pool workers
    finally:
        child.wait()
        child.stderr.close()


def _rows(path):
    try:
        with RunStore(path, readonly=True) as store:
            return len(store)
    except (sqlite3.DatabaseError, FileNotFoundError):  # created, not yet initialised by the child
        return 0


def test_resume_after_sigkill_recomputes_nothing_stored(tmp_path):
    n = 120
    store_path, calls_dir = tmp_path / "study.sqlite", tmp_path / "calls"
    calls_dir.mkdir()
    run_child_and_kill(store_path, calls_dir, n, at_least=40)

    tasks = bt.make_tasks(n, sleep=0.0, calls_dir=str(calls_dir))
    keys = bt.task_keys(tasks)
    with RunStore(store_path) as store:
        before = store.get_many(keys)
        assert 40 <= len(before) < n
        stats = BatchStats()
        with make_executor(2) as executor:
            records = run_batch(
                bt.compute, tasks, executor=executor, store=store, keys=keys, stats=stats, progress=False
            )
        assert len(store) == n
    assert (stats.reused, stats.computed) == (len(before), n - len(before))

    for task, key, record in zip(tasks, keys, records):
        calls = (calls_dir / f"{task['i']}.calls").read_text().split()
        if key in before:  # stored before the kill: run once, by the killed batch, never again
            assert len(calls) == 1 and int(calls[0]) != os.getpid()
            assert record.get("time") == before[key].get("time") and record.get("pid") == before[key].get("pid")
        else:  # in flight at the kill (twice) or not started (once)
            assert 1 <= len(calls) <= 2
    reference = run_batch(bt.compute, bt.make_tasks(n), executor="serial", progress=False)
    assert_records_equal(records, reference)


# -- dask ------------------------------------------------------------------------------------------------


def test_dask_client_gives_the_same_records(serial_records):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        assert make_executor(client) is client
        stats = BatchStats()
        records = run_batch(bt.compute, bt.make_tasks(24), executor=client, stats=stats, progress=False)
        again = run_batch(bt.compute, bt.make_tasks(24), executor=client, progress=False)
    assert_records_equal(records, serial_records)
    assert stats.computed == 24 and stats.failed == N_FAILED
    assert [r["time"] for r in again if "time" in r] != [r["time"] for r in records if "time" in r]  # not cached


def test_filters_run_side_by_side_on_the_pool_and_share_the_store(tmp_path):
    """The multi-start filters run in threads that submit their runs to the pool; each thread writes
    the store through a connection of its own; the ends equal those of the filters run one by one."""
    import fracid
    from fracid.inverse.core.forward_operator import ForwardOperator, Observation
    from fracid.inverse.core.runs import StoredOperator
    from fracid.inverse.methods.kalman import kalman_filter
    from fracid.inverse.studies.uniqueness import multi_start
    from fracid.runtime.executors import concurrently, executor_width

    op = ForwardOperator([Observation(fracid.BarWithWeakZone(n_elements=40), np.linspace(0.004, 0.03, 6))],
                         fracid.DamageParameters(), ("c", "beta"))
    y = op(np.array([2.0, 250.0])).y
    C = np.eye(y.size) * (0.02 * np.abs(y).max()) ** 2
    starts = np.array([[1.5, 200.0], [3.0, 400.0], [2.5, 300.0]])
    C0, bounds = np.diag([1.0, 100.0**2]), (np.array([0.5, 100.0]), np.array([4.0, 500.0]))
    serial = multi_start(op, y, C, starts, C0, bounds=bounds, fit=kalman_filter)
    with RunStore(tmp_path / "runs.sqlite") as store, make_executor(2) as pool:
        assert executor_width(pool) == 2 and concurrently(abs, [-1, -2, 3], pool) == [1, 2, 3]
        evaluate = StoredOperator(op, store).differentiated()
        parallel = multi_start(evaluate, y, C, starts, C0, bounds=bounds, executor=pool, fit=kalman_filter)
        assert evaluate.computed == len(store) > 0 and evaluate.failed == 0
    np.testing.assert_allclose(parallel.ends, serial.ends, rtol=1e-9)
