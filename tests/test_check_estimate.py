"""``fracid check``'s time estimate: the plan's counts against the methods' declared settings (starts, passes,
failed-run retries, error-term loops, sensitivities, workers) and the arithmetic of its likely and upper values
(:mod:`fracid.inverse.core.plans`, :mod:`fracid.cli.check_time`)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from fracid.cli.check_time import REPORT_SECONDS, SENSITIVITY_COST, Timing, _duration, across_points, time_lines, timing_line
from fracid.inverse.core.forward_operator import RETRY_STEP_DIVISOR
from fracid.inverse.core.plans import (FAILED_RUN_COST, FAILED_SHARE, RunTimes, StagePlan, likely_iterations,
                                       plan_seconds, stage_seconds)
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.kalman_settings import KalmanSettings
from fracid.inverse.methods.knn_gauss_newton import KnnGaussNewton
from fracid.inverse.methods.knn_kalman import KnnKalman
from fracid.inverse.methods.knn_settings import KnnSettings

FAILURES = 1 + FAILED_SHARE * (FAILED_RUN_COST - 1)  # the upper value's factor for failed runs
TIMES = RunTimes(plain=2.0, exact=3.0, workers=2, cores=2)


def kalman_plan(max_starts=3, max_iterations=10, groups=4, n=32):
    """The plan of the default method with exact sensitivities (operator None: central differences, so a
    1-parameter problem makes a linearisation 3 runs)."""
    steps = np.array_split(np.arange(40), groups)  # the 40 observations in ``groups`` steps
    method = KnnKalman(KnnSettings(n=n), KalmanSettings(groups=steps, max_iterations=max_iterations,
                                                        max_starts=max_starts))
    return method.plan(None, 40, 1)


def test_the_filter_declares_its_starts_and_the_upper_value_counts_them():
    one, three = kalman_plan(max_starts=1)[1], kalman_plan(max_starts=3)[1]
    assert (one.starts, three.starts) == (1, 3) and three.starts_key == "[identify.kalman] max_starts"
    assert three.runs == one.runs  # the counts are of one start
    assert stage_seconds(three, TIMES, upper=True) == pytest.approx(3 * stage_seconds(one, TIMES, upper=True))
    assert stage_seconds(three, TIMES) == pytest.approx(stage_seconds(one, TIMES))  # likely: one start
    assert "up to 3 starts" in three.line() and f"at most {3 * three.runs} runs" in three.line()
    assert "starts" not in one.line()


def test_the_filter_counts_passes_and_its_likely_value_half_of_them():
    stage = kalman_plan(max_iterations=10, groups=4)[1]
    per_step = 3  # central differences for one parameter: the run and 2 perturbed
    first = per_step * (4 + 1) / 2  # the first pass's steps run up to their observations
    assert stage.runs == 4 * per_step + 10 * per_step
    assert stage.full_runs == pytest.approx(first + 10 * per_step)
    assert stage.likely_full_runs == pytest.approx(first + 5 * per_step)
    assert "5 of 10 passes" in stage.likely_text
    assert stage_seconds(stage, TIMES, upper=True) == pytest.approx(stage.full_runs * 2.0 * 3 * FAILURES)
    assert stage_seconds(stage, TIMES) == pytest.approx(stage.likely_full_runs * 2.0)


@pytest.mark.parametrize("most, likely", [(1, 1), (2, 2), (3, 2), (4, 2), (10, 5), (11, 6)])
def test_likely_iterations_is_half_the_most_and_at_least_two(most, likely):
    assert likely_iterations(most) == likely


def test_failed_runs_cost_the_retry_with_smaller_steps():
    """The retry's step divisor is the one the operator uses, and the upper value counts it."""
    from fracid.inverse.core.forward_operator import ForwardOperator
    from fracid.models import StepOptions

    first = StepOptions(initial=0.004)
    rules = ForwardOperator._step_rules(type("Op", (), {"steps": first})(), None, 1.0)
    assert rules[1].initial == pytest.approx(first.initial / RETRY_STEP_DIVISOR)
    assert FAILED_RUN_COST == 1 + RETRY_STEP_DIVISOR
    population = StagePlan("knn", "KNN", 32, True, 32.0, "")
    assert stage_seconds(population, TIMES, upper=True) / stage_seconds(population, TIMES) == pytest.approx(FAILURES)


@pytest.mark.parametrize("workers, cores, rounds", [(1, 2, 32), (2, 2, 16), (3, 2, 11 * 1.5), (4, 1, 8 * 4)])
def test_side_by_side_runs_go_in_rounds_on_the_workers_and_cores(workers, cores, rounds):
    population = StagePlan("knn", "KNN", 32, True, 32.0, "")
    times = RunTimes(plain=2.0, exact=3.0, workers=workers, cores=cores)
    assert stage_seconds(population, times) == pytest.approx(rounds * 2.0)


def test_sensitivity_runs_cost_the_timed_run_with_sensitivities():
    plain = StagePlan("s", "S", 10, False, 10.0, "")
    exact = replace(plain, exact=True)
    assert stage_seconds(plain, TIMES) == pytest.approx(20.0) and stage_seconds(exact, TIMES) == pytest.approx(30.0)
    assert Timing(first=9.0, across=(2.0, 4.0)).with_sensitivities == pytest.approx(SENSITIVITY_COST * 3.0)
    assert Timing(first=9.0, across=(2.0, 4.0), exact=7.0).with_sensitivities == 7.0


