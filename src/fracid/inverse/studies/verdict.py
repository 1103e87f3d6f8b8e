"""A plain verdict per parameter: identified, correlated with another, or not identifiable.

The rules read the posterior covariance C of the estimate (linearised at the estimate), the prior
covariance from the bounds, and the uniqueness and stability checks when they were run:

* **identified** - relative standard deviation std / ``|x|`` <= ``tolerance``, and the multi-start
  ends agree within their standard deviations;
* **correlated with X** - std / ``|x|`` > tolerance, but the conditional standard deviation (what the
  data would give if the other parameters were known, 1 / sqrt((C^-1)_jj)) is within tolerance:
  the data fix a combination of the parameters, not each one (a valley of the objective);
* **not identifiable from these data** - neither: the data remove little of the prior variance.

A parameter that is not identified gets the extra data that would help: another specimen size
(the size effect separates the internal length from the softening) and local data (the width of
the fracture process zone measures the internal length directly).

**Measure.** Without a posterior the rules read the Gaussian (linearised) covariance C of the
identification, as above (measure ``"Gaussian (linearised) std"``). With a sampled posterior
(:func:`fracid.inverse.sampling.posterior.posterior`, given as ``posterior=``), they read the posterior instead
(measure ``"posterior 90 % credible interval"``), which holds where the Gaussian does not (a skewed
posterior, one cut by a bound):

* the value is the posterior mean, and the "std" is the std-equivalent of the equal-tailed 90 %
  credible interval: its half-width / 1.645 (what it is for a normal distribution); *identified*
  when it is within ``tolerance`` of ``|posterior mean|``;
* the correlation matrix, the partner and r are those of the posterior's weighted covariance;
* the conditional std is the std-equivalent times sqrt(1 - R^2), R^2 = 1 - 1 / (C_jj (C^-1)_jj) the
  squared multiple correlation of the parameter with the others in the weighted covariance (its
  conditional / marginal std), so that an uncorrelated parameter is never called *correlated*; a
  singular weighted covariance gives no conditional std (not *correlated*);
* the prior variance removed is 1 - weighted posterior variance / prior variance;
* the Gaussian estimate and its relative std stay in the remarks, with a word when the Gaussian
  alone would have judged *identified* differently.

The multi-start and stability rules are the same with either measure. Every
:class:`ParameterVerdict` (its text, :meth:`Verdict.as_dict`) names the measure it used.

**Error terms.** With the identification's error terms (the mesh's discretisation error, the model's own error:
:mod:`fracid.inverse.likelihood`), C is the widened covariance; each parameter's remarks give its estimate and
std without them, and the verdict's notes say where a term dominates the measurement std
(:func:`~fracid.inverse.likelihood.record.dominant_terms`): the data's scatter is then not what limits the
identification.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: the measure of the rules without a posterior, and with one (as :class:`ParameterVerdict` names it)
GAUSSIAN_MEASURE = "Gaussian (linearised) std"
POSTERIOR_MEASURE = "posterior 90 % credible interval"
#: half-width of a normal distribution's equal-tailed 90 % interval in standard deviations
Z_90 = 1.6448536269514722


@dataclass(frozen=True)
class ParameterVerdict:
    """Verdict on one parameter.

    Attributes
    ----------
    name : str
    status : {"identified", "correlated", "not identifiable"}
    value, std : float
        Estimate and posterior standard deviation (units of the parameter): with the measure
        ``"posterior 90 % credible interval"``, the posterior mean and the interval's half-width / 1.645.
    conditional_std : float
        Standard deviation if the other parameters were known.
    variance_removed : float
        1 - posterior variance / prior variance.
    partner : str
        The parameter it is most correlated with, and ``correlation`` that correlation.
    remarks : tuple of str
        Observations behind the verdict; ``suggestions`` the data that would help.
    measure : str
        What ``std`` is: :data:`GAUSSIAN_MEASURE` or :data:`POSTERIOR_MEASURE`.
    interval : tuple
        The 90 % credible interval (lower, upper) with the posterior measure; empty otherwise.
    """

    name: str
    status: str
    value: float
    std: float
    conditional_std: float
    variance_removed: float
    partner: str
    correlation: float
    remarks: tuple = ()
    suggestions: tuple = ()
    measure: str = GAUSSIAN_MEASURE
    interval: tuple = ()

    @property
    def relative_std(self) -> float:
        """std / ``|value|``: what the rule compares with the tolerance."""
        return self.std / abs(self.value)

    def measure_text(self, unit: str = "") -> str:
        """The measure the verdict used, in words (with the credible interval when it is the posterior's)."""
        if self.measure == POSTERIOR_MEASURE and len(self.interval) == 2:
            unit = f" {unit}" if unit else ""
            return (f"{self.measure} [{self.interval[0]:.4g}, {self.interval[1]:.4g}]{unit}, "
                    f"std = half-width / 1.645, around the posterior mean")
        return self.measure

    def text(self, unit: str = "") -> str:
        measure = f" [measure: {self.measure_text(unit)}]"
        unit = f" {unit}" if unit else ""
        if self.status == "identified":
            head = f"{self.name}: identified, {self.value:.4g} +- {self.std:.2g}{unit} ({self.relative_std:.1%})"
        elif self.status == "correlated":
            head = (f"{self.name}: correlated with {self.partner} (r = {self.correlation:+.3f}); "
                    f"{self.value:.4g} +- {self.std:.2g}{unit}, +- {self.conditional_std:.2g} if {self.partner} were known")
        else:
            head = (f"{self.name}: not identifiable from these data ({self.value:.4g} +- {self.std:.2g}{unit}; "
                    f"{self.variance_removed:.0%} of the prior variance removed)")
        tail = [f"  - {r}" for r in self.remarks] + [f"  - would help: {s}" for s in self.suggestions]
        return "\n".join([head + measure] + tail)


@dataclass(frozen=True)
class DataDescription:
    """What the data hold, for the suggestions: number of specimen sizes and local data present."""

    sizes: int = 1
    local: bool = False


@dataclass(frozen=True)
class Verdict:
    """Verdicts of all parameters and the correlation matrix they rest on."""

    parameters: tuple
    correlation: np.ndarray = field(repr=False)
    measure: str = GAUSSIAN_MEASURE
    notes: tuple = ()  # statements on the whole verdict (an error term that dominates the data's std)

    def text(self, units: dict | None = None) -> str:
        units = units or {}
        return "\n".join([*(v.text(units.get(v.name, "")) for v in self.parameters), *self.notes])

    def __getitem__(self, name: str) -> ParameterVerdict:
        for v in self.parameters:
            if v.name == name:
                return v
        raise KeyError(name)

    def as_dict(self) -> dict:
        return {"measure": self.measure,
                "parameters": [dict(v.__dict__, remarks=list(v.remarks), suggestions=list(v.suggestions),
                                    interval=list(v.interval)) for v in self.parameters],
                "correlation": self.correlation.tolist(), "notes": list(self.notes)}


def _suggestions(data: DataDescription) -> tuple:
    out = []
    if data.sizes < 2:
        out.append("another specimen size (size effect)")
    if not data.local:
        out.append("local data: the width of the fracture process zone during the test")
    if not out:
        out.append("more precise data, or fixing one of the correlated parameters from another test")
    return tuple(out)


def parameter_verdicts(names, x, C, C_prior, *, data: DataDescription = DataDescription(), tolerance: float = 0.1,
                       multi_start=None, stability=None, strong: float = 0.9, posterior=None,
                       error_terms=None) -> Verdict:
    """Verdict per parameter from the posterior covariance and the checks.

    Parameters
    ----------
    names : sequence of str
    x, C : ndarray
        Estimate and posterior covariance (the identification's Gaussian, linearised).
    C_prior : ndarray
        Reference covariance of what was known before the data (e.g. from the bounds).
    data : DataDescription
    tolerance : float
        Largest relative standard deviation called identified.
    multi_start : MultiStart, optional
        From :func:`fracid.inverse.studies.uniqueness.multi_start`; ends that disagree demote a parameter.
    stability : Stability, optional
        From :func:`fracid.inverse.studies.stability.stability`; its scatter is reported.
    strong : float
        ``|correlation|`` reported as strong.
    posterior : PosteriorResult, optional
        The sampled posterior (:func:`fracid.inverse.sampling.posterior.posterior`; any object with ``mean``,
        ``cov`` and ``credible_intervals(level)`` in the order of ``names``): the rules then read its
        90 % credible intervals and weighted covariance instead of ``x`` and ``C`` (module docstring).
    error_terms : dict, optional
        The identification's ``error_terms`` (``C`` is then the widened covariance): remarks with the estimates
        without them and notes on a term that dominates (module docstring).
    """
    x, C, C_prior = np.asarray(x, float), np.asarray(C, float), np.asarray(C_prior, float)
    if posterior is None:
        std = np.sqrt(np.diag(C))
        corr = C / np.outer(std, std)
        conditional = 1.0 / np.sqrt(np.diag(np.linalg.inv(C)))
        removed = 1.0 - np.diag(C) / np.diag(C_prior)
        value, intervals, measure = x, None, GAUSSIAN_MEASURE
    else:
        value, std, intervals, corr, conditional, removed = _posterior_measure(posterior, C_prior)
        measure = POSTERIOR_MEASURE
        gaussian_std = np.sqrt(np.diag(C))
    verdicts = []
    for j, name in enumerate(names):
        others = [k for k in range(len(names)) if k != j]
        k = max(others, key=lambda k: abs(corr[j, k])) if others else j
        partner, r = (names[k], float(corr[j, k])) if others else ("", 0.0)
        remarks = []
        if abs(r) > strong:
            remarks.append(f"strongly correlated with {partner} (r = {r:+.3f})")
        relative, relative_conditional = std[j] / abs(value[j]), conditional[j] / abs(value[j])
        if relative <= tolerance:
            status = "identified"
        elif relative_conditional <= tolerance and others:
            status = "correlated"
        else:
            status = "not identifiable"
        if posterior is not None:
            remarks.append(_gaussian_remark(x[j], gaussian_std[j], tolerance, relative <= tolerance))
        if multi_start is not None and not multi_start.unique()[j]:
            remarks.append(f"filters from {len(multi_start.ends)} starting points end "
                           f"{multi_start.distance[j]:.1f} standard deviations apart")
            status = "correlated" if status == "identified" and others else status
        if stability is not None and stability.ok.sum() >= 2:
            remarks.append(f"scatter under noise: {stability.relative_scatter[j]:.1%} "
                           f"({stability.amplification[j]:.1f} x the data noise, whose std is {stability.noise_level:.1%} "
                           "of the measured values in RMS)")
        remarks += _terms_remark(error_terms, j, std[j])
        suggestions = () if status == "identified" else _suggestions(data)
        interval = () if intervals is None else (float(intervals[j, 0]), float(intervals[j, 1]))
        verdicts.append(ParameterVerdict(name, status, float(value[j]), float(std[j]), float(conditional[j]),
                                         float(removed[j]), partner, r, tuple(remarks), suggestions, measure,
                                         interval))
    return Verdict(tuple(verdicts), corr, measure, _terms_notes(error_terms))


def _terms_remark(error_terms, j: int, std: float) -> list:
    """The estimate and std of parameter j without the error terms, and how much they widen it."""
    before = (error_terms or {}).get("measurement_only")
    if not before or j >= len(before.get("std", [])):
        return []
    x0, s0 = before["x"][j], before["std"][j]
    return [f"without the error terms (measurement std alone): {x0:.4g} +- {s0:.2g}; with them the std is "
            f"{std / s0:.2g} times wider"] if s0 > 0 else []


def _terms_notes(error_terms) -> tuple:
    """Notes of the verdict on its error terms: what was added, and where a term dominates the data's std."""
    if not error_terms:
        return ()
    from fracid.inverse.likelihood.record import dominant_terms

    added = [name for key, name in (("discretisation", "the mesh's discretisation error"),
                                    ("model_error", "the model's own error")) if error_terms.get(key)]
    return (f"Note: the std include {' and '.join(added)} (error terms of the likelihood)",
            *(f"Note: {text}" for text in dominant_terms(error_terms)))


def _posterior_measure(posterior, C_prior):
    """Per parameter from a sampled posterior: mean, std-equivalent of the 90 % credible interval, the
    interval, the weighted correlation matrix, the conditional std-equivalent and the variance removed."""
    mean = np.asarray(posterior.mean, float)
    intervals = np.asarray(posterior.credible_intervals(0.9), float)
    spread = (intervals[:, 1] - intervals[:, 0]) / (2.0 * Z_90)
    cov = np.asarray(posterior.cov, float)
    variance = np.diag(cov)
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = cov / np.sqrt(np.outer(variance, variance))
        try:
            # conditional / marginal std of the weighted covariance: sqrt(1 - R^2)
            ratio = 1.0 / np.sqrt(variance * np.diag(np.linalg.inv(cov)))
        except np.linalg.LinAlgError:
            ratio = np.full(len(mean), np.nan)
    conditional = spread * np.minimum(ratio, 1.0)
    removed = 1.0 - variance / np.diag(C_prior)
    return mean, spread, intervals, corr, conditional, removed


def _gaussian_remark(x, std, tolerance, identified) -> str:
    """The Gaussian (linearised) estimate beside a posterior verdict, and whether it would have judged otherwise."""
    relative = std / abs(x)
    text = f"{GAUSSIAN_MEASURE}: {x:.4g} +- {std:.2g} ({relative:.1%})"
    if (relative <= tolerance) != identified:
        text += (f"; by it alone the parameter would {'' if relative <= tolerance else 'not '}be identified "
                 f"(tolerance {tolerance:.0%})")
    return text
