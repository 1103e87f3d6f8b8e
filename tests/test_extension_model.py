"""A new model type, written in this file only (no package file edited): a thin variant of the local damage
model with a parameter class of its own (its own usual ranges) and its own first identification. Registered
by one line in ``fracid.models.MODEL_TYPES``, it is offered by ``fracid init --list``, its written
configuration passes ``fracid check``, ``fracid identify`` identifies it and ``fracid compare`` ranks it
beside a built-in model, on a bar of 41 elements (runs of a few ms)."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from fracid import cli
from fracid.fem.material.laws import DamageLaw
from fracid.fem.material.ranges import ELASTIC, Field, ParameterRange, compose
from fracid.models import MODEL_TYPES, DamageModel
from fracid.models.forward import simulate
from fracid.specimens.bar import BarWithWeakZone

#: the damage law's part with usual ranges of its own: beta's (50, 600) is narrower than the built-in (10, 1e4)
THIN_FIELDS = (
    Field("kappa_i", 1.0e-4, ParameterRange(0.0, False, None, False, "-"), "Damage threshold", (2.0e-5, 1.0e-3)),
    Field("alpha", 0.99, ParameterRange(0.0, True, 1.0, True, "-"), "Residual-stress parameter", (0.0, 1.0)),
    Field("beta", 300.0, ParameterRange(0.0, True, None, False, "-"), "Softening rate", (50.0, 600.0)),
    Field("c", 4.0, ParameterRange(0.0, False, None, False, "mm^2"), "Gradient parameter (unused: local)"),
    Field("eta", 10.0, ParameterRange(1.0, True, None, False, "-"), "Compressive to tensile strength ratio"),
)
ThinParameters = compose("ThinParameters", ELASTIC, THIN_FIELDS, defaults={"E": 20000.0},
                         summary="Parameters of the thin local damage model (a test's own model).")
THIN_LAW = DamageLaw(parameters=ThinParameters, name="thin")


@dataclass(frozen=True)
class ThinDamageModel(DamageModel):
    """Local damage with the thin law: its own parameter class, laws and first identification."""

    regularization: str = "local"
    law: DamageLaw = THIN_LAW
    laws: ClassVar[dict] = {"thin": lambda: THIN_LAW}
    first_identified: ClassVar[tuple] = ("beta",)


@pytest.fixture
def registered(monkeypatch):
    """The one registry line; monkeypatch removes it after the test."""
    monkeypatch.setitem(MODEL_TYPES, "thin-damage", ThinDamageModel)
    yield "thin-damage"
    assert "thin-damage" in MODEL_TYPES


def _written(tmp_path, capsys) -> str:
    """``fracid init`` for (bar, thin-damage), with a coarse bar, a short post-peak branch, a small population
    and the measured curve of the thin model at beta = 200 (2 % noise)."""
    path = tmp_path / "fracid.toml"
    assert cli.main(["init", "--specimen", "bar", "--model", "thin-damage", "-o", str(path)]) == 0
    text = path.read_text(encoding="utf-8")
    for key, value in (("n_elements", "41"), ("stop_force_fraction", "0.3"), ("n", "6"), ("k", "3"),
                       ("groups", "2"), ("max_iterations", "2"), ("directory", '"out"')):
        text = re.sub(rf"^{key} = \S+", f"{key} = {value}", text, flags=re.M)
    run = simulate(BarWithWeakZone(n_elements=41), ThinParameters(beta=200.0), model=ThinDamageModel(),
                   stop_force_fraction=0.3)
    u, force = run.curve()
    std = 0.02 * float(np.max(force))
    noisy = force + std * np.random.default_rng(1).standard_normal(force.size)
    np.savetxt(tmp_path / "bar.csv", np.column_stack([u, noisy]), delimiter=",", header="u_mm,F_N", comments="")
    text += ('\n[[experiments]]\nfile = "bar.csv"\ncontrol_column = "u_mm"\ncontrol_unit = "mm"\nforce_unit = "N"\n'
             f'kind = "single"\nforce_columns = ["F_N"]\nstd = {std}\nn_points = 8\n'
             "[posterior]\nsamples_per_round = 10\nmax_rounds = 1\ntarget_ess = 5\nscreening = 1\n")
    path.write_text(text, encoding="utf-8")
    capsys.readouterr()
    return text


def test_init_lists_and_writes_the_new_model_from_its_declarations(registered, tmp_path, capsys):
    assert cli.main(["init", "--list"]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert "--specimen bar --model thin-damage" in listed
    assert "--specimen notched-beam --model thin-damage" in listed  # it runs wherever local damage runs
    text = _written(tmp_path, capsys)
    assert 'type = "thin-damage"' in text and "Parameters of the thin local damage model" in text
    # its first identification (beta alone) within its own usual range: 300 / 3 .. min(300 * 3, 600)
    assert re.search(r'^parameters = \["beta"\]', text, flags=re.M)
    assert re.search(r"^beta = \[100.0, 600.0\]", text, flags=re.M)
    assert cli.main(["check", str(tmp_path / "fracid.toml"), "--no-time"]) == 0
    assert "thin-damage" in capsys.readouterr().out


@pytest.mark.slow  # a few seconds: two identifications and two posteriors on the bar
def test_identify_and_compare_rank_the_new_model(registered, tmp_path, capsys):
    _written(tmp_path, capsys)
    config = str(tmp_path / "fracid.toml")
    assert cli.main(["identify", config, "--workers", "1", "--quiet"]) == 0
    result = json.loads((tmp_path / "out" / "result.json").read_text(encoding="utf-8"))
    assert "thin-damage" in json.dumps(result)
    assert cli.main(["compare", config, "--models", "thin-damage", "local-damage", "--workers", "1", "--quiet",
                     "--samples", "40", "--rounds", "3", "--out", str(tmp_path / "compare")]) == 0
    saved = json.loads((tmp_path / "compare" / "compare.json").read_text(encoding="utf-8"))
    assert sorted(saved["ranking"]) == ["local-damage", "thin-damage"] and not saved["failures"]
    thin = next(m for m in saved["models"] if m["label"] == "thin-damage")
    assert list(thin["parameters"]) == ["beta"] and thin["log_evidence"] is not None
    local = next(m for m in saved["models"] if m["label"] == "local-damage")
    assert list(local["parameters"]) == ["kappa_i", "beta"]  # fracid init's for the built-in local damage


def test_the_registration_is_removed_after_the_tests():
    """Last in the file: the tests above registered the model through the fixture, which removed it."""
    assert "thin-damage" not in MODEL_TYPES
