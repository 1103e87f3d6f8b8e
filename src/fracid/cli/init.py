"""``fracid init``: a commented configuration that runs as written, for a (specimen, model) pair.

Every key of the specimen (the fields of its class in :data:`fracid.specimens.SPECIMENS`) and of the
model's parameters (:data:`fracid.models.MODEL_TYPES`) is written with its value, and a comment with its
default, unit, allowed values and meaning. The meanings are read from the numpydoc ``Parameters`` section
of the classes' docstrings (:func:`numpydoc_parameters`), the ranges and units from the parameter classes.
The notched beam with the gradient-damage model starts from the bundled demo (Grégoire et al. 2013): its
values, its identification settings and its data file; the other pairs get an ``[[experiments]]`` block
commented out, to fill in with the lab's file. What a model needs written it declares itself: the parameters a
first identification looks for (``first_identified``), the specimen fields changed for it (``specimen_starts``)
and the usual ranges of its parameters (:mod:`fracid.models.plausibility`). The Gmsh mesh specimen is not offered: it needs the user's
``.msh`` (README, "Your own specimen: a Gmsh mesh").
"""

from __future__ import annotations

import dataclasses
import sys
import tomllib
from pathlib import Path

from fracid.cli.docstrings import description, numpydoc_parameters, summary
from fracid.settings.checks import COMMENT_COLUMN, show, toml_line

#: (specimen, model) whose configuration is the bundled demo's, with its data file
DEMO_PAIR = ("notched-beam", "gradient-damage")
#: comment column of the written ``key = value`` lines
_COLUMN = COMMENT_COLUMN

#: what the user must do about a key of the data block, before its comment (the key's allowed values and
#: meaning, read from its kind: :func:`fracid.config.reference.comment`)
_EXPERIMENT_PROMPTS = {"file": "REPLACE with your data file"}
#: the commented-out data block of the pairs without bundled data
_EXPERIMENT_TEMPLATE = {"file": "my_test.csv", "control_column": "u_mm", "control_unit": "mm", "force_unit": "N",
                        "kind": "single", "force_columns": ["F_N"], "std": 10.0, "n_points": 24}


def runnable_pairs() -> list:
    """The (specimen type, model type) pairs ``fracid init`` writes: every specimen of
    :data:`fracid.specimens.SPECIMENS` that has a default instance (not the mesh, which needs its file)
    with every model of :data:`fracid.models.MODEL_TYPES` that runs on it (:func:`fracid.models.runs_on`)."""
    from fracid.models import MODEL_TYPES, runs_on
    from fracid.specimens import SPECIMENS

    pairs = []
    for kind, cls in SPECIMENS.items():
        specimen = cls.default_instance()
        if specimen is None:
            continue
        description = specimen.describe()
        pairs += [(kind, name) for name, make in MODEL_TYPES.items() if runs_on(make(), description)]
    return pairs


#: ``key = value  # comment`` (:func:`fracid.settings.checks.toml_line`)
_line = toml_line


def _comments(text: str, width: int = 100) -> list:
    """``text`` as ``#`` lines of at most ``width`` characters."""
    lines, current = [], "#"
    for word in text.split():
        if len(current) + 1 + len(word) > width and current != "#":
            lines.append(current)
            current = "#"
        current += " " + word
    return lines + [current] if current != "#" else lines


def _demo() -> dict:
    from fracid.cli.common import demo_config_path

    with open(demo_config_path(), "rb") as f:
        return tomllib.load(f)


def _model_lines(model_type: str, given: dict) -> list:
    """``[model]`` and ``[model.parameters]``: every parameter with its unit, range and meaning."""
    from fracid.models import model_from_type

    cls = model_from_type(model_type).parameters
    docs = numpydoc_parameters(cls)
    lines = ["[model]", _line("type", model_type, "one of fracid.models.MODEL_TYPES"),
             "[model.parameters]"] + _comments(summary(cls))
    for field in dataclasses.fields(cls):
        rng, meaning = cls.ranges[field.name], docs.get(field.name, ("", ""))[1]
        value = given.get(field.name, field.default)
        default = "" if value == field.default else f"default {field.default!r}; "
        lines.append(_line(field.name, value, f"[{rng.unit}] {default}{rng.describe(field.name)}: {meaning}"))
    return lines


