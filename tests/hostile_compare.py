"""Hostile-input cases of issue 38 (``fracid compare``): a model that fails every run, evidence below the ESS floor,
the report beside identify's, bounds the mesh cannot resolve, progress per model; run by tests/test_hostile_inputs.py.

Every case compares on the 40-element bar of tests/hostile.py (h = 2.5 mm; 50 elements: 2 mm) with ``--workers
1``: gradient damage (the configured model, c and beta identified) and local damage (kappa_i, beta by ``fracid
init``'s rule), a KNN of 8 and at most 2 x 40 posterior draws per model (about 20 s a model).
"""

from __future__ import annotations

import json
import os

from hostile import _clean, case, check, fracid_wrote

#: a posterior whose second round reaches ESS 15 on the bar (measured 19.5 with c at its lower bound), the floor
#: min(15, 50) = 15
ESTIMATED = "[posterior]\nsamples_per_round = 40\nmax_rounds = 2\ntarget_ess = 15\nscreening = 1\n"
#: 10 draws: ESS <= 10, below the floor of 20 whatever the weights
BELOW_FLOOR = "[posterior]\nsamples_per_round = 10\nmax_rounds = 1\ntarget_ess = 20\nscreening = 1\n"
#: c = 6 mm^2 on 50 elements: the rule's c in [2, 18] is resolved everywhere (l = 2 mm >= h = 2 mm)
FINE = {"c": "6.0", "n_elements": "50", "bounds": "c = [2.0, 18.0]\nbeta = [100.0, 900.0]"}
TWO = ("--models", "gradient-damage", "local-damage")
QUIET = ("--out", "out", "--workers", "1", "--quiet")

#: makes every run of local damage fail to converge (imported at start-up from the case's directory)
_FAILING = '''\
from fracid.models.damage import DamageModel

_simulate = DamageModel.simulate


def _failing(self, specimen, params, **options):
    if self.regularization == "local":
        raise ArithmeticError("injected by the test: local damage never converges")
    return _simulate(self, specimen, params, **options)


DamageModel.simulate = _failing
'''


def _failing_local(d):
    (d / "sitecustomize.py").write_text(_FAILING)


def _report_head(d) -> str:
    """compare.html up to its ranking table, paths as <dir>."""
    html = _clean((d / "out" / "compare.html").read_text(encoding="utf-8"), d)
    return html[:html.index("Ranking by log evidence")]


def _failing_model_warned(proc, d):
    err = check(proc, d, 0, ["fracid: warning: local-damage: not compared", "injected by the test"])
    assert not proc.stdout.strip(), proc.stdout  # --quiet: nothing on stdout
    head = _report_head(d)
    assert "Warnings" in head and "local-damage: not compared, left out of the ranking" in head, head
    saved = json.loads((d / "out" / "compare.json").read_text())
    assert saved["ranking"] == ["gradient-damage"] and "local-damage" in saved["failures"]
    # fine enough: no mesh warning (the other direction of the mesh cases)
    assert "cut to the mesh" not in err and "too coarse" not in err and "not resolved" not in err, err


def _not_estimated(proc, d):
    check(proc, d, 3, ["local-damage: log evidence not estimated, not ranked", "below the sampler's floor",
                       "no model gave an estimated log evidence", "compare.html"])
    saved = json.loads((d / "out" / "compare.json").read_text())
    assert saved["ranking"] == [] and saved["not_ranked"] == ["local-damage"] and saved["best"] is None
    model = saved["models"][0]
    assert model["log_evidence"] is None and not model["log_evidence_estimated"]
    assert model["posterior"]["ess"] < 20 and model["log_evidence_sampled"] is not None
    assert "not estimated (ESS" in (d / "out" / "compare.html").read_text(encoding="utf-8")


IDENTIFY_REPORT = "<html><body>identify's report, written by fracid identify</body></html>\n"


def _identify_report(d):
    (d / "out").mkdir()
    (d / "out" / "report.html").write_text(IDENTIFY_REPORT)
    fracid_wrote(d / "out", "report.html", "result.json", "runs.sqlite")


def _beside_identify(proc, d):
    check(proc, d, 3)
    assert (d / "out" / "report.html").read_text() == IDENTIFY_REPORT  # untouched
    assert "fracid compare" in (d / "out" / "compare.html").read_text(encoding="utf-8")


def _mesh_left_out(proc, d):
    check(proc, d, 3, ["fracid: warning: gradient-damage: not compared, its mesh is too coarse",
                       "length / n_elements = 2.5 mm", "l = sqrt(2 c) = 2.45 mm even at the upper bound c = 3"])
    head = _report_head(d)
    assert "gradient-damage: not compared" in head and "too coarse" in head, head
    saved = json.loads((d / "out" / "compare.json").read_text())
    assert saved["not_ranked"] == ["local-damage"] and list(saved["failures"]) == ["gradient-damage"]


def _mesh_cut(proc, d):
    check(proc, d, 3, ["fracid: warning: gradient-damage: bounds cut to the mesh", "c in [0.667, 6] mm^2 cut to "
                       "[3.13, 6]", "not resolved below c = 3.13"])
    saved = json.loads((d / "out" / "compare.json").read_text())
    assert saved["models"][0]["bounds"][0][0] == 3.13 and saved["models"][0]["bounds"][1][0] == 6.0
    assert "cut to [3.13, 6]" in _report_head(d)


def _progress_lines(proc, d):
    check(proc, d, 3)
    lines = proc.stdout.splitlines()
    for label in ("gradient-damage", "local-damage"):
        beats = [line for line in lines if line.startswith(f"{label}: 0:") and " elapsed, " in line]
        assert beats, f"no progress line of {label}:\n{proc.stdout[-3000:]}"
    assert any("elapsed, waiting for a worker" in line for line in lines), proc.stdout[-3000:]
    assert any(line.startswith("local-damage: done: ") for line in lines)


CASES = {
    "compare-model-failing-every-run-warned-quiet": case(
        None, config={**FINE, "tail": ESTIMATED}, files=_failing_local, args=("compare", "cfg.toml", *TWO, *QUIET),
        env={"PYTHONPATH": os.pathsep.join([".", os.environ.get("PYTHONPATH", "")])}, slow=True,
        verify=_failing_model_warned),
    "compare-evidence-below-ess-floor-not-ranked": case(
        None, config={**FINE, "tail": BELOW_FLOOR}, args=("compare", "cfg.toml", "--models", "local-damage", *QUIET),
        slow=True, verify=_not_estimated),
    "compare-report-beside-identify-report": case(
        None, config={**FINE, "tail": BELOW_FLOOR}, files=_identify_report, slow=True, verify=_beside_identify,
        args=("compare", "cfg.toml", "--models", "local-damage", *QUIET)),
    "compare-mesh-cannot-resolve-default-bounds-left-out": case(
        None, config={"c": "1.0", "tail": BELOW_FLOOR}, args=("compare", "cfg.toml", *TWO, *QUIET), slow=True,
        verify=_mesh_left_out),
    "compare-mesh-cuts-default-lower-bound": case(
        None, config={"c": "2.0", "tail": BELOW_FLOOR}, slow=True, verify=_mesh_cut,
        args=("compare", "cfg.toml", "--models", "gradient-damage", *QUIET)),
    "compare-progress-lines-per-model": case(
        None, config={**FINE, "tail": BELOW_FLOOR}, args=("compare", "cfg.toml", *TWO, "--out", "out",
                                                          "--workers", "1"),
        env={"FRACID_PROGRESS_SECONDS": "0.5"}, slow=True, verify=_progress_lines),
}
