"""The forward models the inverse code sees: one small written contract, :class:`ForwardModel`, so a
new model touches no inverse code.

A forward model declares

``key`` : str
    Names the model (and its variant, its law) in run-store keys: runs of different models never share a key.
``parameters`` : type
    Its parameter class: ``names()``, ``units()``, ``valid_bounds(names)`` as class methods and
    ``replace(**changes)`` on instances, returning a validated copy (ValueError for bad values).
``simulate(specimen, params, *, control, target, stop_force_fraction, steps, field_steps, checkpoints,
damage_threshold, observables, sensitivities)``
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

A model of a few lines (``key``, ``parameters``, ``simulate``) inherits the rest from
:class:`ModelDefaults`, or is completed by :func:`declared` (both of :mod:`fracid.models.protocol`,
importable from here).

The models below build their problem from the specimen's
:class:`~fracid.specimens.description.Description` (``specimen.describe()``): a formulation (gradient,
local or integral damage; cohesive interface; crack band) with a material law
(:mod:`fracid.fem.material.laws`). :data:`MODEL_TYPES` is the registry the configuration reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from fracid.fem.formulations.crack_band_problem import CrackBandProblem, element_extent
from fracid.fem.formulations.cohesive_problem import CohesiveCrackProblem, crack_edges
from fracid.fem.formulations.fpz import zone_width_observer
from fracid.fem.material.laws import TRACTION_SEPARATION_LAWS, DamageLaw, HordijkLaw
from fracid.fem.mesh.probes import probe_matrix
from fracid.fem.material.tsl import differentiable as gives_derivatives
from fracid.fem.path.path_following import ConvergenceError, PathResult, StepOptions, follow_path
from fracid.fem.formulations.problem import FORMULATIONS
from fracid.fem.formulations.phase_field_problem import PhaseFieldProblem
from fracid.fem.material.phase_field import PHASE_FIELD_SHAPES, PhaseFieldSoftening
from fracid.models.protocol import ForwardModel, MeshLength, ModelDefaults, declared, runs_on
from fracid.specimens.description import uniform, at_points, conditions, discretize


__all__ = ["IMPLAUSIBLE_FACTOR", "probe_matrix", "MODEL_TYPES", "USUAL_RANGES", "CohesiveCrackModel", "ConvergenceError",
           "CrackBandModel", "DamageModel", "PhaseFieldModel", "ForwardModel", "ModelDefaults", "PathResult", "StepOptions", "declared",
           "implausible", "known_units", "model_from_type", "model_laws", "parameter_units", "runs_on", "usual_range_text"]


def _description(specimen):
    return specimen if hasattr(specimen, "node_sets") else specimen.describe()


def select_observers(observers: dict, names=None) -> dict:
    """The observers named in ``names`` (all if None). Other names are left out: the energies and
    the problem's functionals are recorded at every step anyway."""
    if names is None:
        return observers
    return {name: fn for name, fn in observers.items() if name in set(names)}


class PathFollowingModel(ModelDefaults):
    """``simulate`` of the models below: build the problem, follow the path with the specimen's
    default control, target and steps."""

    def scales(self, params) -> dict:
        """Characteristic strain (and opening) a specimen sizes its default control with."""
        return self.law.scales(params)

    def simulate(self, specimen, params, *, control=None, target=None, stop_force_fraction=0.1, steps=None,
                 damage_threshold=0.0, observables=None, **options):
        description = _description(specimen)  # described once: the mesh is built once per run
        reason = self.why_not(description)
        if reason is not None:
            raise TypeError(f"the {self.key} model does not run on a {type(specimen).__name__}: {reason}")
        problem = self.build(description, params)
        target = target if target is not None else self.default_target(specimen, params)
        if steps is None:
            steps = specimen.default_steps(target) if hasattr(specimen, "default_steps") else StepOptions()
        observers = self.observers(description, params, damage_threshold)
        return follow_path(problem, control or specimen.default_control, target, steps=steps,
                           stop_force_fraction=stop_force_fraction,
                           observers=select_observers(observers, observables), **options)



