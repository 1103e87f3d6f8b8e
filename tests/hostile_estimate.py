"""Hostile-input cases of issue 38 (estimate); run by tests/test_hostile_inputs.py.

``fracid check``'s time estimate on the tiny bar: it states its likely and upper values and its assumptions
(workers, the timed runs, the load), its upper value grows with ``[identify.kalman] max_starts``, and the
population's share of it with the workers. The stage times are compared per timed run (a stage's seconds over
the timed run's), so that the noise of timing in separate commands does not decide."""

from __future__ import annotations

import re

from hostile import bar_config, case, check, run_fracid

CHECK = ("check", "cfg.toml", "--workers", "1")
UNITS = {"s": 1.0, "min": 60.0, "h": 3600.0}


def _seconds(text: str) -> float:
    value, unit = text.split()
    return float(value) * UNITS[unit]


def estimate(out: str) -> dict:
    """The numbers of ``fracid check``'s estimate: likely, upper [s], the stages' likely and upper [s], the plain
    and exact run [s], the workers and cores it assumes."""
    duration = r"([\d.]+ (?:s|min|h))"
    total = re.search(rf"estimate for fracid identify on (\d+) worker\(s\): about {duration}, at most {duration}", out)
    assert total, out
    stages = {kind: {m.group(1): _seconds(m.group(2)) for m in
                     re.finditer(rf"(KNN|Kalman filter) {duration}", re.search(rf"  {kind}: .*", out).group(0))}
              for kind in ("likely", "at most")}
    cores = re.search(r"assumes: (\d+) worker\(s\) on (\d+) core\(s\)", out)
    return {"workers": int(total.group(1)), "likely": _seconds(total.group(2)), "upper": _seconds(total.group(3)),
            "stages": stages, "plain": float(re.search(r"one forward run took ([\d.]+) s", out).group(1)),
            "exact": float(re.search(r"with exact sensitivities ([\d.]+) s", out).group(1)),
            "cores": int(cores.group(2))}


def _states_assumptions(proc, d):
    check(proc, d, 0)
    out = proc.stdout
    for words in ("about", "at most", "assumes: 1 worker(s) on", "the machine's load", "(1-min average)",
                  "mean of 2 runs across the bounds", "with its warm-up and is not counted", "with exact sensitivities",
                  "3 starts: [identify.kalman] max_starts", "1 in 4 runs fail", "2 of 3 passes", "start and write the report"):
        assert words in out, f"{words!r} not in\n{out}"
    numbers = estimate(out)
    assert 0 < numbers["likely"] < numbers["upper"], out
    assert numbers["workers"] == 1


def _again(d, config: str, *args) -> dict:
    """``fracid check`` of ``config`` (written as again.toml) in ``d``: its estimate's numbers."""
    (d / "again.toml").write_text(config)
    proc = run_fracid(["check", "again.toml", *args], d)
    check(proc, d, 0)
    return estimate(proc.stdout)


def _grows_with_starts(proc, d):
    """max_starts = 5 against 1: the stage line counts 5 starts' runs, and the filter's upper time per run with
    sensitivities is 5 times as large; its likely time (one start) is not."""
    check(proc, d, 0)
    assert "up to 5 starts in all when it ends at a poor point ([identify.kalman] max_starts): at most 25 runs" \
        in proc.stdout, proc.stdout
    five, one = estimate(proc.stdout), _again(d, bar_config(kalman="max_starts = 1"), "--workers", "1")
    upper = [e["stages"]["at most"]["Kalman filter"] / e["exact"] for e in (five, one)]
    likely = [e["stages"]["likely"]["Kalman filter"] for e in (five, one)]
    assert abs(upper[0] / upper[1] - 5) < 0.75, (upper, proc.stdout)
    # under 10 s a stage is printed to 0.1 s: each likely time is known to +-0.05 s besides the timing's noise
    rounding = sum(0.05 / t for t in likely if t < 10)
    ratio = (likely[0] / five["exact"]) / (likely[1] / one["exact"])
    assert abs(ratio - 1) < 0.15 + rounding, (likely, proc.stdout)


def _population_shares_the_workers(proc, d):
    """--workers 2 against 1: the population's time per plain run halves (in rounds of the workers, more workers
    than cores sharing them); the assumptions name the workers."""
    check(proc, d, 0)
    two, one = estimate(proc.stdout), _again(d, (d / "cfg.toml").read_text(), "--workers", "1")
    assert two["workers"] == 2 and one["workers"] == 1
    rounds = [e["stages"]["likely"]["KNN"] / e["plain"] for e in (two, one)]
    expected = [32 / 2 * max(1.0, 2 / two["cores"]), 32.0]
    for got, want in zip(rounds, expected):
        assert abs(got / want - 1) < 0.15, (rounds, expected, proc.stdout)


def _no_time_no_estimate(proc, d):
    check(proc, d, 0)
    assert "time: not measured (--no-time)" in proc.stdout and "estimate for" not in proc.stdout
    assert "up to 3 starts in all" in proc.stdout  # the plan still counts the starts


CASES: dict = {
    "check-estimate-states-its-assumptions": case(0, args=CHECK, verify=_states_assumptions),
    "check-upper-grows-with-max-starts": case(0, config={"kalman": "max_starts = 5"}, args=CHECK,
                                              verify=_grows_with_starts),
    "check-estimate-with-two-workers": case(0, config={"n": "32"}, args=("check", "cfg.toml", "--workers", "2"),
                                            verify=_population_shares_the_workers),
    "check-no-time-counts-the-starts": case(0, args=("check", "cfg.toml", "--no-time"), verify=_no_time_no_estimate),
}
