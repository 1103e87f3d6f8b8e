"""
A bundled data set: the Grégoire beam with its scatter
======================================================

fracid ships measured curves by name (:mod:`fracid.datasets`), each with its source, licence and a
configuration that runs. ``gregoire2013-beam4`` is the load-CMOD curve of the repeated tests on notched concrete
beams of depth 50 mm (Grégoire, Rojas-Solano & Pijaudier-Cabot 2013; the number of tests is not stated in the
source): the mean of the tests and the envelope of their
scatter (minimum and maximum). :func:`fracid.datasets.load` turns it into the data an identification uses:
24 points of the mean with a standard deviation of a quarter of the envelope's width at each point.
"""

# %%
# The raw file, then the data as the identification sees them.
import csv

import matplotlib.pyplot as plt
import numpy as np

import fracid
from fracid import datasets
from fracid.specimens import NotchedBeam

print(datasets.names())
entry = datasets.get("gregoire2013-beam4")
print(entry.citation, "|", entry.licence)
with open(entry.file_paths[0], newline="") as handle:
    rows = list(csv.DictReader(handle))
raw = {name: np.array([float(row[name]) for row in rows]) for name in rows[0]}
data = datasets.load("gregoire2013-beam4")  # ExperimentalData: control [mm], y [N], std [N]
print(f"{data.y.size} points, std from {data.std.min():.0f} to {data.std.max():.0f} N")

# %%
# A forward run at the demo's starting parameters (the data set's configuration: gradient damage, E from the
# initial slope, the mesh of 2 mm in the process zone and 6 mm elsewhere), for comparison.
params = fracid.DamageParameters(E=36250.0, nu=0.2, kappa_i=6.6e-5, alpha=0.99, beta=600.0, c=9.0, eta=10.0)
result = fracid.simulate(NotchedBeam(h_fine=2.0, h_coarse=6.0), params, target=0.2, stop_force_fraction=None,
                         observables=())  # the curve only: no FPZ width
cmod, force = result.curve()

# %%
# What to see: the envelope is narrow on the elastic branch and some 200 N wide from the peak (979 N at a CMOD
# of 0.019 mm) on, where the beams cracked differently; the data's error bars (two std, half the envelope's
# width) follow it, so a fit is held tighter where the tests agree. The demo's starting parameters peak later
# and higher than the tests and run near the envelope's upper edge after the peak; the identification
# (``fracid demo``) then adjusts :math:`\kappa_i`, :math:`\beta` and :math:`c` to the data.
fig, ax = plt.subplots(figsize=(6.5, 4))
ax.fill_between(raw["cmod_mm"], raw["load_min_N"], raw["load_max_N"], color="0.85", label="envelope (min-max)")
ax.plot(raw["cmod_mm"], raw["load_mean_N"], color="0.4", linewidth=1, label="mean of the tests")
ax.errorbar(data.control, data.y, yerr=2.0 * data.std, fmt="o", markersize=3, label="data ± 2 std")
ax.plot(cmod, force, label="gradient damage, demo start")
ax.set(xlabel="CMOD [mm]", ylabel="force [N]", xlim=(0.0, 0.21))
ax.legend()
fig.tight_layout()
plt.show()
