"""Comparing models by evidence (issue 28 item 3): the arithmetic of the log evidence, its Laplace approximation,
AIC and BIC on a linear-Gaussian model (where Laplace is exact), the twin of the cohesive crack against gradient
damage in both directions (the generating model ranks first by evidence), and ``fracid compare`` end to end.

The twins: the source model's force at 20 CMOD points to 0.35 mm on a 5 mm beam mesh with coarse steps (a run in
0.3-0.5 s), 2 % of its peak as noise and as the stated std; the cohesive crack identifies ft, Gf, gradient damage
kappa_i, beta (c at the source's 21.4 mm^2, so both are two-parameter models); a population of 8, two Kalman
passes of three steps, a posterior of 2 x 24 draws. Measured (log Z +- Monte-Carlo error): cohesive twin,
cohesive -93.39 +- 0.13 against gradient -112.75 +- 0.13; gradient twin, gradient -93.14 +- 0.12 against
cohesive -143.82 +- 0.13; the Laplace approximations within 0.2 of them.
"""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from fracid.data import Diagonal, ExperimentalData
from fracid.fem.material.cohesive import CohesiveParameters
from fracid.fem.material.parameters import DamageParameters
from fracid.fem.path.path_following import StepOptions
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.sampling.posterior import PosteriorSettings, posterior
from fracid.inverse.studies import evidence
from fracid.inverse.studies.model_comparison import compare, contender
from fracid.inverse.studies.model_fit import Candidate, run_to_end
from fracid.models import CohesiveCrackModel, DamageModel
from fracid.specimens.beam import NotchedBeam

BEAM = NotchedBeam(h_fine=5.0, h_coarse=10.0)
CMOD = np.linspace(0.01, 0.35, 20)  # mm: into the tail, where the two models differ most
# coarse steps (half the cost of the default rule): the CMOD points are landed on whatever the steps, and data and
# model share the rule (forces within 0.05 N of the default rule's)
STEPS = StepOptions(maximum=CMOD[-1] / 15, onset_fraction=0.2, grow=2.0)
E = 37000.0  # MPa, both models
COHESIVE = CohesiveParameters(E=E, nu=0.2, ft=3.0, Gf=0.1)
GRADIENT = DamageParameters(E=E, nu=0.2, kappa_i=4.8e-5, alpha=0.99, beta=1086.0, c=21.4, eta=10.0)
CANDIDATES = (Candidate("cohesive crack", CohesiveCrackModel(), CohesiveParameters(E=E, nu=0.2), ("ft", "Gf"),
                        ParameterSpace(("ft", "Gf"), [1.5, 0.04], [6.0, 0.3], log=(False, True))),
              Candidate("gradient damage", DamageModel("gradient"), GRADIENT.replace(kappa_i=1e-4, beta=300.0),
                        ("kappa_i", "beta"), ParameterSpace(("kappa_i", "beta"), [3e-5, 200.0], [1.2e-4, 3000.0],
                                                            log=(False, True))))
SETTINGS = {"n": 8, "k": 3, "groups": np.array_split(np.arange(CMOD.size), 3), "max_iterations": 2, "max_starts": 1}
SAMPLER = PosteriorSettings(samples_per_round=24, max_rounds=2, target_ess=25.0, screening=1.0)  # single level


# ------------------------------------------------------------------------------------------ arithmetic


def _linear_problem():
    """y = A (a, ln b) + noise: linear in a and ln b, so the posterior in (a, ln b) is Gaussian and the Laplace
    approximation exact (the bounds are many std away)."""
    t = np.linspace(0.0, 1.0, 12)
    A = np.column_stack([1.0 + t, np.sin(3.0 * t)])
    space = ParameterSpace(("a", "b"), [-5.0, 0.01], [5.0, 100.0], log=(False, True))
    std = 0.05
    y = A @ [1.0, math.log(2.0)] + std * np.random.default_rng(1).standard_normal(t.size)
    return t, A, space, y, Diagonal(np.full(t.size, std**2))


def test_laplace_aic_bic_and_sampled_evidence_on_a_linear_gaussian_model():
    t, A, space, y, C = _linear_problem()
    theta = np.linalg.lstsq(A, y, rcond=None)[0]
    x_hat = np.array([theta[0], math.exp(theta[1])])
    chi2 = C.quadratic(A @ theta - y)
    log_l = evidence.gaussian_log_likelihood(chi2, C.logdet(), t.size)
    assert log_l == pytest.approx(-0.5 * chi2 - 0.5 * t.size * math.log(2 * math.pi * 0.05**2), rel=1e-12)
    # exact: the Gaussian integral in (a, ln b), prior density 1/10 in a and 1/ln(1e4) in ln b
    H = A.T @ A / 0.05**2
    exact = log_l - math.log(10.0) - math.log(math.log(1e4)) + math.log(2 * math.pi) - 0.5 * np.linalg.slogdet(H)[1]
    S = A * [1.0, 1.0 / x_hat[1]]  # dy/db = dy/dln b / b: the Jacobian the log-uniform density cancels
    assert evidence.laplace_log_evidence(log_l, x_hat, S, C, space) == pytest.approx(exact, abs=1e-9)
    assert evidence.information_criteria(log_l, 2, 12) == pytest.approx((4 - 2 * log_l, 2 * math.log(12) - 2 * log_l))
    post = posterior(lambda x, needed=None: A @ [x[0], math.log(x[1])], y, C, space, x_hat, np.linalg.inv(S.T @ C.solve(S)),
                     settings=PosteriorSettings(samples_per_round=400, max_rounds=3, target_ess=5000.0))
    # measured: 12.420 +- 0.021 against 12.448
    assert abs(post.log_evidence - exact) < 4 * post.log_evidence_error < 0.2


