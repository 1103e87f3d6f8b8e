"""A configuration's forward operator as an UM-Bridge model (:class:`ServedModel`): one input vector, the
identified parameters in the configuration's order (fracid's units: MPa, mm, N/mm, -); one output vector, the
observations of the configuration's data (N for forces, mm for openings and widths), in the order of
``result.json``'s ``y_exp``.

It has the methods of ``umbridge.Model`` (``get_input_sizes``, ``__call__``, ``gradient``, ``apply_jacobian``, the
``supports_*`` flags), so a Python user may also hand it to ``umbridge.serve_models``; ``fracid serve`` serves it
with :mod:`fracid.exchange.umbridge_server`, which returns fracid's failures as the protocol's error objects.
Gradient and Jacobian come from the runs' exact sensitivities (direct differentiation through the damage
history), offered only when the model and every observation have them. Every run goes through the run store.
"""

from __future__ import annotations

import numpy as np

from fracid.data.covariance_matrix import Diagonal
from fracid.store.provenance import json_safe


class ServedInputError(ValueError):
    """Parameters the model cannot run (a wrong number of them, a value outside the model's valid range)."""


class ServedRunError(RuntimeError):
    """A forward run that failed (its reason and how far it got)."""


class ServedModel:
    """The UM-Bridge model of a forward operator whose runs go through a run store.

    Parameters
    ----------
    name : str
        The model's name on the server.
    plain : StoredOperator
        The operator's runs for ``Evaluate``.
    exact : StoredOperator or None
        The same operator with exact sensitivities (``differentiated()``), None when it has none: then no
        gradient and no Jacobian are offered.
    info : dict
        What the model is (:func:`model_info`), sent with ``ModelInfo``.
    """

    def __init__(self, name: str, plain, exact, info: dict):
        self.name, self.plain, self.exact, self.info = name, plain, exact, info

    # sizes and support, as umbridge.Model
    def get_input_sizes(self, config=None) -> list:
        return [len(self.plain.names)]

    def get_output_sizes(self, config=None) -> list:
        return [int(self.plain.n_outputs)]

    def supports_evaluate(self) -> bool:
        return True

    def supports_gradient(self) -> bool:
        return self.exact is not None

    def supports_apply_jacobian(self) -> bool:
        return self.exact is not None

    def supports_apply_hessian(self) -> bool:
        return False

    # the actions
    def __call__(self, parameters, config=None) -> list:
        """[y]: the observations at the parameters [x]."""
        return [self._run(self.plain, parameters).y.tolist()]

    def gradient(self, out_wrt, in_wrt, parameters, sens, config=None) -> list:
        """sens^T J: the gradient of sens . y with respect to x."""
        return (self._jacobian(parameters, out_wrt, in_wrt).T @ self._vector(sens, self.get_output_sizes()[0],
                                                                             "sens")).tolist()

    def apply_jacobian(self, out_wrt, in_wrt, parameters, vec, config=None) -> list:
        """J vec: the directional derivative of y along vec."""
        return (self._jacobian(parameters, out_wrt, in_wrt) @ self._vector(vec, self.get_input_sizes()[0],
                                                                          "vec")).tolist()

    def _x(self, parameters) -> np.ndarray:
        names = self.plain.names
        if not isinstance(parameters, (list, tuple)) or len(parameters) != 1:
            raise ServedInputError(f"the input is one vector, the parameters {list(names)}; got {parameters!r}")
        x = self._vector(parameters[0], len(names), "input")
        try:
            self.plain.parameters(x)  # the model's valid ranges
        except ValueError as err:
            raise ServedInputError(f"parameters {dict(zip(names, x.tolist()))}: {err}") from None
        return x

    @staticmethod
    def _vector(values, size: int, what: str) -> np.ndarray:
        try:
            vector = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            raise ServedInputError(f"{what} must be a vector of {size} numbers; got {values!r}") from None
        if vector.shape != (size,) or not np.all(np.isfinite(vector)):
            raise ServedInputError(f"{what} must be a vector of {size} finite numbers; got {values!r}")
        return vector

    def _run(self, operator, parameters):
        x = self._x(parameters)
        record = operator(x)
        if not record.ok or not np.all(np.isfinite(record.y)):
            names = operator.names
            raise ServedRunError(f"the forward run at {dict(zip(names, x.tolist()))} failed: "
                                 f"{record.error or 'some observations were not computed'}")
        return record

    def _jacobian(self, parameters, out_wrt, in_wrt) -> np.ndarray:
        if (out_wrt, in_wrt) != (0, 0):
            raise ServedInputError(f"the model has one input and one output: outWrt = inWrt = 0; got "
                                   f"outWrt = {out_wrt!r}, inWrt = {in_wrt!r}")
        record = self._run(self.exact, parameters)
        if record.S is None or not np.all(np.isfinite(record.S)):
            raise ServedRunError("the run gave no sensitivities for every observation")
        return record.S


def with_equal_steps(operator, steps: int):
    """``operator`` whose runs take ``steps`` equal control steps up to its last control, with no jump to damage
    onset: the step sequence no longer moves with the parameters, so the served output is a smooth function of
    them and the gradient its exact derivative (central differences agree to 1e-8 on the test bar, against 3 % with
    the adaptive steps, whose positions move with the parameters). A step that fails is still cut."""
    from dataclasses import replace

    from fracid.models import StepOptions

    last = max(float(np.max(obs.controls)) for obs in operator.observations)
    return replace(operator, steps=StepOptions(initial=last / steps, jump_to_onset=False, onset_fraction=1.0,
                                               max_factor=1.0))


def model_info(operator, data, space, config_path) -> dict:
    """What a client needs to know of the served model: the inputs' names, units and the configuration's bounds
    (the prior's box), the outputs' blocks, the data and its std (the likelihood's), the configuration."""
    units = operator.units
    return json_safe({
        "config": str(config_path),
        "model": operator.model.key,
        "inputs": [{"name": name, "unit": units.get(name, ""), "lower": low, "upper": high}
                   for name, low, high in zip(space.names, space.lower, space.upper)],
        "outputs": [{"block": name, "start": start, "stop": stop} for name, start, stop in data.blocks],
        "data": data.y, "std": data.std,
        "correlated": not isinstance(data.covariance, Diagonal),
        "units": "inputs in the model's units (MPa, mm, N/mm, -); outputs in N (forces) and mm (lengths)",
    })
