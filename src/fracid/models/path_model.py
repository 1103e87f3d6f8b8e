"""What the built-in models share: the problem built from the specimen's description, then the path followed
with the specimen's default control, target and steps (:class:`PathFollowingModel`)."""

from __future__ import annotations

from fracid.fem.path.path_following import StepOptions, follow_path
from fracid.models.protocol import ModelDefaults
from fracid.specimens.description import Description, described


def select_observers(observers: dict, names=None) -> dict:
    """The observers named in ``names`` (all if None). Other names are left out: the energies and
    the problem's functionals are recorded at every step anyway."""
    if names is None:
        return observers
    return {name: fn for name, fn in observers.items() if name in set(names)}


class PathFollowingModel(ModelDefaults):
    """``simulate`` of the built-in models: build the problem (``build(description, params)``), follow the
    path with the specimen's default control, target and steps, recording ``observers(description, params,
    damage_threshold)``. A subclass has a ``law`` (its ``scales`` are the law's)."""

    needs_description = True

    def scales(self, params) -> dict:
        """Characteristic strain (and opening) a specimen sizes its default control with."""
        return self.law.scales(params)

    def simulate(self, specimen, params, *, control=None, target=None, stop_force_fraction=0.1, steps=None,
                 damage_threshold=0.0, observables=None, **options):
        description = described(specimen)  # described once: the mesh is built once per run
        reason = self.why_not(description)
        if reason is not None:
            raise TypeError(f"the {self.key} model does not run on a {type(specimen).__name__}: {reason}")
        problem = self.build(description, params)
        target = target if target is not None else self.default_target(specimen, params)
        if steps is None:
            # a description has no steps of its own; a specimen declares them (Specimen.default_steps)
            steps = StepOptions() if isinstance(specimen, Description) else specimen.default_steps(target)
        observers = self.observers(description, params, damage_threshold)
        return follow_path(problem, control or specimen.default_control, target, steps=steps,
                           stop_force_fraction=stop_force_fraction,
                           observers=select_observers(observers, observables), **options)
