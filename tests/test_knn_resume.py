"""A KNN population of 120 runs killed halfway (SIGKILL of the process group) resumes without recomputing."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from _bar_study import stored_rows
from _knn_child import N_RUNS, operator, search

from fracid.runtime.batch import BatchStats
from fracid.store.runs import RunStore

CHILD = Path(__file__).with_name("_knn_child.py")


@pytest.mark.slow
def test_killed_population_resumes_with_the_same_result(tmp_path):
    path = tmp_path / "population.sqlite"
    child = subprocess.Popen([sys.executable, str(CHILD), str(path)], start_new_session=True, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and child.poll() is None and stored_rows(path) < N_RUNS // 3:
            time.sleep(0.05)
        assert child.poll() is None, f"the population finished or died before the kill: {child.stderr.read().decode()}"
        os.killpg(child.pid, signal.SIGKILL)
    finally:
        child.wait()
        child.stderr.close()
    before = stored_rows(path)
    assert N_RUNS // 3 <= before < N_RUNS

    op = operator()
    stats = BatchStats()
    with RunStore(path) as store:
        resumed = search(op, store=store, stats=stats)
        assert len(store) == N_RUNS
    assert stats.reused == before and stats.computed == N_RUNS - before  # nothing stored was recomputed

    fresh = search(op)  # uninterrupted, no store
    np.testing.assert_array_equal(resumed.order, fresh.order)
    np.testing.assert_allclose(resumed.f, fresh.f, rtol=1e-12)
    np.testing.assert_allclose(resumed.x0, fresh.x0, rtol=1e-12)
    np.testing.assert_allclose(resumed.C0, fresh.C0, rtol=1e-12)
