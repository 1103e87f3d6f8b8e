"""Benchmark: the phase-field regularised cohesive zone model (PF-CZM, Wu 2017), written to docs/pfczm/.

1. 1D bar with a weak zone of two elements, h = l / 10, l in {1, 2, 4} mm, the three softening shapes: the band's
   traction against its opening compared with the exact law of the shape
   (:func:`fracid.fem.material.phase_field_cohesive.traction_at_opening`) and with the nominal law it stands for;
   and the linear shape at l = 2 mm, h = l / 5 to l / 20, with and without the history of the driving force.
2. Length scale and mesh on three notched beams (Gregoire's 50 mm beam, Wu's 100 mm beam with its 5 mm notch and
   with a 2 mm one): l in {1.25, 2.5, 5} mm at h = l / 5 and h = l / 10 at l = 2.5 mm: peak force, dissipated
   energy at the last common CMOD, spreads; where the band of the smallest l starts (the phase field near the notch).
3. Wu's beams against the discrete cohesive crack, with Hordijk's law and with the PF-CZM's own Cornelissen law
   (:class:`PfczmShapeLaw`, the exact law of the shape tabulated once): peaks and the largest force difference
   along the curve.
4. Wall time and number of unknowns of every run.

    python benchmarks/pfczm.py [--out docs/pfczm] [--quick] [--figures-only]

``--quick`` runs the same cases on coarse meshes (a smoke test of a minute or two); ``--figures-only`` redraws the
figures and the README from ``results.json``. Set ``OPENBLAS_NUM_THREADS=1`` on a shared machine.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import time
from dataclasses import asdict, dataclass
from functools import lru_cache
from pathlib import Path
from typing import ClassVar

import numpy as np
from matplotlib.tri import Triangulation
from scipy.interpolate import PchipInterpolator

import fracid
from fracid.fem.formulations.phase_field_problem import PhaseFieldProblem
from fracid.fem.material.phase_field import SHAPES
from fracid.fem.material.phase_field_band import ultimate_opening
from fracid.fem.material.phase_field_cohesive import (default_centre_values, localized_cohesive_law, target_law,
                                                      traction_at_opening)
from fracid.fem.material.ranges import ELASTIC, compose
from fracid.fem.material.tsl import STRENGTH_AND_ENERGY, ShapeLaw
from fracid.fem.path.path_following import follow_path
from fracid.models import CohesiveCrackModel, ConvergenceError, model_from_type
from fracid.report.figures import new_figure, to_png
from fracid.specimens import BarWithWeakZone, NotchedBeam
from fracid.specimens.description import at_points, conditions, discretize

#: Wu's concrete (Wu 2017, section 6; his Abaqus inputs): E [MPa], nu, ft [MPa], Gf [N/mm]
MATERIAL = {"E": 20000.0, "nu": 0.2, "ft": 2.4, "Gf": 0.113}

#: the bar of case 1: length [mm], weak-zone section factor, end displacement target [mm], stop fraction
BAR = {"length": 50.0, "weak": 0.99, "target": 0.5, "stop_force_fraction": 0.02}

#: the beams: geometry of :class:`NotchedBeam`, its coarse element size and the CMOD target [mm]; Wu's beam with its
#: 5 mm notch (his Abaqus inputs) and with a 2 mm one (the notch of the Gregoire beam)
_WU_GEOMETRY = {"depth": 100.0, "thickness": 100.0, "length": 450.0, "span": 450.0, "notch_depth": 50.0,
                "notch_width": 5.0, "h_coarse": 12.5}
BEAMS = {
    "gregoire": {"title": "Gregoire beam (D 50 mm, S 125 mm, a0 25 mm, notch 2 mm, b 50 mm)", "target": 0.3,
                 "short": "Gregoire, notch 2 mm",
                 "geometry": {"depth": 50.0, "thickness": 50.0, "length": 175.0, "span": 125.0, "notch_depth": 25.0,
                              "notch_width": 2.0, "h_coarse": 10.0}},
    "wu": {"title": "Wu's beam (D 100 mm, S = L 450 mm, a0 50 mm, notch 5 mm, b 100 mm)", "target": 0.6,
           "short": "Wu, notch 5 mm",
           "geometry": _WU_GEOMETRY},
    "wu_notch2": {"title": "Wu's beam with a 2 mm notch", "target": 0.6, "short": "Wu, notch 2 mm",
                  "geometry": dict(_WU_GEOMETRY, notch_width=2.0)},
}

#: the beams of case 3 (against the cohesive crack); the cohesive crack's mesh series runs on the first
WU_BEAMS = ("wu", "wu_notch2")

#: the phase field kept for the figures: x <= this [mm], y from a0 - 3 to a0 + 40 mm, at the smallest l
FIELD_WINDOW = 12.0

#: half-width of the refined band of the cohesive-crack meshes [mm] (at least 4 h): that of the PF-CZM at l = 2.5 mm
CZM_FINE_WIDTH = 7.5

#: the claims' tolerances: (b) spread of peak and energy over l and h [-]; (c) peak and curve against the crack [-]
TOLERANCE = {"spread": 0.02, "peak": 0.02, "curve": 0.05}


@dataclass(frozen=True)
class Plan:
    """The meshes of one benchmark run (the full one or the quick smoke version).

    Attributes
    ----------
    bar_lengths : tuple of float
        Length scales l of the bar [mm].
    bar_per_length : float
        l / h on the bar [-].
    beam_lengths : tuple of float
        Length scales l on the beams [mm], increasing.
    beam_per_length : float
        l / h of the length-scale series on the beams [-].
    mesh_check : tuple of float
        (l [mm], l / h [-]) of the extra, finer mesh at one l.
    czm_sizes : tuple of float
        Element sizes along the cohesive crack [mm], decreasing (the finest is the reference).
    history_per_length : tuple of float
        l / h of the bar runs with and without the history of the driving force (linear shape, l = 2 mm) [-].
    """

    bar_lengths: tuple = (1.0, 2.0, 4.0)
    bar_per_length: float = 10.0
    beam_lengths: tuple = (1.25, 2.5, 5.0)
    beam_per_length: float = 5.0
    mesh_check: tuple = (2.5, 10.0)
    czm_sizes: tuple = (1.0, 0.5)
    history_per_length: tuple = (5.0, 10.0, 20.0)


FULL = Plan()
QUICK = Plan(bar_per_length=5.0, beam_lengths=(2.5, 5.0), beam_per_length=2.0, mesh_check=(5.0, 4.0),
             czm_sizes=(2.0,))


# ------------------------------------------------------------------------------- the PF-CZM's law for the crack
PfczmLawParameters = compose(
    "PfczmLawParameters", ELASTIC, STRENGTH_AND_ENERGY, defaults={"E": MATERIAL["E"], "ft": MATERIAL["ft"],
                                                                  "Gf": MATERIAL["Gf"]},
    summary="Parameters x = (E, nu, ft, Gf) of a bulk with cohesive cracks following the exact traction-opening law "
            "of a PF-CZM softening shape.")


@lru_cache(maxsize=None)
def pfczm_shape_table(shape: str):
    """The exact law of a PF-CZM shape of finite ultimate opening (p = 2), tabulated once in units ft and Gf / ft.

    Parameters
    ----------
    shape : str
        ``"cornelissen"`` or ``"linear"`` (the exponential shape has an infinite tail).

    Returns
    -------
    x : ndarray
        Opening over the ultimate opening, w / w_u, from 0 to 1 [-].
    f : ndarray
        Traction over the strength sigma / ft [-].
    w_u : float
        The ultimate opening in units Gf / ft [-] (5.1362 for Cornelissen's shape).
    """
    p, a2, a3 = SHAPES[shape]
    if p != 2.0:
        raise ValueError(f"shape {shape!r}: p = {p} > 2, the law has no finite ultimate opening")
    centres = default_centre_values(p, a2, a3, stress_fraction=1e-4, n_linear=241, n_tail=120)
    w, sigma = localized_cohesive_law(1.0, 1.0, 1.0, 1.0, p, a2, a3, centre_values=centres)
    w_u = ultimate_opening(1.0, 1.0, p, a2, a3)
    keep = np.concatenate([[True], np.diff(w) > 0.0]) & (w < w_u * (1.0 - 1e-9))
    return np.append(w[keep] / w_u, 1.0), np.append(sigma[keep], 0.0), w_u


@lru_cache(maxsize=None)
def shape_interpolant(shape: str):
    """The monotone piecewise-cubic (PCHIP) interpolant of :func:`pfczm_shape_table` and its derivative (built once
    per shape)."""
    x, f, _ = pfczm_shape_table(shape)
    curve = PchipInterpolator(x, f)
    return curve, curve.derivative()


@dataclass(frozen=True)
class PfczmShapeLaw(ShapeLaw):
    """The exact traction-opening law of a PF-CZM softening shape as a cohesive crack's law, sigma = ft f(w / w_u).

    The shape f is the table of :func:`pfczm_shape_table` (the localized band's law, free of E and l), interpolated
    with its slope by a monotone piecewise-cubic (PCHIP) interpolant; w_u = wc = Gf / (ft I) with I = ft w_u / Gf
    its exact inverse, so that the area under the law is Gf. The shape has no parameters of its own (the
    derivatives in ft and Gf are :class:`ShapeLaw`'s).

    Parameters
    ----------
    shape : str
        PF-CZM softening shape with p = 2 (default ``"cornelissen"``).
    """

    shape_name: str = "cornelissen"
    parameters: ClassVar[type] = PfczmLawParameters

    @property
    def name(self) -> str:
        """``pfczm-<shape>``: the cohesive model's run key tells it from Hordijk's law."""
        return f"pfczm-{self.shape_name}"

    def shape(self, x, params):
        """f(x) and df / dx at x = w / w_u in [0, 1) [-]."""
        curve, slope = shape_interpolant(self.shape_name)
        x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
        return curve(x), slope(x)

    def shape_derivatives(self, x, params) -> dict:
        return {}

    def area(self, params) -> float:
        """I = 1 / (w_u ft / Gf) [-]."""
        return 1.0 / pfczm_shape_table(self.shape_name)[2]

    def area_derivatives(self, params) -> dict:
        return {}

    def steepest_shape_slope(self, params) -> float:
        """max |f'| over 4001 points of [0, 1] [-]."""
        return float(np.max(np.abs(self.shape(np.linspace(0.0, 1.0, 4001), params)[1])))


# ----------------------------------------------------------------------------------------------- running a case
def _timed_run(model, specimen, params, **options):
    """One run: its PathResult (the converged part if it stopped early), wall time [s] and whether it completed."""
    start = time.perf_counter()
    try:
        run, complete = model.simulate(specimen, params, **options), True
    except ConvergenceError as error:
        run, complete = error.partial, False
    return run, time.perf_counter() - start, complete


def run_record(label, model, specimen, params, keep=None, **options) -> dict:
    """Run ``model`` on ``specimen`` and keep its curves, peak, timing and size.

    Parameters
    ----------
    label : str
        What the progress line prints.
    model, specimen, params
        The forward model, the specimen and the parameters.
    keep : callable, optional
        ``keep(run) -> dict`` of further values to record (e.g. a window of the phase field).
    **options
        ``simulate``'s keywords (control, target, stop_force_fraction).

    Returns
    -------
    dict
        ``control`` [mm], ``force`` [N], ``energy`` (dissipated) [N mm] along the path; ``peak`` [N],
        ``control_at_peak`` [mm], ``wall_time`` [s], ``n_free``, ``steps``, ``iterations``, ``complete``.
    """
    n_free = int(model.build(specimen, params).n_free)
    print(f"  {label}: {n_free} unknowns ...", end="", flush=True)
    run, wall, complete = _timed_run(model, specimen, params, **options)
    force = np.asarray(run.force, dtype=float)
    k = int(np.argmax(force))
    record = {"control": np.asarray(run.control).tolist(), "force": force.tolist(),
              "energy": np.asarray(run.observables["dissipated_energy"]).tolist(), "peak": float(force[k]),
              "control_at_peak": float(run.control[k]), "wall_time": wall, "n_free": n_free,
              "steps": int(run.stats.steps), "iterations": int(run.stats.iterations), "complete": complete,
              "d_range": phase_field_range(run)}
    if keep is not None:
        record.update(keep(run))
    status = "" if complete else " (stopped early)"
    print(f" {wall:.1f} s, {record['steps']} steps, peak {record['peak']:.2f} N{status}", flush=True)
    return record


def phase_field_range(run):
    """[min, max] of the phase field d over the stored fields of a run (the last step), None without one."""
    values = [fields["d"] for fields in run.fields.values() if "d" in fields]
    if not values:
        return None
    return [float(min(v.min() for v in values)), float(max(v.max() for v in values))]


# --------------------------------------------------------------------------------------------------- case 1: bar
def bar_specimen(l, per_length):
    """The bar of case 1 at h ~ l / per_length: an even number of elements, the two central ones weakened."""
    n = int(round(BAR["length"] * per_length / l))
    n += n % 2
    h = BAR["length"] / n
    return BarWithWeakZone(length=BAR["length"], n_elements=n, weakening="area", weak_zone_factor=BAR["weak"],
                           weak_zone_width=2.0 * h, profile="step"), h


def band_opening(control, force, h):
    """Crack opening of the band w = u_end - F / E (L - 2 h + 2 h / weak) [mm] (section 1 mm^2)."""
    elastic_length = BAR["length"] - 2.0 * h + 2.0 * h / BAR["weak"]
    return np.asarray(control) - np.asarray(force) / MATERIAL["E"] * elastic_length


def law_deviation(shape, opening, force):
    """Largest |F - sigma_exact(w)| over the softening branch where F > 0.2 ft, in % of ft, and its point count."""
    force = np.asarray(force)
    softening = (np.arange(force.size) >= np.argmax(force)) & (force > 0.2 * MATERIAL["ft"])
    exact = traction_at_opening(np.maximum(opening[softening], 0.0), MATERIAL["E"], MATERIAL["ft"], MATERIAL["Gf"],
                                1.0, *SHAPES[shape])
    return 100.0 * float(np.max(np.abs(force[softening] - exact))) / MATERIAL["ft"], int(softening.sum())


def law_curves(shape, w_max):
    """The exact PF-CZM law (its own grid, up to w_max) and the nominal law on a fine grid [mm, MPa], and the largest
    difference between the two over the exact law's grid (down to 1e-3 ft) [% of ft] and where it is [mm]."""
    w, sigma = localized_cohesive_law(MATERIAL["E"], MATERIAL["ft"], MATERIAL["Gf"], 1.0, *SHAPES[shape])
    difference = np.abs(sigma - target_law(shape, w, MATERIAL["ft"], MATERIAL["Gf"]))
    k = int(np.argmax(difference))
    inside = w <= w_max
    grid = np.linspace(0.0, w_max, 400)
    nominal = target_law(shape, grid, MATERIAL["ft"], MATERIAL["Gf"])
    return {"exact_w": w[inside].tolist(), "exact_sigma": sigma[inside].tolist(), "nominal_w": grid.tolist(),
            "nominal_sigma": nominal.tolist(), "nominal_deviation": 100.0 * float(difference[k]) / MATERIAL["ft"],
            "nominal_deviation_at": float(w[k])}


def bar_case(plan) -> dict:
    """Case 1 for every shape and length scale: the runs, their deviations from the exact law, the laws."""
    out = {}
    for shape in SHAPES:
        model = model_from_type("pf-czm", shape)
        runs = {}
        for l in plan.bar_lengths:
            bar, h = bar_specimen(l, plan.bar_per_length)
            params = model.parameters(**MATERIAL, l=l)
            record = run_record(f"bar {shape} l={l:g} h={h:.3g}", model, bar, params, control="end_displacement",
                                target=BAR["target"], stop_force_fraction=BAR["stop_force_fraction"])
            opening = band_opening(record["control"], record["force"], h)
            deviation, points = law_deviation(shape, opening, record["force"])
            record.update(l=l, h=h, n_elements=int(bar.n_elements), opening=opening.tolist(), deviation=deviation,
                          points=points)
            print(f"    max deviation from the exact law {deviation:.3f} % of ft over {points} points", flush=True)
            runs[f"{l:g}"] = record
        w_max = max(max(r["opening"]) for r in runs.values())
        out[shape] = {"runs": runs, "laws": law_curves(shape, w_max)}
    return out


#: the bar runs with and without the history: the linear shape (its exact law is closed-form) at l = 2 mm
HISTORY = {"shape": "linear", "l": 2.0}


def bar_problem(bar, params, irreversible):
    """The PF-CZM problem of the bar as :class:`PhaseFieldModel` builds it, with the history of the driving force
    (``irreversible``, the model) or with the driving force of the current state (Wu's 1D analysis)."""
    description = bar.describe()
    disc = discretize(description)
    return PhaseFieldProblem(disc, params, conditions(description),
                             stiffness_factor=at_points(description.stiffness_factor, disc),
                             damageable=at_points(description.damageable, disc),
                             strength_factor=at_points(description.strength_factor, disc), irreversible=irreversible)


def history_case(plan) -> list:
    """Case 1b: the deviation from the exact law with and without the history, h = l / r for r in the plan."""
    shape, l = HISTORY["shape"], HISTORY["l"]
    params = model_from_type("pf-czm", shape).parameters(**MATERIAL, l=l)
    rows = []
    for per_length in plan.history_per_length:
        bar, h = bar_specimen(l, per_length)
        row = {"per_length": per_length, "h": h}
        for key, irreversible in (("with", True), ("without", False)):
            start = time.perf_counter()
            run = follow_path(bar_problem(bar, params, irreversible), "end_displacement", BAR["target"],
                              stop_force_fraction=BAR["stop_force_fraction"])
            opening = band_opening(run.control, run.force, h)
            row[key] = law_deviation(shape, opening, run.force)[0]
            row[f"{key}_wall"] = time.perf_counter() - start
        print(f"  bar {shape} l={l:g} h=l/{per_length:g}: deviation {row['with']:.3f} % of ft with the history, "
              f"{row['without']:.3f} % without", flush=True)
        rows.append(row)
    return rows


# ------------------------------------------------------------------------------------------------ cases 2 and 3
def beam_specimen(beam, h, fine_width):
    """A :class:`NotchedBeam` of ``BEAMS[beam]`` with process-zone elements h and refined half-width [mm]."""
    return NotchedBeam(**BEAMS[beam]["geometry"], h_fine=h, fine_width=fine_width)


def pf_key(l, h):
    """Run name of a PF-CZM run."""
    return f"pf l={l:g} h={h:g}"


def pf_series(plan):
    """The (l, h) of the PF-CZM runs on each beam: the length-scale series, then the mesh check."""
    series = [(l, l / plan.beam_per_length) for l in plan.beam_lengths]
    l, ratio = plan.mesh_check
    return series + [(l, l / ratio)]


def czm_models():
    """The cohesive crack with Hordijk's law and with the PF-CZM's Cornelissen law, by run-name prefix."""
    return {"czm hordijk": CohesiveCrackModel(), "czm pf-law": CohesiveCrackModel(law=PfczmShapeLaw())}


def pf_fine_width(beam, l, h):
    """Half-width of the refined band of a PF-CZM mesh [mm]: max(3 l, 4 h), and at least the notch's half-width
    plus 2 l (the band may start at the notch's corners: on Wu's 5 mm notch at l = 1.25 mm)."""
    return max(3.0 * l, 4.0 * h, BEAMS[beam]["geometry"]["notch_width"] / 2.0 + 2.0 * l)


def field_keeper(specimen):
    """``keep`` of :func:`run_record`: the phase field of the last stored step near the notch of ``specimen`` (on
    the mesh's vertices, which come first among its nodes)."""

    def keep(run):
        d = run.fields[max(run.fields)]["d"]
        xy = specimen.describe().nodes[: d.size]
        inside = ((xy[:, 0] <= FIELD_WINDOW) & (xy[:, 1] >= specimen.notch_depth - 3.0)
                  & (xy[:, 1] <= specimen.notch_depth + 40.0))
        return {"d_window": {"x": np.round(xy[inside, 0], 4).tolist(), "y": np.round(xy[inside, 1], 4).tolist(),
                             "d": np.round(d[inside], 4).tolist()}}

    return keep


def beam_runs(beam, plan) -> dict:
    """Every run on one beam: the PF-CZM series (the phase field kept at the smallest l) and the cohesive cracks
    (both laws; every size on Wu's beam, the finest on the others)."""
    target, runs = BEAMS[beam]["target"], {}
    model = model_from_type("pf-czm", "cornelissen")
    for l, h in pf_series(plan):
        params = model.parameters(**MATERIAL, l=l)
        specimen = beam_specimen(beam, h, pf_fine_width(beam, l, h))
        keep = field_keeper(specimen) if l == min(plan.beam_lengths) else None
        record = run_record(f"{beam} {pf_key(l, h)}", model, specimen, params, keep=keep, target=target,
                            stop_force_fraction=None)
        runs[pf_key(l, h)] = dict(record, l=l, h=h, model="pf-czm", fine_width=specimen.fine_width)
    sizes = plan.czm_sizes if beam == WU_BEAMS[0] else plan.czm_sizes[-1:]
    for prefix, crack in czm_models().items():
        params = crack.parameters(**MATERIAL)
        for h in sizes:
            specimen = beam_specimen(beam, h, max(CZM_FINE_WIDTH, 4.0 * h))
            record = run_record(f"{beam} {prefix} h={h:g}", crack, specimen, params, target=target,
                                stop_force_fraction=None)
            runs[f"{prefix} h={h:g}"] = dict(record, h=h, model=crack.key, fine_width=specimen.fine_width)
    return runs


def value_at(record, quantity, control):
    """A recorded quantity (``force`` or ``energy``) interpolated at a control value [mm]."""
    return float(np.interp(control, record["control"], record[quantity]))


def spread(values):
    """max / min - 1 [%]."""
    return 100.0 * (max(values) / min(values) - 1.0)


def band_position(record, geometry):
    """Where the phase field of a run peaks across the ligament at its last step, on the rows 20 % to 40 % of the
    ligament above the notch: x, y [mm] and d there, and the largest d on the symmetry line x = 0 on those rows."""
    window = record["d_window"]
    x, y, d = (np.asarray(window[key]) for key in ("x", "y", "d"))
    a0, ligament = geometry["notch_depth"], geometry["depth"] - geometry["notch_depth"]
    rows = (y >= a0 + 0.2 * ligament) & (y <= a0 + 0.4 * ligament)
    k = int(np.argmax(np.where(rows, d, -np.inf)))
    d_axis = float(d[rows & (x < 1e-9)].max())
    off_axis = bool(x[k] > 0.5 and d_axis < 0.5 * d[k])
    return {"x": float(x[k]), "y": float(y[k]), "d": float(d[k]), "d_axis": d_axis, "off_axis": off_axis,
            "rows": [float(a0 + 0.2 * ligament), float(a0 + 0.4 * ligament)]}


def length_scale_summary(beam, runs, plan) -> dict:
    """Case 2 on one beam: peaks and energies at the last common CMOD, their spreads over l (at h = l / r) and over
    all the PF-CZM runs (every h <= l / 5 of the full plan), the mesh change, the runs that stopped early and
    where the band of the smallest l sits."""
    series = pf_series(plan)
    pf_names = [pf_key(l, h) for l, h in series]
    common = min(runs[name]["control"][-1] for name in pf_names)
    energies = {name: value_at(runs[name], "energy", common) for name in pf_names}
    by_l = pf_names[:-1]
    l, ratio = plan.mesh_check
    coarse = pf_key(l, l / plan.beam_per_length)
    fine = pf_names[-1]
    return {"common_cmod": common, "energies": energies,
            "peak_spread": spread([runs[n]["peak"] for n in by_l]),
            "energy_spread": spread([energies[n] for n in by_l]),
            "mesh_pair": [coarse, fine],
            "mesh_peak_change": 100.0 * (runs[fine]["peak"] / runs[coarse]["peak"] - 1.0),
            "mesh_energy_change": 100.0 * (energies[fine] / energies[coarse] - 1.0),
            "all_peak_spread": spread([runs[n]["peak"] for n in pf_names]),
            "all_energy_spread": spread(list(energies.values())),
            "peak_spread_large": spread([runs[n]["peak"] for n in by_l[1:]]),
            "energy_spread_large": spread([energies[n] for n in by_l[1:]]),
            "stopped": [name for name in pf_names if not runs[name]["complete"]],
            "band": dict(band_position(runs[pf_names[0]], BEAMS[beam]["geometry"]), run=pf_names[0])}


def curve_difference(a, b, points=801):
    """Largest |F_a - F_b| over the common control range [N] and where it occurs [mm]."""
    end = min(a["control"][-1], b["control"][-1])
    grid = np.linspace(0.0, end, points)
    gap = np.abs(np.interp(grid, a["control"], a["force"]) - np.interp(grid, b["control"], b["force"]))
    k = int(np.argmax(gap))
    return float(gap[k]), float(grid[k]), float(end)


def comparison(runs, pf_name, czm_name) -> dict:
    """One PF-CZM run against one cohesive crack: peak difference [%] and largest force gap [% of the crack's peak]."""
    pf, czm = runs[pf_name], runs[czm_name]
    gap, where, end = curve_difference(pf, czm)
    return {"pf": pf_name, "czm": czm_name, "peak_difference": 100.0 * (pf["peak"] / czm["peak"] - 1.0),
            "max_gap": 100.0 * gap / czm["peak"], "max_gap_at": where, "common_cmod": end,
            "energy_difference": 100.0 * (value_at(pf, "energy", end) / value_at(czm, "energy", end) - 1.0)}


def crack_summary(runs, plan) -> dict:
    """Case 3: the two finest PF-CZM runs of the length-scale series against the finest cohesive cracks of both
    laws; the cohesive cracks' mesh convergence and the part of the gap due to the law's shape."""
    pf_names = [pf_key(l, l / plan.beam_per_length) for l in plan.beam_lengths[:2]]
    finest = plan.czm_sizes[-1]
    czm_names = [f"{prefix} h={finest:g}" for prefix in czm_models()]
    pairs = [comparison(runs, p, c) for p in pf_names for c in czm_names]
    hordijk, own = (runs[name] for name in czm_names)
    gap, where, _ = curve_difference(own, hordijk)
    coarsest = next(h for h in plan.czm_sizes if f"czm hordijk h={h:g}" in runs)
    convergence = {prefix: 100.0 * (runs[f"{prefix} h={finest:g}"]["peak"] / runs[f"{prefix} h={coarsest:g}"]["peak"]
                                    - 1.0) for prefix in czm_models()}
    shares = {name: (own["peak"] - hordijk["peak"]) / (runs[name]["peak"] - hordijk["peak"]) for name in pf_names}
    return {"pairs": pairs, "shape_peak_difference": 100.0 * (own["peak"] / hordijk["peak"] - 1.0),
            "shape_share": shares,
            "shape_max_gap": 100.0 * gap / hordijk["peak"], "shape_max_gap_at": where,
            "czm_mesh_change": convergence, "czm_sizes": [coarsest, finest], "czm_names": czm_names,
            "pf_names": pf_names}


# ------------------------------------------------------------------------------------------------------- figures
COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")
MARKERS = ("o", "s", "^")
#: line styles of the cohesive cracks in the figures, by run-name prefix
CZM_STYLES = {"czm hordijk": "--", "czm pf-law": ":"}


def bar_figure(bar, per_length):
    """bar_law.png: one panel per shape, the FE curves for each l (every other point), the exact and nominal laws."""
    fig = new_figure(13.0, 4.2)
    axes = fig.subplots(1, len(bar))
    for ax, (shape, data) in zip(axes, bar.items()):
        for colour, marker, (l, run) in zip(COLOURS, MARKERS, data["runs"].items()):
            force = np.asarray(run["force"])
            after = np.flatnonzero(np.arange(force.size) >= np.argmax(force))
            shown = after[::2] if marker == "o" else after[1::2]
            ax.plot(np.asarray(run["opening"])[shown], force[shown], marker, ms=4 if marker == "o" else 3, mfc="none",
                    color=colour, lw=0, label=f"FE, l = {l} mm")
        laws = data["laws"]
        ax.plot(laws["exact_w"], laws["exact_sigma"], "k-", lw=1.0, label="exact PF-CZM law")
        ax.plot(laws["nominal_w"], laws["nominal_sigma"], "k--", lw=1.0, label="nominal law")
        ax.set(title=f"{shape} shape, h = l / {per_length:g}", xlabel="crack opening w [mm]",
               ylabel="traction [MPa]", ylim=(0.0, None))
        ax.legend(fontsize=7)
    return fig


def beam_figure(beams, plan):
    """beam_length_scale.png: force-CMOD per l and mesh on each beam, with the cohesive cracks (finest mesh)."""
    fig = new_figure(5.5 * len(beams), 4.6)
    axes = fig.subplots(1, len(beams))
    finest = plan.czm_sizes[-1]
    for ax, (beam, data) in zip(axes, beams.items()):
        runs = data["runs"]
        for colour, (l, h) in zip(COLOURS, pf_series(plan)):
            run = runs[pf_key(l, h)]
            ax.plot(run["control"], run["force"], color=colour, lw=1.2, label=f"PF-CZM l = {l:g}, h = {h:g}")
        for prefix, style in CZM_STYLES.items():
            run = runs[f"{prefix} h={finest:g}"]
            ax.plot(run["control"], run["force"], "k" + style, lw=1.2, label=f"{prefix} h={finest:g}")
        ax.set(xlabel="CMOD [mm]", ylabel="force [N]", ylim=(0.0, None))
        ax.set_title(BEAMS[beam]["title"], fontsize=9)
        ax.legend(fontsize=7)
    return fig


def wu_figure(beams):
    """wu_beam.png: on each of Wu's beams (a row), the PF-CZM (colours) against the cohesive cracks (black, finest;
    grey, coarser) and their force differences along the curve; beside them the two traction-separation laws."""
    fig = new_figure(15.0, 4.2 * len(WU_BEAMS))
    axes = fig.subplot_mosaic([[f"curves {beam}", f"gaps {beam}", "laws"] for beam in WU_BEAMS])
    for beam in WU_BEAMS:
        curves_panel(axes[f"curves {beam}"], beams[beam]["runs"], beams[beam]["crack"], BEAMS[beam]["title"])
        gaps_panel(axes[f"gaps {beam}"], beams[beam]["runs"], beams[beam]["crack"])
    law_panel(axes["laws"])
    return fig


def curves_panel(ax, runs, crack, title):
    """Force-CMOD of the PF-CZM runs of case 3 and of every cohesive crack on one beam."""
    colours = dict(zip(crack["pf_names"], COLOURS))
    for name in crack["pf_names"]:
        ax.plot(runs[name]["control"], runs[name]["force"], color=colours[name], lw=1.2, label=name)
    for name, run in runs.items():
        prefix = name.rsplit(" h=", 1)[0]
        if prefix in CZM_STYLES:
            shade = "k" if name in crack["czm_names"] else "0.6"
            ax.plot(run["control"], run["force"], CZM_STYLES[prefix], color=shade, lw=1.2, label=name)
    ax.set(xlabel="CMOD [mm]", ylabel="force [N]", ylim=(0.0, None))
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)


def gaps_panel(ax, runs, crack):
    """F_pf - F_czm along the common CMOD range of each pair of case 3, in % of the crack's peak."""
    colours = dict(zip(crack["pf_names"], COLOURS))
    for pair in crack["pairs"]:
        pf, czm = runs[pair["pf"]], runs[pair["czm"]]
        grid = np.linspace(0.0, pair["common_cmod"], 400)
        gap = np.interp(grid, pf["control"], pf["force"]) - np.interp(grid, czm["control"], czm["force"])
        ax.plot(grid, 100.0 * gap / czm["peak"], CZM_STYLES[pair["czm"].rsplit(" h=", 1)[0]],
                color=colours[pair["pf"]], lw=1.2, label=f"{pair['pf']} minus {pair['czm']}")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set(xlabel="CMOD [mm]", ylabel="(F_pf - F_czm) / crack's peak [%]")
    ax.legend(fontsize=7)


def field_figure(beams):
    """notch_phase_field.png: the phase field at the last step of the smallest l near the notch, one panel per beam
    (the notch itself left blank)."""
    fig = new_figure(4.2 * len(beams), 5.5)
    axes = fig.subplots(1, len(beams))
    for ax, (beam, data) in zip(axes, beams.items()):
        band = data["summary"]["band"]
        window = data["runs"][band["run"]]["d_window"]
        x, y, d = (np.asarray(window[key]) for key in ("x", "y", "d"))
        geometry = BEAMS[beam]["geometry"]
        triangles = Triangulation(x, y)
        centre_x, centre_y = x[triangles.triangles].mean(axis=1), y[triangles.triangles].mean(axis=1)
        triangles.set_mask((centre_x < geometry["notch_width"] / 2) & (centre_y < geometry["notch_depth"]))
        image = ax.tripcolor(triangles, d, shading="gouraud", vmin=0.0, vmax=1.0, cmap="viridis")
        ax.set(aspect="equal", xlabel="x [mm] (0: the symmetry line)", ylabel="y [mm]")
        cmod = data["runs"][band["run"]]["control"][-1]
        ax.set_title(f"{BEAMS[beam]['short']}\n{band['run']}, CMOD {cmod:.3g} mm", fontsize=9)
    fig.colorbar(image, ax=axes, label="phase field d", shrink=0.8)
    return fig


def law_panel(ax):
    """Hordijk's law and the PF-CZM's Cornelissen law in units ft and Gf / ft."""
    x, f, w_u = pfczm_shape_table("cornelissen")
    w = np.linspace(0.0, w_u, 400)
    ax.plot(x * w_u, f, "k:", lw=1.5, label="PF-CZM's law, Cornelissen shape (exact)")
    ax.plot(w, target_law("cornelissen", w, 1.0, 1.0), "k--", lw=1.0, label="Hordijk's law")
    ax.set(title="the two traction-separation laws", xlabel="w ft / Gf [-]", ylabel="sigma / ft [-]")
    ax.legend(fontsize=7)


def write_figures(results, out):
    """All the figures from the results."""
    plan = plan_of(results)
    figures = {"bar_law.png": bar_figure(results["bar"], plan.bar_per_length),
               "beam_length_scale.png": beam_figure(results["beams"], plan),
               "wu_beam.png": wu_figure(results["beams"]),
               "notch_phase_field.png": field_figure(results["beams"])}
    for name, fig in figures.items():
        (out / name).write_bytes(to_png(fig))
    return list(figures)


# -------------------------------------------------------------------------------------------------------- README
def _row(cells):
    return "| " + " | ".join(str(c) for c in cells) + " |"


def table(header, rows):
    """A markdown table."""
    return "\n".join([_row(header), _row(["---"] * len(header))] + [_row(r) for r in rows])


def bar_section(bar):
    """README: case 1 (the runs, then the exact laws against the nominal ones)."""
    rows = [[shape, run["l"], f"{run['h']:.3g}", run["n_elements"], f"{run['peak'] / MATERIAL['ft']:.4f}",
             f"{run['deviation']:.3f}", run["points"]]
            for shape, data in bar.items() for run in data["runs"].values()]
    laws = ", ".join(f"{shape} {data['laws']['nominal_deviation']:.2f} % of ft (at w = "
                     f"{data['laws']['nominal_deviation_at'] * MATERIAL['ft'] / MATERIAL['Gf']:.2f} Gf / ft)"
                     for shape, data in bar.items())
    return (table(["shape", "l [mm]", "h [mm]", "elements", "peak / ft", "max dev. [% ft]", "points"], rows)
            + f"\n\nThe exact laws against the nominal ones (`target_law`), largest difference down to 1e-3 ft: "
            f"{laws}.")


def history_section(rows):
    """README: case 1b, the bar with and without the history of the driving force."""
    table_rows = [[f"l / {row['per_length']:g}", f"{row['h']:.3g}", f"{row['with']:.3f}", f"{row['without']:.3f}"]
                  for row in rows]
    return (f"With and without the history ({HISTORY['shape']} shape, l = {HISTORY['l']:g} mm, its exact law in "
            "closed form). The model drives the phase field by the history maximum of the effective stress; Wu's 1D "
            "analysis, which gives the exact law, assumes the driving force of the current state "
            "(`PhaseFieldProblem(..., irreversible=False)`, built as `PhaseFieldModel.build` builds it). Largest "
            "deviation from the exact law above 0.2 ft [% of ft]:\n\n"
            + table(["h", "h [mm]", "with the history (the model)", "without"], table_rows))


def beam_section(beam, data):
    """README: case 2 on one beam (runs and spreads)."""
    runs, summary = data["runs"], data["summary"]
    rows = []
    for name, run in runs.items():
        energy = value_at(run, "energy", summary["common_cmod"])
        rows.append([name, run["n_free"], f"{run['peak']:.1f}", f"{run['control_at_peak']:.4f}", f"{energy:.2f}",
                     f"{run['wall_time']:.1f}"])
    text = table(["run", "unknowns", "peak [N]", "CMOD at peak [mm]",
                  f"energy at CMOD {summary['common_cmod']:.3g} [N mm]", "wall [s]"], rows)
    coarse, fine = summary["mesh_pair"]
    return (f"{text}\n\nSpreads (max / min - 1) over l at h = l / {data['per_length']:g}: peak "
            f"{summary['peak_spread']:.2f} %, energy {summary['energy_spread']:.2f} %; over all "
            f"{len(pf_names_of(data))} PF-CZM runs: peak {summary['all_peak_spread']:.2f} %, energy "
            f"{summary['all_energy_spread']:.2f} %. Mesh change {coarse} -> {fine}: peak "
            f"{summary['mesh_peak_change']:+.2f} %, energy {summary['mesh_energy_change']:+.2f} %.")


def pf_names_of(data):
    """The PF-CZM run names of one beam's runs."""
    return [name for name in data["runs"] if name.startswith("pf ")]


def crack_section(crack, runs):
    """README: case 3 (the pairs, the law's part of the peak gap, the cohesive crack's mesh convergence)."""
    rows = [[p["pf"], p["czm"], f"{p['peak_difference']:+.2f}", f"{p['max_gap']:.2f}", f"{p['max_gap_at']:.3f}",
             f"{p['energy_difference']:+.2f}"] for p in crack["pairs"]]
    text = table(["PF-CZM", "cohesive crack", "peak diff. [%]", "max abs(F_pf - F_czm) [% czm peak]", "at CMOD [mm]",
                  "energy diff. at end [%]"], rows)
    hordijk, own = crack["czm_names"]
    split = table(["PF-CZM", "F_pf - F_hordijk [N]", "of which F_pf-law - F_hordijk [N]", "share of the law [%]"],
                  [[name, f"{runs[name]['peak'] - runs[hordijk]['peak']:.1f}",
                    f"{runs[own]['peak'] - runs[hordijk]['peak']:.1f}", f"{100.0 * share:.0f}"]
                   for name, share in crack["shape_share"].items()])
    changes = ", ".join(f"{k} {v:+.2f} %" for k, v in crack["czm_mesh_change"].items())
    coarse, fine = crack["czm_sizes"]
    convergence = (f"\n\nCohesive crack peak change on refining its elements from h = {coarse:g} to {fine:g} mm: "
                   f"{changes}." if coarse != fine else "")
    return (f"{text}\n\nThe cohesive crack with the PF-CZM's law against Hordijk's (same mesh): peak "
            f"{crack['shape_peak_difference']:+.2f} %, largest force difference {crack['shape_max_gap']:.2f} % of the "
            f"Hordijk peak (at CMOD {crack['shape_max_gap_at']:.3f} mm). The peak gap to the Hordijk crack split into "
            f"the law's part and the rest:\n\n{split}{convergence}")


def timing_section(results):
    """README: wall time and unknowns of every run."""
    runs = [(f"bar {shape} l={run['l']:g}", run) for shape, data in results["bar"].items()
            for run in data["runs"].values()]
    runs += [(f"{beam}: {name}", run) for beam, data in results["beams"].items() for name, run in data["runs"].items()]
    rows = [[name, run["n_free"], run["steps"], run["iterations"], f"{run['wall_time']:.1f}", d_range_text(run)]
            for name, run in runs]
    return table(["run", "unknowns", "steps", "Newton iterations", "wall [s]", "d at the last step (min, max)"], rows)


def d_range_text(run):
    """The phase field's range of a run as text ('-' for the cohesive crack)."""
    if not run.get("d_range"):
        return "-"
    low, high = run["d_range"]
    return f"{low:.2e}, {high:.4f}"


def verdict(value, tolerance):
    """``holds`` or ``fails`` (by how much) of a measured value [%] against a tolerance [%]."""
    if value <= tolerance:
        return f"holds ({value:.2f} % <= {tolerance:g} %)"
    return f"fails ({value:.2f} % > {tolerance:g} %, by {value - tolerance:.2f} points)"


def reading_a(bar, per_length, history):
    """The reading of claim (a) (``per_length``: l / h on the bar; ``history``: the rows of case 1b)."""
    deviations = {shape: [run["deviation"] for run in data["runs"].values()] for shape, data in bar.items()}
    worst = {shape: max(values) for shape, values in deviations.items()}
    spreads = max(max(v) - min(v) for v in deviations.values())
    per_shape = ", ".join(f"{shape} {value:.2f} %" for shape, value in worst.items())
    status = "holds" if max(worst.values()) <= 1.0 and spreads <= 0.1 else "holds only roughly"
    with_history = ", ".join(f"{row['with']:.2f}" for row in history)
    without = ", ".join(f"{row['without']:.2f}" for row in history)
    ratios = ", ".join(f"l / {row['per_length']:g}" for row in history)
    return (f"**(a) The 1D band follows its exact law for any l: {status}.** Largest deviation of the band's traction "
            f"from the exact law over the softening branch above 0.2 ft, at h = l / {per_length:g}: {per_shape} of "
            f"ft; for each shape the three l give deviations within {spreads:.3f} % of ft of each other, so the "
            f"curves of the three l coincide and lie within {max(worst.values()):.2f} % of ft of the exact law: the "
            "residual does not come from l. It is not plain discretisation error either: without the history the "
            f"{HISTORY['shape']} shape's deviation falls with h ({without} % of ft at h = {ratios}), with it (the "
            f"model) it grows ({with_history} %; the explanation of `PhaseFieldProblem`'s docstring: the driving "
            "force falls near the band's edges, the history keeps its maximum there, Wu's analysis assumes the "
            f"current one), up to {max(row['with'] for row in history):.2f} % of ft at h = l / "
            f"{history[-1]['per_length']:g}. The exact laws are not the nominal ones (section 1): a property of the "
            "shape, not of the band.")


def verdict_table(results):
    """The claims in short: what was measured against which tolerance, and whether it holds."""
    bar, beams = results["bar"], results["beams"]
    worst = max(run["deviation"] for data in bar.values() for run in data["runs"].values())
    rows = [["(a) 1D band on its exact law, any l", "bar, 3 shapes x 3 l", f"max deviation {worst:.2f} % of ft",
             "-", "holds" if worst <= 1.0 else "roughly"]]
    tolerance = 100 * TOLERANCE["spread"]
    for beam, data in beams.items():
        s = data["summary"]
        worst = max(s["all_peak_spread"], s["all_energy_spread"])
        measured = f"spread {s['all_peak_spread']:.2f} % / {s['all_energy_spread']:.2f} %"
        if s["band"]["off_axis"]:
            kept = [name for name in pf_names_of(data) if name != s["band"]["run"]]
            measured += (f"; without {s['band']['run']} (band off the axis): "
                         f"{spread([data['runs'][n]['peak'] for n in kept]):.2f} % / "
                         f"{spread([s['energies'][n] for n in kept]):.2f} %")
        rows.append(["(b) peak, energy within 2 % over l and h", BEAMS[beam]["short"], measured, f"{tolerance:g} %",
                     "holds" if worst <= tolerance else f"fails by {worst - tolerance:.2f} points"])
    for beam in WU_BEAMS:
        band = beams[beam]["summary"]["band"]
        for p in beams[beam]["crack"]["pairs"]:
            off = " (band off the axis)" if band["off_axis"] and p["pf"] == band["run"] else ""
            excess = max(abs(p["peak_difference"]) - 100 * TOLERANCE["peak"], p["max_gap"] - 100 * TOLERANCE["curve"])
            rows.append([f"(c) against the {'Hordijk' if 'hordijk' in p['czm'] else 'PF-law'} crack",
                         f"{BEAMS[beam]['short']}, {p['pf']}{off}",
                         f"peak {p['peak_difference']:+.2f} %, curve {p['max_gap']:.2f} %",
                         f"{100 * TOLERANCE['peak']:g} % / {100 * TOLERANCE['curve']:g} %",
                         "holds" if excess <= 0.0 else f"fails by {excess:.2f} points"])
    return table(["claim", "where", "measured", "tolerance", "verdict"], rows)


def relative_to(data, reference, name):
    """Peak and energy (at the common CMOD) of run ``name`` relative to run ``reference`` on one beam [%]."""
    runs, energies = data["runs"], data["summary"]["energies"]
    return (100.0 * (runs[name]["peak"] / runs[reference]["peak"] - 1.0),
            100.0 * (energies[name] / energies[reference] - 1.0))


def reading_b(beams):
    """The reading of claim (b), beam by beam (over all the PF-CZM runs, h <= l / 5), with each run against the one
    at l = 2.5 mm, h = l / 5 (Wu's l)."""
    lines = ["**(b) Peak and dissipated energy insensitive to l and h within 2 % (l in {1.25, 2.5, 5} mm, "
             "h <= l / 5), over all the PF-CZM runs of a beam:**", ""]
    tolerance = 100 * TOLERANCE["spread"]
    for beam, data in beams.items():
        s = data["summary"]
        reference = s["mesh_pair"][0]
        others = "; ".join("{} {:+.2f} % / {:+.2f} %".format(name, *relative_to(data, reference, name))
                           for name in pf_names_of(data) if name != reference)
        stopped = f" ({', '.join(s['stopped'])} stopped early)" if s["stopped"] else ""
        lines.append(f"- {BEAMS[beam]['title']}: peak {verdict(s['all_peak_spread'], tolerance)}; energy at CMOD "
                     f"{s['common_cmod']:.3g} mm {verdict(s['all_energy_spread'], tolerance)}{stopped}. Peak / "
                     f"energy against {reference}: {others}.")
    return "\n".join(lines)


def on_axis_pairs(beams, beam):
    """The pairs of case 3 on ``beam`` whose PF-CZM run was not seen to crack off the symmetry line."""
    band = beams[beam]["summary"]["band"]
    return [p for p in beams[beam]["crack"]["pairs"] if not (band["off_axis"] and p["pf"] == band["run"])]


def claim_c_summary(beams):
    """The ranges of claim (c) over the pairs on the symmetry line, by the cohesive crack's law."""
    out = []
    for prefix in CZM_STYLES:
        pairs = [p for beam in WU_BEAMS for p in on_axis_pairs(beams, beam) if p["czm"].startswith(prefix)]
        if not pairs:
            continue
        peaks = [p["peak_difference"] for p in pairs]
        gaps = [p["max_gap"] for p in pairs]
        out.append(f"against `{prefix}` the peak differs by {min(peaks):+.2f} to {max(peaks):+.2f} % and the largest "
                   f"curve difference is {min(gaps):.2f} to {max(gaps):.2f} % of the peak")
    return "; ".join(out)


def reading_c(beams):
    """The reading of claim (c) on Wu's beams: against Hordijk's crack (the claim), then against the crack with the
    PF-CZM's own law (what remains without the law's shape)."""
    lines = ["**(c) Wu's beam: PF-CZM within 2 % of the cohesive crack in peak and 5 % of the peak along the "
             "curve:**", ""]
    for beam in WU_BEAMS:
        crack, runs = beams[beam]["crack"], beams[beam]["runs"]
        lines.append(f"- {BEAMS[beam]['title']}:")
        for p in crack["pairs"]:
            peak = verdict(abs(p["peak_difference"]), 100 * TOLERANCE["peak"])
            curve = verdict(p["max_gap"], 100 * TOLERANCE["curve"])
            lines.append(f"  - {p['pf']} against {p['czm']}: peak {peak}; curve {curve}, largest at CMOD "
                         f"{p['max_gap_at']:.3f} mm.")
        hordijk, own = crack["czm_names"]
        shares = ", ".join(f"{100.0 * share:.0f} % for {name}" for name, share in crack["shape_share"].items())
        lines.append(f"  - The law's part: with the PF-CZM's own Cornelissen law the cohesive crack's peak is "
                     f"{crack['shape_peak_difference']:+.2f} % above the Hordijk crack's ({runs[own]['peak']:.1f} "
                     f"against {runs[hordijk]['peak']:.1f} N) and its curve departs by up to "
                     f"{crack['shape_max_gap']:.2f} % of the peak: {shares} of the PF-CZM's peak excess over the "
                     "Hordijk crack.")
    lines += ["", "Leaving out the run whose band runs off the symmetry line (next paragraph; the phase field was "
              f"kept for the smallest l only), {claim_c_summary(beams)}. The comparison with Hordijk's crack mixes "
              "two things: the law (the Cornelissen shape of the PF-CZM is not Hordijk's law, section 1) and the "
              "regularisation; against the crack with the PF-CZM's own law only the second remains."]
    return "\n".join(lines)


def corner_text(beam, data):
    """Where the band of the smallest l runs on one beam (from its phase field at the last step)."""
    band, half = data["summary"]["band"], BEAMS[beam]["geometry"]["notch_width"] / 2.0
    run = data["runs"][band["run"]]
    low, high = band["rows"]
    where = (f"on the rows y = {low:g} to {high:g} mm the phase field peaks at x = {band['x']:.2f} mm (d = "
             f"{band['d']:.2f}; the notch's corner is at x = {half:g} mm) and reaches at most d = {band['d_axis']:.2f} "
             "on the symmetry line")
    verdict_text = ("the band runs off the symmetry line, up from the notch's corner, and the half model mirrors it "
                    "into two cracks" if band["off_axis"] else "the band runs on the symmetry line")
    status = "completed" if run["complete"] else "stopped early"
    return (f"- {BEAMS[beam]['title']}, {band['run']} (last step at CMOD {run['control'][-1]:.3g} mm, the run "
            f"{status}; peak {run['peak']:.1f} N): {where}: {verdict_text}.")


def notes(results) -> str:
    """Where the band of the smallest l runs (the notch's corners), and the small ligament of Gregoire's beam."""
    beams = results["beams"]
    gregoire = beams["gregoire"]["crack"]
    excess = "; ".join(f"{p['pf']} {p['peak_difference']:+.1f} % against {p['czm']}" for p in gregoire["pairs"])
    corners = "\n".join(corner_text(beam, data) for beam, data in beams.items())
    return ("**Where the band runs.** The cohesive crack is put on the symmetry line; the PF-CZM's band forms where "
            "the stress peaks, and a notch's re-entrant corners concentrate it. The phase field at the last step "
            "of the smallest l (notch_phase_field.png; the band is about pi l = 3.9 mm wide at l = 1.25 mm):"
            f"\n\n{corners}\n\n![phase field](notch_phase_field.png)\n\n"
            "**Small ligaments.** On Gregoire's beam (a 25 mm ligament) the PF-CZM's peak stays well above the "
            f"cohesive crack's: {excess}. The PF-CZM here degrades the whole stress (isotropic degradation, no "
            "tension/compression split: where the band meets the compressed zone above the crack tip, its "
            "compressive stiffness is degraded as well) and spreads the crack over a band of finite width "
            "(half-width pi l / 2, 2 to 8 mm for l = 1.25 to 5 mm), neither small against a 25 mm ligament; both "
            "matter on small ligaments, and these runs do not separate the two.")


def readme(results) -> str:
    """The README text from the results."""
    meta, beams = results["meta"], results["beams"]
    sections = [
        "# PF-CZM benchmark: the band's law, length scale and mesh, Wu's beam against the cohesive crack",
        "",
        f"Run with `{meta['command']}` on {meta['date']}; machine: {meta['machine']} (2 cores, shared with other "
        f"work; `OPENBLAS_NUM_THREADS=1`, one run at a time); fracid {meta['fracid']}, numpy {meta['numpy']}, "
        f"Python {meta['python']}. Total wall time {meta['total_wall_time'] / 60:.1f} min"
        + (" (the quick smoke version on coarse meshes)." if meta["quick"] else "."),
        "",
        "The phase-field regularised cohesive zone model (PF-CZM, J.-Y. Wu 2017, J. Mech. Phys. Solids 103:72-99; "
        "`fracid.models.PhaseFieldModel`) with Wu's concrete, E = 20 GPa, nu = 0.2, ft = 2.4 MPa, Gf = 0.113 N/mm. "
        "Numbers are those of `results.json`, the figures are drawn from it (`--figures-only` redraws them).",
        "",
        "## 1. The 1D bar: the band against its exact law",
        "",
        f"`BarWithWeakZone(length={BAR['length']:g}, weakening='area', weak_zone_factor={BAR['weak']}, "
        "weak_zone_width=2 h, profile='step')`, an even number of elements, h = l / "
        f"{results['plan']['bar_per_length']:g}, end displacement to {BAR['target']} mm (stopped at "
        f"{BAR['stop_force_fraction']} of the peak). The band's opening is w = u_end - F / E (L - 2 h + 2 h / "
        f"{BAR['weak']}), its traction F (section 1 mm^2); the deviation is max abs(F - sigma_exact(w)) over the "
        "softening branch where F > 0.2 ft, sigma_exact from `traction_at_opening`.",
        "",
        bar_section(results["bar"]),
        "",
        "![bar](bar_law.png)",
        "",
        history_section(results["history"]),
        "",
        "## 2. Length scale and mesh on the notched beams",
        "",
        "PF-CZM, Cornelissen shape, `NotchedBeam(..., h_fine=h, fine_width=max(3 l, 4 h, notch_width / 2 + 2 l))` "
        f"(the last term covers a band starting at the notch's corner); the cohesive cracks with "
        f"`fine_width=max({CZM_FINE_WIDTH:g}, 4 h)`. Gregoire's beam: depth 50, span 125, length 175, notch 25 "
        "deep and 2 wide, thickness 50 mm, h_coarse 10 mm, CMOD to 0.3 mm. Wu's beam (the geometry of Wu's public "
        "Abaqus input files, github.com/jianyingwu/pfczm-abaqus): 450 x 100 mm, span 450 (supports at the ends), "
        "notch 50 deep and 5 wide, thickness 100 mm, plane stress, h_coarse 12.5 mm, CMOD to 0.6 mm; and the same "
        "beam with a 2 mm notch (not Wu's geometry: it tells the notch's corners from the length scale). "
        "`pf l=.. h=..` "
        "are PF-CZM runs, `czm hordijk` the cohesive crack with Hordijk's law, `czm pf-law` the cohesive crack with "
        "the PF-CZM's exact Cornelissen law (case 3). Energies are the dissipated energy at the last CMOD all "
        "PF-CZM runs of the beam reached.",
        "",
    ]
    for beam, data in beams.items():
        sections += [f"### {BEAMS[beam]['title']}", "", beam_section(beam, data), ""]
    sections += [
        "![beams](beam_length_scale.png)",
        "",
        "## 3. Wu's beam against the cohesive crack",
        "",
        "The cohesive crack (`CohesiveCrackModel`, along the ligament) with Hordijk's law and with the PF-CZM's "
        "exact Cornelissen law (`PfczmShapeLaw` of the benchmark: `localized_cohesive_law` tabulated once in units "
        "ft and Gf / ft, interpolated with its slope by PCHIP, the area kept at Gf). Peak differences "
        "F_pf / F_czm - 1; the force difference is taken over the common CMOD range. The cohesive crack's mesh series "
        f"(h = {', '.join(f'{h:g}' for h in results['plan']['czm_sizes'])} mm) runs on {BEAMS[WU_BEAMS[0]]['short']}; "
        f"the other beams use h = {results['plan']['czm_sizes'][-1]:g} mm.",
        "",
    ]
    for beam in WU_BEAMS:
        sections += [f"### {BEAMS[beam]['title']}", "", crack_section(beams[beam]["crack"], beams[beam]["runs"]), ""]
    sections += [
        "![wu](wu_beam.png)",
        "",
        "## 4. Timing",
        "",
        "Wall time per run (one run at a time on the shared 2-core machine) and the number of unknowns "
        "(`model.build(specimen, params).n_free`).",
        "",
        timing_section(results),
        "",
        "## Reading",
        "",
        "In short (details below; claim (c) is the claim against Hordijk's crack, the rows against the PF-law "
        "crack show what remains without the law's shape):",
        "",
        verdict_table(results),
        "",
        reading_a(results["bar"], results["plan"]["bar_per_length"], results["history"]),
        "",
        reading_b(beams),
        "",
        reading_c(beams),
        "",
        notes(results),
        "",
        "## References",
        "",
        "- J.-Y. Wu (2017), A unified phase-field theory for the mechanics of damage and quasi-brittle failure, "
        "J. Mech. Phys. Solids 103:72-99.",
        "- J.-Y. Wu, V. P. Nguyen (2018), A length scale insensitive phase-field damage model for brittle fracture, "
        "J. Mech. Phys. Solids 119:20-42 (the softening shapes).",
        "- Wu's public Abaqus implementation and input files: https://github.com/jianyingwu/pfczm-abaqus (the "
        "geometry of Wu's beam).",
        "",
    ]
    return "\n".join(sections)


# ---------------------------------------------------------------------------------------------------------- main
def machine() -> str:
    """The CPU model and count."""
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} logical CPUs, {platform.system()} {platform.release()}"


def plan_of(results) -> Plan:
    """The plan a results dict was measured with."""
    return Plan(**{k: tuple(v) if isinstance(v, list) else v for k, v in results["plan"].items()})


def summarise(results):
    """(Re)compute the summaries of cases 2 and 3 from the runs kept in ``results`` (in place)."""
    plan = plan_of(results)
    for beam, data in results["beams"].items():
        data["summary"] = length_scale_summary(beam, data["runs"], plan)
        data["crack"] = crack_summary(data["runs"], plan)


def measure(plan, quick) -> dict:
    """Run every case; the results as a JSON-ready dict."""
    start = time.perf_counter()
    print("case 1: the 1D bar", flush=True)
    results = {"plan": asdict(plan), "material": MATERIAL, "bar": bar_case(plan), "history": history_case(plan),
               "beams": {}}
    for beam in BEAMS:
        print(f"cases 2-3: {BEAMS[beam]['title']}", flush=True)
        results["beams"][beam] = {"runs": beam_runs(beam, plan), "per_length": plan.beam_per_length,
                                  "mesh_l": plan.mesh_check[0], "target": BEAMS[beam]["target"]}
    summarise(results)
    command = "python benchmarks/pfczm.py" + (" --quick" if quick else "")
    results["meta"] = {"command": command, "date": datetime.date.today().isoformat(), "machine": machine(),
                       "fracid": getattr(fracid, "__version__", "?"), "numpy": np.__version__,
                       "python": platform.python_version(), "quick": quick,
                       "total_wall_time": time.perf_counter() - start}
    return results


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/pfczm"), help="output directory (default docs/pfczm)")
    parser.add_argument("--quick", action="store_true", help="coarse meshes: a smoke test of a minute or two")
    parser.add_argument("--figures-only", action="store_true", help="redraw the figures and README from results.json")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "results.json"
    if args.figures_only:
        results = json.loads(path.read_text())
        summarise(results)
    else:
        results = measure(QUICK if args.quick else FULL, args.quick)
    path.write_text(json.dumps(results))
    written = write_figures(results, args.out)
    (args.out / "README.md").write_text(readme(results))
    print(f"total wall time {results['meta']['total_wall_time']:.0f} s; wrote {path}, "
          f"{', '.join(written)} and README.md in {args.out}", flush=True)


if __name__ == "__main__":
    main()