def _specimen_lines(kind: str, given: dict) -> list:
    """``[specimen]``: the class's summary, then every field with its default and meaning (fields whose
    default is None are written commented out: TOML has no null)."""
    from fracid.specimens import SPECIMENS

    cls = SPECIMENS[kind]
    docs = numpydoc_parameters(cls)
    controls = cls.default_instance().control_names
    lines = ["[specimen]"] + [line for paragraph in description(cls) for line in _comments(paragraph) + ["#"]] + [
        _line("type", kind, " | ".join(SPECIMENS)),
        _line("control", controls[0], "one of " + ", ".join(controls))]
    for field in dataclasses.fields(cls):
        kind_text, meaning = docs.get(field.name, (str(field.type), ""))
        value = given.get(field.name, field.default)
        note = "" if value == field.default else f"default {field.default!r}; "
        if value is None:
            lines.append(f"# {field.name} = ".ljust(_COLUMN - 1) + f" # ({kind_text}) default None: {meaning}")
        else:
            lines.append(_line(field.name, value, f"({kind_text}) {note}{meaning}"))
    return lines


def _experiment_lines(experiment: dict | None, commented: bool) -> list:
    """One ``[[experiments]]`` block: the demo's (active, or commented out when its file is not beside) or a
    template (commented out)."""
    from fracid.config.reference import comment, experiment_keys
    from fracid.inverse.experiments.registry import EXPERIMENTS, kind_names

    block = _EXPERIMENT_TEMPLATE if experiment is None else experiment
    docs = experiment_keys(EXPERIMENTS[block["kind"]])
    docs["kind"] = dataclasses.replace(docs["kind"], allowed=" | ".join(f'"{name}"' for name in kind_names()))

    def text(key: str) -> str:
        said = comment(docs[key]) if key in docs else ""
        return f"{_EXPERIMENT_PROMPTS[key]}: {said}" if key in _EXPERIMENT_PROMPTS else said

    lines = ["# the measured curve: without it only `fracid simulate` runs; uncomment and fill in to identify"
             if commented else "# the measured curve (the configuration reference: the other keys of a data block)",
             ("# " if commented else "") + "[[experiments]]"]
    return lines + [_line(key, value, text(key), commented) for key, value in block.items()]


def default_identification(model_type: str, params) -> tuple:
    """What ``fracid init`` identifies for a model without the demo's settings: (names, bounds, log names).

    Parameters
    ----------
    model_type : str
        A ``[model] type`` (:data:`fracid.models.MODEL_TYPES`).
    params : parameter object
        The model's parameters (an instance of its parameter class): the bounds are a factor 3 around
        their values, inside the usual and valid ranges (units of the parameters).

    Returns
    -------
    tuple
        The identified names (the model's ``first_identified``, else the two after E and nu), ``{name: [lower,
        upper]}`` (:func:`fracid.models.plausibility.first_bounds`) and the names sampled in log scale (beta:
        its range spans decades).
    """
    from fracid.models import declared, model_from_type

    names = list(declared(model_from_type(model_type)).first_identified or params.names()[2:4])
    return (names, *first_prior(params, names))


def first_prior(params, names) -> tuple:
    """The bounds of :func:`default_identification` for ``names`` of ``params``: ``{name: [lower, upper]}`` a factor
    3 around each value (:func:`fracid.models.plausibility.first_bounds`), and the names sampled in log scale."""
    from fracid.models.plausibility import first_bounds

    bounds = {name: first_bounds(type(params), name, getattr(params, name)) for name in names}
    return bounds, [name for name in names if name == "beta"]


def _identify_lines(model_type: str, demo: dict | None, params) -> list:
    """``[identify]``: the demo's, or the pair's usual parameters with bounds from their ranges; the tables of
    the default inverse method's settings are written by the method (its ``config_template``), with the demo's
    values or its own for a first run."""
    if demo is not None:
        names, bounds = demo["parameters"], {k: v for k, v in demo["bounds"].items() if k != "log"}
        log = demo["bounds"].get("log", [])
    else:
        names, bounds, log = default_identification(model_type, params)
    from fracid.config.reference import comment
    from fracid.config.vocabulary import BOUNDS, IDENTIFY

    return ["[identify]                          # for `fracid identify` (needs [[experiments]])",
            _line("parameters", names, comment(IDENTIFY["parameters"])),
            "[identify.bounds]                   # [lower, upper], inside the valid range of each"] + [
        _line(name, bounds[name], f"valid: {type(params).ranges[name].describe(name)}") for name in names] + [
        _line("log", log, comment(BOUNDS["log"]))] + _method_lines(demo or {})


def _method_lines(tables: dict) -> list:
    """The default inverse method's tables (:data:`fracid.inverse.methods.registry.DEFAULT_METHOD`), written by
    its ``config_template`` with the values of ``tables``; none for a method without one."""
    from fracid.inverse.methods.registry import DEFAULT_METHOD, METHODS, config_tables

    cls = METHODS[DEFAULT_METHOD]
    template = getattr(cls, "config_template", None)  # an optional hook of the method
    if template is None:
        return []
    return template({name: tables.get(name, {}) for name in config_tables(cls)})


