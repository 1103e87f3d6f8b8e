"""Sensitivity along the load history: finite-difference check, information and variance shares."""

import numpy as np
import pytest

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.sensitivity import sensitivity_history


def test_linear_model_information_and_shares_are_exact():
    A = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 2.0]])
    C_exp, C0 = np.diag([0.1, 0.2, 0.3]), np.diag([4.0, 9.0])
    hist = sensitivity_history(lambda x, needed=None: A @ x, np.array([2.0, 1.0]), C_exp, C0, names=["a", "b"])
    np.testing.assert_allclose(hist.S, A, atol=1e-10)
    np.testing.assert_allclose(hist.information[-1], A.T @ np.linalg.inv(C_exp) @ A, rtol=1e-10)
    post = np.linalg.inv(np.linalg.inv(C0) + A.T @ np.linalg.inv(C_exp) @ A)
    np.testing.assert_allclose(hist.variance_share[-1], 1 - np.diag(post) / np.diag(C0), rtol=1e-10)
    assert hist.variance_share[0, 1] == pytest.approx(0.0, abs=1e-12)  # the first observation says nothing of b
    assert np.all(np.diff(hist.variance_share, axis=0) >= -1e-12)  # data never add uncertainty
    np.testing.assert_allclose(hist.normalised, A * [2.0, 1.0] / np.max(np.abs(A @ [2.0, 1.0])), atol=1e-10)


def test_normalised_sensitivities_agree_with_finite_differences_of_the_bar():
    bar = fracid.BarWithWeakZone(n_elements=80)
    points = np.linspace(0.004, 0.03, 14)
    op = ForwardOperator([Observation(bar, points)], fracid.DamageParameters(), ("c", "beta"))
    x = np.array([2.0, 250.0])
    y0 = op(x).y
    C_exp = np.eye(points.size) * (0.02 * np.abs(y0).max()) ** 2
    hist = sensitivity_history(op, x, C_exp, np.diag([1.0, 100.0]) ** 2, names=["c", "beta"])
    # independent check: forward differences with a smaller step, at three steps (pre-peak, peak, softening)
    for j, name in enumerate(["c", "beta"]):
        dx = 2e-3 * x[j]
        shifted = x.copy()
        shifted[j] += dx
        fd = (op(shifted).y - y0) / dx * x[j] / np.abs(y0).max()
        for t in (1, 4, 10):
            assert hist.normalised[t, j] == pytest.approx(fd[t], rel=0.03, abs=2e-3), (name, t)
    # softening is what carries the information on beta and c: little is known before the peak
    peak = int(np.argmax(y0))
    assert hist.variance_share[peak - 1].max() < hist.variance_share[-1].min()


def test_sensitivity_figure_draws():
    from fracid.report.figures import sensitivity_figure, to_png

    A = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 2.0]])
    hist = sensitivity_history(lambda x, needed=None: A @ x, np.array([2.0, 1.0]), np.eye(3) * 0.1, np.eye(2))
    png = to_png(sensitivity_figure(hist, [0.1, 0.2, 0.3]))
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10000