def test_error_term_loops_repeat_the_local_stages_not_the_population():
    plan = kalman_plan()
    once = plan_seconds(plan, TIMES)
    again = plan_seconds(plan, TIMES, refits=(1, 3))
    knn, kalman = plan
    assert again[0] - once[0] == pytest.approx(stage_seconds(kalman, TIMES))
    assert again[1] - once[1] == pytest.approx(3 * stage_seconds(kalman, TIMES, upper=True))
    assert once[1] == pytest.approx(stage_seconds(knn, TIMES, upper=True) + stage_seconds(kalman, TIMES, upper=True))


@pytest.mark.parametrize("starts", [1, 2, 3, 5])
def test_the_likely_value_never_exceeds_the_upper_one(starts):
    for max_iterations in (1, 2, 3, 10):
        likely, upper = plan_seconds(kalman_plan(max_starts=starts, max_iterations=max_iterations), TIMES, (1, 2))
        assert 0 < likely <= upper


def test_gauss_newton_declares_one_start_and_its_likely_linearisations():
    stage = KnnGaussNewton(KnnSettings(n=8), max_iterations=20).plan(None, 40, 2)[1]
    assert stage.starts == 1 and stage.runs == 21 * 5
    assert stage.likely_full_runs == pytest.approx(11 * 5) and "10 of 20 linearisations" in stage.likely_text


def test_the_timed_plain_run_leaves_out_the_warm_up():
    timing = Timing(first=5.0, across=(2.0, 3.0))
    assert timing.plain == pytest.approx(2.5)
    assert "not counted" in timing_line(timing) and "2.5 s" in timing_line(timing)
    assert Timing(first=5.0).plain == 5.0


def test_the_runs_across_the_bounds_are_inside_them_and_log_scaled():
    space = ParameterSpace(("a", "b", "c"), [1.0, 10.0, 0.0], [100.0, 20.0, 1.0], log=(True, False, False))
    points = across_points(space)
    assert points.shape == (2, 3)
    assert np.allclose(points[:, 0], [10 ** 0.5, 10 ** 1.5])  # 1/4 and 3/4 of the decades
    assert np.allclose(points[:, 1], [17.5, 12.5]) and np.allclose(points[:, 2], [0.25, 0.75])


def _lines(monkeypatch, plan, timing, workers=2, cores=2, refits=(0, 0)):
    from fracid.cli import check_time

    warned = []
    monkeypatch.setattr(check_time, "warn", warned.append)
    lines = time_lines(type("Cfg", (), {"path": "cfg.toml"})(), timing, plan, workers, cores, refits, lambda cfg: "key")
    return "\n".join(lines), warned


def test_the_estimate_states_its_values_and_assumptions(monkeypatch):
    text, warned = _lines(monkeypatch, kalman_plan(), Timing(first=2.5, across=(2.0, 2.0), exact=3.0, load=0.42))
    likely, upper = plan_seconds(kalman_plan(), TIMES)
    assert f"about {_duration(likely + REPORT_SECONDS)}, at most {_duration(upper + REPORT_SECONDS)}" in text
    assert "at most" in text and "3 starts: [identify.kalman] max_starts" in text and "1 in 4 runs fail" in text
    assert "2 worker(s) on 2 core(s)" in text and "load 0.42" in text and "5 of 10 passes" in text
    assert not warned


def test_a_slow_plan_is_warned_about_and_a_quick_one_is_not(monkeypatch):
    plan = kalman_plan(n=5000)
    _, warned = _lines(monkeypatch, plan, Timing(first=2.0, across=(2.0, 2.0), exact=3.0))
    assert len(warned) == 1 and "[identify.knn] n = 5000" in warned[0]
    _, warned = _lines(monkeypatch, kalman_plan(n=8), Timing(first=0.1, across=(0.1, 0.1), exact=0.2))
    assert not warned


def test_more_workers_than_cores_are_said(monkeypatch):
    text, _ = _lines(monkeypatch, kalman_plan(), Timing(first=1.0, across=(1.0,)), workers=4, cores=2)
    assert "4 workers share them" in text and "as 1.65 plain runs (not timed)" in text


def test_the_error_terms_refits_are_said(monkeypatch):
    text, _ = _lines(monkeypatch, kalman_plan(), Timing(first=1.0, across=(1.0,), exact=1.5), refits=(1, 3))
    assert "1 more time(s) for the error terms" in text and "3 more time(s) for the error terms" in text


def test_a_busy_machine_is_said_and_a_quiet_one_is_not(monkeypatch):
    busy, _ = _lines(monkeypatch, kalman_plan(), Timing(first=1.0, across=(1.0,), exact=1.5, load=2.5))
    quiet, _ = _lines(monkeypatch, kalman_plan(), Timing(first=1.0, across=(1.0,), exact=1.5, load=0.3))
    assert "load 2.50" in busy and "busy: on a quiet machine the runs are faster" in busy
    assert "load 0.30" in quiet and "busy" not in quiet


def test_an_unknown_load_is_said(monkeypatch):
    text, _ = _lines(monkeypatch, kalman_plan(), Timing(first=1.0, across=(1.0,), exact=1.5))
    assert "load unknown" in text and math.isnan(Timing(first=1.0).load)
