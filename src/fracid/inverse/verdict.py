"""A plain verdict per parameter: identified, correlated with another, or not identifiable.

The rules read the posterior covariance C of the estimate (linearised at the estimate), the prior
covariance from the bounds, and the uniqueness and stability checks when they were run:

* **identified** - relative standard deviation std / |x| <= ``tolerance``, and the multi-start
  ends agree within their standard deviations;
* **correlated with X** - std / |x| > tolerance, but the conditional standard deviation (what the
  data would give if the other parameters were known, 1 / sqrt((C^-1)_jj)) is within tolerance:
  the data fix a combination of the parameters, not each one (a valley of the objective);
* **not identifiable from these data** - neither: the data remove little of the prior variance.

A parameter that is not identified gets the extra data that would help: another specimen size
(the size effect separates the internal length from the softening) and local data (the width of
the fracture process zone measures the internal length directly).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class ParameterVerdict:
    """Verdict on one parameter.

    Attributes
    ----------
    name : str
    status : {"identified", "correlated", "not identifiable"}
    value, std : float
        Estimate and posterior standard deviation (units of the parameter).
    conditional_std : float
        Standard deviation if the other parameters were known.
    variance_removed : float
        1 - posterior variance / prior variance.
    partner : str
        The parameter it is most correlated with, and ``correlation`` that correlation.
    remarks : tuple of str
        Observations behind the verdict; ``suggestions`` the data that would help.
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

    def text(self, unit: str = "") -> str:
        unit = f" {unit}" if unit else ""
        if self.status == "identified":
            head = f"{self.name}: identified, {self.value:.4g} +- {self.std:.2g}{unit} ({self.std / abs(self.value):.1%})"
        elif self.status == "correlated":
            head = (f"{self.name}: correlated with {self.partner} (r = {self.correlation:+.3f}); "
                    f"{self.value:.4g} +- {self.std:.2g}{unit}, +- {self.conditional_std:.2g} if {self.partner} were known")
        else:
            head = (f"{self.name}: not identifiable from these data ({self.value:.4g} +- {self.std:.2g}{unit}; "
                    f"{self.variance_removed:.0%} of the prior variance removed)")
        tail = [f"  - {r}" for r in self.remarks] + [f"  - would help: {s}" for s in self.suggestions]
        return "\n".join([head] + tail)


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

    def text(self, units: dict | None = None) -> str:
        units = units or {}
        return "\n".join(v.text(units.get(v.name, "")) for v in self.parameters)

    def __getitem__(self, name: str) -> ParameterVerdict:
        for v in self.parameters:
            if v.name == name:
                return v
        raise KeyError(name)

    def as_dict(self) -> dict:
        return {"parameters": [dict(v.__dict__, remarks=list(v.remarks), suggestions=list(v.suggestions))
                               for v in self.parameters],
                "correlation": self.correlation.tolist()}


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
                       multi_start=None, stability=None, strong: float = 0.9) -> Verdict:
    """Verdict per parameter from the posterior covariance and the checks.

    Parameters
    ----------
    names : sequence of str
    x, C : ndarray
        Estimate and posterior covariance.
    C_prior : ndarray
        Reference covariance of what was known before the data (e.g. from the bounds).
    data : DataDescription
    tolerance : float
        Largest relative standard deviation called identified.
    multi_start : MultiStart, optional
        From :func:`fracid.inverse.uniqueness.multi_start`; ends that disagree demote a parameter.
    stability : Stability, optional
        From :func:`fracid.inverse.stability.stability`; its scatter is reported.
    strong : float
        |correlation| reported as strong.
    """
    x, C, C_prior = np.asarray(x, float), np.asarray(C, float), np.asarray(C_prior, float)
    std = np.sqrt(np.diag(C))
    corr = C / np.outer(std, std)
    conditional = 1.0 / np.sqrt(np.diag(np.linalg.inv(C)))
    removed = 1.0 - np.diag(C) / np.diag(C_prior)
    verdicts = []
    for j, name in enumerate(names):
        others = [k for k in range(len(names)) if k != j]
        k = max(others, key=lambda k: abs(corr[j, k])) if others else j
        partner, r = (names[k], float(corr[j, k])) if others else ("", 0.0)
        remarks = []
        if abs(r) > strong:
            remarks.append(f"strongly correlated with {partner} (r = {r:+.3f})")
        relative, relative_conditional = std[j] / abs(x[j]), conditional[j] / abs(x[j])
        if relative <= tolerance:
            status = "identified"
        elif relative_conditional <= tolerance and others:
            status = "correlated"
        else:
            status = "not identifiable"
        if multi_start is not None and not multi_start.unique()[j]:
            remarks.append(f"filters from {len(multi_start.ends)} starting points end "
                           f"{multi_start.distance[j]:.1f} standard deviations apart")
            status = "correlated" if status == "identified" and others else status
        if stability is not None and stability.ok.sum() >= 2:
            remarks.append(f"scatter under noise: {stability.relative_scatter[j]:.1%} "
                           f"({stability.amplification[j]:.1f} x the data noise {stability.noise_level:.1%})")
        suggestions = () if status == "identified" else _suggestions(data)
        verdicts.append(ParameterVerdict(name, status, float(x[j]), float(std[j]), float(conditional[j]),
                                         float(removed[j]), partner, r, tuple(remarks), suggestions))
    return Verdict(tuple(verdicts), corr)