@dataclass(frozen=True)
class DamageModel(PathFollowingModel):
    """Continuum damage: ``"gradient"`` (implicit gradient enhancement), ``"local"`` (no
    regularisation; mesh-dependent, for comparison) or ``"integral"`` (Gaussian average of the
    equivalent strain, internal length l = sqrt(2 c)), with a damage law (exponential softening and
    the modified von Mises equivalent strain by default; see docs/theory.md, section 1).

    Observable: the width of the damaged zone where the specimen measures it (``fpz_width`` or
    ``damaged_zone_width`` [mm], the zone where omega exceeds ``damage_threshold``).
    """

    regularization: str = "gradient"
    law: DamageLaw = field(default_factory=DamageLaw)
    #: its observers (the zone widths) have derivatives in the runs with ``sensitivities``
    differentiates_observers: ClassVar[bool] = True

    def __post_init__(self):
        if self.regularization not in FORMULATIONS:
            raise ValueError(f"regularization = {self.regularization!r}; choose 'gradient', 'local' or 'integral'")

    @property
    def parameters(self) -> type:
        return self.law.parameters

    @property
    def key(self) -> str:
        suffix = "" if self.law.name == "exponential" else f"-{self.law.name}"
        return f"{self.regularization}-damage{suffix}"

    @property
    def mesh_length(self) -> MeshLength | None:
        """The internal length l = sqrt(2 c) of the regularised formulations (none for local damage)."""
        if self.regularization == "local":
            return None
        return MeshLength("c", "mm^2", lambda c: math.sqrt(2.0 * c), "the internal length l = sqrt(2 c)",
                          "the damage band")

    def why_not(self, specimen):
        d = _description(specimen)
        if d.strength_factor is not uniform:
            return "its imperfection is a reduced tensile strength, which a damage law does not read"
        return None


    @property
    def differentiable(self) -> tuple:
        """Every parameter of the law if the law gives its parameter derivatives, else none."""
        return tuple(self.parameters.names()) if self.law.differentiable else ()

    def build(self, specimen, params):
        """The problem of this formulation on ``specimen`` (a specimen or its description)."""
        d = _description(specimen)
        disc = discretize(d)
        return FORMULATIONS[self.regularization](
            disc, self.law, params, conditions(d), stiffness_factor=at_points(d.stiffness_factor, disc),
            damageable=at_points(d.damageable, disc), symmetry_planes=d.symmetry_planes)

    def observers(self, description, params, damage_threshold: float = 0.0) -> dict:
        zone = description.zone
        if zone is None:
            return {}
        law = self.law
        return {zone.name: zone_width_observer(zone, law.softening.kappa_at_damage(damage_threshold, params),
                                               lambda names: law.kappa_at_damage_derivatives(damage_threshold, params,
                                                                                             names))}


class _CrackModel(PathFollowingModel):
    """The models of one crack with a traction-separation law (:class:`~fracid.fem.material.tsl.TractionSeparationLaw`,
    Hordijk's by default): plane stress, where the specimen says the crack runs."""

    #: observers whose values the runs do not differentiate (a count of cracked points: a staircase)
    observer_names: ClassVar[tuple] = ("crack_length",)

    @property
    def parameters(self) -> type:
        return self.law.parameters

    @property
    def differentiable(self) -> tuple:
        """Every parameter of the law if the law gives its parameter derivatives, else none."""
        return tuple(self.parameters.names()) if gives_derivatives(self.law) else ()

    def why_not(self, specimen):
        d = _description(specimen)
        if d.dim != 2:
            return "it is a plane-stress model"
        if d.crack is None:
            return "the specimen says nothing of where the crack runs"
        return self._path_problem(d.crack)

    def _path_problem(self, crack):
        return None


@dataclass(frozen=True)
class CohesiveCrackModel(_CrackModel):
    """Discrete cohesive crack with a traction-separation law (Hordijk's by default) along the specimen's crack path (a symmetry line of
    the model), elastic bulk (docs/theory.md, section 5). The faces are tied by a penalty
    ``penalty_factor * E / h`` [MPa/mm] (h the finest element size along the path) until the traction
    reaches ft. Observable: ``crack_length`` [mm], the length of the path whose faces have separated.
    """

    penalty_factor: float = 1000.0
    law: HordijkLaw = HordijkLaw()

    @property
    def key(self) -> str:
        """``cohesive-crack-<law>``: runs of different traction-separation laws never share a key."""
        return f"cohesive-crack-{self.law.name}"

    def _path_problem(self, crack):
        if crack.nodes is None or not crack.mirrored:
            return "the specimen has no crack path on a symmetry line"
        return None


    def build(self, specimen, params):
        d = _description(specimen)
        disc = discretize(d)
        path = d.nodes_of(d.crack.nodes)
        edges = crack_edges(d.nodes, d.cells, disc.u_dofs, path, d.crack.normal)
        h = d.crack.element_size or float((edges[2][:, 2] - edges[2][:, 0]).min())
        return CohesiveCrackProblem(disc, self.law, params, conditions(d, open_crack=True, discrete_crack=True), edges,
                                    float(d.section), self.penalty_factor * params.E / h,
                                    stiffness_factor=at_points(d.stiffness_factor, disc))

    def observers(self, description, params, damage_threshold: float = 0.0) -> dict:
        return {"crack_length": lambda problem, q, arrays: problem.cracked_length(arrays.history)}