def _tail_lines() -> list:
    """``[simulate]`` and ``[output]``, each key commented from its description (:mod:`fracid.config.vocabulary`)."""
    from fracid.config.reference import comment
    from fracid.config.vocabulary import OUTPUT, SIMULATE

    return ["[simulate]                          # optional",
            _line("target", 0.3, comment(SIMULATE["target"]) + " Omit it for the specimen's default.", commented=True),
            _line("stop_force_fraction", SIMULATE["stop_force_fraction"].default, comment(SIMULATE["stop_force_fraction"])),
            _line("damage_threshold", SIMULATE["damage_threshold"].default, comment(SIMULATE["damage_threshold"])),
            "", "[output]",
            _line("directory", OUTPUT["directory"].default, comment(OUTPUT["directory"]) + " (or --out DIR)"),
            _line("vtk_steps", OUTPUT["vtk_steps"].default, comment(OUTPUT["vtk_steps"]))]


def _start_values(specimen: str, model: str) -> tuple:
    """The values written instead of the defaults: ([model.parameters], [specimen] fields, notes saying why).
    On the notched beam, the demo's element size in the process zone (a run in seconds; its other mesh fields
    scale with the beam and stay at their defaults) and, for the demo's model, its values (fitted to the
    Gregoire beam; the integral model's neighbourhood at c = 9 mm^2 would make a run last a minute). Then the
    fields the model declares for the specimen (its ``specimen_starts``), and the mesh its ``mesh_length``
    needs (:func:`_resolving`)."""
    from fracid.models import declared, model_from_type
    from fracid.specimens import SPECIMENS

    cls, params, shape, notes = SPECIMENS[specimen], {}, {}, []
    if specimen == DEMO_PAIR[0]:
        demo = _demo()
        scaling = {f.name for f in dataclasses.fields(cls) if f.default is None}  # derived from the size
        shape = {k: v for k, v in demo["specimen"].items() if k not in ("type", "control", *scaling)}
        notes.append(f"The element size in the process zone is the bundled demo's ({_assignments(shape)}: a run in "
                     "seconds); the other mesh sizes scale with the specimen (their defaults).")
        if model == DEMO_PAIR[1]:
            params = demo["model"]["parameters"]
            notes.append("The parameter values are those of the demo, fitted to the Gregoire et al. (2013) beam.")
    start = declared(model_from_type(model)).specimen_starts.get(cls)
    if start is not None:
        shape = {**shape, **start.fields}
        notes.append(f"Specimen: {start.why}.")
    resolving = _resolving(model, cls, shape, params)
    if resolving is not None:
        shape = {**shape, **resolving[0]}
        notes.append(resolving[1])
    return params, shape, notes


def _assignments(fields: dict) -> str:
    return ", ".join(f"{key} = {value:g}" for key, value in fields.items())


def _resolving(model: str, cls, shape: dict, given: dict):
    """The mesh field that makes the specimen ``cls(**shape)`` resolve the length the model declares (its
    :class:`~fracid.models.protocol.MeshLength` at the written value of its parameter), and the note saying why:
    ``({field: value}, note)``; None when the mesh already resolves it (or the model declares no such length,
    or no field sets the mesh). The field is the one the specimen's
    :meth:`~fracid.specimens.protocol.Specimen.resolution` names, refined by the ratio of the element size to
    that length (:func:`fracid.specimens.protocol.refined`)."""
    from fracid.models import declared, model_from_type
    from fracid.specimens.protocol import refined

    resolved = declared(model_from_type(model)).mesh_length
    if resolved is None:
        return None
    parameters = model_from_type(model).parameters
    value = given.get(resolved.parameter, getattr(parameters(), resolved.parameter))
    length = resolved.length(value)
    specimen = cls(**shape)
    resolution = specimen.resolution(length)
    if resolution.field is None or resolution.h <= length * (1 + 1e-9):
        return None
    fine = refined(specimen, resolution.h / length)
    field = {resolution.field: getattr(fine, resolution.field)}
    return field, (f"The mesh: {_assignments(field)}, so that the elements where the crack runs are at most "
                   f"{resolved.text} = {length:g} mm ({resolved.parameter} = {value:g} {resolved.unit}): "
                   f"{resolved.band} is then resolved. A larger {resolved.parameter} allows a coarser mesh.")


