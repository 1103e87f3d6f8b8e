"""The inverse method as an argument: the interface a method meets and the result every method returns.

:func:`fracid.inverse.methods.strategy.identify` takes any object that meets :class:`InverseMethod`; without
one, the registry's default (:data:`fracid.inverse.methods.registry.DEFAULT_METHOD`). A method returns a
:class:`MethodResult`: the estimate, its covariance and the fit, which every method has, and the stages it
ran (``stages``), the kind of record each left (``stage_records``: a population, a path of estimates or
generic, :mod:`fracid.inverse.core.stage_records`), their forward runs (``runs``) and what they recorded
(``records``), by stage name. Reports, studies and warnings read those by the names and kinds the result
declares, so another method plugs in without changes to them."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from fracid.inverse.core.estimate import GaussianEstimate
from fracid.inverse.core.diagnostics import diagnostic_warnings, diagnostics_lines, fit_diagnostics
from fracid.inverse.core.fit_status import fit_action, status_word, unidentified
from fracid.inverse.core.problem_check import check_problem
from fracid.inverse.core.result_fields import (at_bounds, estimate_curves, identification_bounds, observed_fields,
                                              result_fields)
from fracid.inverse.core.stage_records import StageRecords

#: RMS fit error [% of the measured peak] above which a fit is reported as poor
POOR_FIT_PERCENT = 10.0
#: RMS of the residual in units of the data's std above which the misfit is reported as huge (a good fit
#: is about 1: the residuals are the scatter of the data)
POOR_FIT_STD = 10.0


@runtime_checkable
class InverseMethod(Protocol):
    """What :func:`~fracid.inverse.methods.strategy.identify` calls to identify parameters from data.

    Attributes
    ----------
    name : str
        Names the method in results (``MethodResult.method``) and reports.

    Calling the method
    ``method(operator, y_exp, C_exp, space, *, executor, store, progress, retry_failed, blocks, notes)``
    returns a :class:`MethodResult`:

    operator : ForwardOperator
        Computes the observations at a parameter vector x (``operator(x)`` gives a run record with
        ``ok``, ``y`` and ``error``); its ``names`` are the space's.
    y_exp : ndarray, shape (n,)
        Measured values (units of the observations: N for forces, mm for widths).
    C_exp : Covariance
        Their covariance (squared units of y): what :func:`check_problem` returns from an (n, n) array or
        a :class:`~fracid.data.covariance_matrix.Covariance`.
    space : ParameterSpace
        Names and bounds of the identified parameters (units of the parameters).
    executor : Executor or None
        Runs forward runs in parallel (None: in this process).
    store : RunStore or None
        The persistent run store (wrap the operator in :class:`~fracid.inverse.core.runs.StoredOperator`).
    progress : bool or None
        Progress bars (None: on a terminal).
    retry_failed : bool
        Run again the runs stored as failed.
    blocks, notes : sequence
        Data blocks ``(name, start, stop)`` and notes of the data, to be kept in the result
        (:func:`result_fields` fills them).

    A method may declare ``stages`` (stage name -> label) and ``stage_records`` (stage name -> kind of
    record) as class attributes: the command's plan, the report and the studies read them.

    A failed forward run should be recorded (``runs[stage + "_failed"]``), not raised, whenever the
    method can still give an estimate.
    """

    name: str

    def __call__(self, operator, y_exp, C_exp, space, *, executor=None, store=None, progress=None,
                 retry_failed=False, blocks=(), notes=()) -> MethodResult: ...


@dataclass
class MethodResult(GaussianEstimate, StageRecords):
    """Identified parameters with their uncertainty, the fit and how they were obtained: what every
    :class:`InverseMethod` returns.

    Attributes
    ----------
    names : list of str
    x, C : ndarray
        Estimate and covariance (units of the parameters).
    y_exp, y_fit, std_exp : ndarray
        Measured values, values computed at the estimate, and the measurement standard deviations.
    blocks : list of (name, start, stop)
        Data blocks in y.
    runs : dict
        Forward-run counters by stage: ``runs[stage]`` the stage's forward runs,
        ``runs[stage + "_failed"]`` its failed ones, ``runs[stage + "_" + counter]`` any other counter
        (``computed``, ``reused``, ``iterations``, ...); ``wall_seconds`` the wall time [s].
    notes : list of str
        Rules applied to the data and the methods' settings.
    converged : bool
        Whether the stage that gave the estimate says it converged.
    units : dict
        Unit of every parameter.
    status : str
        What the stage that gave the estimate says, beginning with a word of
        :data:`~fracid.inverse.core.fit_status.STATUS_ACTIONS` (``"converged"``, ``"converged along a valley"``,
        ``"stopped but stable"``, ``"not converged"``, ``"failed"``); ``result.json`` adds the word and its
        action (``status_word``, ``status_action``).
    at_bound : list of str
        Parameters whose estimate lies on a bound.
    bounds : (list, list)
        Lower and upper bounds the estimate was kept in.
    method : str
        ``name`` of the method.
    stages : dict of str -> str
        The stages the method ran, in order: name (the key of their runs and records) -> label used
        in text (e.g. ``{"knn": "KNN", "kalman": "Kalman filter"}``). The last gave the estimate.
    stage_records : dict of str -> str
        The kind of record each stage left (:mod:`fracid.inverse.core.stage_records`: ``"population"``,
        ``"path"``, ``"generic"``; a stage not named here is generic): the report shows it by its kind.
    records : dict of str -> object
        What a stage recorded, by stage name (JSON-serialisable values, of the stage's kind;
        :meth:`~fracid.inverse.core.stage_records.StageRecords.record` reads them).
    control : ndarray or None
        Control value of every entry of y [mm] (the observations' ``control_points``; None if unknown).
    control_names : list of str
        The control quantity of each block (e.g. ``"cmod"``, ``"deflection"``; empty if unknown).
    quantities : list of str
        The observed quantity of each block (``"force"``, ``"fpz_width"``, ...; empty if unknown).
    provenance : dict
        How the result was obtained (:func:`fracid.store.provenance.collect`: version, command line,
        configuration, data files and their SHA-256, specimen, mesh, machine, date); empty if not given.
    error_terms : dict
        The error terms added to the data covariance (the mesh's discretisation error, the model's own
        error: :func:`fracid.inverse.likelihood.record.terms_record`): per block the measurement,
        discretisation and model-error std; empty when none was added (``x`` and ``C`` are then the
        measurement's alone; with them, ``C`` holds them and ``std_exp`` stays the measurement std).
    curves : list
        The forward run's own curve at the estimate, per block: ``{"control": [mm], "values": [unit of the
        block]}`` at every step of the run up to the block's last control value, or None (a block without a
        curve, a displacement field); empty when unknown (an older result). The report draws it, and the fit
        diagnostics judge the computed slope and peak on it (:func:`estimate_curves`).
    """

    names: list
    x: np.ndarray
    C: np.ndarray
    y_exp: np.ndarray
    y_fit: np.ndarray
    std_exp: np.ndarray
    blocks: list = field(default_factory=list)
    runs: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    converged: bool = False
    units: dict = field(default_factory=dict)
    status: str = ""
    at_bound: list = field(default_factory=list)
    bounds: tuple = ()
    method: str = ""
    stages: dict = field(default_factory=dict)
    stage_records: dict = field(default_factory=dict)
    records: dict = field(default_factory=dict)
    control: object = None
    control_names: list = field(default_factory=list)
    quantities: list = field(default_factory=list)
    provenance: dict = field(default_factory=dict)
    error_terms: dict = field(default_factory=dict)
    curves: list = field(default_factory=list)

    @property
    def rms_percent(self) -> float:
        """RMS of (measured - computed) over all the data in per cent of the largest ``|measured|`` value (NaN if
        not computed): the poor-fit bound reads it. With blocks of different units it is dominated by the largest
        (a force in N beside widths in mm); :meth:`block_rms` gives each block in its own unit."""
        y_exp, y_fit = np.asarray(self.y_exp, float), np.asarray(self.y_fit, float)
        scale = np.max(np.abs(y_exp)) if y_exp.size else 0.0
        rms = np.sqrt(np.mean((y_fit - y_exp) ** 2))
        return float(100 * rms / scale) if scale > 0 else float("nan")

    def block_rms(self) -> list:
        """Per data block: ``name``, ``n`` (its points), ``rms`` of (computed - measured) in the block's own
        unit, ``unit`` ("N" for a force, "mm" otherwise) and ``percent`` (the rms in % of the block's largest
        ``|measured|``; NaN if not computed)."""
        y_exp, y_fit = np.asarray(self.y_exp, float), np.asarray(self.y_fit, float)
        blocks = [(str(b[0]), int(b[1]), int(b[2])) for b in (self.blocks or [])] or [("data", 0, y_exp.size)]
        quantities = list(self.quantities or [])
        rows = []
        for k, (name, start, stop) in enumerate(blocks):
            measured = y_exp[start:stop]
            residual = (y_fit[start:stop] - measured) if y_fit.size == y_exp.size else np.full(stop - start, np.nan)
            rms = float(np.sqrt(np.mean(residual**2))) if residual.size else float("nan")  # NaN if a point is
            scale = float(np.max(np.abs(measured))) if measured.size else 0.0
            unit = "N" if (quantities[k] if k < len(quantities) else "force") == "force" else "mm"
            rows.append({"name": name, "n": stop - start, "rms": rms, "unit": unit,
                         "percent": 100.0 * rms / scale if scale > 0 else float("nan")})
        return rows

    def rms_text(self) -> str:
        """The fit error in words: each block's RMS in its own unit and in % of its measured peak."""
        rows = self.block_rms()
        if len(rows) == 1:
            return f"RMS error {rows[0]['percent']:.3g} % of the measured peak ({rows[0]['rms']:.3g} {rows[0]['unit']})"
        return "RMS error " + ", ".join(f"{r['name']} {r['rms']:.3g} {r['unit']} ({r['percent']:.3g} % of its peak)"
                                         for r in rows)

    @property
    def misfit_std(self) -> float:
        """RMS of (computed - measured) / std over the points with a std > 0: the misfit in units of the
        data's standard deviation (about 1 for a fit within the scatter; NaN if not computed)."""
        std = np.asarray(self.std_exp, float)
        residual = np.asarray(self.y_fit, float) - np.asarray(self.y_exp, float)
        scaled = residual[std > 0] / std[std > 0]
        return float(np.sqrt(np.mean(scaled**2))) if scaled.size else float("nan")

    @property
    def status_action(self) -> str:
        """What to do after a fit of this status (:func:`~fracid.inverse.core.fit_status.fit_action`: qualified when
        a parameter is not identified)."""
        return fit_action(self.status, bool(unidentified(self.names, self.x, self.C, self.bounds or None)))

    @property
    def status_label(self) -> str:
        """Label of the stage that gave the estimate (and the status), e.g. ``"Kalman filter"``."""
        labels = list((self.stages or {}).values())
        return labels[-1] if labels else (self.method or "identification")

    def stage_runs(self) -> dict:
        """Counters of every stage: ``{stage: {"runs": .., "failed": .., other counters}}``."""
        runs = self.runs or {}
        out = {}
        for stage in self.stages or {}:
            counters = {"runs": runs.get(stage, 0), "failed": runs.get(f"{stage}_failed", 0)}
            counters.update({key[len(stage) + 1:]: value for key, value in runs.items()
                             if key.startswith(f"{stage}_") and key != f"{stage}_failed"})
            out[stage] = counters
        return out

    @property
    def forward_runs(self) -> int:
        """Forward runs of all stages."""
        return int(sum(counters["runs"] for counters in self.stage_runs().values()))

    def failed_runs_text(self) -> str:
        """The failed forward runs per stage, in words (the warning's)."""
        return ", ".join(f"{c['failed']} of {c['runs']} in the {self.stages[stage]} stage"
                         for stage, c in self.stage_runs().items())

    def diagnostics(self, control=None) -> dict:
        """Elastic slopes, peaks and the worst residual of the fit
        (:func:`~fracid.inverse.core.diagnostics.fit_diagnostics`), at ``control`` [mm] or the result's own."""
        control = self.control if control is None else control
        return fit_diagnostics(None if control is None else np.asarray(control, float), self.y_exp, self.std_exp,
                               self.y_fit, self.blocks, self.quantities, self.curves)

    def warnings(self, poor_fit_percent: float = POOR_FIT_PERCENT, poor_fit_std: float = POOR_FIT_STD, *,
                 control=None) -> list[str]:
        """What a user must know before trusting the result: a non-finite or poor fit (in % of the peak, or
        in units of the data's std), an elastic slope or a peak off the data's
        (:mod:`fracid.inverse.core.diagnostics`, at ``control`` [mm] or the result's own), estimates at a bound,
        a method that did not converge or stopped (with what to do), parameters the data do not identify
        (:func:`~fracid.inverse.core.fit_status.unidentified`), failed forward runs."""
        out = []
        rms = self.rms_percent
        if not np.all(np.isfinite(np.asarray(self.x, float))) or not math.isfinite(rms):
            out.append("the result is not finite: no forward run succeeded at the estimate")
        else:
            out += self._fit_warnings(rms, poor_fit_percent, poor_fit_std)
            out += diagnostic_warnings(self.diagnostics(control))
        if self.at_bound:
            where = ", ".join(f"{n} = {v:.6g}" for n, v in zip(self.names, self.x) if n in self.at_bound)
            out.append(f"estimate at a bound of [identify.bounds]: {where}; the data pull it outside the bounds "
                       "(widen them if that is physical); its std is the curvature there, not a spread")
        if self.status and not self.converged:
            action = self.status_action
            out.append(f"{self.status_label} {self.status}" + (f". What to do: {action}" if action else ""))
        out += unidentified(self.names, self.x, self.C, self.bounds or None)
        if any(c["failed"] for c in self.stage_runs().values()):
            out.append(f"failed forward runs: {self.failed_runs_text()} (each with its reason, in the result)")
        return out

    def _fit_warnings(self, rms: float, poor_fit_percent: float, poor_fit_std: float) -> list[str]:
        out = []
        if rms > poor_fit_percent:
            out.append(f"the fit is poor: RMS error {rms:.3g} % of the measured peak (above {poor_fit_percent:g} %). "
                       "Check the data's units (force_unit, control_unit) and sign, the bounds and the model")
        misfit = self.misfit_std
        if misfit > poor_fit_std:
            out.append(f"the misfit is {misfit:.3g} times the data's std (RMS of (computed - measured) / std; above "
                       f"{poor_fit_std:g}, where about 1 is a fit within the scatter): the model cannot follow the "
                       "data within their std. Usually the units are wrong (force_unit, control_unit), the specimen's "
                       "geometry is not that of the test (its size, [specimen]), or the std is too small (std, "
                       "relative_std of [[experiments]])")
        return out

    def summary(self) -> str:
        """The estimates (rounded to two significant digits of their std), the correlation, the status
        and the fit diagnostics, as printed by ``fracid identify``."""
        units = self.units
        lines = []
        for name, v, s in zip(self.names, self.x, self.std):
            flag = "  (at a bound: the std is not a spread)" if name in self.at_bound else ""
            lines.append(f"{name:>8} = {estimate_text(v, s)} {units.get(name, '')}{flag}".rstrip())
        lines.append("correlation:\n" + np.array2string(self.correlation, precision=3))
        if self.status:
            action = self.status_action
            lines.append(f"{self.status_label}: {self.status}" + (f"\n  what to do: {action}" if action else ""))
        if np.size(self.y_fit) == np.size(self.y_exp) and np.any(np.isfinite(np.asarray(self.y_fit, float))):
            lines.append("fit diagnostics:")
            lines += [f"  {line}" for line in diagnostics_lines(self.diagnostics())]
        if self.error_terms:
            lines.append("error terms in the data covariance (the std above include them):")
            lines += [f"  {line}" for line in self.error_terms.get("notes", [])]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        def plain(v):
            if isinstance(v, np.ndarray):
                return v.tolist()
            if isinstance(v, dict):
                return {k: plain(w) for k, w in v.items()}
            if isinstance(v, (list, tuple)):
                return [plain(w) for w in v]
            if isinstance(v, (np.floating, np.integer)):
                return v.item()
            return v

        d = {k: plain(getattr(self, k)) for k in self.__dataclass_fields__}
        d["std"], d["correlation"] = self.std.tolist(), self.correlation.tolist()
        d["f_fit"] = float(np.sum(((self.y_exp - self.y_fit) / self.std_exp) ** 2))
        d["diagnostics"] = plain(self.diagnostics())
        d["status_word"], d["status_action"] = status_word(self.status), self.status_action
        return json.loads(json.dumps(d, allow_nan=True).replace("Infinity", "null"))

    def save(self, path) -> Path:
        """Write the result as JSON."""
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1))
        return path

    @classmethod
    def from_dict(cls, d: dict) -> "MethodResult":
        """The result of :meth:`to_dict` (or of a ``result.json`` written by an older fracid: fields it
        lacks take their defaults). Derived entries (std, correlation, f_fit, diagnostics) are recomputed."""
        known = {name: value for name, value in d.items() if name in cls.__dataclass_fields__}
        for name in ("x", "C", "y_exp", "y_fit", "std_exp"):
            known[name] = np.array([np.nan if v is None else v for v in np.ravel(np.asarray(known[name], object))],
                                   float).reshape(np.shape(known[name]))
        if known.get("control") is not None:
            known["control"] = np.asarray(known["control"], float)
        known["blocks"] = [tuple(b) for b in known.get("blocks") or []]
        known["bounds"] = tuple(known.get("bounds") or ())
        return cls(**known)

    @classmethod
    def load(cls, path) -> "MethodResult":
        """Read a result written by :meth:`save` (``result.json``)."""
        return cls.from_dict(json.loads(Path(path).read_text(encoding="utf-8")))


def estimate_text(value: float, std: float) -> str:
    """``"value +- std"`` with the std rounded to two significant digits and the value to the same
    decimal place (e.g. ``"21.3 +- 4.2"``, ``"4.79e-05 +- 4.2e-06"``); six significant digits when
    the std is zero or not finite."""
    if not (math.isfinite(value) and math.isfinite(std) and std > 0):
        return f"{value:.6g} +- {std:.3g}"
    std = float(f"{std:.2g}")
    place = math.floor(math.log10(std)) - 1  # the decimal place of the std's second digit
    if value == 0 or 1e-3 <= abs(value) < 1e6:
        decimals = max(0, -place)
        return f"{round(value, -place):.{decimals}f} +- {std:.{decimals}f}"
    digits = max(2, math.floor(math.log10(abs(value))) - place + 1)
    return f"{value:.{digits - 1}e} +- {std:.1e}"


__all__ = ["POOR_FIT_PERCENT", "POOR_FIT_STD", "InverseMethod", "MethodResult", "at_bounds", "check_problem",
           "estimate_curves", "estimate_text", "identification_bounds", "observed_fields", "result_fields"]
