""":func:`load_config`: the whole file validated section by section, then the checks joining
sections (the model runs on the specimen, the size of the calibration data, the mesh against the
internal length)."""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import numpy as np

from fracid.config.checker import MAX_CONFIG_BYTES, STDIN, _Checker, _read_toml
from fracid.config.experiments import _data_limit_text, _experiments
from fracid.config.identify import _identify
from fracid.config.mesh_section import c_range, check_mesh_units
from fracid.config.posterior import _posterior
from fracid.config.registry import _model_of, _specimen_class
from fracid.config.schema import (
    _PURPOSES,
    _TOP_KEYS,
    MAX_BAR_ELEMENTS,
    MAX_DATA_VALUES,
    Config,
    ConfigError,
    ModelConfig,
    SpecimenConfig,
)
from fracid.config.sections import (
    _check_model_runs_on,
    _field_key,
    _model,
    _output,
    _simulate,
    _specimen,
    _study,
)


def load_config(path: str | os.PathLike, *, purpose: str = "identify") -> Config:
    """Read and validate a TOML configuration.

    Parameters
    ----------
    path : str or path-like
        The TOML file; relative paths inside it are resolved against its directory.
    purpose : {"identify", "simulate"}
        ``"identify"`` requires ``[[experiments]]`` and ``[identify]``; ``"simulate"`` does not
        (they are validated when present).

    Returns
    -------
    Config
        Frozen, validated configuration.

    Raises
    ------
    ConfigError
        For any invalid, missing or unknown key, naming the file, the key, the value and what is allowed.
    """
    if purpose not in _PURPOSES:
        raise ValueError(f"purpose = {purpose!r}; choose 'identify' or 'simulate'")
    path, stdin = _config_path(path)
    ck = _Checker(path)
    raw = ck.table("", _read_toml(path, stdin), _TOP_KEYS)
    base = path.parent
    model = _model(ck, raw.get("model"))
    specimen = _specimen(ck, raw.get("specimen"), base)
    _check_model_runs_on(ck, model, specimen)
    experiments = _experiments(ck, raw.get("experiments"), base, specimen, purpose == "identify")
    n_y = sum(e.n_points for e in experiments if e.role == "calibration") or None
    if experiments and not n_y and purpose == "identify":
        ck.fail("experiments", [e.role for e in experiments], "at least one experiment needs role = 'calibration'")
    if n_y and n_y > MAX_DATA_VALUES:
        ck.fail("experiments", [e.n_points for e in experiments if e.role == "calibration"],
                _data_limit_text(n_y, "the n_points of the calibration blocks add up to"))
    identify = _identify(ck, raw.get("identify"), n_y, purpose == "identify", model)
    output = _output(ck, raw.get("output"), base)
    simulate = _simulate(ck, raw.get("simulate"))
    study = _study(ck, raw.get("study"))
    posterior = _posterior(ck, raw.get("posterior"))
    check_mesh_units(ck, model, specimen, identify)
    _mesh_warnings(ck, model, specimen, experiments, identify)
    return Config(path=path, purpose=purpose, model=model, specimen=specimen, experiments=experiments,
                  identify=identify, output=output, simulate=simulate, study=study, posterior=posterior,
                  warnings=tuple(ck.warnings))


def _config_path(path) -> tuple[Path, bytes | None]:
    """The configuration's absolute path, and its bytes when it is read from standard input (``"-"``: then
    the relative paths inside it are resolved against the working directory)."""
    if os.fspath(path) == STDIN:
        return Path.cwd() / "<stdin>", sys.stdin.buffer.read(MAX_CONFIG_BYTES + 1)
    text = os.fspath(path)
    if "\0" in str(text):
        raise ConfigError(f"{text!r}: a path cannot contain a NUL byte (\\0): check how it was typed or generated")
    try:
        return Path(path).expanduser().resolve(), None
    except (OSError, RuntimeError) as err:  # a symbolic-link loop
        raise ConfigError(f"{text}: cannot be resolved ({err}): a symbolic link that points to itself?") from None


def _mesh_warnings(ck: _Checker, model: ModelConfig, specimen: SpecimenConfig, experiments, identify) -> None:
    """Warn when the element size in the process zone exceeds the internal length l = sqrt(2 c) of a
    gradient or integral damage model (the smallest c: the given one, or the lower bound when c is
    identified): the damage band, a few l wide, is then not resolved and the results depend on the mesh.

    Element size: ``h_fine`` for the notched beam and the dog-bone (8-node elements in the refined
    band), ``length / n_elements`` for the bar.
    """
    if model.regularization not in ("gradient", "integral"):
        return
    (c, where), _ = c_range(model, identify)
    length = math.sqrt(2.0 * c)
    variants = [("specimen", dict(specimen.options), dict(specimen.options))]
    variants += [(f"experiments[{e.index}].specimen", {**dict(specimen.options), **dict(e.specimen)}, dict(e.specimen))
                 for e in experiments if e.specimen]
    cls = _specimen_class(specimen.type)
    for prefix, options, given in variants:
        built = cls(**options)
        if specimen.type == "mesh":
            h = _smallest_side(built.describe())
            size = f"specimen.file = {built.path!r}: its smallest element side, {h:.3g} mm,"
            advice = "refine the mesh where the crack runs to sides <= l/2"
        elif specimen.type == "bar":
            h = built.length / built.n_elements
            key, default = _field_key(prefix, "n_elements", options, given)
            size = f"{key} = {built.n_elements}{default}: the element size length / n_elements = {h:.3g} mm"
            needed = 2.0 * built.length / length
            advice = (f"use n_elements >= {math.ceil(needed)} (h <= l/2)" if needed <= MAX_BAR_ELEMENTS else
                      f"that needs {needed:.3g} elements, beyond the limit {MAX_BAR_ELEMENTS}: is c in mm^2?")
        else:
            h = built.h_fine
            key, default = _field_key(prefix, "h_fine", options, given)
            size = f"{key} = {h:g}{default}: the element size h_fine = {h:g} mm"
            advice = "use h_fine <= l/2"
        if h > length:
            ck.warn(f"{size} is larger than the internal length l = sqrt(2 c) = {length:.3g} mm (with {where}): "
                    f"the damage band is not resolved and the results depend on the mesh; {advice}")


def _smallest_side(description) -> float:
    """The shortest element side of a plane mesh [mm] (corner to corner)."""
    corners = description.nodes[description.cells[:, :(3 if description.cells.shape[1] == 6 else 4)]]
    return float(np.min(np.linalg.norm(corners - np.roll(corners, -1, axis=1), axis=-1)))


def _model_parameters(model: ModelConfig):
    """The parameters of a validated ``[model]`` section (those given, the rest the class's defaults)."""
    return _model_of(model.type).parameters(**dict(model.parameters))