def config_text(specimen: str, model: str, beside: bool = False) -> str:
    """The configuration ``fracid init --specimen SPECIMEN --model MODEL`` writes.

    Parameters
    ----------
    specimen, model : str
        A pair of :func:`runnable_pairs`.
    beside : bool
        The demo pair's data file is copied beside the written file (``-o FILE``): its block names it and is
        active. Otherwise (standard output) the block is commented out: the file is to be put there.

    Returns
    -------
    str
        A TOML configuration that :func:`fracid.config.load_config` accepts and ``fracid simulate`` runs
        (``fracid identify`` too for the demo pair written with ``-o``); no path into the installed package.
    """
    from fracid.models import model_from_type

    demo = _demo() if (specimen, model) == DEMO_PAIR else None
    given, shape, notes = _start_values(specimen, model)
    params = model_from_type(model).parameters(**given)
    experiment = None
    if demo:
        experiment = demo["experiments"][0]
        if not beside:
            notes.append(f"The data block names the demo's data file {experiment['file']}, which `fracid init -o FILE` "
                         "copies beside FILE: uncomment it there, or name your own file.")
    head = [f"# fracid configuration: {model} on the {specimen} (written by `fracid init`).",
            f"# Check it: fracid check FILE; run it: fracid simulate FILE, fracid identify FILE.",
            "# Units: N, mm, MPa. Every key is shown with its value; the comment gives the default,",
            "# the unit and the allowed values. The configuration reference (docs/reference/configuration.md)",
            "# documents every key.", ""]
    head[-1:] = [line for note in notes for line in _comments(note)] + [""]
    sections = [_model_lines(model, given), _specimen_lines(specimen, shape),
                _experiment_lines(experiment, commented=experiment is None or not beside), _identify_lines(model, demo and demo["identify"], params),
                _tail_lines()]
    return "\n".join(head + [line for section in sections for line in section + [""]])


def unknown_pair(specimen: str, model: str, pairs: list) -> str:
    """Why ``fracid init`` writes nothing for (``specimen``, ``model``): an unknown specimen or model type (the
    known ones listed, the closest suggested), a specimen without a default instance (a mesh file), or a model
    that does not run on the specimen."""
    import difflib

    from fracid.models import MODEL_TYPES
    from fracid.specimens import SPECIMENS

    for option, name, known in (("--specimen", specimen, SPECIMENS), ("--model", model, MODEL_TYPES)):
        if name not in known:
            close = [k for k in known if name and name in k] or difflib.get_close_matches(name, list(known), 1, 0.4)
            hint = f"; did you mean {close[0]}?" if close else ""
            return f"{option} {show(name)}: unknown {option[2:]} type; the types are {', '.join(known)}{hint}"
    if SPECIMENS[specimen].default_instance() is None:
        return (f"--specimen {specimen}: it needs your mesh file, so fracid init writes no configuration for it; "
                "README, 'Your own specimen: a Gmsh mesh'")
    runs = [m for s, m in pairs if s == specimen]
    return (f"--specimen {specimen} --model {model}: the model does not run on this specimen; on the {specimen}: "
            f"--model {', '.join(runs)} (`fracid init --list` gives every pair)")


def run_init(args) -> int:
    """``fracid init``: print or write the configuration (``-o FILE``, not over an existing file unless
    ``--force``), or list the pairs (``--list``)."""
    from fracid.cli.common import output_file
    from fracid.runtime.exits import UsageError

    pairs = runnable_pairs()
    args.specimen, args.model = args.specimen or DEMO_PAIR[0], args.model or DEMO_PAIR[1]
    if args.list:
        print("\n".join(f"--specimen {s} --model {m}" for s, m in pairs))
        return 0
    if (args.specimen, args.model) not in pairs:
        raise UsageError(unknown_pair(args.specimen, args.model, pairs))
    if args.output is None:
        sys.stdout.write(config_text(args.specimen, args.model))
        return 0
    path = output_file(args.output)
    if (path.exists() or path.is_symlink()) and not args.force:
        raise UsageError(f"-o {path}: the file exists; fracid init does not overwrite it (give --force to replace it)")
    copied = []
    if (args.specimen, args.model) == DEMO_PAIR:  # its data file and licence beside it, as --dataset does
        from fracid.cli.common import demo_config_path
        from fracid.cli.datasets import bundled_dataset, copy_beside

        copied = copy_beside(bundled_dataset(demo_config_path()), path, args.force)
    path.write_text(config_text(args.specimen, args.model, beside=True), encoding="utf-8")
    also = f" and, beside it, {', '.join(copied)}" if copied else ""
    print(f"wrote {path}{also}: check it with `fracid check {path}`", file=sys.stderr)
    return 0


def add_parser(sub, parents) -> None:
    """The ``init`` subcommand's arguments."""
    p = sub.add_parser("init", help="write a commented configuration to start from")
    p.add_argument("--specimen", help=f"specimen type (default {DEMO_PAIR[0]})")
    p.add_argument("--model", help=f"model type (default {DEMO_PAIR[1]})")
    p.add_argument("-o", "--output", type=Path, help="file to write (default: standard output)")
    p.add_argument("--force", action="store_true", help="replace an existing -o file")
    p.add_argument("--list", action="store_true", help="list the (specimen, model) pairs")
    p.add_argument("--debug", action="store_true", help="show the traceback of a failure")
    p.set_defaults(run=run_init, out_option="-o FILE")
