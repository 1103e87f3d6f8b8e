"""
The bar with a weak zone: snap-back under indirect control
===========================================================

A bar fixed at one end and pulled at the other, with a 10 mm zone at mid-length whose Young's modulus is 10 %
lower, is the smallest specimen fracid runs (:class:`fracid.BarWithWeakZone`, gradient damage). Damage
localises in the weak zone while the rest of the bar unloads elastically. The longer the bar, the more elastic
energy it gives back after the peak: beyond some length the force-end displacement curve turns back on
itself (snap-back), and no displacement-controlled machine could follow it. fracid prescribes instead the
elongation of the weak zone (``control="weak_zone_elongation"``), which keeps growing through the snap-back.
"""

# %%
# Three bars of 100, 300 and 600 mm, all with the same material and the same 10 mm weak zone. Each is meshed
# with elements of 1 mm; the gradient damage model (the default) has an internal length
# :math:`\sqrt{2c} \approx 1.4` mm at :math:`c = 1` mm².
import matplotlib.pyplot as plt

import fracid

params = fracid.DamageParameters(E=20000.0, kappa_i=1e-4, alpha=0.99, beta=300.0, c=1.0)
runs = {}
for length in (100.0, 300.0, 600.0):
    bar = fracid.BarWithWeakZone(length=length, n_elements=int(length))
    runs[length] = fracid.simulate(bar, params, control="weak_zone_elongation", target=0.05,
                                   stop_force_fraction=0.05)
    print(f"L = {length:5.0f} mm: peak {runs[length].peak_force:.3f} N after {runs[length].n_steps} steps")

# %%
# Left: the force against the end displacement, the curve a test machine under displacement control would
# see. The 100 mm bar softens gradually; the longer bars snap back: after the peak the end displacement
# *decreases* while the force drops. Right: the same runs against the weak zone's elongation, the control,
# which grows monotonically. The peak force is the same for all three (the strength of the weak zone); only the
# elastic energy stored in the bar, proportional to its length, differs.
fig, (ax_end, ax_zone) = plt.subplots(1, 2, figsize=(9, 3.6), sharey=True)
for length, result in runs.items():
    ax_end.plot(result.observables["end_displacement"], result.force, label=f"L = {length:g} mm")
    ax_zone.plot(result.control, result.force)
ax_end.set(xlabel="end displacement [mm]", ylabel="force [N]", title="what the machine sees")
ax_zone.set(xlabel="weak-zone elongation [mm]", title="the control fracid prescribes")
ax_end.legend()
fig.tight_layout()
plt.show()
