"""An identification's result read back for export: the model it identified, the estimate with its std, and where
it came from (:func:`read_identified`)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fracid.models.registry import DEFAULT_MODEL_TYPE, model_from_type, parameter_units
from fracid.runtime.exits import UsageError


@dataclass(frozen=True)
class Identified:
    """What ``fracid export`` takes from a ``result.json``.

    Attributes
    ----------
    model : ForwardModel
        The model the configuration named (``[model] type`` and ``law``).
    model_type : str
        Its ``[model] type``.
    params : ParameterSet
        The model's parameters: the estimate for the identified ones, the configuration's values for the others.
    std : dict
        Identified parameter name -> its standard deviation (same unit); the others are fixed.
    units : dict
        Parameter name -> unit.
    status : str
        The identification's status (``"converged"``, ...).
    source : str
        One line: the result file, the command, the date and the fracid version.
    covariance : ndarray or None
        The estimate's covariance, in the order of ``std``.
    """

    model: object
    model_type: str
    params: object
    std: dict
    units: dict
    status: str
    source: str
    covariance: np.ndarray | None = None

    def value_text(self, name: str) -> str:
        """``name = value unit (identified, std s)`` or ``(fixed)``, for a comment line."""
        value, unit = getattr(self.params, name), self.units.get(name, "").strip("-")
        how = f"identified, std {self.std[name]:.3g}" if name in self.std else "fixed"
        return f"{name} = {value:.6g} {unit} ({how})".replace("  ", " ")


def _load(path: Path) -> dict:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise UsageError(f"{path}: no such file (give the result.json of fracid identify)") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise UsageError(f"{path}: not a result of fracid identify (not JSON: {err})") from None
    if not isinstance(data, dict) or not {"names", "x"} <= set(data):
        raise UsageError(f"{path}: not a result of fracid identify (no 'names' and 'x' entries)")
    return data


def _configured_model(path: Path, data: dict) -> tuple[str, str | None, dict]:
    model = ((data.get("provenance") or {}).get("config") or {}).get("model")
    if not isinstance(model, dict):
        raise UsageError(f"{path}: the result does not record its configuration's [model] (provenance.config.model); "
                         f"identify again with this fracid to export it")
    values = {name: value for name, value in model.get("parameters") or []}
    return model.get("type") or DEFAULT_MODEL_TYPE, model.get("law"), values


def read_identified(path) -> Identified:
    """The model and parameters of an identification's ``result.json``.

    Raises
    ------
    UsageError
        When the file is missing, not a result, lacks its configuration, or names a model this fracid lacks.
    """
    path = Path(path)
    data = _load(path)
    model_type, law, values = _configured_model(path, data)
    try:
        model = model_from_type(model_type, law)
    except ValueError as err:
        raise UsageError(f"{path}: {err}") from None
    names, x = list(data["names"]), [float("nan") if v is None else float(v) for v in data["x"]]
    if not all(math.isfinite(v) for v in x):
        raise UsageError(f"{path}: the estimate is not finite ({dict(zip(names, x))}; status "
                         f"{data.get('status', '?')!r}): nothing to export")
    values.update(zip(names, x))
    try:
        params = model.parameters(**{k: v for k, v in values.items() if k in model.parameters.names()})
    except (TypeError, ValueError) as err:
        raise UsageError(f"{path}: the parameters do not make a {model_type} model: {err}") from None
    C = None if data.get("C") is None else np.array([[np.nan if v is None else v for v in row] for row in data["C"]],
                                                    float)
    std = {} if C is None else dict(zip(names, np.sqrt(np.clip(np.diag(C), 0.0, None)).tolist()))
    prov = data.get("provenance") or {}
    source = (f"{path.resolve()} ({prov.get('command', 'fracid identify')}, {prov.get('date', 'date unknown')}, "
              f"fracid {prov.get('fracid', '?')})")
    return Identified(model, model_type, params, std, parameter_units(model), str(data.get("status", "?")), source, C)