@dataclass(frozen=True)
class CrackBandModel(_CrackModel):
    """Smeared crack band: a rotating crack with a traction-separation law (Hordijk's by default) scaled by the band width
    (docs/theory.md, section 5). Same parameters as the cohesive crack, so the two are directly
    comparable. The band is confined to the elements along the specimen's crack path (in a half
    model a band elsewhere would be mirrored into two cracks), or free where the specimen has no path.

    ``band_width`` [mm] overrides the element widths the law is scaled by (to see what an unscaled
    softening law does to the energy).
    """

    band_width: float | None = None
    law: HordijkLaw = HordijkLaw()

    @property
    def key(self) -> str:
        """``crack-band-<law>[-band-<width>]``: runs of different laws or band widths never share a key."""
        return f"crack-band-{self.law.name}" + ("" if self.band_width is None else f"-band-{self.band_width:g}")


    def build(self, specimen, params):
        d = _description(specimen)
        disc = discretize(d)
        direction = [0.0, 0.0]
        direction[d.crack.normal] = 1.0
        width = element_extent(d.nodes, d.cells, direction)
        if self.band_width is not None:
            width = np.full(len(d.cells), float(self.band_width))
        crackable = 1.0
        if d.crack.nodes is not None:
            on_path = (d.nodes_of(d.crack.nodes)[None, None, :] == d.corners[:, :, None]).any(axis=2).sum(axis=1) >= 2
            crackable = np.repeat(on_path[:, None], disc.weights.shape[1], axis=1).astype(float)
        if d.crack.mirrored and self.band_width is None:
            width = 2.0 * width
        return CrackBandProblem(disc, self.law, params, conditions(d, open_crack=True), width,
                                strength_factor=at_points(d.strength_factor, disc), crackable=crackable,
                                stiffness_factor=at_points(d.stiffness_factor, disc))

    def observers(self, description, params, damage_threshold: float = 0.0) -> dict:
        return {}


@dataclass(frozen=True)
class PhaseFieldModel(PathFollowingModel):
    """The phase-field regularised cohesive zone model (PF-CZM; Wu 2017, docs/theory.md, section 7): the
    displacements and a crack phase field of length scale ``l`` solved together, whose global response follows
    the cohesive law of its softening shape (Cornelissen's by default; linear, exponential) for any l fine enough
    for the mesh (h <= l / 5 where the crack runs). Runs wherever a damage model runs, and reads a specimen's
    strength imperfection.
    """

    law: PhaseFieldSoftening = PhaseFieldSoftening()

    @property
    def parameters(self) -> type:
        return self.law.parameters

    @property
    def key(self) -> str:
        """``pf-czm-<shape>``: runs of different softening shapes never share a key."""
        return f"pf-czm-{self.law.name}"

    @property
    def differentiable(self) -> tuple:
        return PhaseFieldProblem.differentiable

    #: h <= l / 5 where the crack runs (Wu 2017): the band's profile is then resolved
    mesh_length: ClassVar[MeshLength] = MeshLength("l", "mm", lambda l: l / 5.0, "l / 5 (a fifth of the length scale)",
                                                   "the phase field's band",
                                                   "make the elements where the crack runs {size:.3g} mm or smaller")

    def build(self, specimen, params):
        d = _description(specimen)
        disc = discretize(d)
        return PhaseFieldProblem(disc, params, conditions(d), stiffness_factor=at_points(d.stiffness_factor, disc),
                                 damageable=at_points(d.damageable, disc),
                                 strength_factor=at_points(d.strength_factor, disc))

    def observers(self, description, params, damage_threshold: float = 0.0) -> dict:
        return {}


def known_units() -> dict:
    """Unit of every parameter name of the registered models (:data:`MODEL_TYPES`), those of the
    damage model first where two models share a name."""
    units = {}
    for make in MODEL_TYPES.values():
        for name, unit in make().parameters.units().items():
            units.setdefault(name, unit)
    return units


def parameter_units(model_or_params) -> dict:
    """Units of a model's parameters (from its parameter class or a parameter object)."""
    cls = getattr(model_or_params, "parameters", None) or type(model_or_params)
    return dict(cls.units())


