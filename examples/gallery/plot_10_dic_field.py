"""
Reading a DIC displacement field
================================

Digital image correlation (DIC) measures the displacement of the specimen's face at a cloud of points in
every frame. fracid reads a DIC export (a frame table and one point cloud per frame, CSV or VTK) with
:func:`fracid.data.read_dic_frames`, places it on the specimen with a :class:`fracid.data.CameraPlacement`
(scale [mm/px], rotation, a point known in both frames) and returns the points and displacements in the
specimen's frame [mm], with their std and the load of every frame. The files here are the synthetic DIC data
of ``examples/dic`` (the demo's notched beam, 6 frames, 301 points, 1 µm noise).
"""

# %%
# The placement of ``examples/dic/identify.toml``: 0.1 mm per pixel, the camera turned by 1.5 degrees, the pixel
# (120, 80) on the notch mouth's centre. The gallery runs each script from its own folder.
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fracid.data import CameraPlacement, read_dic_frames

folder = Path("../dic") if Path("../dic/frames.csv").exists() else Path("examples/dic")  # gallery or repository root
placement = CameraPlacement(scale=0.1, rotation=np.radians(1.5), origin_camera=(120.0, 80.0))
dic = read_dic_frames(folder / "frames.csv", sigma="sigma", coordinate_unit="px", placement=placement)
print(f"{len(dic.points)} points, frames {dic.frames}, CMOD {dic.load['cmod_mm']} mm")
print(*dic.notes, sep="\n")

# %%
# Left: the horizontal displacement :math:`u_x` [µm] at the last frame (CMOD 0.2 mm), on the half beam
# x >= 0 that fracid models (the ligament is x = 0, the notch tip at y = 25 mm). Right: the force and CMOD of
# the six frames. What to see: :math:`u_x` grows from about zero at the top to 0.1 mm at the
# bottom: as the crack opens, the half beam turns about a point near the loading plate, and at the mouth it has
# moved by half the CMOD. The points within 3 mm of the notch and the cracked part of the ligament are missing
# (NaN, crosses), as correlation fails there: the identification uses the points that have a value.
last = -1
ux = 1e3 * dic.u[last, :, 0]  # [µm]
fig, (ax_field, ax_load) = plt.subplots(1, 2, figsize=(10, 3.8), gridspec_kw={"width_ratios": [1.6, 1]})
shown = ax_field.scatter(dic.points[:, 0], dic.points[:, 1], c=ux, s=14, cmap="coolwarm")
ax_field.plot(*dic.points[np.isnan(ux)].T, "x", color="0.5", markersize=4, label="missing")
ax_field.set(xlabel="x [mm]", ylabel="y [mm]", aspect="equal", title=f"frame {dic.frames[last]}")
ax_field.legend(loc="upper right", fontsize="small")
fig.colorbar(shown, ax=ax_field, label="$u_x$ [µm]", shrink=0.8)
ax_load.plot(dic.load["cmod_mm"], dic.load["force_N"], "o-")
ax_load.set(xlabel="CMOD [mm]", ylabel="force [N]", title="the frames")
fig.tight_layout()
plt.show()
