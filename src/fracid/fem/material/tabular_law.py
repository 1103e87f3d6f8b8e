"""A traction-separation law given as a table of (opening, traction) points, piecewise linear between them.

:class:`TabularSoftening` is a :class:`~fracid.fem.material.tsl.ShapeLaw`: the table fixes the normalised shape
f(w / wc), and the strength ``ft`` [MPa] and the fracture energy ``Gf`` [N/mm] scale it, so that a table read
from another code (or from ``fracid export --to csv``) runs in fracid's cohesive crack and crack band as it is
(at the ``ft`` and ``Gf`` of the table, :meth:`TabularSoftening.table_parameters`) and can still be identified in
strength and energy with its shape kept.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from fracid.fem.material.ranges import ELASTIC, compose
from fracid.fem.material.tsl import STRENGTH_AND_ENERGY, ShapeLaw

TabularSofteningParameters = compose(
    "TabularSofteningParameters", ELASTIC, STRENGTH_AND_ENERGY,
    summary="Parameters x = (E, nu, ft, Gf) of a bulk with cohesive cracks whose softening shape is a table: "
            "sigma = ft f(w / wc), f piecewise linear through the table's points, wc = Gf / (ft I), I the area "
            "under f.")


@dataclass(frozen=True)
class TabularSoftening(ShapeLaw):
    """Softening through the points (x_i, f_i) of a normalised table, linear between them.

    Parameters
    ----------
    shape_x : tuple of float
        Normalised openings x = w / wc [-], strictly increasing from 0 to 1.
    shape_f : tuple of float
        Normalised tractions f = sigma / ft [-], f_0 = 1, f >= 0, the last 0.

    Build it from a table in physical units with :meth:`from_table`.
    """

    shape_x: tuple
    shape_f: tuple
    parameters = TabularSofteningParameters

    def __post_init__(self):
        x, f = np.asarray(self.shape_x, float), np.asarray(self.shape_f, float)
        if x.ndim != 1 or x.shape != f.shape or x.size < 2:
            raise ValueError("a tabular law needs two sequences of the same length, at least 2 points")
        if x[0] != 0.0 or x[-1] != 1.0 or np.any(np.diff(x) <= 0.0):
            raise ValueError("the normalised openings must increase strictly from 0 to 1")
        if f[0] != 1.0 or f[-1] != 0.0 or np.any(f < 0.0) or not np.all(np.isfinite(f)):
            raise ValueError("the normalised tractions must start at 1, end at 0 and never be negative")

    @property
    def name(self) -> str:
        """``tabular-<8 hex digits of the table>``: runs of different tables never share a run-store key."""
        digest = hashlib.sha256(np.asarray([self.shape_x, self.shape_f], float).tobytes()).hexdigest()
        return f"tabular-{digest[:8]}"

    @classmethod
    def from_table(cls, opening, traction) -> "TabularSoftening":
        """The law through (w_i, sigma_i): w [mm] strictly increasing from 0, sigma [MPa] from ft > 0, >= 0,
        ending at 0 (a table that ends above 0 is closed by a vertical drop to 0 at its last opening: the energy
        beyond it is lost, as in a code that reads the table as given).

        Raises
        ------
        ValueError
            Naming what is wrong with the table.
        """
        w, sigma = np.asarray(opening, float), np.asarray(traction, float)
        if w.ndim != 1 or w.shape != sigma.shape or w.size < 2 or not np.all(np.isfinite(w) & np.isfinite(sigma)):
            raise ValueError("the table needs finite openings and tractions of the same length, at least 2 rows")
        if w[0] != 0.0 or np.any(np.diff(w) <= 0.0):
            raise ValueError(f"the openings must start at 0 and increase strictly (first {w[0]:g} mm)")
        if sigma[0] <= 0.0 or np.any(sigma < 0.0):
            raise ValueError(f"the tractions must start at the strength > 0 and never be negative "
                             f"(first {sigma[0]:g} MPa, smallest {sigma.min():g} MPa)")
        if sigma[-1] > 0.0:
            w, sigma = np.append(w, w[-1] * (1.0 + 1e-9)), np.append(sigma, 0.0)
        return cls(tuple(w / w[-1]), tuple(sigma / sigma[0]))

    def table_parameters(self, opening, traction, E: float, nu: float = 0.2):
        """The parameters at which this law reproduces the table (w_i, sigma_i) it was built from: ft =
        sigma_0 [MPa], Gf = the area under the table [N/mm], and the bulk's E [MPa] and nu [-]."""
        w, sigma = np.asarray(opening, float), np.asarray(traction, float)
        return self.parameters(E=E, nu=nu, ft=float(sigma[0]), Gf=float(np.trapezoid(sigma, w)))

    def shape(self, x, params):
        x = np.asarray(x, dtype=float)
        xs, fs = np.asarray(self.shape_x), np.asarray(self.shape_f)
        segment = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, xs.size - 2)
        return np.interp(x, xs, fs), (np.diff(fs) / np.diff(xs))[segment]

    def shape_derivatives(self, x, params) -> dict:
        return {}

    def area(self, params) -> float:
        return float(np.trapezoid(self.shape_f, self.shape_x))

    def area_derivatives(self, params) -> dict:
        return {}

    def steepest_shape_slope(self, params) -> float:
        return float(np.max(np.abs(np.diff(self.shape_f) / np.diff(self.shape_x))))
