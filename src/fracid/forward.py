"""One forward analysis: specimen + model parameters -> curves and local data."""

from __future__ import annotations

from fracid.model.path_following import PathResult, StepOptions, follow_path
from fracid.model.solver import NewtonOptions


def select_observers(observers: dict, names=None) -> dict:
    """The observers named in ``names`` (all if None). Other names are left out: the energies and
    the problem's functionals are recorded at every step anyway."""
    if names is None:
        return observers
    return {name: fn for name, fn in observers.items() if name in set(names)}


def simulate(
    specimen,
    params,
    *,
    regularization: str = "gradient",
    control: str | None = None,
    target: float | None = None,
    stop_force_fraction: float | None = 0.1,
    damage_threshold: float = 0.0,
    observables=None,
    steps: StepOptions | None = None,
    newton: NewtonOptions = NewtonOptions(),
    linear_solver=None,
    field_steps="last",
    max_steps: int = 2000,
    callback=None,
    checkpoints=None,
) -> PathResult:
    """Run the forward model of ``specimen`` with ``params``.

    Parameters
    ----------
    specimen
        A specimen object (e.g. :class:`~fracid.specimens.bar.BarWithWeakZone`).
    params : DamageParameters
    regularization : {"gradient", "local", "integral"}
    control : str, optional
        Prescribed quantity; the specimen's default (plain displacement control) if None.
    target : float, optional
        Final control value [mm]; the specimen's default if None.
    stop_force_fraction : float or None
        Stop when the force falls below this fraction of its peak (None: run to ``target``).
    damage_threshold : float
        Damage above which a point counts in the damaged-zone width [-].
    observables : iterable of str, optional
        The specimen's observables to record along the path (e.g. ``["fpz_width"]``); all of them if
        None. Energies and functionals are always recorded.
    steps : StepOptions, optional
        Step-size rule; the specimen's default (``specimen.default_steps(target)``) if None.

    Other parameters are passed to :func:`~fracid.model.path_following.follow_path`.
    """
    problem = specimen.build_problem(params, regularization)
    target = target if target is not None else specimen.default_target(params)
    if steps is None:
        steps = specimen.default_steps(target) if hasattr(specimen, "default_steps") else StepOptions()
    return follow_path(
        problem,
        control or specimen.default_control,
        target,
        steps=steps,
        stop_force_fraction=stop_force_fraction,
        max_steps=max_steps,
        newton=newton,
        linear_solver=linear_solver,
        observers=select_observers(specimen.observers(params, damage_threshold), observables),
        field_steps=field_steps,
        callback=callback,
        checkpoints=checkpoints,
    )