def test_ranking_flags_ties_within_the_combined_errors():
    order, tied = evidence.rank_by_evidence([-10.0, -3.0, -3.2, float("nan"), -3.5], [0.1, 0.1, 0.1, 0.1, 0.1])
    assert order == [1, 2, 4, 0, 3]  # NaN last
    # 0.2 is within 2 x hypot(0.1, 0.1) = 0.28 of the best, 0.5 is not
    assert tied == [False, True, True, False, False]
    assert evidence.log_prior_density([0.5, 20.0], ParameterSpace(("a", "b"), [0, 10], [1, 100], log=(False, True))) \
        == pytest.approx(-math.log(20.0 * math.log(10.0)))


# ------------------------------------------------------------------------------------------ twins


@pytest.fixture(scope="module")
def executor():
    from fracid.runtime.executors import make_executor

    with make_executor(2) as pool:
        yield pool


def _twin_data(model, params, seed) -> ExperimentalData:
    """The model's force at the CMOD points with 2 % of its peak as Gaussian noise (and as the stated std)."""
    run, _ = run_to_end(model, BEAM, params, CMOD, steps=STEPS)
    y = np.interp(CMOD, run.control, run.force)
    std = 0.02 * float(np.max(y))
    noisy = y + std * np.random.default_rng(seed).standard_normal(y.size)
    return ExperimentalData(CMOD, noisy, Diagonal(np.full(CMOD.size, std**2)), (("global", 0, CMOD.size),), ())


def _twin(source, params, executor, seed):
    data = _twin_data(source, params, seed)
    lines = []
    result = compare(data, [contender(c, data, BEAM, steps=STEPS) for c in CANDIDATES], posterior=SAMPLER,
                     executor=executor, log=lines.append, **SETTINGS)
    print("\n" + "\n".join(lines) + "\n" + result.summary())
    return result


@pytest.mark.slow  # about 35 s each on two cores
@pytest.mark.parametrize("source, params, label", [(CohesiveCrackModel(), COHESIVE, "cohesive crack"),
                                                   (DamageModel("gradient"), GRADIENT, "gradient damage")],
                         ids=["cohesive-twin", "gradient-twin"])
def test_the_generating_model_ranks_first_by_evidence(executor, source, params, label):
    result = _twin(source, params, executor, seed=5)  # noise chi^2 18.2 of 20
    assert not result.failures and [s.label for s in result.scores][0] == label
    best, other = result.scores
    gap = best.log_evidence - other.log_evidence
    # measured: gaps 19.4 and 50.7, combined errors 0.18
    assert gap > 2 * math.hypot(best.log_evidence_error, other.log_evidence_error) and not best.tied
    assert best.rank == 1 and other.delta == pytest.approx(-gap)
    for score in result.scores:
        assert np.isfinite([score.chi2, score.aic, score.bic, score.map_objective, score.log_evidence_laplace]).all()
        assert score.aic == pytest.approx(2 * score.p - 2 * score.log_likelihood)
        assert score.map_objective >= score.chi2 - 1e-9  # the prior's term is >= 0
        assert [v.name for v in score.verdict.parameters] == score.names
    json.dumps(result.to_dict())  # compare.json is plain JSON


# ------------------------------------------------------------------------------------------ command line

_BAR_CONFIG = """
[model]
type = "gradient-damage"
[model.parameters]
E = 20000.0
kappa_i = 1e-4
beta = 300.0
c = 4.0
[specimen]
type = "bar"
n_elements = 41
[[experiments]]
file = "bar.csv"
control_column = "u_mm"
control_unit = "mm"
force_unit = "N"
kind = "single"
force_columns = ["F_N"]
std = {std}
n_points = 8
[identify]
parameters = ["kappa_i", "beta"]
[identify.bounds]
kappa_i = [5e-5, 2e-4]
beta = [100.0, 900.0]
log = ["beta"]
[identify.knn]
n = 12
k = 3
[identify.kalman]
groups = 2
max_iterations = 3
max_starts = 1
[posterior]
samples_per_round = 40
max_rounds = 3
target_ess = 20
screening = 1
[output]
directory = "out"
"""


