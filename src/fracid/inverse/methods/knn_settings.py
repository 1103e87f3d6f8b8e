"""The settings of a KNN population search (:class:`KnnSettings`) and their table ``[identify.knn]`` of the
configuration, shared by every KNN-started method: :func:`knn_from_table` checks it (with the population
limit :data:`MAX_POPULATION`), :func:`knn_template` writes it for ``fracid init``."""

from __future__ import annotations

from dataclasses import dataclass

from fracid.settings import checks as settings
from fracid.settings.checks import SettingError, SettingsContext, bytes_text, toml_line
from fracid.settings.keys import Key, described


@dataclass(frozen=True)
class KnnSettings:
    """The KNN population search (:func:`~fracid.inverse.methods.knn.knn_search`).

    Attributes
    ----------
    n : int
        Population size (for ``method="grid"``: points per parameter).
    method : {"sobol", "lhs", "grid"}
        Design of the population over the parameter space (:func:`~fracid.inverse.methods.knn.design`).
    seed : int
        Seed of the design.
    k : int
        Nearest neighbours whose mean and spread are the Kalman filter's prior.
    start : tuple of float or None
        The prior mean of the local fit instead of the neighbours' mean (units of the parameters; the
        neighbours' spread stays its covariance): the error terms' loops start from the last estimate
        (:mod:`fracid.inverse.likelihood.terms`). Not a key of the configuration.
    screening : float
        The element-size factor of the population's mesh (>= 1): the identification's population runs on a mesh
        this many times coarser where the specimen localises (a screening mesh: each run costs less), the local
        fit then on the configured mesh from the population's prior, so that the estimate is the configured
        mesh's. 1: the population on the configured mesh. Where the specimen cannot be coarsened or the
        screening mesh would not resolve the model's internal length, the population runs on the configured mesh
        and the stage says so (:mod:`fracid.inverse.methods.knn_screening`). The studies' populations (the
        uniqueness maps) stay on the configured mesh: they map the objective, not only rank a start.
    """

    n: int = 64
    method: str = "sobol"
    seed: int = 0
    k: int = 5
    start: tuple | None = None
    screening: float = 1.0

    def population(self, p: int) -> int:
        """Number of forward runs of the population for ``p`` parameters (``n``, or ``n**p`` for a grid)."""
        return self.n**p if self.method == "grid" else self.n


#: largest KNN population (n, or n**p for a grid): each member is one forward run (seconds to
#: minutes each), so 1e5 is already days of computing; n = 1e9 allocated 23.5 GB before the first run
MAX_POPULATION = 100_000

#: the table of the population's settings in ``[identify]``, and its keys
KNN_TABLE = "knn"
#: ``[identify.knn] screening``: the default element-size factor of the population's mesh (benchmarks/demo_speed.py,
#: docs/speed/install.md) and the largest allowed (a coarser mesh resolves too little of a process zone to rank)
DEFAULT_SCREENING = 2.0
MAX_SCREENING = 4.0
#: ``[identify.knn] method``: how the KNN population is sampled (:func:`~fracid.inverse.methods.knn.design`)
KNN_METHODS = ("sobol", "lhs", "grid")
#: the keys of ``[identify.knn]``, described (their meanings are :class:`KnnSettings`'s)
KNN_KEY_DOCS = described({
    "n": Key(64, "", f"integer >= 2; the population (n, or n**p for a grid) at most {MAX_POPULATION:,}"),
    "method": Key("sobol", "", " | ".join(f'"{m}"' for m in KNN_METHODS)),
    "k": Key(5, "", "1 <= k <= the population"),
    "seed": Key(0, "", "integer >= 0"),
    "screening": Key(DEFAULT_SCREENING, "-", f"1 <= screening <= {MAX_SCREENING:g}"),
}, KnnSettings)
KNN_KEYS = tuple(KNN_KEY_DOCS)


