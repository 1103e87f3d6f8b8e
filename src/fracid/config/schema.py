"""The schema of a TOML configuration, its vocabularies and limits, and the frozen dataclasses of a
validated one (:class:`Config` and its sections).

Schema
------
The sections ``[[experiments]]`` and ``[identify]`` are required for identification
(``purpose="identify"``) and optional for a forward analysis (``purpose="simulate"``); when
present they are always validated. Every other key is optional unless marked *required*. The keys and
values allowed are named in :mod:`fracid.config.vocabulary`.

.. code-block:: toml

    [model]                             # optional; defaults: gradient damage, DamageParameters()
    type = "gradient-damage"            # any name of fracid.models.MODEL_TYPES, read when the file is
                                        #   validated: "gradient-damage" | "local-damage" (mesh-
                                        #   dependent) | "cohesive-crack" (Hordijk crack on the beam's
                                        #   ligament; parameters E nu ft Gf c1 c2) | "crack-band" |
                                        #   "pf-czm" (phase-field cohesive zone model; E nu ft Gf l p a2 a3)
    law = "hordijk"                     # optional, cohesive-crack and crack-band: the traction-separation
                                        #   law by name (fracid.fem.material.laws.TRACTION_SEPARATION_LAWS):
                                        #   "hordijk" (default) | "linear" | "bilinear"; the parameters are
                                        #   then the law's (linear: E nu ft Gf; bilinear: + psi chi);
                                        #   pf-czm: the softening shape "cornelissen" (default) |
                                        #   "linear" | "exponential" (parameters E nu ft Gf l p a2 a3)
    [model.parameters]                  # any subset of the model's parameters (its parameter class's
                                        # names(); checked by its own validation); the rest take the
                                        # class's defaults. Gradient and local damage (DamageParameters):
                                        # E 20000, nu 0.2, kappa_i 1e-4, alpha 0.99, beta 300, c 1, eta 10
    E = 37000.0                         # MPa, E > 0
    nu = 0.2                            # -, -1 < nu < 0.5
    kappa_i = 6.6e-5                    # -, kappa_i > 0
    alpha = 0.99                        # -, 0 <= alpha <= 1
    beta = 600.0                        # -, beta >= 0
    c = 9.0                             # mm^2, c > 0
    eta = 10.0                          # -, eta >= 1

    [specimen]                          # required
    type = "notched-beam"               # required: a key of fracid.specimens.SPECIMENS: "notched-beam" |
                                        #   "dogbone" | "bar" | "wedge-splitting" | "strip" | "mesh" (its
                                        #   own keys: fracid.specimens.mesh_section) | specimens added later
    control = "cmod"                    # the specimen's default if omitted:
                                        #   notched-beam: "cmod" (default) | "deflection"
                                        #   dogbone:      "elongation" (default) | "platen_displacement"
                                        #   bar:          "end_displacement" (default) | "weak_zone_elongation"
    # every other key is a field of the specimen class, type-checked (lengths in mm):
    #   notched-beam (NotchedBeam): depth thickness length span notch_depth notch_width plate_width
    #                               h_fine h_coarse fine_width
    #   dogbone (DogBone):          size thickness gauge_length h_fine fine_height h_coarse
    #                               notch_radius notch_width platens ("glued" | "hinged")
    #                               platen_height platen_stiffness hinge_offset
    #   bar (BarWithWeakZone):      length area (mm^2) weak_zone_width weak_zone_factor
    #                               weakening ("modulus" | "area") profile ("step" | "hat")
    #                               n_elements (integer)
    h_fine = 1.0

    [[experiments]]                     # one or more data blocks, stacked in this order into y_exp
    file = "load_cmod.csv"              # required: CSV with a header row, relative to this file
    control_column = "cmod_mm"          # required: column of the control quantity
    control_unit = "mm"                 # required: "mm" | "um" | "m" (scaled to mm)
    force_unit = "N"                    # required: quantity "force": "N" | "kN" | "MN" (scaled to N);
                                        #   a local quantity: its unit, "mm" | "um" | "m" (scaled to mm)
    kind = "envelope"                   # required: "repeats" | "envelope" | "single"
    #   repeats:  force_columns = ["F1", "F2", ...]   (>= 2 columns: mean and sample std of the repeats)
    #   envelope: mean_column, lower_column, upper_column   (std = (upper - lower) / 4)
    #   single:   force_columns = ["F"]  (exactly 1) and either std (absolute, in force_unit, > 0)
    #             or relative_std (fraction of |y|, > 0)
    mean_column = "load_mean_N"
    lower_column = "load_min_N"
    upper_column = "load_max_N"
    n_points = 40                       # required: integer >= 3, the number of data values
    sampling = "equally-spaced"         # "equally-spaced" (default): n_points equally spaced control
                                        #   values, the one nearest the measured peak moved onto it (the
                                        #   data keep the peak) | "measured": the measured points
                                        #   themselves, all if there are at most n_points, else n_points of
                                        #   them by arc length along the normalised curve (ends, peak kept)
    # negate = ["control", "force"]    # columns a machine records with a negative sign, multiplied by -1
    control_range = [0.001, 0.2]        # optional [start, stop], 0 < start < stop, in control_unit;
                                        #   default: the range common to the columns
    quantity = "force"                  # "force" (default) or a local observable of the specimen:
                                        #   notched-beam, dogbone: "fpz_width"; bar: "damaged_zone_width"
    name = "global"                     # block name; default "global" (force) or the quantity's name
    specimen = { size = 200.0 }         # optional: fields of [specimen] overridden for this test (a size
                                        #   series: one block per size); blocks of the same specimen
                                        #   share one forward run
    weight = 1.0                        # optional p_b > 0: f = sum p_b f_b (global p1, local p2); the
                                        #   block's covariance is divided by p_b
    damage_threshold = 0.5              # optional, local quantity only: 0 <= t < 1, damage counted in
                                        #   the width (default 0: any damage)
    role = "calibration"                # "calibration" (default) | "prediction": predicted at the
                                        #   estimate by `fracid study`, not calibrated on | "source": read
                                        #   and checked only (the field a derived block comes from)
    delimiter = ","                     # cell separator: "," (default) | ";" | "\\t" (or "tab") | " " (any
                                        #   run of spaces and tabs)
    decimal = "."                       # decimal mark: "." (default) | "," (0,001); "," needs another delimiter
    backtrack_tolerance = 0.002         # optional number >= 0 in control_unit: the largest backtrack of the
                                        #   control column dropped as noise (default 1 % of its range)

    [[experiments]]                     # a DIC displacement field (fracid.inverse.experiments.field):
    kind = "field"                      #   its own keys, read while checking; examples/dic/identify.toml
    frames_file = "frames.csv"          # required: frame table (frame, file, load columns), relative here
    control_column = "cmod_mm"          # required: the table's control value of each frame [mm]
    # x, y, u, v = "X", "Y", "U", "V"  # point-cloud columns (these defaults); sigma, quality optional
    # displacement = "U"                # frames listed as .vtu/.vtk files: their displacement array (default
                                        #   "displacement", else "U"); sigma, quality name point-data arrays
    # min_quality = 0.9                 # points of lower quality dropped (needs quality)
    coordinate_unit = "px"              # "mm" (default) | "px" (needs the placement)
    scale = 0.1                         # placement: mm per camera unit, rotation_deg, origin_camera [X, Y],
                                        #   origin_specimen [x, y] mm; or marked_camera and marked_specimen
                                        #   (lists of the same points in both frames, fitted); points off the
                                        #   specimen's mesh: up to 10 % dropped (warned), more refused
    # frames = [1, 2, 3]                # frame numbers used (default all), control increasing; a frame
                                        #   without any valid value is dropped (warned)
    # components = ["u", "v"]           # "u" | "v" | both (default)
    # std = 0.001                       # mm, every value; default the files' sigma (scaled to mm)
    # subset_size = 6.0                 # mm: errors correlated over a subset (low rank + diagonal)
    # rigid_motion = true               # the rigid motion of every frame removed from data and model (default;
    # rigid_std = 1.0                   #   false: none), by a vague prior of this std [mm] (default 1)
    # exclude_near = 4.0                # mm: points nearer the specimen's crack path dropped
    # point_spacing = 3.0               # mm: thin a dense field to one point per square of this side
    # name = "field", weight = 1.0, role = "calibration"

    [[experiments]]                     # local data derived from a field block (fracid.inverse.experiments.derived):
    kind = "opening"                    #   "opening": the crack-opening profile by virtual extensometers across
                                        #   the crack | "fpz-width": the process-zone width by strain transects
    field = "field"                     # required: the name of a kind = "field" block of this file; give that
                                        #   block role = "source" (its measurements not counted twice)
    heights = [30, 35, 40, 45]          # required, mm: positions along the ligament, increasing
    gauge = 6.0                         # "opening", required, mm: half-length of the gauges (ends at +-gauge
                                        #   from the crack line), beyond the band of missing points
    radius = 5.0                        # required, mm: radius of the plane fits (>= 1.5 DIC point spacings)
    # pairs = false                     # "opening": ends on both sides of the crack (true: the rigid motion
                                        #   cancels) or one, the symmetric half, w = 2 u_n(+gauge) (false: the
                                        #   field's rigid_motion prior makes each frame's mean and tilt
                                        #   uninformative); default: true if the field has points on both sides
    # offsets = [5, 8, 11, 14]          # "fpz-width", required, mm: samples of each transect, signed distances
                                        #   from the crack line (positive on the modelled side), increasing
    # threshold = 3e-5                  # "fpz-width", required, > 0: the strain above which a sample counts
    # name = "opening" ("fpz_width"), weight = 1.0, role = "calibration"

    [identify]                          # required for identification
    parameters = ["kappa_i", "beta", "c"]   # required: parameters of the [model] type to identify,
                                            #   no duplicates
    method = "knn-kalman"               # inverse method (fracid.inverse.methods.registry.METHODS): "knn-kalman"
                                        #   (default: KNN population, then the Kalman filter) |
                                        #   "knn-gauss-newton" (KNN, then bounded Gauss-Newton on the same
                                        #   objective; settings in [identify.gauss-newton])
    [identify.bounds]                   # required: [lower, upper] for every identified parameter,
                                        #   lower < upper, both inside the parameter's valid range
    kappa_i = [4e-5, 1.2e-4]
    beta = [100.0, 2000.0]
    c = [1.0, 30.0]                     # mm^2
    log = ["beta"]                      # optional: sampled uniformly in log(x); needs lower > 0
    # The tables below are the built-in methods' settings: the configuration allows every table a
    # registered method declares (its config_tables) and the method's from_config checks its own
    # ([identify.knn]: fracid.inverse.methods.knn_settings; [identify.kalman]: fracid.inverse.methods.kalman_settings;
    # [identify.gauss-newton]: knn_gauss_newton.KnnGaussNewton); a method's own table is [identify.<name>].
    [identify.knn]                      # optional
    n = 64                              # integer >= 2 (grid: points per parameter), default 64
    method = "sobol"                    # "sobol" (default) | "lhs" | "grid"
    k = 5                               # neighbours, 1 <= k <= population (n, or n**p for grid), default 5
    seed = 0                            # integer >= 0, default 0
    screening = 2.0                     # 1 <= screening <= 4, default 2: the population runs on a mesh this many
                                        #   times coarser (element sizes x screening), the fit on the configured
                                        #   one; 1: the configured mesh. A mesh file, or a screening mesh resolving
                                        #   the internal length over less than half its range, runs it on the
                                        #   configured mesh (the stage line says so). The studies' populations
                                        #   stay on the configured mesh
    [identify.kalman]                   # optional
    groups = 4                          # consecutive observation groups, 1 <= groups <= n_y (total
                                        #   n_points); default 4 (n_y if fewer)
    max_iterations = 10                 # integer >= 1, default 10
    tol = 0.01                          # > 0, in standard deviations, default 0.01
    restart = "linearize"               # "linearize" (default) | "prior-mean"
    max_starts = 3                      # integer >= 1, default 3: after a poor end (chi^2 per point > 10), the
                                        #   filter starts again from the next-best population points
    [identify.gauss-newton]             # optional, read when method = "knn-gauss-newton"
    max_iterations = 20                 # integer >= 1: linearisations at most, default 20
    tol = 0.01                          # > 0, in standard deviations, default 0.01
    # The error terms of the likelihood (fracid.inverse.likelihood), each a word or a table with that word as
    # kind; the identification is run again with them (its stored runs reused):
    # discretisation_error = "richardson"  # "off" (default) | "richardson": the mesh's error at the estimate from
    #                                     #   a mesh refined twice (Richardson), added to the data covariance
    [identify.discretisation_error]     # optional, the same with its settings:
    kind = "richardson"
    refinement = 2.0                    # 1 < r <= 4: the refined mesh has h / r (bar: n_elements x r), default 2
    observed_order = false              # true: also a mesh of h x r, the order observed per block (guarded)
    order = 1.0                         # 0.5 <= p <= 4: the order where not observed (default 1, conservative)
    correlation_length = 0.25           # > 0: along the control, a fraction of each block's range
    iterations = 1                      # 1 <= n <= 10: identifications with the term (more: recomputed at each)
    # model_error = "variance"          # "off" (default) | "variance" | "bias": the model's own error identified
    [identify.model_error]              # optional, the same with its settings:
    kind = "variance"                   # "variance" (independent, std sigma_m) | "bias" (smooth along the control)
    prior = "half-cauchy"               # "half-cauchy" (default) | "log-uniform"
    scale = 0.05                        # > 0: the half-Cauchy's scale, a fraction of the group's peak |y|
    bounds = [1e-4, 1.0]                # 0 < lower < upper: the range of sigma_m, fractions of the peak
    groups = "block"                    # "block" (one sigma_m per [[experiments]] block) | "quantity"
    correlation_length = 0.25           # "bias": along the control, a fraction of each block's range
    iterations = 3                      # 1 <= n <= 10: fixed-point loops at most

    [study]                             # optional: the checks of `fracid study`
    starts = 3                          # multi-start Kalman filters from distinct population points
                                        #   (0 or 1: no check), default 3
    replicates = 5                      # identifications on data with noise added (0: none; else >= 2)
    seed = 0                            # seed of the replicates' noise, default 0
    tolerance = 0.1                     # largest relative std called "identified", default 0.1
    prior = "search"                    # refinement's prior covariance: "search" (the search's, default)
                                        #   | "bounds" (uniform over the bounds: the data's information only)
    posterior = false                   # true: `fracid study` also samples the posterior with the
                                        #   [posterior] settings; the verdict then uses its 90 % credible
                                        #   intervals instead of the Gaussian std (default false)

    [posterior]                         # optional: the sampler of `fracid posterior` (adaptive importance
                                        #   sampling on the exact model, prior uniform between the bounds)
    samples_per_round = 200             # integer >= 2: forward runs per round (side by side), default 200
    max_rounds = 10                     # integer >= 1, default 10 (runs at most: samples_per_round x max_rounds)
    target_ess = 500.0                  # > 1: stop at this effective sample size, default 500
    components = 8                      # integer >= 1: Gaussian components of the adapted proposals, default 8
    defensive = 0.1                     # 0 <= d < 1: share of the prior in every proposal, default 0.1
    inflation = 2.0                     # > 0: std multiplier of the first proposal around the Kalman
                                        #   estimate, default 2
    seed = 0                            # integer >= 0: seed of the draws (same seed: same runs, reused)
    screening = 1.0                     # 1 <= s <= 4: screen the draws on a mesh s times coarser and correct
                                        #   them by fine runs (the fine model's posterior, its Monte-Carlo
                                        #   error stated); 1: every draw a fine run. Default 1; where the
                                        #   mesh cannot be coarsened (a mesh file), every draw is a fine run
                                        #   and the results say so
    fine_runs = 300                     # integer >= 2: with screening, fine runs at most, default 300

    [output]                            # optional
    directory = "results"               # default "results", relative to this file unless absolute
    vtk_steps = []                      # integers >= 0: steps whose fields go to VTK (simulate)

    [simulate]                          # optional: settings of a forward analysis
    target = 0.3                        # mm, > 0; default: the specimen's
    stop_force_fraction = 0.1           # 0 < f < 1, default 0.1: stop below f x peak force
    damage_threshold = 0.0              # 0 <= t < 1, default 0: damage counted in widths
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from fracid.config.registry import model_of
from fracid.models.registry import DEFAULT_MODEL_TYPE
from fracid.config.vocabulary import DEFAULT_INVERSE_METHOD, SIMULATE, STUDY
from fracid.inverse.sampling.posterior import PosteriorSettings


class ConfigError(ValueError):
    """An invalid configuration: the message names the file, the dotted key, the value and what is allowed."""


# ------------------------------------------------------------------------------ size limits
# A configuration asking for more than a workstation can hold is refused when it is loaded, with
# the estimate, instead of failing (or swapping for hours) in the middle of a study.

# The largest KNN population (MAX_POPULATION) is the KNN settings' (fracid.inverse.methods.knn_settings), checked
# by the methods that read [identify.knn]; the limits of a forward run's memory (MAX_BAR_ELEMENTS,
# BAR_BYTES_PER_ELEMENT, MAX_UNKNOWNS, BYTES_PER_UNKNOWN) are the specimens' (fracid.specimens.protocol).


# ------------------------------------------------------------------------------ validated config


@dataclass(frozen=True)
class ModelConfig:
    """``[model]``: the model type, its law and the parameter values given (the rest are defaults)."""

    type: str = DEFAULT_MODEL_TYPE
    parameters: tuple = ()  # ((name, value), ...) as given
    law: str | None = None  # a law of the model by name (fracid.models.model_laws); None: its default

    @property
    def regularization(self) -> str | None:
        """The ``regularization`` argument of :func:`fracid.models.forward.simulate` for the damage models
        (``"gradient"``, ``"local"``); None for a model that has none (e.g. the cohesive crack)."""
        return model_of(self.type, self.law).regularization


@dataclass(frozen=True)
class SpecimenConfig:
    """``[specimen]``: type, control (resolved to the default when omitted) and the dataclass fields given."""

    type: str
    control: str
    options: tuple = ()  # ((field, value), ...) as given, type-checked


@dataclass(frozen=True)
class IdentifyConfig:
    """``[identify]``: identified parameters, their bounds and log flags, the inverse method (a key of
    :data:`fracid.inverse.methods.registry.METHODS`) and the tables of the methods' settings."""

    parameters: tuple
    lower: tuple
    upper: tuple
    log: tuple = ()  # names sampled in log scale
    method: str = DEFAULT_INVERSE_METHOD
    #: the tables of the methods' settings ``[identify.<table>]`` given, by name, as read (the methods that
    #: read them check them: :func:`fracid.config.identify.method_from_config`)
    tables: dict = field(default_factory=dict)
    #: the error terms added to the data covariance (None: "off"): a
    #: :class:`~fracid.inverse.likelihood.settings.DiscretisationError` and a
    #: :class:`~fracid.inverse.likelihood.settings.ModelError`
    discretisation_error: object = None
    model_error: object = None


