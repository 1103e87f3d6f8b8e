"""Hostile-input cases of issue 38 (status); run by tests/test_hostile_inputs.py.

A fit's status word and what to do (result.json, report.html), the warning that names a parameter the data do
not identify (and its absence on a well-identified fit), the Kalman stage's progress over its restarts, and a
model error that must not hide a poor fit."""

from __future__ import annotations

import json
import re

import numpy as np

from hostile import IDENTIFY, case, check, run_fracid, write_csv

#: E and beta of the bar: well identified by the whole curve (measured: std 0.5 % and 1.4 %, r = 0.68)
E_BETA = {"parameters": '["E", "beta"]', "bounds": "E = [10000.0, 40000.0]\nbeta = [100.0, 500.0]", "c": "2.0"}
#: the curve cut before its peak (0.01 mm): the softening is not seen
PRE_PEAK = {"control_range": "[0.001, 0.006]", "n_points": "8"}
#: the words of a status (fracid.inverse.core.fit_status.STATUS_ACTIONS)
WORDS = ("converged", "converged along a valley", "stopped but stable", "not converged", "failed")
#: progress lines at every update
LINES = {"FRACID_PROGRESS_SECONDS": "0"}


def _result(d):
    return json.loads((d / "out" / "result.json").read_text())


def _converged_words(proc, d):
    """A converged bar fit: the word and its action in result.json and report.html; no warning at all."""
    err = check(proc, d, 0)
    result = _result(d)
    assert result["status_word"] == "converged" and result["status"].startswith("converged"), result["status"]
    assert result["status_action"] == "the estimate and its std can be used", result["status_action"]
    report = (d / "out" / "report.html").read_text(encoding="utf-8")
    assert "converged (what to do: the estimate and its std can be used)" in report
    warned = [line for line in err.splitlines() if "warning" in line and "specimen.n_elements" not in line]
    assert warned == [], err  # only the coarse mesh's


def _no_identification_warning(proc, d):
    """E and beta, well identified: no "not identified" warning, the std below 10 % of the estimates."""
    err = check(proc, d, 0)
    assert "not identified" not in err and "fracid study" not in err, err
    result = _result(d)
    assert np.all(np.array(result["std"]) < 0.1 * np.abs(result["x"])), result["std"]
    assert abs(result["correlation"][0][1]) < 0.99


def _progress_within_total(proc, d):
    """Every progress line of the Kalman stage reads n/m with n <= m, says which start of max_starts, and the
    last one's estimate is result.json's (a restarted filter's: tests/test_fit_status.py)."""
    err = check(proc, d, 0)
    lines = [line for line in err.splitlines() if line.startswith("fracid: Kalman filter:")]
    counts = [tuple(map(int, m.groups())) for m in (re.search(r"(\d+)/(\d+) steps?", line) for line in lines) if m]
    assert counts and all(n <= m for n, m in counts), "\n".join(lines)
    result = _result(d)
    assert any("start 1/3" in line for line in lines), "\n".join(lines)  # restarts: tests/test_fit_status.py
    shown = [float(v) for v in lines[-1].split("returned x = ")[1].split(", ")]
    np.testing.assert_allclose(shown, result["x"], rtol=1e-3)


def _model_error_no_worse(proc, d):
    """With the model error the fit ends no worse (measurement-only RMS, within 2 %) than without it, and its std are
    wider."""
    check(proc, d, 0)
    with_term = _result(d)
    (d / "plain.toml").write_text((d / "cfg.toml").read_text().replace('model_error = "variance"\n', ""))
    plain = run_fracid(["identify", "plain.toml", "--out", "plain", "--workers", "1", "--quiet"], d)
    check(plain, d, 0)
    without = json.loads((d / "plain" / "result.json").read_text())
    assert with_term["error_terms"] and not without["error_terms"]

    def rms(result):
        return float(np.sqrt(np.mean((np.array(result["y_fit"]) - np.array(result["y_exp"])) ** 2)))

    assert rms(with_term) <= 1.02 * rms(without), (rms(with_term), rms(without))  # the other minimum: 1.04
    assert np.all(np.array(with_term["std"]) > np.array(without["std"])), (with_term["std"], without["std"])


def _model_form_error(d, curve):
    """The bar's curve with a 5 % ripple no parameter reproduces (a model-form error, 2.2 periods over the 12 points
    of [0.004, 0.03] mm) has two minima. Measured: without the term the fit ends at c = 0.5 (its lower bound), beta =
    138, RMS 2.59 % of the peak; with the term started again from the KNN prior (before issue 38) it ended in the
    other, c = 2.21, beta = 259, RMS 2.69 %; started from the estimate without the term: 2.59 %, std 0.5 and 58
    (0.027 and 3.1 without)."""
    ripple = 0.05 * np.sin(14.0 * (curve[0] - 0.004) / 0.026)
    write_csv(d / "bar.csv", curve[0], curve[1] * (1 + ripple))


def _off_by(factor):
    def csv(d, curve):
        write_csv(d / "bar.csv", curve[0], factor * curve[1])
    return csv


CASES = {
    "status-words-on-a-converged-bar-fit": case(None, config=E_BETA, args=IDENTIFY, verify=_converged_words, slow=True),
    "parameter-not-identified-warned-by-name": case(
        0, ["not identified by the data", "c = ", "beta = ", "% of the estimate", "fracid study"],
        config=PRE_PEAK, args=IDENTIFY, slow=True),
    "unsensed-parameter-within-bounds-warned": case(
        0, ["not identified by the data: beta = ", "bounds alone", "fracid study"],
        config={**E_BETA, **PRE_PEAK}, args=IDENTIFY, slow=True),
    "well-identified-fit-not-warned": case(None, config=E_BETA, args=IDENTIFY, verify=_no_identification_warning,
                                           slow=True),
    "progress-never-past-total-over-restarts": case(
        None, config={"kalman": "max_starts = 3"}, csv=_off_by(1.3), env=LINES,
        args=("identify", "cfg.toml", "--out", "out", "--workers", "1"), verify=_progress_within_total, slow=True),
    "model-error-with-two-minima-ends-no-worse": case(
        None, config={"identify": 'model_error = "variance"', "std": "std = 0.002", "kalman": "max_starts = 3"},
        csv=_model_form_error, args=IDENTIFY, verify=_model_error_no_worse, slow=True),
}
