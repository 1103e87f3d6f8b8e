"""The status words of a fit and what to do (fracid.inverse.core.fit_status), the non-identified warning, and the
Kalman stage's progress over its restarts (issue 38)."""

import io
import re
from contextlib import redirect_stderr
from dataclasses import replace

import numpy as np
import pytest

from fracid.inverse.core.fit_status import (CONVERGED, FAILED, NOT_CONVERGED, STABLE, STATUS_ACTIONS, VALLEY,
                                            correlated_pairs, fit_action, stable_step, status_action, status_word,
                                            unidentified)
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.kalman import kalman_filter
from fracid.inverse.methods.kalman_status import KalmanResult, judge_stop, restarted
from fracid.inverse.methods.knn import design, knn_from_population
from fracid.inverse.methods.knn_kalman import KalmanProgress
from fracid.runtime.progress import LineProgress


@pytest.mark.parametrize("status, word", [
    ("converged", CONVERGED), ("converged: the last pass moved the estimate by 0.03 std", CONVERGED),
    ("converged (an oscillation between passes was damped: 1 step(s) under-relaxed)", CONVERGED),
    ("converged along a valley (parameters c and beta correlated, r = 0.998: see the study)", VALLEY),
    ("stopped but stable: 10 global iterations reached", STABLE), ("not converged: oscillates", NOT_CONVERGED),
    ("failed: the forward run at the starting point failed", FAILED),
    ("stopped: no step", NOT_CONVERGED),  # an older result's or another method's
    ("", ""), ("converging", ""), ("some words", "")])
def test_a_status_reads_as_one_word_with_an_action(status, word):
    assert status_word(status) == word
    assert status_action(status) == STATUS_ACTIONS.get(word, "")


def test_every_word_says_what_to_do():
    assert set(STATUS_ACTIONS) == {CONVERGED, VALLEY, STABLE, NOT_CONVERGED, FAILED}
    assert "fracid study" in STATUS_ACTIONS[VALLEY] and "max_iterations" in STATUS_ACTIONS[STABLE]
    assert "do not use" in STATUS_ACTIONS[NOT_CONVERGED] and "no usable estimate" in STATUS_ACTIONS[FAILED]


def test_a_wide_or_correlated_parameter_is_named_and_a_sharp_one_is_not():
    names = ["c", "beta"]
    sharp = np.diag([0.05**2, 3.0**2])
    assert unidentified(names, [2.0, 250.0], sharp, ([0.5, 100.0], [4.0, 500.0])) == []
    # the real beam of issue 38: c = 45 +- 48 mm^2, r = 0.998
    C = np.array([[48.0**2, 0.998 * 48 * 20], [0.998 * 48 * 20, 20.0**2]])
    texts = unidentified(names, [45.0, 300.0], C)
    assert len(texts) == 2 and all("fracid study" in t for t in texts)
    assert "c = 45 +- 48 (std 107 % of the estimate)" in texts[0] and "beta" not in texts[0]
    assert "c and beta (r = +0.9980)" in texts[1]
    # just below and above the limits
    assert unidentified(names, [1.0, 1.0], np.diag([0.49**2, 0.1**2])) == []
    assert "c = 1 +- 0.51" in unidentified(names, [1.0, 1.0], np.diag([0.51**2, 0.1**2]))[0]
    r = lambda v: np.array([[1.0, v], [v, 1.0]]) * 1e-4  # noqa: E731
    assert correlated_pairs(r(0.989)) == [] and correlated_pairs(r(-0.991))[0][:2] == (0, 1)
    # a std as wide as the bounds' (uniform over [100, 500]: 115): the data add nothing
    texts = unidentified(names, [2.0, 310.0], np.diag([0.05**2, 139.0**2]), ([0.5, 100.0], [4.0, 500.0]))
    assert len(texts) == 1 and "beta = 310 +- 1.4e+02" in texts[0] and "bounds alone" in texts[0]
    assert unidentified(names, [np.nan, 1.0], np.eye(2)) == []  # no estimate: another warning says so


def test_a_stopped_filter_reads_stable_or_not_converged_by_its_last_moves():
    C = np.eye(2)
    assert stable_step([[0.0, 0.0], [0.3, 0.0], [0.4, 0.1]], C) == pytest.approx(0.3)
    for end, word in (([0.2, 0.0], STABLE), ([1.5, 0.0], NOT_CONVERGED)):
        result = KalmanResult(x=np.array(end), C=C, y=np.ones(3), passes=[{"x": np.zeros(2)}, {"x": np.zeros(2)}])
        judge_stop(result, "at iteration 3: the objective does not decrease along the step")
        assert result.status.startswith(f"{word}: stopped at iteration 3") and not result.converged
    failed = KalmanResult(x=np.zeros(2), C=C, y=np.full(3, np.nan))
    judge_stop(failed, "the forward run at the final estimate failed: diverged")
    assert failed.status == "failed: stopped, the forward run at the final estimate failed: diverged"


def two_basins(x, needed=None):
    return (x[0] ** 2 - 1.0) ** 2 * np.linspace(0.2, 1.0, 8)


def test_the_progress_of_a_restarted_filter_never_passes_its_total_and_ends_on_the_returned_estimate(monkeypatch):
    """Issue 38 read '16/13 steps' and an estimate other than the returned one: each start adds its steps to the
    total, the lines say which start, the last one's estimate is the winner's."""
    monkeypatch.setenv("FRACID_PROGRESS_SECONDS", "0")
    y = two_basins(np.array([2.0]))
    C_exp = np.eye(y.size) * (0.01 * y.max()) ** 2
    space = ParameterSpace(("x",), [-0.5], [3.0])
    points = design(space, 16, "sobol", seed=1)
    knn = replace(knn_from_population(space, points, np.array([two_basins(p) for p in points]), ["ok"] * 16,
                                      [""] * 16, y, C_exp, 3), x0=np.array([0.0]))
    err = io.StringIO()
    with redirect_stderr(err):
        with LineProgress(8 + 10 - 1, "Kalman filter", unit="step") as bar:
            shown = KalmanProgress(bar, 8 + 10 - 1, 3)

            def run(x0):
                return kalman_filter(two_basins, y, C_exp, x0, np.eye(1), bounds=(space.lower, space.upper),
                                     callback=shown.start())

            result = restarted(run, run(knn.x0), knn, y, C_exp, max_starts=3)
            shown.returned(result.x)
    lines = err.getvalue().splitlines()
    counts = [tuple(map(int, m.groups())) for m in (re.search(r"(\d+)/(\d+) steps", line) for line in lines) if m]
    assert len(result.starts) == 2 and shown.starts == 2
    assert counts and all(n <= m for n, m in counts) and counts[-1][1] == 2 * 17, lines
    assert any("start 2/3" in line for line in lines)
    assert lines[-1].endswith(f"returned x = {result.x[0]:.4g}") and result.x[0] == pytest.approx(2.0)


def test_a_converged_fit_with_an_unidentified_parameter_is_not_said_usable_as_a_whole():
    assert fit_action("converged", False) == STATUS_ACTIONS[CONVERGED]
    assert "except the parameters the data do not identify" in fit_action("converged: small step", True)
    assert "except" in fit_action("stopped but stable: 3 global iterations reached", True)
    assert fit_action("not converged: oscillates", True) == STATUS_ACTIONS[NOT_CONVERGED]
