"""One forward analysis: specimen + model parameters -> curves and local data."""

from __future__ import annotations

from fracid.fem.path_following import PathResult


def simulate(specimen, params, *, model=None, regularization: str | None = None, **options) -> PathResult:
    """Run a forward model on ``specimen`` with ``params``.

    Parameters
    ----------
    specimen
        A specimen object (e.g. :class:`~fracid.specimens.bar.BarWithWeakZone`) or its description.
    params
        The model's parameters (:class:`~fracid.fem.parameters.DamageParameters` for the damage models).
    model : forward model, optional
        A model of :mod:`fracid.models`; the gradient damage model if None.
    regularization : {"gradient", "local", "integral"}, optional
        Shorthand for ``model=DamageModel(regularization)``.
    **options
        ``control`` (the prescribed functional; the specimen's default if None), ``target`` (final
        control value [mm]; the specimen's default for the model if None), ``stop_force_fraction``
        (stop when the force falls below this fraction of its peak; None: run to ``target``),
        ``damage_threshold`` (damage above which a point counts in the damaged-zone width [-]),
        ``observables`` (names to record; all if None), ``steps`` (:class:`StepOptions`; the
        specimen's default if None) and the options of :func:`~fracid.fem.path_following.follow_path`.
    """
    from fracid.models import DamageModel

    if model is None:
        model = DamageModel(regularization or "gradient")
    elif regularization is not None:
        raise ValueError("give either model= or regularization=, not both")
    return model.simulate(specimen, params, **options)
