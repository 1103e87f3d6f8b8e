"""The result of a comparison of models by evidence (:func:`fracid.inverse.studies.model_comparison.compare`):
a :class:`ModelScore` per model and the :class:`ComparisonResult` that ranks them.

Units: RMS in % of the measured peak; chi^2, the MAP objective, AIC, BIC and the log evidences are
dimensionless (natural logarithms); parameters in their units.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fracid.inverse.studies.evidence import BOUND_MARGIN, BOUND_SHARE, TIE_SIGMAS, rank_by_evidence

#: the gap [log units] between a sampled log evidence and its Laplace value that a comparison warns about beyond
#: the Monte-Carlo error: a Gaussian approximation is off by a few tenths on a mildly skewed posterior, and a
#: log Bayes factor below 1 is "barely worth mentioning" (Jeffreys' scale)
LAPLACE_TOLERANCE = 1.0

__all__ = ["LAPLACE_TOLERANCE", "ComparisonResult", "ModelScore", "map_objective"]


def map_objective(result, chi2: float) -> float:
    """The inverse method's Bayesian objective at its estimate: chi^2 + (x - x0)^T C0^-1 (x - x0), with x0, C0
    the prior its search gave (:meth:`~fracid.inverse.core.stage_records.StageRecords.search_prior`); chi^2 alone
    for a result without one [-]."""
    prior = result.search_prior()
    if prior is None:
        return float(chi2)
    _, x0, C0 = prior
    d = np.asarray(result.x, float) - x0
    try:
        return float(chi2 + d @ np.linalg.solve(C0, d))
    except np.linalg.LinAlgError:
        return float("nan")


def _plain(value):
    """``value`` for JSON: floats that are not finite become None, arrays lists."""
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value.item() if isinstance(value, np.generic) else value


@dataclass
class ModelScore:
    """One model identified on the data, with its posterior and the numbers it is ranked by.

    Attributes
    ----------
    label, model : str
        The contender's label and the forward model's ``key``.
    names : list of str
        Its identified parameters (p = len(names)).
    identification : MethodResult
        Estimate ``x``, covariance ``C``, the fit ``y_fit``, the status.
    posterior : PosteriorResult or None
        The sampled posterior (None when every draw failed: ``posterior_status`` says why).
    verdict : Verdict
        Per parameter (:func:`~fracid.inverse.studies.verdict.parameter_verdicts`).
    n : int
        Data values.
    chi2, map_objective, log_likelihood, aic, bic : float
        At the estimate (:mod:`fracid.inverse.studies.evidence`) [-].
    log_evidence, log_evidence_error : float
        From the posterior's importance weights, and its Monte-Carlo standard error [-].
    log_evidence_laplace : float
        The Laplace approximation at the estimate [-] (NaN when it could not be formed).
    posterior_status : str
    bounds : (list, list)
        The prior's bounds (units of the parameters); ``log`` its log flags.
    seconds : float
        Wall time of the model's identification and sampling [s].
    log_evidence_wider : float
        The log evidence with the prior's box widened (:func:`~fracid.inverse.studies.evidence.widened`), by the
        closed form of :func:`~fracid.inverse.studies.evidence.prior_volume_shift` [-] (a lower bound when
        ``at_bounds`` exceeds :data:`~fracid.inverse.studies.evidence.BOUND_SHARE`).
    at_bounds : float
        The posterior's weight within :data:`~fracid.inverse.studies.evidence.BOUND_MARGIN` of a bound [-].
    rank : int
        1 for the largest log evidence, 0 when not ranked (:attr:`estimated` false); ``tied`` whether it ties with the first (:data:`TIE_SIGMAS`), ``delta``
        its log evidence less the first's (the log Bayes factor against the best) [-].
    """

    label: str
    model: str
    names: list
    identification: object
    posterior: object
    verdict: object
    n: int
    chi2: float
    map_objective: float
    log_likelihood: float
    aic: float
    bic: float
    log_evidence: float
    log_evidence_error: float
    log_evidence_laplace: float
    posterior_status: str
    bounds: tuple = ()
    log: list = field(default_factory=list)
    seconds: float = 0.0
    log_evidence_wider: float = float("nan")
    at_bounds: float = float("nan")
    rank: int = 0
    tied: bool = False
    delta: float = float("nan")

    @property
    def p(self) -> int:
        return len(self.names)

    @property
    def rms_percent(self) -> float:
        """RMS misfit at the estimate [% of the measured peak]."""
        return self.identification.rms_percent

    def parameters_text(self) -> str:
        """``name = value +- std unit`` of every identified parameter (the identification's Gaussian)."""
        units = self.identification.units or {}
        return "; ".join(f"{n} = {v:.4g} +- {s:.2g}" + (f" {units[n]}" if units.get(n, "-") != "-" else "")
                         for n, v, s in zip(self.names, self.identification.x, self.identification.std))

    @property
    def estimated(self) -> bool:
        """Whether the log evidence is estimated: sampled, finite, and its posterior's effective sample size at or
        above the sampler's floor (:func:`~fracid.inverse.sampling.posterior.ess_floor`; below it the weights
        sit on a few draws and neither log Z nor its Monte-Carlo error is credible). Only these are ranked."""
        post = self.posterior
        return post is not None and not post.sampling_failed and math.isfinite(self.log_evidence)

    def evidence_text(self) -> str:
        """``log Z +- error``, or why there is none (``not estimated (ESS 2 below the floor)``)."""
        if self.posterior is not None and self.posterior.sampling_failed:
            return f"not estimated (ESS {self.posterior.ess:.2g} below the floor)"
        if not self.estimated:
            return "n/a"
        return f"{self.log_evidence:.2f} +- {self.log_evidence_error:.2f}"

    def laplace_disagrees(self) -> bool:
        """Whether the sampled log evidence and the Laplace value differ by more than :data:`TIE_SIGMAS` times the
        Monte-Carlo error and :data:`LAPLACE_TOLERANCE` (one of them is off: a bound, a curved valley, too few
        draws)."""
        gap = abs(self.log_evidence - self.log_evidence_laplace)
        return (self.estimated and math.isfinite(gap)
                and gap > max(TIE_SIGMAS * self.log_evidence_error, LAPLACE_TOLERANCE))

    def sampling_text(self) -> str:
        """The posterior's effective sample size and whether it reached the target (``ESS 212``, ``ESS 40 (below
        the target)``, ``ESS 12 (below the floor)``), or ``not sampled``."""
        post = self.posterior
        if post is None:
            return "not sampled"
        state = "" if post.converged else " (below the floor)" if post.sampling_failed else " (below the target)"
        return f"ESS {post.ess:.0f}{state}"

    def line(self) -> str:
        """One line: estimate, RMS, chi^2, AIC, BIC, log evidences."""
        return (f"{self.parameters_text()}; RMS {self.rms_percent:.3g} %, chi2 {self.chi2:.4g}, AIC {self.aic:.4g}, "
                f"BIC {self.bic:.4g}, log Z {self.evidence_text()} (Laplace {self.log_evidence_laplace:.4g}); "
                f"{self.seconds:.0f} s")

    def to_dict(self) -> dict:
        """Plain values for JSON (None for numbers that are not finite)."""
        ident, post = self.identification, self.posterior
        return _plain({
            "rank": self.rank, "label": self.label, "model": self.model, "p": self.p, "n": self.n,
            "parameters": {n: {"value": float(v), "std": float(s), "unit": (ident.units or {}).get(n, "")}
                           for n, v, s in zip(self.names, ident.x, ident.std)},
            "covariance": np.asarray(ident.C, float), "bounds": list(self.bounds), "log": list(self.log),
            "identification_status": ident.status, "rms_percent": self.rms_percent, "chi2": self.chi2,
            "map_objective": self.map_objective, "log_likelihood": self.log_likelihood, "aic": self.aic,
            "bic": self.bic, "log_evidence": self.log_evidence if self.estimated else None,
            "log_evidence_sampled": self.log_evidence, "log_evidence_estimated": self.estimated,
            "log_evidence_error": self.log_evidence_error, "log_evidence_wider": self.log_evidence_wider,
            "posterior_at_bounds": self.at_bounds,
            "log_evidence_laplace": self.log_evidence_laplace,
            "delta_log_evidence": self.delta if self.estimated else None,
            "tied_with_best": self.tied, "posterior_status": self.posterior_status,
            "posterior": post.to_dict() if post is not None else None, "verdict": self.verdict.as_dict(),
            "y_fit": np.asarray(ident.y_fit, float), "forward_runs": ident.forward_runs,
            "stage_runs": ident.stage_runs(), "seconds": self.seconds})


#: the ranking table's columns (:meth:`ComparisonResult.table`)
TABLE_HEADER = ["rank", "model", "p", "RMS [% of peak]", "chi2", "MAP objective", "AIC", "BIC",
                "log Z (+- MC error)", "log Z Laplace", "delta log Z", "log Z, bounds widened", "posterior"]


@dataclass
class ComparisonResult:
    """Models ranked by log evidence on one data set.

    Attributes
    ----------
    data : ExperimentalData
        The data every model was identified on.
    scores : list of ModelScore
        Best (largest log evidence) first; those without one last.
    failures : dict
        label -> why the model could not be compared.
    settings : dict
        The sampler's settings, the verdict's tolerance, the inverse method, the prior sensitivity's ``widen``.
    setup_warnings : list of str
        What the set-up changed that the numbers depend on (e.g. bounds cut to the mesh): the first warnings.
    """

    data: object
    scores: list
    failures: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    setup_warnings: list = field(default_factory=list)

    @classmethod
    def ranked(cls, data, scores, failures, settings) -> "ComparisonResult":
        """The result with ``scores`` ranked (:func:`~fracid.inverse.studies.evidence.rank_by_evidence`)."""
        ranked = [s.log_evidence if s.estimated else float("nan") for s in scores]
        order, tied = rank_by_evidence(ranked, [s.log_evidence_error for s in scores])
        best = ranked[order[0]] if order else float("nan")
        for rank, i in enumerate(order, start=1):
            scores[i].rank = rank if scores[i].estimated else 0
            scores[i].tied, scores[i].delta = tied[i], ranked[i] - best
        return cls(data, [scores[i] for i in order], dict(failures), dict(settings))

    @property
    def best(self):
        """The score of the largest estimated log evidence (None when no model has one)."""
        return self.scores[0] if self.scores and self.scores[0].estimated else None

    def score(self, label: str) -> ModelScore:
        for s in self.scores:
            if s.label == label:
                return s
        raise KeyError(f"no model labelled {label!r}; labels: {[s.label for s in self.scores]}")

    def table(self) -> tuple[list, list]:
        """The ranking table's header and rows, formatted (:data:`TABLE_HEADER`)."""
        rows = [[(str(s.rank) + (" (tie)" if s.tied else "")) if s.rank else "not ranked", s.label, str(s.p),
                 f"{s.rms_percent:.2f}", f"{s.chi2:.4g}", f"{s.map_objective:.4g}", f"{s.aic:.4g}", f"{s.bic:.4g}",
                 s.evidence_text(), f"{s.log_evidence_laplace:.2f}", f"{s.delta:.2f}" if s.rank else "-",
                 f"{s.log_evidence_wider:.2f}" + (" (lower bound)" if s.at_bounds > BOUND_SHARE else "") if s.rank
                 else "-", s.sampling_text()] for s in self.scores]
        return list(TABLE_HEADER), rows

    def warnings(self) -> list[str]:
        """What makes the ranking incomplete or a number doubtful: the models not compared, those whose log evidence
        is not estimated (not ranked), and sampled log evidences far from their Laplace value. ``fracid compare``
        prints them on stderr and its report opens with them."""
        lines = list(self.setup_warnings)
        lines += [f"{label}: not compared, left out of the ranking ({why})" for label, why in self.failures.items()]
        lines += [f"{s.label}: log evidence not estimated, not ranked: " + (
            f"its posterior's effective sample size {s.posterior.ess:.2g} is below the sampler's floor, so log Z "
            f"({s.log_evidence:.3g}) and its Monte-Carlo error are not credible (more draws: --samples, --rounds)"
            if s.posterior is not None and s.posterior.sampling_failed else f"posterior {s.posterior_status}")
                  for s in self.scores if not s.estimated]
        lines += [f"{s.label}: log Z {s.evidence_text()} and its Laplace value {s.log_evidence_laplace:.3g} differ by "
                  f"{abs(s.log_evidence - s.log_evidence_laplace):.3g}, more than {TIE_SIGMAS:g} Monte-Carlo errors: "
                  "one of them is off (the Laplace value at a bound or in a curved valley, the sampled one with few "
                  "effective draws); trust its Bayes factors to that much only"
                  for s in self.scores if s.laplace_disagrees()]
        return lines

    def notes(self) -> list[str]:
        """What to read in the ranking: the :meth:`warnings` first, then the best model and its margin or ties, and
        how far the margin moves when the priors widen."""
        best, ranked = self.best, [s for s in self.scores if s.rank]
        lines = self.warnings()
        if best is not None and len(ranked) > 1:
            second = ranked[1]
            ties = [s.label for s in ranked if s.tied and s is not best]
            lines.append(f"best by evidence: {best.label}" + (
                f", tied within {TIE_SIGMAS:g} combined Monte-Carlo errors with {', '.join(ties)}" if ties else
                f", log Bayes factor {-second.delta:.3g} against {second.label}"))
            lines.append(self._sensitivity(best, second))
        elif best is not None:
            lines.append(f"{best.label}: the only model with an estimated log evidence: nothing to rank it against")
        return lines

    def _sensitivity(self, best, second) -> str:
        """The prior sensitivity of the first two: their log Bayes factor with every span widened."""
        factor = self.settings.get("widen", float("nan"))
        moved = (best.log_evidence_wider - second.log_evidence_wider) - (best.log_evidence - second.log_evidence)
        bounded = [s.label for s in (best, second) if s.at_bounds > BOUND_SHARE]
        return (f"prior sensitivity: with every prior span x {factor:g} (in x, or ln x for a log parameter; clipped to "
                f"the valid ranges) the log Bayes factor of {best.label} against {second.label} moves by "
                f"{moved:+.3g} to "
                f"{best.log_evidence_wider - second.log_evidence_wider:.3g} (log Z moves by -log of the volume ratio "
                "where the likelihood has no mass beyond the bounds)" + (
                    f"; {', '.join(bounded)}: over {BOUND_SHARE:.0%} of the posterior weight within "
                    f"{BOUND_MARGIN:.0%} of a bound, so its widened log Z is a lower bound" if bounded else ""))

    def summary(self) -> str:
        """The ranking as a text table, with the notes."""
        header, rows = self.table()
        widths = [max(len(str(c)) for c in column) for column in zip(header, *rows)]
        text = ["  ".join(str(c).rjust(w) for c, w in zip(line, widths)) for line in (header, *rows)]
        return "\n".join(text + self.notes())

    def to_dict(self) -> dict:
        """compare.json: the ranking (labels, best first; those whose log evidence is not estimated under
        ``not_ranked``), every model's numbers, the failures, the settings
        and the data (control [mm], values, std)."""
        data = self.data
        return _plain({"ranking": [s.label for s in self.scores if s.rank],
                       "not_ranked": [s.label for s in self.scores if not s.rank],
                       "best": self.best.label if self.best else None,
                       "tie_sigmas": TIE_SIGMAS, "models": [s.to_dict() for s in self.scores],
                       "failures": dict(self.failures), "settings": self.settings,
                       "warnings": self.warnings(), "notes": self.notes(),
                       "data": {"control": np.asarray(data.control, float), "y": np.asarray(data.y, float),
                                "std": np.asarray(data.std, float), "blocks": [list(b) for b in data.blocks]}})

    def save(self, path) -> Path:
        """Write :meth:`to_dict` as JSON."""
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1) + "\n", encoding="utf-8")
        return path
