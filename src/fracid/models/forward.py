"""One forward analysis: specimen + model parameters -> curves and local data."""

from __future__ import annotations

from fracid.fem.path.path_following import PathResult
from fracid.models.protocol import declared
from fracid.specimens.description import Description


def _specimen_names() -> str:
    from fracid.specimens import SPECIMENS

    return ", ".join(f"{kind!r} -> {cls.__module__}.{cls.__name__}()" for kind, cls in SPECIMENS.items()
                     if cls.default_instance() is not None)


def check_specimen(specimen, model=None) -> None:
    """Raise a TypeError unless ``specimen`` is a specimen object: not a string (the message lists the
    specimen types of a configuration and their classes), a class, None or a number; for a model that
    declares ``needs_description`` (the built-in models), one with ``describe`` or a description. Another
    model may take other specimen objects."""
    if isinstance(specimen, str):
        raise TypeError(f"specimen = {specimen!r} is a name; give a specimen object, e.g. fracid.BarWithWeakZone() "
                        f"(the [specimen] types of a configuration and their classes: {_specimen_names()})")
    if isinstance(specimen, type):
        raise TypeError(f"specimen is the class {specimen.__name__}; give an instance, e.g. {specimen.__name__}()")
    described = isinstance(specimen, Description) or hasattr(specimen, "describe")
    if (specimen is None or isinstance(specimen, (int, float))
            or (model is not None and declared(model).needs_description and not described)):
        raise TypeError(f"specimen is a {type(specimen).__name__}; give a specimen object, e.g. "
                        f"fracid.BarWithWeakZone() (the specimen classes: {_specimen_names()})")


def check_parameters(model, params) -> None:
    """Raise a TypeError unless ``params`` is an instance of ``model.parameters`` (for a dict, the message
    says how to build one); a TypeError too when ``model`` is no forward model
    (:func:`~fracid.models.protocol.declared`)."""
    cls = declared(model).parameters
    if not isinstance(cls, type) or isinstance(params, cls):  # a parameter factory that is no class checks itself
        return
    hint = f"{cls.__name__}(**params)" if isinstance(params, dict) else f"{cls.__name__}(c=2.0)"
    raise TypeError(f"params is a {type(params).__name__}; the model {model.key!r} takes a {cls.__name__} "
                    f"(e.g. {hint}; its parameters: {', '.join(cls.names())})")


def model_with_regularization(model=None, regularization: str | None = None, *, restated: bool = False):
    """The forward model of ``model=`` and of the shorthand ``regularization=`` (``DamageModel(regularization)``).

    Parameters
    ----------
    model : forward model, optional
        A model of :mod:`fracid.models`; if None, ``DamageModel(regularization or "gradient")``.
    regularization : {"gradient", "local", "integral"}, optional
        Not with ``model``, unless ``restated``.
    restated : bool
        Accept a ``regularization`` equal to the model's own (an object that records its model's
        regularization is rebuilt from both, e.g. by :func:`dataclasses.replace`).

    Returns
    -------
    forward model

    Raises
    ------
    ValueError
        Both given (with ``restated``: a ``regularization`` other than the model's).
    """
    from fracid.models import DamageModel, declared

    if model is None:
        return DamageModel(regularization or "gradient")
    if regularization is None:
        return model
    if not restated:
        raise ValueError("give either model= or regularization=, not both")
    if regularization != declared(model).regularization:
        raise ValueError(f"regularization = {regularization!r} contradicts the model {model.key!r}; give one of them")
    return model


def simulate(specimen, params, *, model=None, regularization: None = None, **options) -> PathResult:
    """Run a forward model on ``specimen`` with ``params``.

    Parameters
    ----------
    specimen
        A specimen object (e.g. :class:`~fracid.specimens.bar.BarWithWeakZone`) or its description.
    params
        The model's parameters (:class:`~fracid.fem.material.parameters.DamageParameters` for the damage models).
    model : forward model, optional
        A model of :mod:`fracid.models`; the gradient damage model if None.
    regularization : None
        Removed (issue 37): give ``model=DamageModel(regularization)``; any other value raises TypeError.
    **options
        ``control`` (the prescribed functional; the specimen's default if None), ``target`` (final
        control value [mm]; the specimen's default for the model if None), ``stop_force_fraction``
        (stop when the force falls below this fraction of its peak; None: run to ``target``),
        ``damage_threshold`` (damage above which a point counts in the damaged-zone width [-]),
        ``observables`` (names to record; all if None), ``steps`` (:class:`StepOptions`; the
        specimen's default if None) and the options of :func:`~fracid.fem.path.path_following.follow_path`.

    Raises
    ------
    TypeError
        Before the run: ``specimen`` is not a specimen object (e.g. its name), ``params`` not the
        model's parameter class, or the removed ``regularization`` given.
    """
    if regularization is not None:
        raise TypeError(f"simulate(regularization={regularization!r}) was removed: give the model, "
                        f"model=fracid.models.DamageModel({regularization!r})")
    model = model_with_regularization(model)
    check_specimen(specimen, model)
    check_parameters(model, params)
    return model.simulate(specimen, params, **options)
