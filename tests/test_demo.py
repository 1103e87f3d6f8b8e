"""The main job: `fracid demo` identifies kappa_i, beta and c on the real Gregoire et al. (2013) beam.

It runs the full demo (about 4 minutes on 2 cores) and checks the fit against the measured mean curve:
root-mean-square error over the measured range below 5 % of the peak load, and the computed peak
inside the measured scatter band (between the lower and upper envelopes at the CMOD of the computed peak).
"""

import json

import numpy as np
import pytest

from fracid import cli, datasets


pytestmark = pytest.mark.slow  # the fast loop (-m "not slow") leaves this module out


def test_demo_fits_the_gregoire_beam(tmp_path):
    out = tmp_path / "demo"
    assert cli.main(["demo", "--out", str(out), "--quiet"]) == 0
    result = json.loads((out / "result.json").read_text())
    fit = np.genfromtxt(out / "fit.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    measured, computed, cmod = fit["measured"], fit["computed"], fit["control_mm"]
    rms = np.sqrt(np.mean((computed - measured) ** 2))
    assert rms < 0.05 * measured.max(), (rms, measured.max())
    raw = np.genfromtxt(datasets.path("gregoire2013-beam4"), delimiter=",", names=True)
    at_peak = np.argmin(np.abs(raw["cmod_mm"] - cmod[np.argmax(computed)]))
    assert raw["load_min_N"][at_peak] <= computed.max() <= raw["load_max_N"][at_peak]
    assert result["runs"]["knn_failed"] == 0 and result["converged"]
    # exact sensitivities: one run per linearisation (central differences took 89 to 102 runs in all)
    assert result["runs"]["knn"] + result["runs"]["kalman"] <= 45
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") >= 5
