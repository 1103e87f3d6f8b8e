"""Hostile-input cases of ``[identify.knn] screening`` (the KNN population on a coarser mesh, issue 39); run by
tests/test_hostile_inputs.py.

A bad value exits 2 naming the key, the value and the range, in ``fracid check`` and ``fracid identify``; a
screening mesh that would leave the internal length unresolved falls back to the configured mesh and says so
(the plan's line, the result's notes and population record, the report); a screening mesh that is used is named
in the plan, timed by ``fracid check`` and recorded with the population."""

from __future__ import annotations

import json

from hostile import IDENTIFY, _clean, case, check

#: the 120-element bar with c in [1.5, 4] mm^2: l = sqrt(2 c) >= 1.73 mm, resolved on 60 elements (h = 1.67 mm)
RESOLVED = {"n_elements": "120", "bounds": "c = [1.5, 4.0]\nbeta = [100.0, 500.0]", "c": "2.0"}
CHECK = ("check", "cfg.toml", "--workers", "1")
WORDS = ["identify.knn.screening", "1 <= screening <= 4", "element-size factor"]


def _stdout(proc, d, status=0) -> str:
    check(proc, d, status)
    return _clean(proc.stdout, d)


def _fallback_in_plan(proc, d):
    """The default bar (40 elements, c in [0.5, 4]): a screening mesh 2 times coarser resolves none of the range."""
    out = _stdout(proc, d)
    assert "stage KNN: 8 forward runs side by side (sobol, k = 3) on the configured mesh: [identify.knn] screening = 2 " \
           "would mesh it with element size = 5 mm" in out, out
    assert "would be resolved over 0% of the range of c [0.5, 4] mm^2 only (at least 50% needed)" in out, out
    assert "screening mesh" not in out.split("time:")[-1], out  # no screening run timed


def _coarse_in_plan_and_timed(proc, d):
    out = _stdout(proc, d)
    assert "on a screening mesh 2 times coarser (element size = 1.67 mm, the configured 0.833 mm; " \
           "[identify.knn] screening = 2); the fit runs on the configured mesh" in out, out
    assert "on the population's screening mesh" in out and "times a plain run on the configured mesh" in out, out


def _fallback_recorded(proc, d):
    """``fracid identify``: the stage line, the notes of result.json, its population record and the report say it."""
    out = _stdout(proc, d)
    assert out.count("on the configured mesh: [identify.knn] screening = 2") == 1, out  # said once, in the plan
    result = json.loads((d / "out" / "result.json").read_text())
    assert result["knn"]["screening"].startswith("on the configured mesh: [identify.knn] screening = 2"), result["knn"]
    assert any("on the configured mesh: [identify.knn] screening = 2" in n for n in result["notes"]), result["notes"]
    report = (d / "out" / "report.html").read_text()
    assert "The population ran on the configured mesh: [identify.knn] screening = 2" in report


def _coarse_recorded(proc, d):
    out = _stdout(proc, d)
    assert "on a screening mesh 2 times coarser" in out, out
    result = json.loads((d / "out" / "result.json").read_text())
    assert "screening mesh 2 times coarser" in result["knn"]["screening"], result["knn"]
    assert "The population ran on a screening mesh 2 times coarser" in (d / "out" / "report.html").read_text()


CASES = {
    "knn-screening-below-1-refused": case(2, [*WORDS, "0.5"], config={"knn": "screening = 0.5"}, args=IDENTIFY),
    "knn-screening-above-4-refused": case(2, [*WORDS, "10"], config={"knn": "screening = 10"}, args=IDENTIFY),
    "knn-screening-a-string-refused": case(2, [*WORDS, "'2'"], config={"knn": 'screening = "2"'}, args=CHECK),
    "knn-screening-a-bool-refused": case(2, [*WORDS, "True"], config={"knn": "screening = true"}, args=CHECK),
    "knn-screening-fallback-said-in-the-plan": case(None, config={"knn": "screening = 2"},
                                                    args=(*CHECK, "--no-time"), verify=_fallback_in_plan),
    "knn-screening-coarse-named-and-timed-by-check": case(None, config={**RESOLVED, "knn": "screening = 2"}, args=CHECK,
                                                          verify=_coarse_in_plan_and_timed, slow=True),
    "knn-screening-fallback-recorded": case(None, config={"knn": "screening = 2"},
                                            args=("identify", "cfg.toml", "--out", "out", "--workers", "1"),
                                            verify=_fallback_recorded, slow=True),
    "knn-screening-coarse-recorded": case(None, config={**RESOLVED, "knn": "screening = 2"},
                                          args=("identify", "cfg.toml", "--out", "out", "--workers", "1"),
                                          verify=_coarse_recorded, slow=True),
}