@pytest.fixture(scope="module")
def bar_config(tmp_path_factory):
    """A gradient-damage bar of 41 elements and its own curve with 2 % noise (runs of a few ms)."""
    import fracid
    from fracid.specimens.bar import BarWithWeakZone

    folder = tmp_path_factory.mktemp("compare_cli")
    params = fracid.DamageParameters(E=20000.0, kappa_i=1e-4, beta=300.0, c=4.0)
    u, force = fracid.simulate(BarWithWeakZone(n_elements=41), params, stop_force_fraction=0.3).curve()
    std = 0.02 * float(np.max(force))
    noisy = force + std * np.random.default_rng(0).standard_normal(force.size)
    np.savetxt(folder / "bar.csv", np.column_stack([u, noisy]), delimiter=",", header="u_mm,F_N", comments="")
    (folder / "bar.toml").write_text(_BAR_CONFIG.format(std=std), encoding="utf-8")
    return folder / "bar.toml"


def _fracid(*args, cwd):
    return subprocess.run([sys.executable, "-m", "fracid", *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=300)


def test_compare_command_end_to_end(bar_config):
    run = _fracid("compare", bar_config, "--models", "gradient-damage", "local-damage", "--workers", "1",
                  cwd=bar_config.parent)
    assert run.returncode == 0, run.stderr
    out = bar_config.parent / "out"
    saved = json.loads((out / "compare.json").read_text(encoding="utf-8"))
    assert sorted(saved["ranking"]) == ["gradient-damage", "local-damage"] and not saved["failures"], run.stdout
    local = next(m for m in saved["models"] if m["label"] == "local-damage")
    assert list(local["parameters"]) == ["kappa_i", "beta"]  # fracid init's: bounds a factor 3 around the values
    assert local["bounds"] == [[pytest.approx(3.33e-5), 100.0], [pytest.approx(3e-4), 900.0]]
    own = next(m for m in saved["models"] if m["label"] == "gradient-damage")  # one prior rule: not [identify.bounds]
    assert list(own["parameters"]) == ["kappa_i", "beta"] and own["bounds"] == local["bounds"]
    assert own["log"] == [False, True]
    for model in saved["models"]:
        assert model["log_evidence"] is not None and model["log_evidence_error"] > 0
    for name in ("compare.html", "figures/compare_fits.png", "figures/compare_evidence.png", "runs.sqlite"):
        assert (out / name).is_file(), name
    assert "log Z (+- MC error)" in run.stdout and "best by evidence" in run.stdout
    assert "prior sensitivity" in run.stdout
    assert "prior of every model: uniform between bounds a factor 3" in run.stdout
    assert not (out / "report.html").exists()  # its own compare.html
    again = _fracid("compare", bar_config, "--models", "gradient-damage", "local-damage", "--workers", "1", "--quiet",
                    cwd=bar_config.parent)  # the runs come from the store
    assert again.returncode == 0 and json.loads((out / "compare.json").read_text())["ranking"] == saved["ranking"]


def test_unknown_model_is_named_with_the_allowed_ones(bar_config):
    run = _fracid("compare", bar_config, "--models", "gradient-damage", "phase-field", cwd=bar_config.parent)
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert "phase-field" in run.stderr and "cohesive-crack" in run.stderr and "gradient-damage" in run.stderr


def test_a_model_that_does_not_run_on_the_specimen_is_refused(bar_config, capsys):
    from fracid import cli

    assert cli.main(["compare", str(bar_config), "--models", "cohesive-crack", "--out", str(bar_config.parent / "x")]) == 2
    err = capsys.readouterr().err
    assert "cohesive-crack" in err and "does not run on the bar" in err and "Traceback" not in err


def test_a_failing_model_is_recorded_and_the_others_go_on(bar_config):
    """A contender that cannot be identified (its space names another parameter than its operator) is recorded
    with its reason; the other is compared."""
    from fracid.config import build_data, build_operator, build_space, load_config
    from fracid.inverse.studies.model_comparison import Contender

    cfg = load_config(bar_config, purpose="identify")
    data = build_data(cfg)
    operator, space = build_operator(cfg, data), build_space(cfg)
    wrong = ParameterSpace(("kappa_i", "c"), space.lower, space.upper)
    result = compare(data, [Contender("bar", operator, space), Contender("broken", operator, wrong)],
                     posterior=PosteriorSettings(samples_per_round=40, max_rounds=2, target_ess=15.0, screening=1.0), n=12, k=3,
                     groups=np.array_split(np.arange(data.y.size), 2), max_iterations=3, max_starts=1)
    assert [s.label for s in result.scores] == ["bar"] and result.best.label == "bar"
    assert "broken" in result.failures and "ValueError" in result.failures["broken"]
    assert any("broken: not compared" in line for line in result.notes())
