"""The vocabulary of a TOML configuration: the keys of the sections that have no settings class of a kind (the
file's top level, ``[model]``, ``[specimen]``'s type and control, ``[identify]`` and ``[identify.bounds]``,
``[output]``, ``[simulate]``, ``[study]``, ``[posterior]``), each described once here (a mapping key ->
:class:`~fracid.settings.keys.Key`: default, unit, allowed values, meaning), and the purposes.

The checker accepts exactly these keys (``tuple(MAPPING)``: :data:`TOP_KEYS` ...); the configuration reference
(:mod:`fracid.config.reference`) and ``fracid init`` read the same descriptions. The keys of ``[[experiments]]``
are its kinds' (:mod:`fracid.inverse.experiments.registry`), those of the methods' tables the methods', those of
a specimen or a model its class's.
"""

from __future__ import annotations

from fracid.inverse.methods.registry import DEFAULT_METHOD, METHODS
from fracid.inverse.sampling.posterior import MAX_SCREENING, PosteriorSettings
from fracid.models.registry import DEFAULT_MODEL_TYPE
from fracid.settings.keys import FROM_CLASS, REQUIRED, UNSET, Key, Said, described

# ------------------------------------------------------------------------------------ values

# The kinds of [[experiments]] blocks, their keys and data columns, and the kinds derived from another's blocks
# are the registry's, asked when a configuration is read (so that a kind registered later is known):
# fracid.inverse.experiments.registry (kind_names, column_keys, derived_kinds); the units and roles
# of a block are the kinds' shared vocabulary (fracid.inverse.experiments.vocabulary).
PURPOSES = ("identify", "simulate")


def _names(registry) -> str:
    """The names of a registry (a mapping), as TOML strings joined by ``|``."""
    return " | ".join(f'"{name}"' for name in registry)


def _model_types() -> str:
    from fracid.models import MODEL_TYPES

    return _names(MODEL_TYPES)


def _specimen_types() -> str:
    from fracid.specimens import SPECIMENS

    return _names(SPECIMENS)


# ------------------------------------------------------------------------------------ keys

