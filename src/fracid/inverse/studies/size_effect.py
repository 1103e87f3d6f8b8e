"""Size effect on the nominal strength: nominal strengths of specimens and a series of forward runs.

:func:`nominal_strength` converts a force to a nominal strength, :func:`size_effect_series` computes the
nominal strengths with the model for a series of specimens, and :func:`compare_size_effect` sets them
against measured ones, with Bazant's size effect law fitted to each
(:mod:`fracid.inverse.studies.size_effect_law`).

Units: sizes D and D0 [mm], forces [N], nominal strengths and B f_t [MPa].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.inverse.studies.size_effect_law import fit_size_effect
from fracid.models import ConvergenceError
from fracid.runtime.batch import run_batch

__all__ = [
    "SizeEffectComparison",
    "SizeEffectSeries",
    "compare_size_effect",
    "nominal_strength",
    "size_effect_series",
    "specimen_size",
]


# ----------------------------------------------------------------------------------------------
# nominal strength of the specimens


def _size_and_section(specimen) -> tuple[float, float]:
    """Characteristic size D [mm] and the area A_N [mm^2] with sigma_N = F / A_N, as the specimen
    declares them (``characteristic_size``, ``nominal_section``)."""
    try:
        return float(specimen.characteristic_size), float(specimen.nominal_section)
    except AttributeError:
        raise TypeError(f"no nominal strength is defined for a {type(specimen).__name__} (it declares no "
                        "characteristic_size and nominal_section); use a DogBone, a NotchedBeam or a BarWithWeakZone") from None


def has_nominal_strength(specimen) -> bool:
    """Whether ``specimen`` declares a characteristic size and a nominal section (a mesh specimen does not)."""
    return hasattr(specimen, "characteristic_size") and hasattr(specimen, "nominal_section")


def specimen_size(specimen) -> float:
    """Characteristic size D [mm]: ``size`` of a DogBone, ``depth`` of a NotchedBeam, ``length`` of a bar.

    Raises
    ------
    TypeError
        For any other specimen class.
    """
    return float(_size_and_section(specimen)[0])


def nominal_strength(specimen, force):
    """Nominal strength sigma_N [MPa] of ``specimen`` under the force ``force`` [N].

    DogBone: F / (0.6 D t), the notched section. NotchedBeam: 3 F S / (2 b D^2). BarWithWeakZone:
    F / area, the section outside the weak zone.

    Parameters
    ----------
    specimen : DogBone, NotchedBeam or BarWithWeakZone
    force : float or array_like
        Force [N] (e.g. the peak force of a run).

    Returns
    -------
    float or ndarray
        Nominal strength [MPa], of the shape of ``force``.

    Raises
    ------
    TypeError
        For any other specimen class.
    """
    return np.asarray(force, dtype=float) / _size_and_section(specimen)[1]


# ----------------------------------------------------------------------------------------------
# a series of forward runs


@dataclass
class SizeEffectSeries:
    """Forward runs of a series of specimens of several sizes, in the order of the specimens.

    Attributes
    ----------
    sizes : ndarray
        Characteristic size D of every specimen [mm] (see :func:`specimen_size`).
    peak_force : ndarray
        Largest force of every run [N]; nan for a failed run.
    sigma_N : ndarray
        Nominal strength at the peak [MPa]; nan for a failed run.
    status : list of str
        ``"ok"`` or ``"failed"``.
    errors : list of str
        The failure's message (``"ConvergenceError: ..."``), ``""`` for a run that succeeded.
    curves : list of (ndarray, ndarray)
        (control [mm], force [N]) of every run; for a run that failed to converge, the part that
        converged (empty arrays when nothing did).
    """

    sizes: np.ndarray
    peak_force: np.ndarray
    sigma_N: np.ndarray
    status: list
    errors: list
    curves: list

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of the runs that succeeded."""
        return np.array([s == "ok" for s in self.status], dtype=bool)


