"""The small bar identification shared by command-line tests: synthetic data of (c, beta) = (2, 250) and its
configuration, and the number of runs in a store."""

import sqlite3
from pathlib import Path

import numpy as np

import fracid
from fracid.store.runs import RunStore

TEMPLATE = """
[model.parameters]
c = 1.0
beta = 300.0

[specimen]
type = "bar"
n_elements = {n_elements}

[[experiments]]
file = "bar.csv"
control_column = "u_mm"
control_unit = "mm"
force_unit = "N"
kind = "single"
force_columns = ["F_N"]
std = 0.02
n_points = 12
control_range = [0.004, 0.03]

[identify]
parameters = ["c", "beta"]
[identify.bounds]
c = [{c_lower}, 4.0]
beta = [100.0, 500.0]
[identify.knn]
n = {n}
k = {k}
[identify.kalman]
groups = 3
{kalman}
[output]
directory = "results"
"""


def write_bar_study(directory, *, n_elements=60, n=16, k=4, c_lower=0.5, kalman="") -> Path:
    """bar.csv (the bar with ``n_elements`` at (c, beta) = (2, 250)) and study.toml in ``directory``."""
    run = fracid.simulate(fracid.BarWithWeakZone(n_elements=n_elements), fracid.DamageParameters(c=2.0, beta=250.0),
                          target=0.032, stop_force_fraction=None, checkpoints=np.linspace(0.001, 0.032, 40))
    np.savetxt(directory / "bar.csv", np.column_stack([run.control, run.force]), delimiter=",", header="u_mm,F_N",
               comments="")
    path = directory / "study.toml"
    path.write_text(TEMPLATE.format(n_elements=n_elements, n=n, k=k, c_lower=c_lower, kalman=kalman))
    return path


def stored_rows(path) -> int:
    """Runs in the store at ``path`` (0 if it does not exist yet or is being created)."""
    try:
        with RunStore(path, readonly=True) as store:
            return len(store)
    except (sqlite3.DatabaseError, FileNotFoundError):
        return 0


#: a [posterior] section small enough for tests (3 rounds of 40 runs), sampled on the bar's own mesh (single level:
#: the coarse-mesh screening costs more than it saves on a 60-element bar; SCREENED_POSTERIOR tests it)
SMALL_POSTERIOR = "\n[posterior]\nsamples_per_round = 40\nmax_rounds = 3\ntarget_ess = 30\nscreening = 1\n"
#: the same with the default coarse-mesh screening (two levels)
SCREENED_POSTERIOR = SMALL_POSTERIOR.replace("screening = 1", "screening = 2")


def run_bar_command(directory, command, extra="", workers="1"):
    """``fracid COMMAND`` on the bar study written in ``directory`` with ``extra`` appended to its
    configuration (asserting exit status 0): (config, output directory)."""
    from fracid import cli

    config = write_bar_study(directory)
    config.write_text(config.read_text() + extra)
    out = directory / "out"
    assert cli.main([command, str(config), "--out", str(out), "--workers", workers, "--quiet"]) == 0
    return config, out
