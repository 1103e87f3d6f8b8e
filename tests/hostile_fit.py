"""Hostile-input cases of issue 38 (fit); run by tests/test_hostile_inputs.py.

The elastic-slope warning on a configuration whose specimen is not the test's (item 2): the synthetic data come
from a 100 mm bar; a 70 mm bar in the configuration is about 100/70 = 1.43 times stiffer, a 140 mm one 0.71 times
as stiff. With data points low on the rising branch the warning names the direction and its size; with the data's
first point above 35 % of their peak it says it cannot tell, rather than guess."""

from __future__ import annotations

import json
import re

from hostile import IDENTIFY, case, check

#: the data from 0.001 mm on: points on the rising branch below 35 % of the peak
LOW_START = {"control_range": "[0.001, 0.03]", "n_points": "30"}


def _slope_warning(way: str, low: float, high: float):
    """Exit 0, the warning "the model is N % <way> than the data" with N in [low, high], and the same ratio in
    result.json's diagnostics, judged on the run's own curve."""
    def verify(proc, d):
        err = " ".join(check(proc, d, 0).split())
        found = re.search(rf"the model is (\d+) % {way} than the data in block 'global'", err)
        assert found and low <= float(found.group(1)) <= high, err
        block, = json.loads((d / "out" / "result.json").read_text())["diagnostics"]["blocks"]
        assert block["run_curve"] and abs(100 * abs(block["slope_ratio"] - 1) - float(found.group(1))) < 1, block
    return verify


CASES = {
    "slope-specimen-too-stiff-said-stiffer": case(0, config={"specimen": "length = 70.0", **LOW_START}, args=IDENTIFY,
                                                  slow=True, verify=_slope_warning("stiffer", 35, 50)),
    "slope-specimen-too-soft-said-softer": case(0, config={"specimen": "length = 140.0", **LOW_START}, args=IDENTIFY,
                                                slow=True, verify=_slope_warning("softer", 22, 36)),
    "slope-first-point-high-cannot-tell": case(
        0, ["the elastic slopes differ in block 'global'", "the data's rising branch is above 35 % of its peak",
            "too few points on the rising branch to tell whether the model is stiffer or softer"],
        config={"specimen": "length = 70.0"}, args=IDENTIFY, slow=True),
}