_TABLE = "a table"
TOP = {
    "model": Key(UNSET, "", _TABLE, "The forward model: its type, its law and the values of its parameters "
                                    "(default: the default model type with its class's defaults)."),
    "specimen": Key(REQUIRED, "", _TABLE, "The test specimen: its type, its control and its geometry and mesh "
                                          "(lengths in mm)."),
    "experiments": Key(UNSET, "", "one or more [[experiments]] tables",
                       "The measured data, one block per data file or derived quantity, stacked in this order; "
                       "required for identification, optional for a forward analysis."),
    "identify": Key(UNSET, "", _TABLE, "What is identified and how: the parameters, their bounds, the inverse method "
                                       "and its settings, the error terms of the likelihood; required for "
                                       "identification."),
    "output": Key(UNSET, "", _TABLE, "Where the results go."),
    "simulate": Key(UNSET, "", _TABLE, "The settings of a forward analysis (`fracid simulate`)."),
    "study": Key(UNSET, "", _TABLE, "The checks of `fracid study`: multi-start, noisy replicates, the verdict."),
    "posterior": Key(UNSET, "", _TABLE, "The sampler of `fracid posterior` (adaptive importance sampling on the "
                                        "exact model, the prior uniform between the bounds)."),
}
MODEL = {
    "type": Key(DEFAULT_MODEL_TYPE, "", _model_types, "The forward model (a name of fracid.models.MODEL_TYPES)."),
    "law": Key(UNSET, "", "a law of the model by name (fracid.models.model_laws); a model with a fixed law takes none",
               "The traction-separation law or softening shape by name; the parameters are then the law's (their "
               "tables below). Not set: the model's default law."),
    "parameters": Key(UNSET, "", "a table of the model's parameters",
                      "Any subset of the model's parameters (the table model.parameters of the model below); the "
                      "rest take the class's defaults."),
}
SPECIMEN = {
    "type": Key(REQUIRED, "", _specimen_types, "The specimen (a name of fracid.specimens.SPECIMENS); every other key "
                                               "of [specimen] is the specimen's own (its table below)."),
    "control": Key(Said("the specimen's first control"), "", "a control of the specimen",
                   "The quantity the forward run controls, and the data's control column measures."),
}
IDENTIFY = {
    "parameters": Key(REQUIRED, "", "a non-empty list of the model's parameters, each once",
                      "The parameters identified; the others keep their [model.parameters] value."),
    "method": Key(DEFAULT_METHOD, "", lambda: _names(METHODS),
                  "The inverse method (fracid.inverse.methods.registry.METHODS); its settings are the tables "
                  "[identify.<table>] it reads (below)."),
    "bounds": Key(REQUIRED, "", "a table", "The [lower, upper] bounds of every identified parameter "
                                           "([identify.bounds], below)."),
    "discretisation_error": Key("off", "", '"off" | "richardson", or a table (below)',
                                "The mesh's discretisation error at the estimate (Richardson), added to the data "
                                "covariance; the identification is run again with it (its stored runs reused)."),
    "model_error": Key("off", "", '"off" | "variance" | "bias", or a table (below)',
                       "The model's own (form) error, identified with the parameters."),
}
#: the key of [identify.bounds] that stands for every identified parameter's name
PARAMETER_KEY = "<parameter>"
BOUNDS = {
    PARAMETER_KEY: Key(REQUIRED, "the parameter's", "[lower, upper], lower < upper, both in the parameter's valid "
                                                    "range", "The bounds of an identified parameter (one key per "
                                                             "parameter of identify.parameters)."),
    "log": Key([], "", "a list of identified parameters with lower bound > 0",
               "The parameters sampled uniformly in log(x) (their range spans decades)."),
}
OUTPUT = {
    "directory": Key("results", "", "a directory path",
                     "Where the results are written; relative to the configuration file unless absolute."),
    "vtk_steps": Key([], "", "a list of integers >= 0", "`fracid simulate`: the steps whose fields go to VTK files."),
}
SIMULATE = {
    "target": Key(Said("the specimen's"), "mm", "> 0", "The final control value of a forward run."),
    "stop_force_fraction": Key(0.1, "-", "0 < f < 1", "The run stops when the force falls below f times its peak."),
    "damage_threshold": Key(0.0, "-", "0 <= t < 1", "The damage counted in the widths of damaged zones (fpz_width)."),
}
STUDY = {
    "starts": Key(3, "", "integer >= 0", "Multi-start local fits from distinct population points (0 or 1: no "
                                         "multi-start check)."),
    "replicates": Key(5, "", "0 or an integer >= 2", "Identifications on the data with noise added (0: no stability "
                                                     "check)."),
    "seed": Key(0, "", "integer >= 0", "The seed of the replicates' noise."),
    "tolerance": Key(0.1, "-", "0 < t < 1", 'The largest relative standard deviation called "identified".'),
    "prior": Key("search", "", '"search" | "bounds"', "The local fit's prior covariance: the search's, or uniform "
                                                      "over the bounds (the data's information only)."),
    "posterior": Key(False, "", "true | false", "true: `fracid study` also samples the posterior with the "
                                                "[posterior] settings, and the verdict reads its 90 % credible "
                                                "intervals instead of the Gaussian standard deviation."),
}
#: the sampler's settings: defaults and meanings are those of PosteriorSettings
POSTERIOR = described({
    "samples_per_round": Key(FROM_CLASS, "", "integer >= 2"),
    "max_rounds": Key(FROM_CLASS, "", "integer >= 1"),
    "target_ess": Key(FROM_CLASS, "", "> 1"),
    "components": Key(FROM_CLASS, "", "integer >= 1"),
    "defensive": Key(FROM_CLASS, "-", "0 <= d < 1"),
    "inflation": Key(FROM_CLASS, "-", "> 0"),
    "seed": Key(FROM_CLASS, "", "integer >= 0"),
    "screening": Key(FROM_CLASS, "-", f"1 <= s <= {MAX_SCREENING:g}"),
    "fine_runs": Key(FROM_CLASS, "", "integer >= 2"),
}, PosteriorSettings)

TOP_KEYS = tuple(TOP)
MODEL_KEYS = tuple(MODEL)
#: the keys of [identify] itself; it also allows every table of a registered inverse method's settings
#: (fracid.inverse.methods.registry.known_tables), which the method checks; the error terms of the likelihood
#: (fracid.inverse.likelihood.settings) are a word or a table each
IDENTIFY_KEYS = tuple(IDENTIFY)
#: the keys of [identify.bounds] besides the identified parameters' names
BOUNDS_KEYS = tuple(key for key in BOUNDS if key != PARAMETER_KEY)
OUTPUT_KEYS = tuple(OUTPUT)
SIMULATE_KEYS = tuple(SIMULATE)
STUDY_KEYS = tuple(STUDY)
POSTERIOR_KEYS = tuple(POSTERIOR)
#: the keys of [specimen] besides a specimen class's fields (a specimen with its own section declares all its keys)
SPECIMEN_KEYS = tuple(SPECIMEN)

# ------------------------------------------------------------------------------------ inverse methods

#: the default of [identify] method: the registry's (fracid.inverse.methods.registry.DEFAULT_METHOD)
DEFAULT_INVERSE_METHOD = DEFAULT_METHOD
