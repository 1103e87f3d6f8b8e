"""The vocabulary of a TOML configuration: the keys each section allows and the values its choices
take (the purposes, the keys of every section but ``[[experiments]]``, whose kinds declare theirs).

The schema itself, with every key explained, is the docstring of :mod:`fracid.config.schema`.
"""

from __future__ import annotations

from fracid.inverse.methods.registry import DEFAULT_METHOD

# ------------------------------------------------------------------------------------ values

# The kinds of [[experiments]] blocks, their keys and data columns, and the kinds derived from another's blocks
# are the registry's, asked when a configuration is read (so that a kind registered later is known):
# fracid.inverse.experiments.registry (kind_names, column_keys, derived_kinds); the units and roles
# of a block are the kinds' shared vocabulary (fracid.inverse.experiments.vocabulary).
PURPOSES = ("identify", "simulate")

# ------------------------------------------------------------------------------------ keys

TOP_KEYS = ("model", "specimen", "experiments", "identify", "output", "simulate", "study", "posterior")
MODEL_KEYS = ("type", "law", "parameters")
#: the keys of [identify] itself; it also allows every table of a registered inverse method's settings
#: (fracid.inverse.methods.registry.known_tables), which the method checks; the error terms of the likelihood
#: (fracid.inverse.likelihood.settings) are a word or a table each
IDENTIFY_KEYS = ("parameters", "method", "bounds", "discretisation_error", "model_error")
OUTPUT_KEYS = ("directory", "vtk_steps")
SIMULATE_KEYS = ("target", "stop_force_fraction", "damage_threshold")
STUDY_KEYS = ("starts", "replicates", "seed", "tolerance", "prior", "posterior")
POSTERIOR_KEYS = ("samples_per_round", "max_rounds", "target_ess", "components", "defensive", "inflation", "seed",
                  "screening", "fine_runs")

# ------------------------------------------------------------------------------------ inverse methods

#: the default of [identify] method: the registry's (fracid.inverse.methods.registry.DEFAULT_METHOD)
DEFAULT_INVERSE_METHOD = DEFAULT_METHOD
