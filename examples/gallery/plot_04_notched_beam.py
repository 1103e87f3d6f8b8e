"""
The notched beam: its mesh and its load-CMOD curve
==================================================

fracid's default 2D specimen is the notched beam of Grégoire et al. (2013) in three-point bending
(:class:`fracid.specimens.NotchedBeam`: depth 50 mm, span 125 mm, notch 25 mm deep). Only the half x >= 0 is
meshed (symmetry), with 8-node quadrilaterals of size ``h_fine`` [mm] in a band around the ligament where the
crack runs, growing to ``h_coarse`` away from it. The run is controlled by the crack mouth opening
displacement (CMOD), which grows through the snap-back a brittle beam can show; the curve is that of the
whole beam: force [N] against CMOD [mm].
"""

# %%
# A coarse mesh (4 mm in the process zone instead of the demo's 2 mm, growing to 8 mm away from it) keeps this
# run to a few seconds. The gradient damage parameters are those of the published model of this test.
import matplotlib.pyplot as plt
from matplotlib.collections import PolyCollection

import fracid
from fracid.specimens import NotchedBeam

beam = NotchedBeam(h_fine=4.0, h_coarse=8.0)
mesh = beam.mesh()
elements, nodes, vertices = beam.mesh_size()
print(f"{elements} elements, {nodes} nodes")
params = fracid.DamageParameters(E=37000.0, kappa_i=8.4e-5, alpha=0.99, beta=600.0, c=9.0)
# observables=(): no observer beyond the controls and energies (the FPZ width is not drawn here)
result = fracid.simulate(beam, params, stop_force_fraction=0.3, field_steps="last", observables=())
cmod, force = result.curve()
print(f"peak {result.peak_force:.0f} N at CMOD {cmod[force.argmax()]:.4f} mm, {result.n_steps} steps")

# %%
# Left: the half mesh, coloured by the damage at the last step (the largest value in each element): the
# process zone has risen from the notch tip (y = 25 mm) up the ligament (x = 0) towards the loading plate; some
# damage also appears above the support (x = 62.5 mm), where the plate's edges concentrate the strains. Right: the
# force against the CMOD, and against the deflection under the loading plate, the other control the beam offers
# (``control="deflection"``). The peak (about 1.3 kN) comes at a CMOD of about 0.03 mm; the run stops when the
# force has fallen to 30 % of it.
omega = result.fields[result.n_steps]["omega"].max(axis=1)
fig, (ax_mesh, ax_curve) = plt.subplots(1, 2, figsize=(10, 3.6), gridspec_kw={"width_ratios": [1.6, 1]})
cells = PolyCollection(mesh.nodes[mesh.cells[:, :4]], array=omega, cmap="viridis", edgecolor="white",
                       linewidth=0.3)
ax_mesh.add_collection(cells)
ax_mesh.set(xlim=(0.0, beam.length / 2), ylim=(0.0, beam.depth), aspect="equal", xlabel="x [mm]", ylabel="y [mm]",
            title=f"half beam, elements of {beam.h_fine:g} to {beam.h_coarse:g} mm")
fig.colorbar(cells, ax=ax_mesh, label="damage ω [-]", shrink=0.8)
ax_curve.plot(cmod, force / 1e3, label="CMOD")
ax_curve.plot(result.observables["deflection"], force / 1e3, label="deflection")
ax_curve.set(xlabel="CMOD or deflection [mm]", ylabel="force [kN]")
ax_curve.legend()
fig.tight_layout()
plt.show()
