"""``fracid compare``'s set-up (issue 38 items 5 and 12): one prior rule for every model and the bounds fitted to the
mesh (:func:`fracid.config.mesh_bounds.fit_to_mesh`): kept where the mesh resolves them, the lower bound raised
where it resolves part of them, the model left out where it resolves none."""

import math
import types

import pytest

from fracid.config import load_config
from fracid.config.mesh_bounds import fit_to_mesh, smallest_resolved
from hostile import bar_config, synthetic_curve, write_csv


def _l(c):
    return math.sqrt(2.0 * c)  # the internal length of gradient damage [mm]


@pytest.mark.parametrize("h, lower, upper, expected", [
    (5.0, 0.33, 30.0, 12.5),     # l >= 5 mm: c >= 12.5 mm^2
    (2.5, 0.667, 6.0, 3.13),     # c >= 3.125, rounded up to 3 digits
    (1.0, 0.667, 6.0, 0.667),    # resolved at the lower bound: kept
    (5.0, 0.33, 3.0, None),      # not even the upper bound (the c in [0.33, 3] on 5 mm elements)
    (2.0, 1.0, 2.0, 2.0),        # only the upper bound: the range shrinks to it
])
def test_smallest_resolved(h, lower, upper, expected):
    value = smallest_resolved(_l, h, lower, upper)
    assert value == (pytest.approx(expected) if expected is not None else None)
    if value is not None:
        assert _l(value) >= h and lower <= value <= upper


@pytest.fixture()
def configs(tmp_path):
    write_csv(tmp_path / "bar.csv", *synthetic_curve())

    def make(**changes):
        path = tmp_path / f"cfg{len(list(tmp_path.glob('*.toml')))}.toml"
        path.write_text(bar_config(**changes))
        return load_config(path)

    return make


def test_fit_to_mesh_keeps_cuts_and_leaves_out(configs):
    from fracid.cli.compare import model_config

    fine = configs(c="6.0", n_elements="50")  # h = 2 mm; the rule gives c in [2, 18]: l(2) = 2 mm
    kept = fit_to_mesh(model_config(fine, "gradient-damage"))
    assert kept.text is None and kept.config.identify.lower[0] == 2.0
    cut = fit_to_mesh(model_config(configs(c="2.0"), "gradient-damage"))  # h = 2.5 mm, c in [0.667, 6]
    assert cut.config.identify.lower[0] == 3.13 and cut.config.identify.upper[0] == 6.0
    assert "cut to [3.13, 6]" in cut.text and "2.5 mm" in cut.text
    out = fit_to_mesh(model_config(configs(c="1.0"), "integral-damage"))  # c in [0.333, 3]: l(3) = 2.45 < 2.5 mm
    assert out.config is None and "even at the upper bound c = 3" in out.text
    local = fit_to_mesh(model_config(configs(c="1.0"), "local-damage"))  # no mesh length: as it is
    assert local.text is None and local.config.identify.parameters == ("kappa_i", "beta")


def test_a_fixed_mesh_length_parameter_not_resolved_leaves_the_model_out(configs):
    """pf-czm's l (not identified by the rule: ft, Gf) at its default 2.5 mm needs h <= 0.5 mm."""
    from fracid.cli.compare import model_config

    out = fit_to_mesh(model_config(configs(), "pf-czm"))
    assert out.config is None and "l = 2.5 mm" in out.text and "0.5 mm" in out.text
    assert fit_to_mesh(model_config(configs(n_elements="200"), "pf-czm")).config is not None  # h = 0.5 mm


def test_one_prior_rule_for_the_configured_model_too(configs):
    """The configured model keeps its [identify] parameters but not its [identify.bounds]: a factor 3 around its
    values, beta on a log scale, as every other model's."""
    from fracid.cli.compare import model_config

    cfg = configs(c="2.0", beta="250.0")  # [identify.bounds] c = [0.5, 4], beta = [100, 500], no log
    own = model_config(cfg, "gradient-damage")
    assert own.identify.parameters == ("c", "beta") and own.model == cfg.model
    assert own.identify.lower == pytest.approx((0.667, 83.3)) and own.identify.upper == pytest.approx((6.0, 750.0))
    assert own.identify.log == ("beta",)
    other = model_config(cfg, "integral-damage")
    assert other.identify.parameters == ("kappa_i", "beta", "c")
    assert dict(zip(other.identify.parameters, other.identify.lower))["c"] == pytest.approx(0.667)
    assert types.SimpleNamespace(**dict(other.model.parameters)).c == 2.0
