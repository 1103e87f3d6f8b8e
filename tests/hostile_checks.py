"""Hostile-input cases (plausibility of bounds and settings, the posterior's effective sample size, misfit warnings);
run by tests/test_hostile_inputs.py."""

from __future__ import annotations

import csv

from hostile import IDENTIFY, OUT, REACHES_OUTPUT, _clean, _out_is_file, case, check, write_csv

#: [identify] of the bar's gradient-damage model with kappa_i identified too
KAPPA_I = '["c", "beta", "kappa_i"]'
BOUNDS = "c = [0.5, 4.0]\nbeta = [100.0, 500.0]\n"
#: a [posterior] whose 8 draws can never reach the floor of 50 effective samples (the validator's minima: 2 and 1),
#: on one level (the floor is the subject, not the screening)
TINY_POSTERIOR = "[posterior]\nsamples_per_round = 8\nmax_rounds = 1\nscreening = 1\n"


def _misfit_csv(d, curve):
    """Forces 4 % above the model's: a fine fit in % of the peak, but 65 std off with std = 0.0005 N."""
    write_csv(d / "bar.csv", curve[0], 1.04 * curve[1])


MISFIT = {"std": "std = 0.0005"}


def _bound_not_units(proc, d):
    """Exit 2 naming kappa_i, its bound and usual range; the control_unit of the data is not blamed."""
    err = check(proc, d, 2, ["identify.bounds.kappa_i", "lower bound", "implausible", "usual range", "1e-4"])
    assert "control_unit" not in err, err


def _verdict_has_warnings(proc, d):
    """verdict.txt carries the warnings of the identification that stderr and report.html give."""
    check(proc, d, 0)
    verdict = _clean((d / "out" / "verdict.txt").read_text(), d)
    assert "Warning: the misfit is" in verdict and "times the data's std" in verdict, verdict
    assert "Warning: estimate at a bound" in verdict, verdict
    with open(d / "out" / "population.csv", newline="") as handle:  # each KNN run's objective and status
        rows = list(csv.reader(handle))
    assert rows[0] == ["c", "beta", "f", "status", "error"] and len(rows) == 1 + 8, rows
    assert all(r[3] == "ok" and float(r[2]) >= 0 for r in rows[1:]), rows


def _study_posterior_failed(proc, d):
    """A study whose posterior stays below the floor: its verdict reads the Gaussian std, and says why."""
    check(proc, d, 0)
    verdict = _clean((d / "out" / "verdict.txt").read_text(), d)
    assert "posterior failed: effective sample size" in verdict and "the verdict reads the Gaussian std" in verdict
    assert "Verdict measure" not in verdict and "[measure: Gaussian" in verdict, verdict


CASES = {
    # ---- plausibility of the bounds: the parameter and the bound are named, not the data's units
    "kappa_i-bounds-1000x-too-large": case(2, args=IDENTIFY, verify=_bound_not_units,
                                           config={"parameters": KAPPA_I, "bounds": BOUNDS + "kappa_i = [0.05, 0.2]"}),
    "E-bounds-in-GPa": case(2, ["identify.bounds.E", "implausible", "usual range", "MPa"],
                            config={"parameters": '["c", "E"]', "bounds": "c = [0.5, 4.0]\nE = [20.0, 40.0]"},
                            args=IDENTIFY),
    "kappa_i-upper-bound-9x-too-large-named": case(
        2, ["identify.bounds.kappa_i (upper bound 0.009)", "0.032 mm", "usual"], args=IDENTIFY,
        config={"parameters": KAPPA_I, "bounds": BOUNDS + "kappa_i = [1e-4, 0.009]"}),
    "model-kappa_i-50x-too-large-named": case(2, ["model.parameters.kappa_i", "50 times", "usual range"],
                                              config={"params": "kappa_i = 0.05"}, args=IDENTIFY),
    "model-kappa_i-9x-named-beside-control_unit": case(2, ["control_unit", "or model.parameters.kappa_i = 0.009"],
                                                       config={"params": "kappa_i = 0.009"}, args=IDENTIFY),
    "settings-of-a-method-not-chosen-warned": case(
        4, ["fracid: warning", "[identify.gauss-newton] is given but identify.method = 'knn-kalman'",
            "not used", "taken is a file"],
        files=_out_is_file, config={"tail": "[identify.gauss-newton]\nmax_iterations = 5\n"},
        args=("study", "cfg.toml", *REACHES_OUTPUT)),
    # ---- [posterior] settings warned about when the configuration is loaded
    "posterior-target_ess-below-floor-warned": case(
        4, ["fracid: warning", "posterior.target_ess = 20", "below 50", "taken is a file"], files=_out_is_file,
        config={"tail": "[posterior]\ntarget_ess = 20\n"}, args=("posterior", "cfg.toml", *REACHES_OUTPUT)),
    "posterior-draws-below-floor-warned": case(
        4, ["fracid: warning", "8 draws at most", "floor of 50", "taken is a file"], files=_out_is_file,
        config={"tail": TINY_POSTERIOR}, args=("posterior", "cfg.toml", *REACHES_OUTPUT)),
    # ---- the posterior below the floor of the effective sample size: the computation failed
    "posterior-ess-below-floor-fails": case(3, ["failed: effective sample size", "< 50", "samples_per_round",
                                                "inflation"], config={"tail": TINY_POSTERIOR},
                                            args=("posterior", "cfg.toml", *OUT), slow=True),
    # ---- a misfit of tens of std: a warning in units of the data's std
    "misfit-65-std-warns": case(0, ["fracid: warning", "the misfit is", "times the data's std", "std is too small"],
                                csv=_misfit_csv, config=MISFIT, args=IDENTIFY, slow=True),
    "verdict-txt-has-the-warnings": case(0, csv=_misfit_csv, args=("study", "cfg.toml", *OUT), slow=True,
                                         config={**MISFIT, "tail": "[study]\nstarts = 0\nreplicates = 0\n"},
                                         verify=_verdict_has_warnings),
    "study-posterior-below-floor-reads-gaussian": case(
        0, args=("study", "cfg.toml", *OUT), slow=True, verify=_study_posterior_failed,
        config={"tail": "[study]\nstarts = 0\nreplicates = 0\nposterior = true\n" + TINY_POSTERIOR}),
}