def size_effect_series(params, specimens, *, model=None, executor=None, progress=None) -> SizeEffectSeries:
    """One forward run per specimen; peaks and nominal strengths by size.

    Parameters
    ----------
    params
        Parameters of ``model`` (e.g. :class:`~fracid.fem.material.parameters.DamageParameters`).
    specimens : sequence
        DogBone, NotchedBeam or BarWithWeakZone objects (any order; results keep it).
    model : forward model, optional
        Any model of :mod:`fracid.models`; gradient damage if None.
    executor : Executor, optional
        From :func:`fracid.runtime.executors.make_executor`; the runs go to it together. None: one after
        the other in this process.
    progress : None, bool or callable
        As in :func:`fracid.runtime.batch.run_batch`.

    Returns
    -------
    SizeEffectSeries
        A run that fails (ConvergenceError, ValueError, or any other exception in a worker) is
        recorded with status ``"failed"`` and its error; the others go on.

    Raises
    ------
    TypeError
        For a specimen without a defined nominal strength (checked before any run).
    """
    from fracid.models import DamageModel

    model = model if model is not None else DamageModel("gradient")
    specimens = list(specimens)
    geometry = [_size_and_section(s) for s in specimens]  # fail before hours of runs, not after
    tasks = [(specimen, params, model) for specimen in specimens]
    records = run_batch(_run_one_size, tasks, executor=executor if executor is not None else "serial",
                        progress=progress)
    peaks = np.array([r.get("peak_force", np.nan) for r in records], dtype=float)
    return SizeEffectSeries(
        sizes=np.array([D for D, _ in geometry], dtype=float),
        peak_force=peaks,
        sigma_N=peaks / np.array([area for _, area in geometry], dtype=float),
        status=[str(r["status"]) for r in records],
        errors=[str(r.get("error", "")) for r in records],
        curves=[(np.asarray(r.get("control", ())), np.asarray(r.get("force", ()))) for r in records],
    )


def _run_one_size(task) -> dict:
    """Worker side (module level, so process pools can pickle it): one run as a record."""
    specimen, params, model = task
    try:
        result = model.simulate(specimen, params, field_steps=None)
    except ConvergenceError as err:
        partial = err.partial
        return {"status": "failed", "error": f"ConvergenceError: {err}", "control": partial.control,
                "force": partial.force}
    except ValueError as err:
        return {"status": "failed", "error": f"ValueError: {err}"}
    return {"status": "ok", "peak_force": result.peak_force, "control": result.control, "force": result.force}


@dataclass
class SizeEffectComparison:
    """Computed and measured nominal strengths over a size series, with Bazant's law fitted to each.

    Attributes
    ----------
    series : SizeEffectSeries
        The forward runs, one per size (sorted).
    computed : SizeEffectFit or None
        Fit of the computed strengths (None with fewer than three successful runs).
    sigma_measured : ndarray
        Mean measured nominal strength per size [MPa] (nan where no test).
    measured : SizeEffectFit or None
        Fit of the measured strengths (None with fewer than three sizes tested).
    calibrated : ndarray of bool
        Sizes whose tests were used for calibration.
    """

    series: SizeEffectSeries
    computed: object
    sigma_measured: np.ndarray
    measured: object
    calibrated: np.ndarray

    def figure_arguments(self) -> dict:
        """Keyword arguments of :func:`fracid.report.size_effect_figure.size_effect_figure`."""
        have = np.isfinite(self.sigma_measured).any()
        return {"sizes": self.series.sizes, "sigma_computed": self.series.sigma_N, "fit": self.computed,
                "sigma_measured": self.sigma_measured if have else None, "calibrated": self.calibrated}

    def save(self, directory) -> list:
        """size_effect.csv (size, peak, strength) and size_effect.json (the fits) in ``directory``."""
        import json
        from pathlib import Path

        directory = Path(directory)
        s = self.series
        np.savetxt(directory / "size_effect.csv", np.column_stack([s.sizes, s.peak_force, s.sigma_N]),
                   delimiter=",", header="D_mm,peak_force_N,nominal_strength_MPa", comments="")
        fits = {"computed": self.computed, "measured": self.measured}
        (directory / "size_effect.json").write_text(
            json.dumps({k: (v.as_dict() if v is not None else None) for k, v in fits.items()}, indent=1))
        return [directory / "size_effect.csv", directory / "size_effect.json"]


def compare_size_effect(params, specimens: dict, measured=None, calibrated=(), *, model=None, executor=None,
                        progress=None) -> SizeEffectComparison | None:
    """Nominal strength at ``params`` over a size series, against the measured one, with Bazant fits.

    Parameters
    ----------
    params
        Model parameters (e.g. the identified ones).
    specimens : dict {D: specimen}
        One specimen per size D [mm].
    measured : dict {D: list of float}, optional
        Measured nominal strengths per size [MPa] (several tests per size are averaged).
    calibrated : collection of float
        Sizes whose tests were used for calibration (marked in the figure).
    model, executor, progress
        As in :func:`size_effect_series`.

    Returns
    -------
    SizeEffectComparison or None
        None when fewer than three sizes are given.
    """
    if len(specimens) < 3:
        return None
    measured = measured or {}
    order = sorted(specimens)
    series = size_effect_series(params, [specimens[D] for D in order], model=model, executor=executor,
                                progress=progress)
    computed = fit_size_effect(series.sizes[series.ok], series.sigma_N[series.ok]) if series.ok.sum() >= 3 else None
    sigma = np.array([np.mean(measured[D]) if D in measured else np.nan for D in order])
    have = np.isfinite(sigma)
    fit_measured = fit_size_effect(np.array(order)[have], sigma[have]) if have.sum() >= 3 else None
    return SizeEffectComparison(series, computed, sigma, fit_measured, np.array([D in calibrated for D in order]))
