"""The vocabulary of a TOML configuration: the keys each section allows and the values its choices
take (units with their scale to mm and N, the kinds of data, the roles of an experiment, ...).

The schema itself, with every key explained, is the docstring of :mod:`fracid.config.schema`.
"""

from __future__ import annotations

from fracid.inverse.methods.registry import DEFAULT_METHOD

# ------------------------------------------------------------------------------------ values

#: ``control_unit`` -> multiplier to mm
CONTROL_UNITS = {"mm": 1.0, "um": 1e-3, "m": 1e3}
#: ``delimiter`` values -> the cell separator ("tab" spells a tab; " " is any run of whitespace)
DELIMITERS = {",": ",", ";": ";", "\t": "\t", "tab": "\t", " ": " "}
DECIMALS = (".", ",")
#: ``force_unit`` of a force -> multiplier to N
FORCE_UNITS = {"N": 1.0, "kN": 1e3, "MN": 1e6}
#: ``force_unit`` of a local quantity (a length) -> multiplier to mm
LOCAL_UNITS = dict(CONTROL_UNITS)
#: kinds of local data derived from a field block (fracid.config.derived_experiments): the crack-opening
#: profile and the process-zone width
DERIVED_KINDS = ("opening", "fpz-width")
KINDS = ("repeats", "envelope", "single", "field", *DERIVED_KINDS)
PURPOSES = ("identify", "simulate")
#: "source": read and checked, neither calibrated on nor predicted: the field a derived block comes from
ROLES = ("calibration", "prediction", "source")

# ------------------------------------------------------------------------------------ keys

TOP_KEYS = ("model", "specimen", "experiments", "identify", "output", "simulate", "study", "posterior")
MODEL_KEYS = ("type", "law", "parameters")
EXPERIMENT_KEYS = ("file", "control_column", "control_unit", "force_unit", "kind", "force_columns", "mean_column",
                   "lower_column", "upper_column", "std", "relative_std", "n_points", "control_range", "quantity",
                   "name", "specimen", "weight", "damage_threshold", "role", "delimiter", "decimal",
                   "backtrack_tolerance", "negate", "sampling")
#: ``kind`` -> the keys of its data columns (and of its std)
KIND_KEYS = {
    "repeats": ("force_columns",),
    "envelope": ("mean_column", "lower_column", "upper_column"),
    "single": ("force_columns", "std", "relative_std"),
    "field": (),  # a DIC field: its own keys (fracid.config.field_experiments.FIELD_KEYS)
    "opening": (),  # derived from a field: its own keys (fracid.config.derived_experiments.DERIVED_KEYS)
    "fpz-width": (),
}
#: the keys of [identify] itself; it also allows every table of a registered inverse method's settings
#: (fracid.inverse.methods.registry.known_tables), which the method checks; the error terms of the likelihood
#: (fracid.inverse.likelihood.settings) are a word or a table each
IDENTIFY_KEYS = ("parameters", "method", "bounds", "discretisation_error", "model_error")
OUTPUT_KEYS = ("directory", "vtk_steps")
SIMULATE_KEYS = ("target", "stop_force_fraction", "damage_threshold")
STUDY_KEYS = ("starts", "replicates", "seed", "tolerance", "prior", "posterior")
POSTERIOR_KEYS = ("samples_per_round", "max_rounds", "target_ess", "components", "defensive", "inflation", "seed")

# ------------------------------------------------------------------------------------ inverse methods

#: the default of [identify] method: the registry's (fracid.inverse.methods.registry.DEFAULT_METHOD)
DEFAULT_INVERSE_METHOD = DEFAULT_METHOD
