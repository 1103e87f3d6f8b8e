"""The forward models the inverse code sees: one small written contract, :class:`ForwardModel`, so a
new model touches no inverse code.

A forward model declares

``key`` : str
    Names the model (and its variant, its law) in run-store keys: runs of different models never share a key.
``parameters`` : type
    Its parameter class: ``names()``, ``units()``, ``valid_bounds(names)`` as class methods, ``usual_ranges``
    (name -> (lower, upper) of quasi-brittle materials; may be empty) and ``replace(**changes)`` on instances,
    returning a validated copy (ValueError for bad values); :class:`~fracid.fem.material.ranges.ParameterSet`
    gives them all.
``simulate(specimen, params, *, control, target, stop_force_fraction, steps, field_steps, checkpoints, damage_threshold, observables, sensitivities)``
    One forward run, returning an object with ``control`` [mm], ``force`` [N] and ``observables``
    (dict of arrays, e.g. ``fpz_width`` [mm]) along the path, raising
    :class:`~fracid.fem.path.path_following.ConvergenceError` (with ``.partial``) when it cannot go on.
``runs_on(specimen)`` / ``why_not(specimen)``
    Whether it runs on a specimen, and why not (None when it does).
``differentiable`` : tuple of str
    The parameters whose exact sensitivities a run computes (``simulate(..., sensitivities=names)``).
``differentiates_observers`` : bool
    Whether its observers (zone widths) have such derivatives too.
``observer_names`` : tuple of str
    Observers of its own beyond the specimen's observables (e.g. ``crack_length``).
``regularization`` : str or None
    The damage formulation ("gradient", "local", "integral"); None for the crack models.
``scales(params)`` / ``default_target(specimen, params)``
    Its characteristic strain (and opening), and the specimen's default final control value [mm].
``mesh_length`` : MeshLength or None
    The length its mesh must resolve where the crack runs, set by one of its parameters: the configuration's
    only source of the resolution warning and of a Gmsh mesh's unit check.
``band_width`` : BandWidth or None
    The width of the band it spreads its crack over, set by one of its parameters (pi l of the PF-CZM, 2 pi sqrt(c)
    of gradient and integral damage): the configuration compares it with the specimen's ``band_room()``.
``laws`` : mapping
    The laws a configuration may name (``[model] law``): name -> factory of its ``law`` field.
``first_identified`` : tuple of str or None
    The parameters a first identification looks for (``fracid init``, ``fracid compare``); None: the two after
    E and nu.
``specimen_starts`` : mapping
    Specimen class -> :class:`~fracid.models.protocol.SpecimenStart`, the fields ``fracid init`` writes.
``needs_description`` : bool
    Whether it builds its problem from the specimen's description (the built-in models), so that
    :func:`~fracid.models.forward.simulate` refuses a specimen object without ``describe()``; False: the model
    checks its specimens itself.

A model of a few lines (``key``, ``parameters``, ``simulate``) inherits the rest from
:class:`ModelDefaults`, or is completed by :func:`declared` (both of :mod:`fracid.models.protocol`,
importable from here).

The package: :mod:`~fracid.models.protocol` (the contract and its defaults), one module per model family
(:mod:`~fracid.models.damage`, :mod:`~fracid.models.crack`, :mod:`~fracid.models.phase_field`, sharing
:mod:`~fracid.models.path_model`), :mod:`~fracid.models.registry` (:data:`MODEL_TYPES`, the registry the
configuration reads, and the laws by name), :mod:`~fracid.models.plausibility` (the usual ranges the parameter
classes declare) and :mod:`~fracid.models.forward` (one forward run, :func:`~fracid.models.forward.simulate`).
The built-in models build their problem from the specimen's
:class:`~fracid.specimens.description.Description` (``specimen.describe()``): a formulation (gradient,
local or integral damage; cohesive interface; crack band; phase field) with a material law
(:mod:`fracid.fem.material.laws`).

It may import :mod:`fracid.fem`, :mod:`fracid.specimens` and :mod:`fracid.settings` (the lower floors). Below are
the names other packages import from it; ``ConvergenceError``, ``PathResult``, ``StepOptions``, ``probe_matrix``
and ``find_elements`` are the finite elements' names the inverse code sees through this window (it does not
import :mod:`fracid.fem`).
"""

from fracid.fem.mesh.probes import find_elements, probe_matrix
from fracid.fem.path.path_following import ConvergenceError, PathResult, StepOptions
from fracid.models.crack import CohesiveCrackModel, CrackBandModel, CrackModel
from fracid.models.damage import DamageModel
from fracid.models.path_model import PathFollowingModel
from fracid.models.phase_field import PhaseFieldModel
from fracid.models.plausibility import (IMPLAUSIBLE_FACTOR, implausible, implausible_text, usual_range_text,
                                        usual_ranges)
from fracid.models.protocol import BandWidth, ForwardModel, MeshLength, ModelDefaults, SpecimenStart, declared, runs_on
from fracid.models.registry import MODEL_TYPES, known_units, model_from_type, model_laws, parameter_units

__all__ = ["IMPLAUSIBLE_FACTOR", "MODEL_TYPES", "BandWidth", "CohesiveCrackModel", "ConvergenceError", "CrackBandModel",
           "CrackModel", "DamageModel", "ForwardModel", "MeshLength", "ModelDefaults", "PathFollowingModel", "PathResult",
           "PhaseFieldModel", "SpecimenStart", "StepOptions", "declared", "find_elements", "implausible",
           "implausible_text", "known_units", "model_from_type", "model_laws", "parameter_units", "probe_matrix",
           "runs_on", "usual_range_text", "usual_ranges"]
