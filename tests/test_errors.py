"""Invalid parameters and impossible requests fail early with messages naming what is wrong."""

import numpy as np
import pytest

import fracid
from fracid.models import DamageModel


@pytest.mark.parametrize(
    "changes, words",
    [
        ({"E": -1.0}, ["'E'", "-1.0", "0 < E"]),
        ({"nu": 0.5}, ["'nu'", "0.5", "nu < 0.5"]),
        ({"kappa_i": 0.0}, ["'kappa_i'", "0 < kappa_i"]),
        ({"alpha": 1.5}, ["'alpha'", "1.5", "0 <= alpha <= 1"]),
        ({"beta": -3}, ["'beta'", "-3", "0 <= beta"]),
        ({"c": 0.0}, ["'c'", "0 < c"]),
        ({"eta": 0.5}, ["'eta'", "1 <= eta"]),
        ({"c": float("nan")}, ["'c'", "nan"]),
        ({"E": "stiff"}, ["'E'", "'stiff'", "not a number"]),
    ],
)
def test_invalid_parameters_are_named(changes, words):
    with pytest.raises(ValueError) as info:
        fracid.DamageParameters(**changes)
    for word in words:
        assert word in str(info.value)


def test_replace_validates_and_rejects_unknown_names():
    p = fracid.DamageParameters()
    assert p.replace(c=2.0).c == 2.0 and p.c == 1.0
    with pytest.raises(ValueError, match="'alpha'"):
        p.replace(alpha=-0.1)
    with pytest.raises(ValueError, match="unknown parameter"):
        p.replace(gamma=1.0)
    with pytest.raises(ValueError, match="7 parameters"):
        fracid.DamageParameters.from_array([1.0, 2.0])
    assert fracid.DamageParameters.from_array(p.as_array()) == p


@pytest.mark.parametrize(
    "changes, word",
    [
        ({"length": -1.0}, "length"),
        ({"weak_zone_width": 200.0}, "weak_zone_width"),
        ({"weak_zone_factor": 0.0}, "weak_zone_factor"),
        ({"weakening": "density"}, "weakening"),
        ({"profile": "gauss"}, "profile"),
        ({"n_elements": 2}, "n_elements"),
    ],
)
def test_invalid_bar_is_named(changes, word):
    with pytest.raises(ValueError, match=word):
        fracid.BarWithWeakZone(**changes)


@pytest.mark.parametrize(
    "kwargs, word",
    [
        ({"target": -0.01}, "target"),
        ({"target": float("inf")}, "target"),
        ({"control": "cmod"}, "unknown control 'cmod'"),
        ({"stop_force_fraction": 1.5}, "stop_force_fraction"),
        ({"steps": fracid.StepOptions(initial=1.0), "target": 0.01}, "step initial"),
        ({"steps": fracid.StepOptions(grow=0.5)}, "grow"),
        ({"max_steps": 0}, "max_steps"),
        ({"damage_threshold": 1.0}, "never reached"),
    ],
)
def test_impossible_requests_are_refused(kwargs, word):
    with pytest.raises(ValueError, match=word):
        fracid.simulate(fracid.BarWithWeakZone(n_elements=20), fracid.DamageParameters(), **kwargs)


def test_the_regularization_shorthand_is_a_marker_naming_the_model():
    """simulate(regularization=...) was removed (issue 37): the model is given as model=DamageModel(...)."""
    bar, params = fracid.BarWithWeakZone(n_elements=20), fracid.DamageParameters()
    with pytest.raises(TypeError, match=r"regularization='local'\) was removed: .*model=fracid.models.DamageModel\('local'\)"):
        fracid.simulate(bar, params, regularization="local")
    with pytest.raises(ValueError, match="regularization"):
        fracid.simulate(bar, params, model=DamageModel("nonlocal"))


def test_newton_options_are_checked():
    with pytest.raises(ValueError, match="rtol_u"):
        fracid.NewtonOptions(rtol_u=0.0)
    with pytest.raises(ValueError, match="max_iterations"):
        fracid.NewtonOptions(max_iterations=0)
    with pytest.raises(ValueError, match=r"reuse_ratio = 1.0; it must be in \[0, 1\)"):
        fracid.NewtonOptions(reuse_ratio=1.0)
    with pytest.raises(ValueError, match="reuse_iterations = -1; it must be a non-negative integer"):
        fracid.NewtonOptions(reuse_iterations=-1)


