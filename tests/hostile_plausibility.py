"""Hostile-input cases of issue 38 (plausibility); run by tests/test_hostile_inputs.py.

What ``[model.parameters]`` fixes: a length scale whose band cannot form inside the specimen (refused, exit 2),
one whose band takes much of it (warned), a value far outside its usual range (warned), and the usual values (not
warned). ``fracid check`` of a 60-element bar of 100 mm: one short forward run, nothing identified.
"""

from __future__ import annotations

from hostile import case, check

IDENTIFY_CHECK = ("check", "cfg.toml")

SIMULATE = """\
[model]
type = "{model}"
[model.parameters]
{params}

[specimen]
type = "bar"
n_elements = {n_elements}
"""

#: the words of this module's warnings
OURS = ("room of the specimen", "implausible", "cannot form")


def _config(model: str, params: str, n_elements: int = 60) -> str:
    return SIMULATE.format(model=model, params=params, n_elements=n_elements)


def _quiet(words=(), *, at_all=False):
    """Exit 0, the configuration valid, and none of this module's warnings on stderr (``at_all``: no warning at all;
    else the mesh's resolution may be warned about, another check's business)."""
    def verify(proc, d):
        err = check(proc, d, 0)
        assert not any(word in err for word in (("warning",) if at_all else OURS)), err
        for word in words:
            assert word in proc.stdout, proc.stdout
    return verify


def _band(status, words, model, params):
    return case(status, words, config=_config(model, params), csv=None, args=IDENTIFY_CHECK)


CASES = {
    # ---- PF-CZM: the band's width pi l against the bar's length (warned above a half, refused above it)
    "pf-czm-l-1000mm-on-100mm-bar-refused": _band(
        2, ["model.parameters.l = 1000 mm", "pi l = 3.14e+03 mm", "31.4 times", "its length = 100 mm",
            "cannot form", "cohesive law", "lower l below 31.8 mm", "15.9 mm or less"], "pf-czm", "l = 1000.0"),
    "pf-czm-l-just-beyond-bar-refused": _band(
        2, ["model.parameters.l = 32 mm", "1.01 times", "lower l below 31.8 mm"], "pf-czm", "l = 32.0"),
    "pf-czm-l-above-half-warned": _band(
        0, ["fracid: warning", "model.parameters.l = 20 mm", "pi l = 62.8 mm", "62.8% of", "its length = 100 mm",
            "more than the 50%", "1.4 % of the peak at the whole length", "15.9 mm or less"], "pf-czm", "l = 20.0"),
    "pf-czm-l-below-half-not-warned": case(None, config=_config("pf-czm", "l = 15.0"), csv=None,
                                           args=IDENTIFY_CHECK, verify=_quiet(["valid"])),
    "pf-czm-default-l-not-warned": case(None, config=_config("pf-czm", "", n_elements=200), csv=None,
                                        args=IDENTIFY_CHECK, verify=_quiet(["valid"], at_all=True)),
    # ---- gradient and integral damage: 2 pi sqrt(c) (warned above a half, refused above the length)
    "gradient-damage-c-beyond-bar-refused": _band(
        2, ["model.parameters.c = 300 mm^2", "2 pi sqrt(c) = 109 mm", "1.09 times", "its length = 100 mm",
            "cannot form", "lower c below 253 mm^2", "63.3 mm^2 or less"], "gradient-damage", "c = 300.0"),
    "gradient-damage-c-above-half-warned": _band(
        0, ["fracid: warning", "model.parameters.c = 100 mm^2", "2 pi sqrt(c) = 62.8 mm", "62.8% of",
            "more than the 50%", "9.5 % at the whole length", "63.3 mm^2 or less"], "gradient-damage", "c = 100.0"),
    "gradient-damage-c-below-half-not-warned": case(None, config=_config("gradient-damage", "c = 50.0"), csv=None,
                                                    args=IDENTIFY_CHECK, verify=_quiet(["valid"])),
    "integral-damage-c-beyond-bar-refused": _band(
        2, ["model.parameters.c = 300 mm^2", "1.09 times", "its length = 100 mm", "lower c below 253 mm^2"],
        "integral-damage", "c = 300.0"),
    "integral-damage-c-above-half-warned": _band(
        0, ["fracid: warning", "model.parameters.c = 100 mm^2", "62.8% of", "more than the 50%"],
        "integral-damage", "c = 100.0"),
    # ---- the upper end of an identified parameter's bounds whose band cannot form: warned
    "bound-upper-c-beyond-bar-warned": case(
        0, ["fracid: warning", "identify.bounds.c: the upper bound 300 mm^2", "1.09 times", "its length = 100 mm",
            "lower the upper bound below 253 mm^2"],
        config={"bounds": "c = [0.5, 300.0]\nbeta = [100.0, 500.0]"}, args=IDENTIFY_CHECK),
    "bound-upper-c-within-bar-not-warned": case(None, config={"bounds": "c = [0.5, 200.0]\nbeta = [100.0, 500.0]"},
                                                args=IDENTIFY_CHECK, verify=_quiet(["valid"])),
    # ---- a fixed value far outside its usual range (another unit): warned naming the key, as a bound is refused
    "fixed-E-in-GPa-warned": _band(
        0, ["fracid: warning", "model.parameters.E = 30 is implausible", "1/167 of the lower end",
            "5000 <= E <= 100000 [MPa]", "check its unit and scale"], "gradient-damage", "E = 30.0"),
    "fixed-Gf-in-J-per-m2-warned": _band(
        0, ["fracid: warning", "model.parameters.Gf = 113 is implausible", "113 times the upper end",
            "0.005 <= Gf <= 1 [N/mm]"], "pf-czm", "Gf = 113.0"),
    "fixed-values-within-tenfold-not-warned": case(None, config=_config("gradient-damage", "E = 90000.0\neta = 40.0"),
                                                   csv=None, args=IDENTIFY_CHECK, verify=_quiet(["valid"])),
}
