"""The traction-separation law a model stands for, as a table: what ``fracid export`` writes for other codes.

A crack model's law is its own (:func:`law_table`, relation ``"same"``). A continuum model has none, but a bar
pulled until it fails turns its response into one: the force over the section against the bar's inelastic
elongation (its end displacement less the elastic part) is the cohesive law whose energy is the energy the
model dissipates per unit section (:func:`equivalent_law_on_bar`, relation ``"equivalent"``). The PF-CZM has its
1D law in closed form (:func:`fracid.fem.material.phase_field_cohesive.localized_cohesive_law`). An equivalent
law is not the same model: in 2D the band of a continuum model widens and interacts with the specimen's
geometry where a cohesive crack does not (``fracid export`` says so in the file).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.fem.path.path_following import StepOptions
from fracid.specimens.bar import BarWithWeakZone

#: rows of a law's table by default (the piecewise-linear table of Hordijk's law is within 0.06 % of ft of it)
TABLE_POINTS = 101
#: the bar's length in widths of the model's band, the band's room: the energy of the law of gradient damage (at
#: its defaults) on a bar 4, 8 and 16 band widths long: 0.04052, 0.04029, 0.04028 N/mm
BAR_LENGTH_IN_BANDS = 8.0
#: the weak section's area relative to the bar's, at the bar's centre (a hat profile): where the band forms
WEAK_SECTION = 0.995
#: the run stops when the force falls below this fraction of the peak: the table's last traction (above the
#: residual stress (1 - alpha) ft of the exponential damage law's default alpha = 0.99, which never vanishes)
END_FRACTION = 0.02
#: the bar's target end displacement in its elongation at the model's characteristic strain: far enough for any
#: softening (the run ends at END_FRACTION of the peak; the steps are the path follower's, not the target's)
TARGET_IN_ELASTIC_ELONGATIONS = 1000.0


@dataclass(frozen=True)
class CohesiveLawTable:
    """A traction-separation law as points, from w = 0 at the strength to the end of softening.

    Attributes
    ----------
    opening : ndarray
        w [mm], increasing from 0.
    traction : ndarray
        sigma [MPa], from the strength down to 0 at the last opening.
    relation : str
        ``"same"`` (the model's own law) or ``"equivalent"`` (the law a continuum model dissipates like, on a bar).
    law : str
        What the law is, e.g. ``"hordijk"`` or ``"gradient damage on a bar"``.
    how : str
        How the table was obtained, one sentence (written into every exported file).
    """

    opening: np.ndarray
    traction: np.ndarray
    relation: str
    law: str
    how: str

    @property
    def strength(self) -> float:
        """sigma at w = 0 [MPa]."""
        return float(self.traction[0])

    @property
    def fracture_energy(self) -> float:
        """The area under the table [N/mm]."""
        return float(np.trapezoid(self.traction, self.opening))

    @property
    def critical_opening(self) -> float:
        """The last opening of the table [mm]."""
        return float(self.opening[-1])

    def scaled(self, length: float, stress: float) -> "CohesiveLawTable":
        """The table in other units: openings times ``length``, tractions times ``stress``."""
        return CohesiveLawTable(length * self.opening, stress * self.traction, self.relation, self.law, self.how)


def law_table(law, params, points: int = TABLE_POINTS) -> CohesiveLawTable:
    """The table of a traction-separation law at ``params``: ``points`` equally spaced openings from 0 to wc, and
    the law's kinks (its optional ``kinks(params)`` [mm]) so that a piecewise-linear law is exact."""
    wc = law.critical_opening(params)
    if not np.isfinite(wc):
        raise ValueError(f"the {law.name} law never reaches zero traction: no table ends it")
    kinks = np.asarray(getattr(law, "kinks", lambda p: ())(params), float)
    w = np.union1d(np.linspace(0.0, wc, int(points)), kinks[(kinks > 0) & (kinks < wc)])
    sigma = law.traction(w, params)[0]
    sigma[-1] = 0.0  # the law's cut-off at wc: its traction there is 0 (Hordijk's reaches it from above)
    return CohesiveLawTable(w, sigma, "same", law.name,
                            f"the {law.name} law at the identified parameters, sampled at {w.size} openings")


def equivalent_bar(band_width: float, element_size: float) -> BarWithWeakZone:
    """The bar a continuum model's equivalent law is computed on: :data:`BAR_LENGTH_IN_BANDS` band widths long,
    unit section, its centre's section :data:`WEAK_SECTION` (a hat, so the band forms there), elements of
    ``element_size`` [mm] or finer."""
    length = BAR_LENGTH_IN_BANDS * band_width
    n = max(40, int(np.ceil(length / element_size)))
    return BarWithWeakZone(length=length, area=1.0, weak_zone_width=0.5 * length, weak_zone_factor=WEAK_SECTION,
                           weakening="area", profile="hat", n_elements=n + n % 2)


def equivalent_law_on_bar(model, params, band_width: float, element_size: float, what: str) -> CohesiveLawTable:
    """The cohesive law a continuum model dissipates like: its 1D response on :func:`equivalent_bar`, pulled
    at its end until the force falls below :data:`END_FRACTION` of the peak; traction = F / A_centre, opening =
    end displacement - F C (C = the bar's elastic compliance, int dx / (E A)), from the peak on (before it the
    opening is elastic, zero to the solver's tolerance).

    Raises
    ------
    RuntimeError
        When the run stops before the force has fallen below twice :data:`END_FRACTION` of the peak (the
        table would miss part of the softening).
    """
    bar = equivalent_bar(band_width, element_size)
    target = TARGET_IN_ELASTIC_ELONGATIONS * model.scales(params)["strain"] * bar.length
    onset = model.scales(params)["strain"] * band_width  # the band's elongation at the peak: steps of half of it
    run = model.simulate(bar, params, control="end_displacement", target=target,
                         steps=StepOptions(initial=0.1 * onset, maximum=0.5 * onset), stop_force_fraction=END_FRACTION)
    x = bar.vertices()
    compliance = float(np.sum(np.diff(x) / (params.E * bar.weakness(0.5 * (x[:-1] + x[1:])))))
    force, end = np.asarray(run.force, float), np.asarray(run.control, float)
    peak = int(np.argmax(force))
    if force[-1] > 2.0 * END_FRACTION * force[peak]:
        raise RuntimeError(f"the bar run of the equivalent law stopped at {force[-1] / force[peak]:.0%} of the "
                           f"peak force ({run.status})")
    traction = force[peak:] / WEAK_SECTION
    opening = np.maximum.accumulate(np.maximum(end[peak:] - force[peak:] * compliance, 0.0))
    opening, keep = np.unique(opening, return_index=True)
    traction = traction[keep]
    traction[-1] = 0.0  # the table ends the law: below END_FRACTION of ft the energy left is given up
    opening[0] = 0.0
    return CohesiveLawTable(opening, traction, "equivalent", what,
                            f"{what} on a bar {bar.length:.4g} mm long (unit section, {bar.n_elements} elements): "
                            f"force / section against the inelastic elongation, from the peak until the force is "
                            f"{END_FRACTION:.0%} of it")
