""":func:`load_config`: the whole file validated section by section, then the checks joining
sections (the model runs on the specimen, the size of the calibration data, the mesh against the
internal length, the band of the internal length against the specimen)."""

from __future__ import annotations

import dataclasses
import os
import stat
import sys
from pathlib import Path

from fracid.config.checker import MAX_CONFIG_BYTES, STDIN, Checker, read_toml
from fracid.config.experiments import read_experiments
from fracid.config.identify import check_refinable, read_identify
from fracid.config.posterior import read_posterior
from fracid.config.registry import model_of, parameter_range, specimen_class
from fracid.models.protocol import declared
from fracid.config.schema import (
    Config,
    ConfigError,
    ModelConfig,
    SpecimenConfig,
)
from fracid.config.sections import (
    check_model_runs_on,
    check_specimen_section,
    field_key,
    read_model,
    read_output,
    read_simulate,
    read_specimen,
    read_study,
    specimen_variants,
    value_text,
)
from fracid.config.plausible import check_band_room, warn_implausible_parameters
from fracid.config.vocabulary import PURPOSES, TOP_KEYS


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
    if purpose not in PURPOSES:
        raise ValueError(f"purpose = {purpose!r}; choose 'identify' or 'simulate'")
    path, stdin = _config_path(path)
    ck = Checker(path)
    raw = ck.table("", read_toml(path, stdin), TOP_KEYS)
    base = path.parent
    model = read_model(ck, raw.get("model"))
    warn_implausible_parameters(ck, model)
    specimen = read_specimen(ck, raw.get("specimen"), base)
    check_model_runs_on(ck, model, specimen)
    experiments = read_experiments(ck, raw.get("experiments"), base, specimen, purpose == "identify")
    n_y = sum(e.n_points for e in experiments if e.role == "calibration") or None
    if experiments and not n_y and purpose == "identify":
        ck.fail("experiments", [e.role for e in experiments], "at least one experiment needs role = 'calibration'")
    identify = read_identify(ck, raw.get("identify"), n_y, purpose == "identify", model)
    check_refinable(ck, specimen, experiments, identify)
    output = read_output(ck, raw.get("output"), base)
    simulate = read_simulate(ck, raw.get("simulate"))
    study = read_study(ck, raw.get("study"))
    posterior = read_posterior(ck, raw.get("posterior"))
    check_specimen_section(ck, model, specimen, identify)  # a mesh's units against the model's mesh length
    _mesh_warnings(ck, model, specimen, experiments, identify)
    check_band_room(ck, model, specimen, experiments, identify)
    return Config(path=path, purpose=purpose, model=model, specimen=specimen, experiments=experiments,
                  identify=identify, output=output, simulate=simulate, study=study, posterior=posterior,
                  warnings=tuple(ck.warnings))


def _config_path(path) -> tuple[Path, bytes | None]:
    """The configuration's absolute path, and its bytes when it is read from standard input (``"-"``: then
    the relative paths inside it are resolved against the working directory)."""
    text = os.fspath(path)
    if text == STDIN or (text in STDIN_NAMES and not _stdin_is_a_file()):
        return Path.cwd() / "<stdin>", sys.stdin.buffer.read(MAX_CONFIG_BYTES + 1)
    if "\0" in str(text):
        raise ConfigError(f"{text!r}: a path cannot contain a NUL byte (\\0): check how it was typed or generated")
    try:
        resolved = Path(path).expanduser().resolve()
    except (OSError, RuntimeError) as err:  # a symbolic-link loop
        raise ConfigError(f"{text}: cannot be resolved ({err}): a symbolic link that points to itself?") from None
    if not resolved.exists() and os.path.exists(text):  # /dev/fd/N of a pipe: links to "pipe:[...]", no file
        return Path(text).expanduser().absolute(), None  # read_toml names it: not a regular file, give '-'
    return resolved, None


#: the names of standard input as a file: read as ``-`` when it is a pipe or a terminal (a redirected file
#: is read as that file, its relative paths against its directory)
STDIN_NAMES = ("/dev/stdin", "/dev/fd/0", "/proc/self/fd/0")


def _stdin_is_a_file() -> bool:
    """Whether standard input is a regular file (``< cfg.toml``); False for a pipe, a terminal or none."""
    try:
        return stat.S_ISREG(os.fstat(sys.stdin.fileno()).st_mode)
    except (OSError, ValueError, AttributeError):  # closed, or replaced by an object without a descriptor
        return False


def _mesh_warnings(ck: Checker, model: ModelConfig, specimen: SpecimenConfig, experiments, identify) -> None:
    """Warn when the element size in the process zone exceeds the length the model's mesh must resolve (its
    :class:`~fracid.models.protocol.MeshLength`: the internal length l = sqrt(2 c) of a gradient or integral damage
    model, l / 5 of the PF-CZM) at the smallest value of its parameter (the given one, or the lower bound when it is
    identified): the band is then not resolved and the results depend on the mesh.

    The element size, the key that sets it and the advice are the specimen's
    (:meth:`~fracid.specimens.protocol.Specimen.resolution`): ``h_fine`` of the notched beam, ``length /
    n_elements`` of the bar, the smallest element side of a mesh file.
    """
    resolved = declared(model_of(model.type, model.law)).mesh_length
    if resolved is None:
        return
    (value, where), _ = parameter_range(model, identify, resolved.parameter, resolved.unit)
    length = resolved.length(value)
    cls = specimen_class(specimen.type)
    fields = {f.name for f in dataclasses.fields(cls)}
    for prefix, options, given in specimen_variants(specimen, experiments):
        resolution = cls(**options).resolution(length)
        if resolution.h <= length:
            continue
        size = f"specimen ({specimen.type}): {resolution.text}"
        if resolution.field is not None:
            key, default = field_key(prefix, resolution.field, options, given)
            size = f"{key} = {value_text(resolution.value)}{default if resolution.field in fields else ''}: {resolution.text}"
        advice = resolution.advice if resolved.advice is None else resolved.advice.format(size=length)
        ck.warn(f"{size} is larger than {resolved.text} = {length:.3g} mm (with {where}): "
                f"{resolved.band} is not resolved and the results depend on the mesh; {advice}")
