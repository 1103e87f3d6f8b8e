"""The written contract of a forward model, :class:`ForwardModel` (described in :mod:`fracid.models`),
the defaults of a model that declares only ``key``, ``parameters`` and ``simulate``
(:class:`ModelDefaults`, :func:`declared`) and :func:`runs_on`.

Everything the outer ring (the configuration, ``fracid init``, ``fracid compare``) asks of a model is a
member here with its default: the length its mesh must resolve (:class:`MeshLength`), the width of its
crack's band (:class:`BandWidth`), the laws a
configuration may name, the parameters a first identification looks for and the specimen fields
``fracid init`` changes for it (:class:`SpecimenStart`). No caller probes a model with ``getattr``.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Callable, ClassVar, Mapping, NamedTuple, Protocol, runtime_checkable


class MeshLength(NamedTuple):
    """The length a model's mesh must resolve where the crack runs, set by one of its parameters (a
    configuration is warned when its element size there is larger).

    Attributes
    ----------
    parameter, unit : str
        The parameter it follows and the parameter's unit.
    length : callable
        Parameter value -> the largest element size [mm].
    text : str
        The length in words, e.g. ``"the internal length l = sqrt(2 c)"``.
    band : str
        What a coarser mesh does not resolve, e.g. ``"the damage band"``.
    advice : str or None
        What to do, with ``{size}`` the largest element size [mm]; None: the specimen's advice
        (:meth:`~fracid.specimens.protocol.Specimen.resolution`, written for h <= l / 2 of an internal length).
    """

    parameter: str
    unit: str
    length: Callable[[float], float]
    text: str
    band: str
    advice: str | None = None


class BandWidth(NamedTuple):
    """The width of the band a model spreads its crack over, set by one of its parameters:
    ``width(value) = factor * value ** exponent`` [mm]. A configuration compares it with the room its
    specimen leaves the band (:meth:`~fracid.specimens.protocol.Specimen.band_room`): warned above
    ``warn`` times the room, refused above it (the band cannot form, and what the model promises fails).

    Attributes
    ----------
    parameter, unit : str
        The parameter it follows and the parameter's unit.
    factor, exponent : float
        width = factor * value ** exponent [mm] (exponent > 0: a larger value, a wider band).
    text : str
        The width in words, e.g. ``"the band's width pi l"``.
    promise : str
        What the model promises while the band fits, e.g. ``"the cohesive law of its softening shape"``.
    warn : float
        The fraction of the room above which the configuration is warned [-] (the reason in the model's docstring).
    beyond : str
        What was measured beyond ``warn`` (how far to trust the warning), e.g. ``"the curve departs ..."``.
    """

    parameter: str
    unit: str
    factor: float
    exponent: float
    text: str
    promise: str
    warn: float
    beyond: str

    def width(self, value: float) -> float:
        """The band's width at ``value`` of the parameter [mm]."""
        return self.factor * value**self.exponent

    def value_for(self, width: float) -> float:
        """The parameter's value whose band is ``width`` [mm] wide (the inverse of :meth:`width`)."""
        return (width / self.factor) ** (1.0 / self.exponent)


class SpecimenStart(NamedTuple):
    """The specimen fields ``fracid init`` writes for a model instead of the specimen's defaults, and why
    (the written configuration's comment says so).

    Attributes
    ----------
    fields : dict
        Field name -> value (e.g. ``{"h_fine": 0.5}`` [mm]).
    why : str
        The reason in words, e.g. ``"a finer mesh ... resolves the phase field's band"``.
    """

    fields: dict
    why: str


#: no laws by name, no specimen fields changed (the read-only defaults of :class:`ModelDefaults`)
_NONE = MappingProxyType({})


@runtime_checkable
class ForwardModel(Protocol):
    """The written contract of a forward model (see the module docstring)."""

    key: str
    parameters: type
    differentiable: tuple
    differentiates_observers: bool
    observer_names: tuple
    regularization: str | None
    mesh_length: MeshLength | None
    band_width: BandWidth | None
    laws: Mapping
    first_identified: tuple | None
    specimen_starts: Mapping
    needs_description: bool
    crack_representation: str

    def simulate(self, specimen, params, **options): ...

    def cohesive_law(self, params): ...

    def runs_on(self, specimen) -> bool: ...

    def why_not(self, specimen) -> str | None: ...

    def scales(self, params) -> dict: ...

    def default_target(self, specimen, params) -> float: ...


class ModelDefaults:
    """The capabilities of a model that declares nothing more than ``key``, ``parameters`` and ``simulate``:
    it runs on every specimen, differentiates nothing, has no observers of its own, no regularisation, no
    length its mesh must resolve, no band of a width of its own and no laws by name, takes the specimen's default target with no
    characteristic scales, a first identification looks for the two parameters after E and nu,
    ``fracid init`` writes the specimens' defaults for it, and it checks its specimen objects itself."""

    differentiable: ClassVar[tuple] = ()
    differentiates_observers: ClassVar[bool] = False
    observer_names: ClassVar[tuple] = ()
    regularization: ClassVar[str | None] = None
    #: the length its mesh must resolve (:class:`MeshLength`), None: no such length
    mesh_length: ClassVar[MeshLength | None] = None
    #: the width of the band it spreads its crack over (:class:`BandWidth`), None: no band (a local model, a crack)
    band_width: ClassVar[BandWidth | None] = None
    #: the laws a configuration may name (``[model] law``): name -> factory of the ``law`` field's value
    laws: ClassVar[Mapping] = _NONE
    #: specimen class -> the :class:`SpecimenStart` ``fracid init`` writes for this model on it
    specimen_starts: ClassVar[Mapping] = _NONE

    #: the parameters a first identification looks for (``fracid init``, ``fracid compare``); None: the two
    #: after E and nu of its parameter class
    first_identified: ClassVar[tuple | None] = None

    #: whether it builds its problem from the specimen's description, so that it takes only a specimen with
    #: ``describe()`` or a :class:`~fracid.specimens.description.Description`; False: it checks its own specimens
    needs_description: ClassVar[bool] = False

    #: how another code represents its crack: ``"discrete"`` (an interface with a traction-separation law) or
    #: ``"smeared"`` (a continuum whose softening is scaled by a crack band width); ``fracid export`` writes that
    crack_representation: ClassVar[str] = "smeared"

    def why_not(self, specimen) -> str | None:
        return None

    def cohesive_law(self, params):
        """The traction-separation law it stands for at ``params``
        (:class:`~fracid.models.cohesive_law.CohesiveLawTable`), None: it declares none (``fracid export`` then
        refuses it); raises ValueError saying why when it has none at all."""
        return None

    def runs_on(self, specimen) -> bool:
        return self.why_not(specimen) is None

    def scales(self, params) -> dict:
        return {}

    def default_target(self, specimen, params) -> float:
        """The specimen's default final control value for this model with ``params`` [mm]."""
        return specimen.default_target(self.scales(params))


@dataclass(frozen=True)
class _Declared(ModelDefaults):
    """A model of a few lines completed by :func:`declared`: what it declares is its own, the rest the
    defaults of :class:`ModelDefaults` (whose methods then see the model's members through the wrapper)."""

    model: object

    # declared here too: a runtime-checkable protocol looks members up statically, past __getattribute__
    @property
    def key(self) -> str:
        return self.model.key

    @property
    def parameters(self) -> type:
        return self.model.parameters

    def simulate(self, specimen, params, **options):
        return self.model.simulate(specimen, params, **options)

    def __getattribute__(self, name):
        model = object.__getattribute__(self, "model")
        if not name.startswith("__") and name != "model" and hasattr(model, name):
            return getattr(model, name)
        return object.__getattribute__(self, name)


def declared(model) -> ForwardModel:
    """``model`` itself when it declares every capability of :class:`ForwardModel`, else ``model``
    completed with the defaults of :class:`ModelDefaults` for the members it lacks (it must have ``key``,
    ``parameters`` and ``simulate``).

    Raises
    ------
    TypeError
        When ``model`` lacks ``key``, ``parameters`` or ``simulate``.
    """
    if isinstance(model, ForwardModel):
        return model
    missing = [name for name in ("key", "parameters", "simulate") if not hasattr(model, name)]
    if missing:
        raise TypeError(f"model = {model!r} is no forward model: it lacks {', '.join(missing)} (see fracid.models)")
    return _Declared(model)


def runs_on(model, specimen) -> bool:
    """Whether ``model`` can run on ``specimen`` (an instance or its class: its default instance); a
    model that declares no ``runs_on`` (:func:`declared`) runs on every specimen."""
    if isinstance(specimen, type):
        specimen = specimen()
    return declared(model).runs_on(specimen)