@dataclass(frozen=True)
class OutputConfig:
    """``[output]``: ``directory`` absolute (resolved against the config file)."""

    directory: Path
    vtk_steps: tuple = ()


@dataclass(frozen=True)
class SimulateConfig:
    """``[simulate]``: target [mm] (None: the specimen's), stop_force_fraction, damage_threshold."""

    target: float | None = None
    stop_force_fraction: float = SIMULATE["stop_force_fraction"].default
    damage_threshold: float = SIMULATE["damage_threshold"].default


@dataclass(frozen=True)
class StudyConfig:
    """``[study]``: multi-start points, noisy replicates, their seed, the tolerance of the verdict, the
    Kalman prior, and whether ``fracid study`` samples the posterior (its verdict then reads it)."""

    # the defaults are the vocabulary's (fracid.config.vocabulary.STUDY), where each key is described
    starts: int = STUDY["starts"].default
    replicates: int = STUDY["replicates"].default
    seed: int = STUDY["seed"].default
    tolerance: float = STUDY["tolerance"].default
    prior: str = STUDY["prior"].default
    posterior: bool = STUDY["posterior"].default


#: ``[posterior]``: the sampler's own settings object (its defaults are the section's; the section's checker
#: gives the messages, so that building it never raises)
PosteriorConfig = PosteriorSettings


@dataclass(frozen=True)
class Config:
    """A validated configuration (see the module docstring for the schema)."""

    path: Path
    purpose: str
    model: ModelConfig
    specimen: SpecimenConfig
    experiments: tuple  # of the kinds' validated blocks (fracid.inverse.experiments); empty if none given
    identify: IdentifyConfig | None
    output: OutputConfig
    simulate: SimulateConfig
    study: StudyConfig = StudyConfig()
    posterior: PosteriorConfig = PosteriorConfig()
    warnings: tuple = ()  # of str: valid but probably unintended settings, for the user to read

    @property
    def calibration(self) -> tuple:
        """The experiments used for calibration (role "calibration")."""
        return tuple(e for e in self.experiments if e.role == "calibration")

    @property
    def n_y(self) -> int:
        """Number of measured values used for calibration (sum of their blocks' n_points)."""
        return sum(e.n_points for e in self.calibration)
