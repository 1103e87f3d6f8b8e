"""Every run of an identification is stored: the Kalman stage resumes after a kill, reruns compute nothing,
run keys change with the forward code, failed runs are retried on request."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from _bar_study import stored_rows, write_bar_study

import fracid
from fracid.inverse.core import runs as runs_module
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.runs import StoredOperator, run_key
from fracid.store.runs import RunStore

N_KNN = 8


@pytest.fixture()
def bar_config(tmp_path):
    return write_bar_study(tmp_path, n_elements=120, n=N_KNN, k=3, c_lower=1.0, kalman="max_iterations = 4")


def identify(config, out, **popen):
    command = [sys.executable, "-m", "fracid", "identify", str(config), "--out", str(out), "--workers", "1", "--quiet"]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **popen)


def finished(config, out):
    process = identify(config, out)
    stdout, stderr = process.communicate(timeout=600)
    assert process.returncode == 0 and "Traceback" not in stderr, stderr
    return json.loads((out / "result.json").read_text())


@pytest.mark.slow
def test_identification_killed_in_its_kalman_stage_resumes(bar_config, tmp_path):
    out = tmp_path / "killed"
    store = out / "runs.sqlite"
    child = identify(bar_config, out, start_new_session=True)
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and child.poll() is None and stored_rows(store) < N_KNN + 3:
            time.sleep(0.02)
        assert child.poll() is None, f"finished or died before the kill: {child.stderr.read()}"
        os.killpg(child.pid, signal.SIGKILL)  # in the Kalman stage: the population (8) and 3 Kalman runs stored
    finally:
        child.communicate()
    before = stored_rows(store)
    assert before >= N_KNN + 3 and not (out / "result.json").exists()

    resumed = finished(bar_config, out)
    runs = resumed["runs"]
    # nothing stored is recomputed: every stored Kalman run is reused, every computed one is new
    assert runs["knn_computed"] == 0 and runs["kalman_reused"] == before - N_KNN
    assert stored_rows(store) - before == runs["kalman_computed"] > 0

    again = finished(bar_config, out)  # a finished identification run again recomputes nothing
    assert again["runs"]["knn_computed"] == 0 and again["runs"]["kalman_computed"] == 0
    assert again["runs"]["kalman"] == resumed["runs"]["kalman"] > 0

    fresh = finished(bar_config, tmp_path / "fresh")  # uninterrupted
    np.testing.assert_allclose(resumed["x"], fresh["x"], rtol=1e-10)
    np.testing.assert_allclose(again["x"], fresh["x"], rtol=1e-10)


def test_run_keys_change_with_the_forward_code_and_the_outputs_needed(monkeypatch):
    bar = fracid.BarWithWeakZone(n_elements=40)
    op = ForwardOperator([Observation(bar, np.linspace(0.004, 0.03, 6))], fracid.DamageParameters(), ("c",))
    x = np.array([2.0])
    key = run_key(op, x)
    assert run_key(op, x, needed=3) != key and run_key(op, x, needed=6) == key  # all 6 outputs: the full run
    assert runs_module.code_version().startswith(fracid.__version__ + "+")
    monkeypatch.setattr(runs_module, "code_version", lambda: "0.0.0+edited")
    assert run_key(op, x) != key


def test_stored_operator_reuses_runs_and_retries_failed_ones_on_request(tmp_path):
    bar = fracid.BarWithWeakZone(n_elements=40)
    op = ForwardOperator([Observation(bar, np.linspace(0.004, 0.03, 6))], fracid.DamageParameters(), ("c", "kappa_i"))
    good, bad = np.array([2.0, 1e-4]), np.array([2.0, -1.0])  # kappa_i < 0: a failed run
    with RunStore(tmp_path / "runs.sqlite") as store:
        first = StoredOperator(op, store)
        records = first.evaluate_many([good, bad, good])
        assert [r.ok for r in records] == [True, False, True] and first.computed == 2 and first.failed == 1
        second = StoredOperator(op, store)
        again = second.evaluate_many([good, bad])
        assert second.computed == 0 and second.reused == 2
        np.testing.assert_array_equal(again[0].y, records[0].y)
        retry = StoredOperator(op, store, retry_failed=True)
        retry.evaluate_many([good, bad])
        assert retry.computed == 1 and retry.reused == 1  # the failed run only
        partial = second(good, 3)
        assert second.computed == 1 and np.all(np.isnan(partial.y[3:])) and np.isfinite(partial.y[:3]).all()
