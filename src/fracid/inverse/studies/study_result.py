"""What a study computed: :class:`StudyResult` (saved as study.json, verdict.txt and CSV tables) and the
predictions of data not used for calibration (:func:`predict`)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fracid.inverse.core.misfit import objective
from fracid.inverse.core.sensitivity import ForwardRunError, exact_sensitivity
from fracid.inverse.studies.verdict import DataDescription
from fracid.store.tables import without_nan, write_csv_table


@dataclass
class Prediction:
    """Data not used for calibration, computed at the estimate.

    Attributes
    ----------
    name : str
    control, y_exp, std_exp : ndarray
        The held-out data.
    y, std : ndarray
        Computed at the estimate, and its standard deviation from the estimate's covariance
        (S C S^T, linearised).
    status : str
        "ok" or the failure reason.
    """

    name: str
    control: np.ndarray
    y_exp: np.ndarray
    std_exp: np.ndarray
    y: np.ndarray
    std: np.ndarray
    status: str = "ok"

    @property
    def relative_rms(self) -> float:
        """RMS of (computed - measured) / max ``|measured|``."""
        return float(np.sqrt(np.mean((self.y - self.y_exp) ** 2)) / np.max(np.abs(self.y_exp)))

    @property
    def chi2_per_point(self) -> float:
        """Mean of ((computed - measured) / sqrt(std_exp^2 + std^2))^2: about 1 when the prediction holds."""
        return float(np.mean((self.y - self.y_exp) ** 2 / (self.std_exp**2 + self.std**2)))


def predict(operator, data, x, C, *, executor=None, name="prediction") -> Prediction:
    """Compute held-out data at the estimate x with the uncertainty propagated from C."""
    nan = np.full(data.n_y, np.nan)
    try:
        evaluate, sensitivity = exact_sensitivity(operator)
        y, S, _ = sensitivity(evaluate, x, None, executor)
    except ForwardRunError as err:
        return Prediction(name, data.control, data.y, data.std, nan, nan, status=str(err))
    std = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", S, C, S), 0.0))
    return Prediction(name, data.control, data.y, data.std, y, std)


def estimate_objective(ident, y, C):
    """(x, f): the identification's estimate and its objective (y - y_fit)^T C^-1 (y - y_fit), the centre of
    the objective maps and valley; None when the run at the estimate failed."""
    y_fit = np.asarray(ident.y_fit, float) if ident.y_fit is not None else None
    if y_fit is None or not np.all(np.isfinite(y_fit)):
        return None
    return np.asarray(ident.x, float), float(objective(y, C, y_fit)[0])


def describe_data(operator) -> DataDescription:
    """Number of specimens with a force curve and whether local data are present."""
    force = [getattr(obs, "measures_force", False) for obs in operator.observations]  # a kind that does not say measures no force
    sizes = {obs.run_key[0] for obs, is_force in zip(operator.observations, force) if is_force}
    return DataDescription(sizes=max(len(sizes), 1), local=not all(force))


@dataclass
class StudyResult:
    """Everything a study computed; :meth:`save` writes it, :func:`fracid.report.study` reports it.

    ``posterior`` is the sampled :class:`~fracid.inverse.sampling.posterior_result.PosteriorResult` when the study was
    asked for one and it could be sampled, None otherwise.
    """

    identification: object
    sensitivity: object
    maps: list
    valley_extent: np.ndarray
    multi_start: object
    stability: object
    predictions: list
    verdict: object
    timings: dict = field(default_factory=dict)
    runs: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    posterior: object = None

    @property
    def names(self) -> list:
        return list(self.identification.names)

    def runs_text(self) -> str:
        """One line per stage: forward runs and how many failed."""
        parts = [f"{stage} {total} ({failed} failed)" for stage, (total, failed) in self.runs.items()]
        return "Forward runs: " + ", ".join(parts) if parts else ""

    def summary(self) -> str:
        """The text of verdict.txt: the verdict per parameter, the warnings of the identification (a poor fit,
        estimates at a bound, no convergence, failed runs: those stderr and report.html give), the posterior,
        the forward runs, the status, the notes and the predictions."""
        ident = self.identification
        lines = ["Verdict:", self.verdict.text(ident.units)]
        lines += [f"Warning: {text}" for text in ident.warnings()]
        if self.posterior is not None:
            first = self.posterior.summary().splitlines()[0]
            if not self.posterior.sampling_failed:
                lines.append(f"Verdict measure: {self.verdict.measure} (std-equivalent: half-width / 1.645)")
            lines.append(f"P{first[1:]}")
        if self.runs:
            lines.append(self.runs_text())
        if getattr(ident, "status", ""):
            lines.append(f"{ident.status_label}: {ident.status}")
        lines += [f"Note: {note}" for note in self.notes]
        if self.predictions:
            lines.append("Predictions of data not used for calibration:")
            lines += [f"  {p.name}: RMS {p.relative_rms:.1%} of the peak, chi2/point {p.chi2_per_point:.2f}"
                      for p in self.predictions if p.status == "ok"]
            lines += [f"  {p.name}: failed ({p.status})" for p in self.predictions if p.status != "ok"]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        ident = self.identification.to_dict()
        out = {"identification": ident, "verdict": self.verdict.as_dict(),
               "valley_extent": dict(zip(self.names, self.valley_extent.tolist())),
               "maps": [{"pair": list(m.names), "correlation_in_valley": m.correlation, "valley_points": int(m.valley.sum()),
                         "level": m.level} for m in self.maps],
               "timings_seconds": self.timings,
               "runs": {stage: {"runs": total, "failed": failed} for stage, (total, failed) in self.runs.items()},
               "notes": list(self.notes)}
        if self.sensitivity is not None:
            out["sensitivity"] = {"normalised": self.sensitivity.normalised.tolist(),
                                  "variance_share": self.sensitivity.variance_share.tolist(), "x": self.sensitivity.x.tolist()}
        if self.multi_start is not None:
            ms = self.multi_start
            out["multi_start"] = {"starts": ms.starts.tolist(), "ends": ms.ends.tolist(), "std": ms.stds.tolist(),
                                  "f": ms.f.tolist(), "distance_in_std": ms.distance.tolist()}
        if self.stability is not None:
            st = self.stability
            out["stability"] = {"estimates": st.estimates.tolist(), "errors": st.errors, "seed": st.seed,
                                "noise_level": st.noise_level, "scatter": st.scatter.tolist(),
                                "relative_scatter": st.relative_scatter.tolist(),
                                "amplification": st.amplification.tolist()}
        out["predictions"] = [{"name": p.name, "control": p.control.tolist(), "y_exp": p.y_exp.tolist(),
                               "y": p.y.tolist(), "std": p.std.tolist(), "status": p.status,
                               "relative_rms": p.relative_rms if p.status == "ok" else None,
                               "chi2_per_point": p.chi2_per_point if p.status == "ok" else None}
                              for p in self.predictions]
        if self.posterior is not None:
            out["posterior"] = {**self.posterior.to_dict(), "interval_90_label": "equal-tailed 90 % credible "
                                "interval (weighted 5 % and 95 % quantiles of the importance-weighted draws)"}
        return without_nan(out)

    def save(self, directory) -> Path:
        """Write study.json, verdict.txt and the CSV tables into ``directory``."""
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        (directory / "study.json").write_text(json.dumps(self.to_dict(), indent=1))
        (directory / "verdict.txt").write_text(self.summary() + "\n")
        ident = self.identification
        population = ident.population()
        if population.get("points") is not None:
            points, f = np.asarray(population["points"], float), np.asarray(population["f"], float)
            status = population.get("status") or ["ok" if np.isfinite(v) else "failed" for v in f]
            errors = population.get("errors") or [""] * len(f)
            # a failed run has no objective: an empty cell and its status, not "inf"
            write_csv_table(directory / "population.csv", [*self.names, "f", "status", "error"],
                            ([*x, v, s, e or ""] for x, v, s, e in zip(points.tolist(), f.tolist(), status, errors)))
        if self.sensitivity is not None:
            table = np.column_stack([self.sensitivity.normalised, self.sensitivity.variance_share])
            cols = [f"S_{n}" for n in self.names] + [f"variance_removed_{n}" for n in self.names]
            write_csv_table(directory / "sensitivity.csv", cols, table.tolist())
        if self.stability is not None:
            write_csv_table(directory / "stability.csv", self.names, np.asarray(self.stability.estimates).tolist())
        if self.posterior is not None:
            self.posterior.save_csv(directory / "posterior.csv")
        return directory


__all__ = ["Prediction", "StudyResult", "describe_data", "estimate_objective", "predict"]
