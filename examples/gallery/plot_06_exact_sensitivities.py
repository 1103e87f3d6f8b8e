"""
Exact sensitivities against central differences
===============================================

The identification needs the derivatives of the simulated curve with respect to the parameters. fracid
computes them inside the run (direct differentiation through the damage history, docs/theory.md section 6):
``fracid.simulate(..., sensitivities=names)`` returns ``result.derivatives["force"]``, one row per step and one
column per parameter, at about the cost of one run, where central differences cost two runs per parameter.
Here both are computed on the bar with a weak zone, through the peak and well into softening.
"""

# %%
# Central differences compare runs at different parameters, so the runs must take the same steps: every run
# here steps exactly on 60 evenly spaced end displacements (``checkpoints`` with a fixed step size), so that
# the derivative of the discrete path is what both methods see.
import matplotlib.pyplot as plt
import numpy as np

import fracid
from fracid.models import StepOptions

bar = fracid.BarWithWeakZone(n_elements=60)
params = fracid.DamageParameters(E=20000.0, kappa_i=1e-4, alpha=0.99, beta=300.0, c=1.0)
names = ("kappa_i", "beta", "c")
checkpoints = np.linspace(0.0, 0.12, 61)[1:]  # end displacement [mm]
fixed = StepOptions(initial=0.002, onset_fraction=1.0, max_factor=1.0, jump_to_onset=False)


def run(parameters, sensitivities=None):
    """The bar at ``parameters``, stepping on the checkpoints; (end displacement [mm], force [N], result)."""
    result = fracid.simulate(bar, parameters, target=0.12, stop_force_fraction=None, steps=fixed,
                             checkpoints=checkpoints, sensitivities=sensitivities)
    return result.control, result.force, result


u, force, exact = run(params, names)
central = {}
for name in names:
    value = getattr(params, name)
    h = 1e-6 * value  # a relative step: small against the curvature, large against the solver's tolerance
    _, plus, _ = run(params.replace(**{name: value + h}))
    _, minus, _ = run(params.replace(**{name: value - h}))
    central[name] = (plus - minus) / (2.0 * h)

# %%
# Each panel: the derivative of the force scaled by the parameter, :math:`x\, \partial F / \partial x` [N] (the
# change of force for a 100 % change of x, to first order), exact (line) and by central differences (dots).
# What to see: they coincide at every step. In the elastic range none of the three matters (only E would);
# :math:`\kappa_i` (the strain where damage starts) sets the peak, :math:`\beta` (the softening rate) pulls the
# force down just after it, and
# :math:`c` raises the force in the tail: a wider band dissipates more energy. The printed relative difference is
# at the level of the differences' own truncation and rounding error.
fig, axes = plt.subplots(1, 3, figsize=(10, 3.3), sharex=True)
for k, (name, ax) in enumerate(zip(names, axes)):
    value = getattr(params, name)
    ddm = exact.derivatives["force"][:, k]
    ax.plot(u, value * ddm, label="exact (direct differentiation)")
    ax.plot(u[::2], value * central[name][::2], "o", markersize=3, label="central differences")
    ax.set(title=name, xlabel="end displacement [mm]")
    difference = np.abs(ddm - central[name]).max() / np.abs(central[name]).max()
    print(f"d F / d {name:7s}: largest difference {difference:.1e} of its largest value")
axes[0].set_ylabel("x ∂F/∂x [N]")
axes[0].legend(fontsize="small")
fig.tight_layout()
plt.show()

# %%
# The force curve itself, for reference.
fig, ax = plt.subplots(figsize=(5, 3.2))
ax.plot(u, force)
ax.set(xlabel="end displacement [mm]", ylabel="force [N]")
fig.tight_layout()
plt.show()