def test_snap_back_under_end_displacement_fails_with_partial_result():
    """Local model of a long bar snaps back: plain displacement control cannot follow it."""
    params = fracid.DamageParameters(beta=100.0)
    bar = fracid.BarWithWeakZone(n_elements=200, profile="hat", length=400.0)
    with pytest.raises(fracid.ConvergenceError) as info:
        fracid.simulate(bar, params, model=DamageModel("local"), target=0.2, stop_force_fraction=0.05)
    partial = info.value.partial
    assert "end_displacement" in str(info.value) and "failed" in partial.status
    assert partial.n_steps > 2 and partial.peak_force > 0
    assert np.all(np.isfinite(partial.force))
    # the weak-zone elongation is monotonic through the snap-back and gets further
    result = fracid.simulate(bar, params, model=DamageModel("local"), control="weak_zone_elongation", target=0.1, stop_force_fraction=0.05)
    assert result.status.startswith("force below")
    end = result.observables["end_displacement"]
    assert np.any(np.diff(end) < 0)  # the end displacement goes back: snap-back traced


BRITTLE = fracid.DamageParameters(E=37000.0, kappa_i=1e-4, beta=10000.0, c=1.0)  # snaps back in a small beam


def _snap_back_failure(specimen, params, control):
    """The ConvergenceError of ``specimen`` under ``control`` and the command's (status, message) for it."""
    from fracid.runtime import exits

    with pytest.raises(fracid.ConvergenceError) as info:
        fracid.simulate(specimen, params, control=control, stop_force_fraction=0.2)
    return info.value, exits.describe(info.value)


@pytest.mark.slow
def test_snap_back_under_deflection_is_named_and_cmod_advised():
    """A brittle beam under deflection control fails past the peak with the force falling steeply: the
    error says the curve snaps back and names cmod, which then traces the curve to 20 % of the peak."""
    from fracid.runtime import exits

    from fracid.specimens import NotchedBeam

    beam = NotchedBeam(h_fine=4.0, h_coarse=10.0)
    err, (status, text) = _snap_back_failure(beam, BRITTLE, "deflection")
    assert err.snap_back and err.control == "deflection" and set(err.functionals) == {"cmod", "deflection"}
    assert err.partial.force[-1] < err.partial.peak_force  # past the peak
    assert status == exits.FAILED and "did not converge" in text
    assert "snaps back under control 'deflection'" in text and 'control = "cmod"' in text
    assert "weak_zone_elongation" not in text  # only the beam's control is named
    assert fracid.simulate(beam, BRITTLE, control="cmod", stop_force_fraction=0.2).status.startswith("force below")


def test_snap_back_of_a_bar_names_the_weak_zone_elongation():
    bar = fracid.BarWithWeakZone(length=400.0, n_elements=40)
    err, (_, text) = _snap_back_failure(bar, fracid.DamageParameters(beta=1000.0), "end_displacement")
    assert err.snap_back and "snaps back under control 'end_displacement'" in text
    assert 'control = "weak_zone_elongation"' in text and "cmod" not in text


def test_a_failure_without_snap_back_is_not_called_one():
    """c = 1e12 fails at the first step: no peak, no snap-back diagnosis, the general advice."""
    err, (_, text) = _snap_back_failure(fracid.BarWithWeakZone(n_elements=40), fracid.DamageParameters(c=1e12),
                                        "end_displacement")
    assert not err.snap_back and "snaps back" not in text and "did not converge" in text


@pytest.mark.parametrize("force, expected", [
    ([0.0, 1.0, 2.0, 1.9, 1.0], True),  # past the peak, falling at 9 x the initial stiffness
    ([0.0, 1.0, 2.0, 1.9, 1.85], False),  # softening at half the initial stiffness
    ([0.0, 1.0, 2.0, 2.1, 2.2], False),  # still rising
    ([0.0, 1.0], False),  # too short to tell
])
def test_snaps_back_reads_the_slope_past_the_peak(force, expected):
    from fracid.fem.path.path_following import snaps_back

    control = [0.0, 1.0, 2.0, 2.1, 2.2][:len(force)]
    assert snaps_back(force, control) is expected


def test_convergence_error_keeps_its_diagnosis_when_pickled():
    import pickle

    from fracid.fem.path.path_following import ConvergenceError

    err = pickle.loads(pickle.dumps(ConvergenceError("failed", None, True, "deflection", ("cmod", "deflection"))))
    assert (str(err), err.snap_back, err.control, err.functionals) == ("failed", True, "deflection",
                                                                        ("cmod", "deflection"))


def test_snap_back_control_of_each_specimen():
    from fracid.specimens import snap_back_control

    assert snap_back_control("deflection", ("cmod", "deflection")) == "cmod"
    hinged_dogbone = ("elongation", "platen_displacement", "platen_tilt")
    assert snap_back_control("platen_displacement", hinged_dogbone) == "elongation"
    assert snap_back_control("elongation", ("band_opening", "elongation")) == "band_opening"  # the tension strip
    assert snap_back_control("cmod", ("cmod", "deflection")) is None  # already the one that follows
    assert snap_back_control("u_top", ("u_top", "opening")) is None  # a mesh of one's own: unknown