def knn_from_table(raw, context: SettingsContext) -> KnnSettings:
    """The :class:`KnnSettings` of the table ``[identify.knn]`` (``raw``, a dict; empty: the defaults).

    Parameters
    ----------
    raw : dict
        The table as given: ``n`` (integer >= 2, default 64), ``method`` (:data:`KNN_METHODS`, default
        ``"sobol"``), ``seed`` (integer >= 0, default 0), ``k`` (1 <= k <= the population, default 5),
        ``screening`` (a number in [1, :data:`MAX_SCREENING`], default :data:`DEFAULT_SCREENING`: the element-size
        factor of the population's mesh, see :class:`KnnSettings`).
    context : SettingsContext
        ``parameters`` (their count p sets a grid's population n**p) and ``n_y`` (the data values, for the
        memory of the population in the message of the limit).

    Raises
    ------
    SettingError
        Naming ``knn.<key>``, the value and what is allowed; ``knn.n`` for a population above
        :data:`MAX_POPULATION` (with its memory).
    """
    raw = settings.table(KNN_TABLE, raw, KNN_KEYS)
    n = settings.integer("knn.n", raw.get("n", 64), "must be an integer >= 2", lambda v: v >= 2)
    method = settings.choice("knn.method", raw.get("method", "sobol"), KNN_METHODS)
    seed = settings.integer("knn.seed", raw.get("seed", 0), "must be an integer >= 0", lambda v: v >= 0)
    p = len(context.parameters)
    knn = KnnSettings(n=n, method=method, seed=seed)
    population = knn.population(p)
    how = f"n**p = {n}**{p}" if method == "grid" else f"n = {n}"
    if population > MAX_POPULATION:
        raise SettingError("knn.n", n, _population_text(population, how, method, p, context.n_y or 0))
    k = settings.integer("knn.k" + ("" if "k" in raw else " (default)"), raw.get("k", 5),
                         f"must be an integer with 1 <= k <= the population size {population} ({how}, method "
                         f"{method!r})", lambda v: 1 <= v <= population)
    screening = settings.number("knn.screening", raw.get("screening", DEFAULT_SCREENING),
                                f"must be a number with 1 <= screening <= {MAX_SCREENING:g} (the element-size factor "
                                "of the population's mesh; 1: the configured mesh)",
                                lambda v: 1.0 <= v <= MAX_SCREENING)
    return KnnSettings(n=n, method=method, seed=seed, k=k, screening=screening)


def _population_text(population: int, how: str, method: str, p: int, n_y: int) -> str:
    """Why a population above :data:`MAX_POPULATION` is refused: its runs and its memory."""
    values = population * (p + n_y)
    return (f"the population of {population:,} points ({how}, method {method!r}) is above the limit of "
            f"{MAX_POPULATION:,}: each point is one forward run (seconds to minutes each), and the points and their "
            f"outputs alone take {values:,} x 8 bytes = {bytes_text(8.0 * values)} (p = {p} parameters + n_y = {n_y} "
            "outputs per point); a few hundred points are enough to start the Kalman filter")


def knn_template(raw: dict, prior: str = "the prior") -> list[str]:
    """The lines of ``[identify.knn]`` in a generated configuration: ``n`` (default 32, a first run's),
    ``method``, ``k`` and ``screening`` of ``raw`` (the values to write), each with its comment; ``prior`` names
    what the neighbours give."""
    return [f"[identify.{KNN_TABLE}]", toml_line("n", raw.get("n", 32), "population of forward runs (the bulk of the cost)"),
            toml_line("method", raw.get("method", "sobol"), " | ".join(f'"{m}"' for m in KNN_METHODS)),
            toml_line("k", raw.get("k", 5), f"neighbours giving {prior}"),
            toml_line("screening", raw.get("screening", DEFAULT_SCREENING),
                      "population on a mesh this many times coarser (1: the configured mesh)")]


__all__ = ["DEFAULT_SCREENING", "KNN_KEYS", "KNN_KEY_DOCS", "MAX_SCREENING", "KNN_METHODS", "KNN_TABLE", "MAX_POPULATION", "KnnSettings", "knn_from_table", "knn_template"]
