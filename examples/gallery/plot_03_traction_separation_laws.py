"""
Traction-separation laws and their fracture energy
==================================================

The crack models (the discrete cohesive crack and the crack band) transmit across a crack a traction
:math:`\\sigma(w)` [MPa] that falls from the tensile strength :math:`f_t` to zero as the opening :math:`w`
[mm] grows. fracid has three such laws: Hordijk's (the default, a smooth exponential-like curve fitted to
concrete), linear softening and bilinear softening (Petersson's by default). Each is written as
:math:`\\sigma = f_t\\, f(w / w_c)` with :math:`w_c` chosen so that the area under the law is exactly the
fracture energy :math:`G_f` [N/mm]: laws with the same :math:`f_t` and :math:`G_f` dissipate the same energy
per unit crack area, but differ in how far the crack must open before it is traction-free.
"""

# %%
# The laws by name (:data:`fracid.fem.material.laws.TRACTION_SEPARATION_LAWS`), each with its own parameter
# class; the same strength 3 MPa and fracture energy 0.1 N/mm for all three.
import matplotlib.pyplot as plt
import numpy as np

from fracid.fem.material.laws import TRACTION_SEPARATION_LAWS

ft, Gf = 3.0, 0.1  # MPa, N/mm
curves = {}
for name, law_class in TRACTION_SEPARATION_LAWS.items():
    law = law_class()
    params = law.parameters(E=30000.0, ft=ft, Gf=Gf)
    wc = law.critical_opening(params)
    w = np.linspace(0.0, wc, 2001)
    sigma, _ = law.traction(w, params)  # traction [MPa] and its slope d sigma / d w [MPa/mm]
    area = np.trapezoid(sigma, w)
    curves[name] = w, sigma, area
    print(f"{name:9s} strength {law.strength(params):.2f} MPa, w_c {wc:.4f} mm, area under the law {area:.5f} N/mm")

# %%
# What to see: all three start at :math:`f_t` = 3 MPa and enclose the same area, 0.1 N/mm (the trapezoidal rule
# on 2001 points recovers it to 1e-5). The linear law is traction-free soonest (:math:`w_c = 2 G_f / f_t`
# = 0.067 mm), Hordijk's latest (:math:`w_c = 5.14\, G_f / f_t` = 0.17 mm). Below a
# third of the strength (1 MPa) Hordijk's and the bilinear law still dissipate 47 % of :math:`G_f`, the linear
# law 11 %: the tail of a test's curve informs :math:`G_f` and the shape of the law, the peak :math:`f_t`.
fig, ax = plt.subplots(figsize=(6, 3.8))
for name, (w, sigma, area) in curves.items():
    ax.plot(w, sigma, label=f"{name}: $w_c$ = {w[-1]:.3f} mm, area = {area:.4f} N/mm")
ax.set(xlabel="crack opening w [mm]", ylabel="traction σ [MPa]", title=f"$f_t$ = {ft} MPa, $G_f$ = {Gf} N/mm")
ax.legend(fontsize="small")
fig.tight_layout()
plt.show()
