"""A specimen with extra displacement functionals (probes), so that a run records them.

A run records every named functional of its specimen's description at every step, and a run with
``sensitivities`` differentiates them exactly (:mod:`fracid.fem.path.ddm`). :class:`ProbedSpecimen` adds
the probes the observation kinds of a run ask for (``{name: ((node, component, weight), ...)}``, the
weighted sum of nodal displacement components [mm]) to the specimen's functionals, one single-node
set per node involved; everything else (controls, default steps and target, observables) is the
specimen's own.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np


def specimen_key(specimen):
    """What identifies a specimen's runs: (hash, specimen) when it hashes (equal frozen specimens
    share runs), else its id."""
    try:
        return (hash(specimen), specimen)
    except TypeError:
        return id(specimen)


def describe(specimen):
    """The specimen's :class:`~fracid.specimens.description.Description` (a description is its own)."""
    return specimen if hasattr(specimen, "node_sets") else specimen.describe()


def _node_set(node: int) -> str:
    return f"probe-node:{node}"


def check_probes(probes) -> dict:
    """``probes`` as ``{name: ((node, component, weight), ...)}`` with int nodes and components and float
    weights, or a ValueError naming the probe at fault."""
    out = {}
    for name, terms in dict(probes).items():
        try:
            out[str(name)] = tuple((int(n), int(c), float(w)) for n, c, w in terms)
        except (TypeError, ValueError):
            raise ValueError(f"probe {name!r}: give its terms as (node, component, weight) triples, got "
                             f"{terms!r}") from None
        if not out[str(name)]:
            raise ValueError(f"probe {name!r} has no terms; give (node, component, weight) triples")
    return out


def merge_probes(kinds) -> dict:
    """The probes of several observation kinds of one run; a ValueError when two define one name differently."""
    merged: dict = {}
    for kind in kinds:
        for name, terms in check_probes(kind.probes).items():
            if merged.setdefault(name, terms) != terms:
                raise ValueError(f"two observations of one run define the probe {name!r} differently; give the "
                                 "observations different names")
    return merged


@dataclass(frozen=True, eq=False)
class ProbedSpecimen:
    """``specimen`` whose description also has the functionals ``probes``.

    Parameters
    ----------
    specimen
        A specimen object (with ``describe()``) or a description.
    probes : dict
        ``{name: ((node, component, weight), ...)}``: functional ``name`` is the sum of ``weight`` times
        the displacement ``component`` (0: x, 1: y) of ``node`` [mm]. Names must not be functionals
        of the specimen already.
    """

    specimen: object
    probes: dict

    def __post_init__(self):
        object.__setattr__(self, "probes", check_probes(self.probes))

    def __getattr__(self, name):  # controls, default_control, default_steps, observables, ... of the specimen
        if name.startswith("__") or name in ("specimen", "probes"):
            raise AttributeError(name)
        return getattr(self.specimen, name)

    def describe(self):
        """The specimen's description with the probes as functionals (and a one-node set per probed node)."""
        from fracid.specimens.description import Measure

        d = describe(self.specimen)
        clash = sorted(set(self.probes) & set(d.functionals))
        if clash:
            raise ValueError(f"probes {clash} are functionals of the specimen already; rename the observation")
        n_nodes = len(d.nodes)
        nodes = {n for terms in self.probes.values() for n, _, _ in terms}
        bad = sorted(n for n in nodes if not 0 <= n < n_nodes)
        if bad:
            raise ValueError(f"probes refer to nodes {bad[:10]} outside the mesh's 0..{n_nodes - 1}")
        components = sorted({c for terms in self.probes.values() for _, c, _ in terms} - set(range(d.dim)))
        if components:
            raise ValueError(f"probes refer to components {components}; a {d.dim}D specimen has 0..{d.dim - 1}")
        node_sets = {**d.node_sets, **{_node_set(n): np.array([n]) for n in sorted(nodes)}}
        functionals = {**d.functionals, **{name: tuple(Measure(_node_set(n), c, w) for n, c, w in terms)
                                           for name, terms in self.probes.items()}}
        return replace(d, node_sets=node_sets, functionals=functionals, _cache=d._cache)
