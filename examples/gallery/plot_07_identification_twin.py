"""
Identification twin: KNN then Kalman filter on the bar
======================================================

A twin experiment: synthetic data are computed at known parameters, noise is added, and the parameters are
identified back, so the result can be checked against the truth. fracid's default inverse method
(``"knn-kalman"``) first runs a population of parameter sets spread over the bounds and keeps the k nearest to
the data (KNN: a global overview and a prior), then refines with a Kalman filter that uses the exact
sensitivities. It returns the estimate with its standard deviation and correlation.
"""

# %%
# The data: the force of the 100-element bar at 16 end displacements from 0.004 to 0.03 mm (before the peak,
# the peak and the softening) at :math:`c` = 2 mm² and :math:`\beta` = 250, plus Gaussian noise of std 2 % of
# the peak force. The bounds of the search: :math:`c` in [0.5, 4] mm², :math:`\beta` in [100, 500].
import matplotlib.pyplot as plt
import numpy as np

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.strategy import identify

bar = fracid.BarWithWeakZone(n_elements=100)
points = np.linspace(0.004, 0.03, 16)  # end displacement [mm]
operator = ForwardOperator([Observation(bar, points)], fracid.DamageParameters(), ("c", "beta"))
truth = np.array([2.0, 250.0])
clean = operator(truth).y  # force [N] at the points
std = 0.02 * np.abs(clean).max()
data = clean + np.random.default_rng(7).normal(scale=std, size=clean.size)
space = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])

result = identify(operator, data, np.eye(data.size) * std**2, space, n=32, k=4,
                  groups=[range(i, i + 4) for i in range(0, 16, 4)])
for name, value, sigma, true in zip(result.names, result.x, result.std, truth):
    print(f"{name:5s} = {value:8.3f} +- {sigma:.3f} (truth {true:g}; {abs(value - true) / sigma:.1f} std away)")
print(f"correlation of c and beta: {result.correlation[0, 1]:+.2f}; forward runs: {result.runs['knn']} KNN, "
      f"{result.runs['kalman']} Kalman")

# %%
# Left: the noisy data (error bars: one std), the curve at the truth and the fitted curve. Right: the KNN
# population in the parameter plane, the Kalman filter's path of estimates and the ellipse of two standard
# deviations around the estimate. What to see: the truth lies within the ellipse, and the ellipse is long and
# thin: one curve of one bar size does not separate :math:`c` from :math:`\beta` well (a large :math:`c` with a
# large :math:`\beta` gives almost the same curve), which is why lab tests on several sizes, or full-field data,
# help.
fig, (ax_fit, ax_space) = plt.subplots(1, 2, figsize=(10, 3.8))
ax_fit.errorbar(points, data, yerr=std, fmt="o", markersize=3, label="synthetic data")
ax_fit.plot(points, clean, "k--", label="truth")
ax_fit.plot(points, result.y_fit, label="identified")
ax_fit.set(xlabel="end displacement [mm]", ylabel="force [N]")
ax_fit.legend()

population = np.asarray(result.knn["points"])
ax_space.plot(population[:, 0], population[:, 1], ".", color="0.6", label="KNN population")
path = np.array([step["x"] for step in result.history])
ax_space.plot(path[:, 0], path[:, 1], "o-", color="C1", markersize=3, label="Kalman path")
values, vectors = np.linalg.eigh(result.C)
angle = np.linspace(0.0, 2.0 * np.pi, 200)
ellipse = result.x[:, None] + 2.0 * vectors @ (np.sqrt(values)[:, None] * np.array([np.cos(angle), np.sin(angle)]))
ax_space.plot(*ellipse, color="C1", label="estimate ± 2 std")
ax_space.plot(*truth, "k*", markersize=10, label="truth")
ax_space.set(xlabel="c [mm²]", ylabel="β [-]", xlim=(0.5, 4.0), ylim=(100.0, 500.0))
ax_space.legend(fontsize="small", loc="upper left")
fig.tight_layout()
plt.show()
