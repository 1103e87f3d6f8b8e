"""A lab's first day (issue 25): ``fracid --version``, ``fracid init`` (every pair it offers passes
``fracid check`` and runs in ``fracid simulate``; the demo pair identifies from the bundled data),
``fracid check``'s plan, and ``init`` refusing to overwrite a file."""

import re

import pytest

from fracid import cli
from fracid.cli.init import numpydoc_parameters, runnable_pairs

PAIRS = runnable_pairs()


def small(text: str) -> str:
    """A written configuration with a coarse bar and a short post-peak branch (a fast test; the 2D meshes
    are written small enough)."""
    text = re.sub(r"^n_elements = \S+", "n_elements = 41", text, flags=re.M)  # odd: the bar and the strip
    return re.sub(r"^stop_force_fraction = \S+", "stop_force_fraction = 0.5", text, flags=re.M)


def init(tmp_path, *args) -> str:
    path = tmp_path / "fracid.toml"
    assert cli.main(["init", *args, "-o", str(path)]) == 0
    return path.read_text(encoding="utf-8")


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["--version"])
    assert stop.value.code == 0
    assert re.fullmatch(r"fracid \d+\.\d+\.\d+\S*\n", capsys.readouterr().out)


def test_list_names_the_pairs_and_leaves_out_those_that_do_not_run(capsys):
    assert cli.main(["init", "--list"]) == 0
    out = capsys.readouterr().out
    assert "--specimen wedge-splitting --model cohesive-crack" in out
    assert "--specimen bar --model gradient-damage" in out
    assert "--model cohesive-crack" not in [line for line in out.splitlines() if "bar" in line]
    assert len(out.splitlines()) == len(PAIRS)