#: The usual values of the parameters of the registered models for quasi-brittle materials (concrete, mortar,
#: rock), wide on purpose: name -> (lower, upper) in the unit of the parameter class (MPa, mm^2, N/mm, -).
#: Concrete: kappa_i ~ 1e-4 (ft / E), c of a few mm^2, beta of a few hundred, ft of 2 to 5 MPa, Gf ~ 0.1 N/mm; the
#: PF-CZM's length scale l of a few mm and its shape constants (p, a2, a3) near Wu's (2, -0.5..1.4, 0..0.7).
USUAL_RANGES = {
    "E": (5.0e3, 1.0e5), "nu": (0.0, 0.45), "kappa_i": (2.0e-5, 1.0e-3), "alpha": (0.0, 1.0), "beta": (10.0, 1.0e4),
    "c": (0.01, 1000.0), "eta": (1.0, 30.0), "ft": (0.5, 20.0), "Gf": (0.005, 1.0), "c1": (0.0, 10.0),
    "c2": (1.0, 20.0), "l": (0.1, 50.0), "p": (1.5, 5.0), "a2": (-0.5, 5.0), "a3": (0.0, 5.0),
}

#: A value further outside its usual range than this factor (above upper * factor, below lower / factor) is
#: implausible: almost surely another unit or scale (kappa_i in per mille, E in GPa, c in cm^2)
IMPLAUSIBLE_FACTOR = 10.0


def usual_range_text(name: str, units: dict | None = None) -> str:
    """The usual range of parameter ``name`` in words, e.g. ``"2e-05 <= kappa_i <= 0.001 [-]"`` ("" if unknown)."""
    if name not in USUAL_RANGES:
        return ""
    lower, upper = USUAL_RANGES[name]
    unit = (units or known_units()).get(name, "-")
    return f"{lower:g} <= {name} <= {upper:g} [{unit}]"


def implausible(name: str, value: float, units: dict | None = None) -> str | None:
    """Why ``value`` of parameter ``name`` is implausible for a quasi-brittle material, or None.

    Implausible: more than :data:`IMPLAUSIBLE_FACTOR` times above the upper end of its
    :data:`USUAL_RANGES` entry, or positive and below its lower end divided by the factor. Parameters
    without a usual range are never implausible.

    Examples
    --------
    >>> implausible("kappa_i", 0.2)
    'kappa_i = 0.2 is 200 times the upper end of its usual range 2e-05 <= kappa_i <= 0.001 [-]'
    >>> implausible("kappa_i", 1e-4) is None
    True
    """
    if name not in USUAL_RANGES or not math.isfinite(value):
        return None
    lower, upper = USUAL_RANGES[name]
    usual = usual_range_text(name, units)
    if value > upper * IMPLAUSIBLE_FACTOR:
        return f"{name} = {value:g} is {value / upper:.3g} times the upper end of its usual range {usual}"
    if 0 < value < lower / IMPLAUSIBLE_FACTOR:  # 0 itself is a bound, not a scale (e.g. beta >= 0)
        return f"{name} = {value:g} is 1/{lower / value:.3g} of the lower end of its usual range {usual}"
    return None


# ``[model] type`` of a configuration -> the forward model (one line per model)
MODEL_TYPES = {
    "gradient-damage": lambda: DamageModel("gradient"),
    "local-damage": lambda: DamageModel("local"),
    "integral-damage": lambda: DamageModel("integral"),
    "cohesive-crack": lambda: CohesiveCrackModel(),
    "crack-band": lambda: CrackBandModel(),
    "pf-czm": lambda: PhaseFieldModel(),
}


def model_from_type(name: str, law: str | None = None):
    """The forward model named ``name`` in a configuration's ``[model] type`` (see :data:`MODEL_TYPES`), with
    the law named ``law`` among its :func:`model_laws` (None: its default law)."""
    try:
        model = MODEL_TYPES[name]()
    except KeyError:
        raise ValueError(f"model type = {name!r}; choose one of {sorted(MODEL_TYPES)}") from None
    if law is None:
        return model
    laws = model_laws(model)
    if law not in laws:
        allowed = ", ".join(map(repr, laws)) or "none: its law is fixed"
        raise ValueError(f"law = {law!r} for model type {name!r}; choose one of {allowed}")
    return replace(model, law=laws[law]())


def model_laws(model) -> dict:
    """The laws a configuration may give ``model`` by name (``[model] law``): the traction-separation laws
    (:data:`~fracid.fem.material.laws.TRACTION_SEPARATION_LAWS`) for the crack models, the softening shapes (:data:`~fracid.fem.material.phase_field.PHASE_FIELD_SHAPES`) for the PF-CZM; none for
    the others (their law is given in Python: ``DamageModel(law=...)``)."""
    if isinstance(model, PhaseFieldModel):
        return dict(PHASE_FIELD_SHAPES)
    return dict(TRACTION_SEPARATION_LAWS) if isinstance(model, _CrackModel) else {}