@pytest.mark.parametrize("specimen, model", PAIRS, ids=[f"{s}-{m}" for s, m in PAIRS])
@pytest.mark.slow
def test_every_pair_is_checked_and_simulated(tmp_path, capsys, specimen, model):
    text = init(tmp_path, "--specimen", specimen, "--model", model)
    (tmp_path / "fracid.toml").write_text(small(text), encoding="utf-8")
    assert cli.main(["check", str(tmp_path / "fracid.toml"), "--no-time"]) == 0
    out = capsys.readouterr().out
    assert "unknowns" in out and f"model: {model}" in out
    assert cli.main(["simulate", str(tmp_path / "fracid.toml"), "--quiet", "--out", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "curve.csv").is_file()


@pytest.mark.parametrize("specimen, model", [("wedge-splitting", "crack-band"), ("dogbone", "cohesive-crack")])
def test_every_key_has_its_meaning_unit_and_range(tmp_path, specimen, model):
    import dataclasses

    from fracid.models import model_from_type
    from fracid.specimens import SPECIMENS

    text = init(tmp_path, "--specimen", specimen, "--model", model)
    parameters = model_from_type(model).parameters
    for field in dataclasses.fields(SPECIMENS[specimen]):
        line = re.search(rf"^(# )?{field.name} = .*# (.*)$", text, re.M)
        assert line and len(line.group(2)) > 12, field.name
    for name, rng in parameters.ranges.items():
        line = re.search(rf"^{name} = .*# (.*)$", text, re.M).group(1)
        assert f"[{rng.unit}]" in line and rng.describe(name) in line and numpydoc_parameters(parameters)[name][1] in line
    if specimen == "wedge-splitting":  # which dimension is which
        assert re.search(r"^height = .*2nd of width, height, thickness.*height H", text, re.M)


def test_numpydoc_parameters_reads_shared_entries():
    from fracid.specimens import WedgeSplitting

    entries = numpydoc_parameters(WedgeSplitting)
    assert entries["thickness"][1].startswith("Whole specimen's width B") and "thickness t" in entries["thickness"][1]
    assert "3rd of width, height, thickness" in entries["thickness"][0]
    assert entries["wedge_angle"] == ("float", "Full angle of the wedge [degrees].")


def test_init_refuses_to_overwrite_unless_forced(tmp_path, capsys):
    path = tmp_path / "mine.toml"
    path.write_text("# the lab's own notes\n", encoding="utf-8")
    assert cli.main(["init", "-o", str(path)]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "--force" in err and "Traceback" not in err
    assert path.read_text(encoding="utf-8") == "# the lab's own notes\n"
    assert cli.main(["init", "-o", str(path), "--force"]) == 0
    assert "[identify]" in path.read_text(encoding="utf-8")


def test_init_to_stdout_and_an_unknown_pair(capsys):
    assert cli.main(["init", "--specimen", "bar", "--model", "local-damage"]) == 0
    assert 'type = "bar"' in capsys.readouterr().out
    assert cli.main(["init", "--specimen", "bar", "--model", "cohesive-crack"]) == 2
    assert "--list" in capsys.readouterr().err


@pytest.mark.slow
def test_init_then_identify_the_bundled_data(tmp_path, capsys):
    text = small(init(tmp_path))
    assert "load_cmod.csv" in text and "REPLACE" in text
    for key, value in (("n", "6"), ("k", "3"), ("groups", "2"), ("max_iterations", "1"), ("h_fine", "4.0"),
                       ("h_coarse", "8.0")):
        text = re.sub(rf"^{key} = \S+", f"{key} = {value}", text, flags=re.M)
    (tmp_path / "fracid.toml").write_text(text, encoding="utf-8")
    status = cli.main(["identify", str(tmp_path / "fracid.toml"), "--workers", "1", "--out", str(tmp_path / "out")])
    out = capsys.readouterr().out
    assert status == 0, out
    assert (tmp_path / "out" / "result.json").is_file()
    assert "1 run per step" in out  # exact sensitivities: one run per Kalman step
    assert "wrote in" in out and "figures/" in out and "runs.sqlite" in out


def test_check_prints_the_plan_with_unknowns_runs_and_time(tmp_path, capsys):
    text = small(init(tmp_path))
    (tmp_path / "fracid.toml").write_text(text, encoding="utf-8")
    assert cli.main(["check", str(tmp_path / "fracid.toml"), "--workers", "2"]) == 0
    out = capsys.readouterr().out
    unknowns = int(re.search(r"([\d,]+) unknowns", out).group(1).replace(",", ""))
    assert 100 < unknowns < 6000  # h_fine 2 of the demo, h_coarse D / 12.5 = 4 mm (its scaling default)
    assert "stage KNN: 32 forward runs" in out
    assert re.search(r"Kalman filter: 4 steps per pass, 1 run per step \(the run with its exact sensitivities\)", out)
    assert re.search(r"one forward run took [\d.]+ s \(the mean of 2 runs across the bounds", out)
    assert re.search(r"estimate for fracid identify on 2 worker\(s\): about .*, at most", out)
    assert re.search(r"assumes: 2 worker\(s\) on \d+ core\(s\)", out) and "the machine's load" in out
    assert not list(tmp_path.glob("results*"))  # nothing computed into the output directory


def test_check_warns_of_a_slow_plan_naming_the_key(tmp_path, capsys, monkeypatch):
    from fracid.cli import check as cli_check

    text = re.sub(r"^n = \S+", "n = 5000", small(init(tmp_path)), flags=re.M)
    (tmp_path / "fracid.toml").write_text(text, encoding="utf-8")
    from fracid.cli.check_time import Timing

    monkeypatch.setattr(cli_check, "timed_runs", lambda *args: Timing(40.0))  # a 40 s run, not measured
    assert cli.main(["check", str(tmp_path / "fracid.toml"), "--workers", "2"]) == 0
    err = capsys.readouterr().err
    assert "one forward run takes 40 s" in err and "specimen.h_fine = 2" in err
    assert "[identify.knn] n = 5000" in err


def test_check_of_a_bad_config_exits_2(tmp_path, capsys):
    text = init(tmp_path).replace("h_fine = 2.0", "h_fine = -1.0")
    (tmp_path / "fracid.toml").write_text(text, encoding="utf-8")
    assert cli.main(["check", str(tmp_path / "fracid.toml"), "--no-time"]) == 2
    err = capsys.readouterr().err
    assert "h_fine" in err and "Traceback" not in err


def test_the_planned_runs_bound_those_of_the_identification(tmp_path, capsys):
    from hostile import bar_config, synthetic_curve, write_csv

    write_csv(tmp_path / "bar.csv", *synthetic_curve())
    (tmp_path / "cfg.toml").write_text(bar_config(), encoding="utf-8")
    assert cli.main(["check", str(tmp_path / "cfg.toml"), "--no-time"]) == 0
    out = capsys.readouterr().out
    assert "stage KNN: 8 forward runs" in out
    planned = int(re.search(r"at most (\d+) runs one after another", out).group(1))
    assert planned == 2 + 2 + 1  # 2 steps, 2 later passes of one linearisation, the run at the estimate
    assert cli.main(["identify", str(tmp_path / "cfg.toml"), "--workers", "1", "--out", str(tmp_path / "out")]) == 0
    kalman = int(re.search(r"\+ (\d+) Kalman filter", capsys.readouterr().out).group(1))
    assert 0 < kalman <= planned
